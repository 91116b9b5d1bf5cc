"""Scenes on any scheduler (process/scheduler.py, scenes/queue.py): --scheduler and --jobs read
in one line; a scene's result for a seed the same bit for bit in this process, on a local
cluster and on a running scheduler reached by TCP; a worker that dies retried as --retries says,
no scene whose result has arrived run again."""
import json
from pathlib import Path

import pytest

from yadebreak.process.scheduler import Scheduler, SchedulerError, chosen, usable_cores


@pytest.mark.parametrize("text, kind, workers, shown", [
    ("local", "local", None, "local"), ("local:3", "local", 3, "local:3"),
    ("tcp://head:8786", "tcp", None, "tcp://head:8786"), ("slurm", "slurm", None, "slurm"),
    ("pbs:4", "pbs", 4, "pbs:4")])
def test_the_scheduler_forms(text, kind, workers, shown):
    s = Scheduler.parse(text)
    assert (s.kind, s.workers, str(s)) == (kind, workers, shown)


def test_worker_counts_and_what_runs_here():
    assert Scheduler.parse("local").count == usable_cores()
    assert Scheduler.parse("slurm").count == 1 and Scheduler.parse("tcp://h:1").count is None
    assert Scheduler.parse("local:1").in_process and not Scheduler.parse("tcp://h:1").in_process


@pytest.mark.parametrize("text, message", [
    ("local:0", "--scheduler = local:0: N must be a whole number >= 1"),
    ("local:x", "--scheduler = local:x: N must be a whole number >= 1"),
    ("tcp://", "--scheduler = tcp://: tcp:// needs HOST:PORT"),
    ("lsf", "--scheduler = lsf: accepted local, local:N")])
def test_a_form_not_accepted_is_one_line(text, message):
    with pytest.raises(SchedulerError, match="^" + message.replace("+", r"\+")):
        Scheduler.parse(text)


def test_jobs_is_a_spelling_of_local_n_and_both_are_refused():
    assert chosen("", 3) == Scheduler("local", 3)
    assert chosen("tcp://h:1", None) == Scheduler("tcp", None, "tcp://h:1")
    assert chosen("", None) == Scheduler("local")
    with pytest.raises(SchedulerError, match=r"^--scheduler = local:2 and --jobs = 2: give one "
                                             r"\(--jobs N is --scheduler local:N\)$"):
        chosen("local:2", 2)


def test_a_script_refuses_both_in_one_line(capsys):
    from yadebreak.jobs import options as job_options
    with pytest.raises(SystemExit) as end:
        job_options.read("single_impact", None, ["--jobs", "2", "--scheduler", "local:2"])
    err = capsys.readouterr().err.strip().splitlines()
    assert end.value.code == 2 and err == [
        "[yadebreak] error: --scheduler = local:2 and --jobs = 2: give one (--jobs N is "
        "--scheduler local:N)"]


def _timeless(tally):
    return {k: v for k, v in tally.to_dict().items()
            if k not in ("scene_wall_s", "scene_walls", "yade_engines_s")}


@pytest.mark.yade
def test_a_scene_gives_the_same_result_on_every_scheduler(scene, tmp_path):
    """Six 5.5 mm copper ore particles at 700 J/kg (cascades, two scenes of three at the end of
    each set), here, on local:2 and on a running scheduler reached by its tcp:// address: the
    tallies and the event logs agree to the last digit (but the times taken: each tally carries
    the time YADE's own engines took, a part of its scenes' time)."""
    from yadebreak import scenes
    from yadebreak.process.scheduler import LocalCluster
    running = LocalCluster(2)                       # a scheduler someone else started
    try:
        got = {}
        for name, scheduler in (("here", None), ("local:2", Scheduler.parse("local:2")),
                                ("tcp", Scheduler.parse(running.address))):
            log = tmp_path / f"{name.replace(':', '')}.jsonl"
            tally, _ = scenes.single_impacts("copper_ore", 5.5e-3, 37.4, 6, 1, 3,
                                             event_log=str(log), scheduler=scheduler,
                                             time_step_fraction=0.05)
            got[name] = (_timeless(tally), log.read_text())
            assert not log.with_suffix(".workers").exists()      # the workers' events joined
            assert 0.0 < tally.yade_engines_s < tally.scene_wall_s
            assert tally.mass_relative_error < 1e-12 and tally.scenes == 6
            assert not scene.timingEnabled                       # YADE's timing as it was
    finally:
        running.close()
    assert got["here"][0]["breakage_events"] > 0
    assert json.dumps(got["local:2"]) == json.dumps(got["here"])
    assert json.dumps(got["tcp"]) == json.dumps(got["here"])


def mortal_scene(spec, k):
    """A task's scene that kills its worker the first time scene `spec["dies"]` runs; every run
    of a scene leaves a line in <folder>/<k>.runs."""
    import os
    folder = Path(spec["folder"])
    runs = folder / f"{k}.runs"
    with open(runs, "a") as f:
        f.write("run\n")
    if k == spec["dies"] and len(runs.read_text().splitlines()) == 1:
        os._exit(3)
    return k * k


@pytest.mark.parametrize("retries", [1, 0])
def test_a_worker_that_dies_is_retried_and_no_finished_scene_runs_again(tmp_path, retries,
                                                                        monkeypatch):
    """Scene 2 of 6 kills its worker once: with --retries 1 every scene's result arrives and
    scene 2 ran twice, every other once; with --retries 0 the run stops naming the scene."""
    from yadebreak.scenes.queue import SceneQueue
    monkeypatch.setenv("PYTHONPATH", str(Path(__file__).parent))     # the workers' imports
    spec = {"task": "test_scheduler:mortal_scene", "counts": [1] * 6, "folder": str(tmp_path),
            "dies": 2}
    with SceneQueue(Scheduler.parse("local:2"), retries=retries) as queue:
        if retries == 0:
            with pytest.raises(RuntimeError, match=r"scenes 2-2 failed 1 times \(--retries 0\)"):
                queue.collect(queue.submit(spec))
            return
        assert queue.collect(queue.submit(spec)) == [k * k for k in range(6)]
    runs = {k: len((tmp_path / f"{k}.runs").read_text().splitlines()) for k in range(6)}
    assert runs == {0: 1, 1: 1, 2: 2, 3: 1, 4: 1, 5: 1}
