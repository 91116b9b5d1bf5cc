"""Interrupted script runs continue with --resume 1 and give what an uninterrupted run gives
(issue 7). The scripts run as users run them: yade -n -x scripts/<name>.py ..."""
import json
import subprocess
from pathlib import Path

import pytest

from wall_times import timeless  # tests/wall_times.py

pytestmark = pytest.mark.yade

ROOT = Path(__file__).resolve().parent.parent


def _script(name, out, *extra):
    proc = subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / f"{name}.py"),
                           "--out", str(out), *extra], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-1500:] + proc.stderr[-1500:]
    return proc.stdout


@pytest.mark.parametrize("name, arguments", [
    ("repeated_impact", ["--material", "ab_t10_ore", "--size", "5.5e-3", "--energy", "180",
                         "--impacts", "4", "--particles", "30"]),
    ("single_impact", ["--material", "limestone", "--energies", "60,120", "--particles", "30",
                       "--jobs", "1"]),
    ("drop_weight", ["--material", "limestone", "--energies", "60,120", "--particles", "6",
                     "--max-time", "3e-4"]),
])
def test_interrupted_script_resumes_to_the_same_result(tmp_path, name, arguments):
    _script(name, tmp_path / "whole", *arguments)
    _script(name, tmp_path / "cut", *arguments, "--stop-after", "1")
    assert not (tmp_path / "cut" / "summary.json").exists()        # it did stop early
    log = _script(name, tmp_path / "cut", *arguments, "--resume", "1")
    assert "resum" in log
    whole = json.loads((tmp_path / "whole" / "summary.json").read_text())
    cut = json.loads((tmp_path / "cut" / "summary.json").read_text())
    assert timeless(cut) == timeless(whole)


def test_resume_with_other_arguments_is_refused(tmp_path):
    args = ["--material", "limestone", "--jobs", "1", "--energies", "60,120", "--particles", "20"]
    _script("single_impact", tmp_path, *args, "--stop-after", "1")
    proc = subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / "single_impact.py"),
                           "--out", str(tmp_path), *args[:-1], "30", "--resume", "1"],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode != 0
    assert "other values of ['particles']" in proc.stdout + proc.stderr


def _bed_args(out, **changes):
    """A one-ring bed under 0.6 J (3 breakages, 19,400 steps, about 3 s)."""
    import argparse
    values = dict(material="copper_ore", size=5.5e-3, rings=1, layers=1, energy=0.6, speed=0.0,
                  seed=3, time_step_fraction=0.05, dmin=0.0, global_damping="material",
                  dummies="ledger", read_period="fast", max_time=0.02, out=str(out),
                  checkpoint_every=-1.0, vtk_interval=2e-4, resume=False, stop_after=0.0)
    values.update(changes)
    return argparse.Namespace(**values)


def _events(out):
    return [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]


def test_a_bed_killed_after_its_checkpoint_resumes_to_the_same_run(scene, tmp_path):
    """Killed after a checkpoint (its events and frames written past it), resumed: the run's
    summary is the uninterrupted one's, its events are the same events (kind, body, step; those
    closed at the last step in any order) with the same numbers, and no event or frame of the
    killed run is left."""
    from yadebreak.jobs import bed
    from yadebreak import engine as coupling

    def run(out, **changes):
        coupling.forget()
        scene.reset()
        return bed.run(_bed_args(out, **changes), quiet=True)[1]

    whole = run(tmp_path / "whole")
    cut = tmp_path / "cut"
    assert run(cut, checkpoint_every=0.0, stop_after=5e-4) is None      # a checkpoint at 0.5 ms
    at_checkpoint = len(_events(cut))
    checkpoint = (cut / "checkpoint.yade.gz").read_bytes()
    assert run(cut, checkpoint_every=0.0, stop_after=1e-3, resume=True) is None
    frames_then = sorted(p.name for p in (cut / "paraview").iterdir())
    assert len(_events(cut)) > at_checkpoint          # the killed run went on past it...
    (cut / "checkpoint.yade.gz").write_bytes(checkpoint)     # ... and died: the last checkpoint
    resumed = run(cut, resume=True)
    assert timeless(resumed) == timeless(whole)
    def ordered(events):                   # (those closed at the last step: in any order)
        return sorted(events, key=lambda e: (e["iter"], e["id"], e["kind"]))
    a, b = ordered(_events(tmp_path / "whole")), ordered(_events(cut))
    assert [(e["kind"], e["id"], e["iter"]) for e in b] == [(e["kind"], e["id"], e["iter"])
                                                           for e in a]
    for x, y in zip(a, b):
        for key, value in x.items():
            if isinstance(value, float):
                assert y[key] == pytest.approx(value, rel=1e-9, abs=1e-300), (key, x, y)
    frames = sorted(p.name for p in (cut / "paraview").iterdir())
    assert frames == sorted(p.name for p in (tmp_path / "whole" / "paraview").iterdir())
    assert len(frames_then) >= 1 and "surfaces_0001.vtp" not in frames
    for name in ("spheres.pvd", "surfaces.pvd"):
        assert (cut / "paraview" / name).read_text() == (
            tmp_path / "whole" / "paraview" / name).read_text()


def test_zeroed_overlaps_go_on_after_a_reload_as_if_never_saved(scene, tmp_path):
    """Zeroed overlaps, one of a sphere with the anvil (a wall) and one of two spheres moving
    apart (slack: asleep), saved and loaded: the next steps are the unsaved scene's, bit for bit.
    O.load keeps neither a wall pair's overlap (NaN until the next InteractionLoop, but the zeroing
    reads it before: it would make NaN forces) nor which pairs sleep and since when."""
    from yade import utils
    from yadebreak import engine as coupling
    from yadebreak.scenes.impacts import hertz_engines
    ip2, _ = coupling.add_materials({"ore": "copper_ore", "steel": "steel"})
    wall = scene.bodies.append(utils.wall(0.0, axis=2, sense=1, material="steel"))
    low = scene.bodies.append(utils.sphere((0, 0, 2.7e-3), 3e-3, material="ore"))
    high = scene.bodies.append(utils.sphere((0, 0, 8.5e-3), 3e-3, material="ore"))
    scene.bodies[high].state.vel = (0, 0, 1e-4)     # away, then back (gravity): turns asleep
    scene.engines = hertz_engines(ip2, gravity=(0.0, 0.0, -9.81))
    brk = coupling.attach({"ore": "copper_ore"}, seed=1, read_period="every_step")
    brk.zeroing.zero_pair(wall, low, 3e-4, created=False)        # as fresh fragments' are
    brk.zeroing.zero_pair(low, high, 2e-4, created=False)
    brk.zeroing.wake()
    coupling.run_steps(20)
    assert brk.zeroing.asleep and (wall, low) in brk.zeroing.awake      # both kinds at the save

    def states(steps):
        out = []
        for _ in range(steps):
            coupling.run_steps(1)
            out.append(repr([(tuple(scene.bodies[i].state.pos), tuple(scene.bodies[i].state.vel),
                              tuple(scene.forces.f(i))) for i in (low, high)]))
        return out
    coupling.save(tmp_path / "scene.yade.gz")
    unsaved = states(2000)
    scene.load(str(tmp_path / "scene.yade.gz"))
    assert states(2000) == unsaved


def test_a_bed_resumed_from_any_cut_is_the_uninterrupted_run(scene, tmp_path):
    """The one-ring bed under the default 3.05 J up to 0.9 ms (42,100 steps, 13-14 breakages as
    the CPU rounds) cut at 0.4, 0.5, 0.6 and 0.7 ms while its fragments crowd (breakages before
    the first cut and after the last), each resumed from its last checkpoint:
    every event and the summary are the uninterrupted run's, bit for bit. Without the reload
    (coupling.reload) every cut ended with other events (41 against 42 or 43, the first moved by
    14 steps or more): the resumed collider made YADE's potential contacts anew in another order,
    so forces were summed in another order and the impact grew the last bit."""
    from yadebreak.jobs import bed
    from yadebreak import engine as coupling

    def run(out, **changes):
        coupling.forget()
        scene.reset()
        summary = bed.run(_bed_args(out, energy=3.05, seed=1, max_time=9e-4, vtk_interval=0.0,
                                    **changes), quiet=True)[1]
        return None if summary is None else timeless(summary)

    whole = run(tmp_path / "whole")
    cuts = (4e-4, 5e-4, 6e-4, 7e-4)                                # s of simulated time
    broke = [e["time"] for e in _events(tmp_path / "whole") if e["kind"] == "breakage"]
    assert whole["end_reason"] == "time_limit" and whole["breakage_events"] == len(broke)
    assert min(broke) < cuts[0] and max(broke) > cuts[-1], broke  # the cuts fall among them
    for k, cut_at in enumerate(cuts):
        cut = tmp_path / f"cut{k}"
        assert run(cut, checkpoint_every=0.0, stop_after=cut_at) is None
        assert run(cut, resume=True) == whole, cut_at
        assert _events(cut) == _events(tmp_path / "whole"), cut_at


def test_a_checkpoint_keeps_the_last_read_and_the_rolling_checks(scene, tmp_path):
    """Loaded from a checkpoint taken between two reads, the engine knows the step of its last
    read (the next read's interval, hence its first-touch work and the "fast" period) and the
    rolling friction part where its checks are (which one passes over every interaction, the
    counts the next compares with): the state the saved run had, not a fresh one's."""
    from yadebreak import engine as coupling
    from yadebreak.engine import scene as engine
    from yadebreak.engine.parts import protocol
    from yadebreak.jobs import bed
    out = tmp_path / "cut"
    coupling.forget()
    assert bed.run(_bed_args(out, vtk_interval=0.0, checkpoint_every=0.0, stop_after=6e-4),
                   quiet=True)[1] is None                  # stopped just after its checkpoint
    while "rolling" not in protocol._LIVE or engine.controller_of().last_iter >= scene.iter - 1:
        coupling.run_steps(1)                 # to a step between reads, the rolling part rebuilt
    ctl, part = engine.controller_of("yadebreak"), protocol._LIVE["rolling"]
    saved = (scene.iter, ctl.last_iter, part._checks, list(part._seen))
    coupling.save_checkpoint(out / "checkpoint.yade.gz", {})
    assert saved[1] < saved[0] - 1 and saved[2] > 1          # between reads, after many checks
    coupling.forget()
    protocol.forget()
    scene.reset()
    ctl, _ = coupling.load_checkpoint(out / "checkpoint.yade.gz")
    assert (scene.iter, ctl.last_iter) == saved[:2]
    stored = json.loads(scene.tags["yadebreak_rolling:rolling"])
    assert (stored["checks"], stored["seen"]) == tuple(saved[2:])
    assert "rolling" not in protocol._LIVE            # rebuilt from them at its next run
    while "rolling" not in protocol._LIVE:
        coupling.run_steps(1)
    assert protocol._LIVE["rolling"]._checks == saved[2] + 1
