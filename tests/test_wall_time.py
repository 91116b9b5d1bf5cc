"""A command's wall time on N workers, predicted from its scenes' wall times (jobs/wall_time.py):
the queue played exactly, within Graham's bounds for list scheduling; and single impacts report
their scenes' times and the prediction, at the start from an earlier run in --out."""
import numpy as np
import pytest

from yadebreak.jobs import wall_time


def test_the_queue_is_played_in_order_each_scene_to_the_first_worker_free():
    # 2 workers: 5 | 4, then 3 to the one free at 4 (7), 3 to the one free at 5 (8), 3 at 7: 10
    assert wall_time.makespan([5.0, 4.0, 3.0, 3.0, 3.0], 2) == 10.0
    assert wall_time.makespan([5.0, 4.0, 3.0], 1) == 12.0
    assert wall_time.makespan([5.0, 4.0, 3.0], 128) == 5.0
    assert wall_time.makespan([], 8) == 0.0


def test_list_scheduling_lies_within_grahams_bounds():
    """max(longest, sum / N) <= makespan <= sum / N + longest (1 - 1/N), on 200 random queues."""
    rng = np.random.default_rng(7)
    for _ in range(200):
        durations = rng.lognormal(0.0, 1.0, rng.integers(1, 40)).tolist()
        n = int(rng.integers(1, 20))
        span, total, longest = wall_time.makespan(durations, n), sum(durations), max(durations)
        assert max(longest, total / n) - 1e-9 <= span <= total / n + longest * (1 - 1 / n) + 1e-9


def test_stages_wait_for_each_other():
    """An energy's scenes start when the energy before has ended: [2, 2] then [3] on 2 workers
    take 2 + 3 s, not 3 s; the sum and the longest scene are the scenes'."""
    got = wall_time.predict([[2.0, 2.0], [3.0]], "test", (1, 2))
    assert got.predicted_s == {1: 7.0, 2: 5.0}
    assert (got.scenes, got.sum_s, got.longest_s) == (3, 7.0, 3.0)
    assert got.to_dict()["predicted"] == [{"workers": 1, "wall_s": 7.0},
                                          {"workers": 2, "wall_s": 5.0}]
    assert "7 s on 1, 5 s on 2 worker(s) (test)" in got.line()


@pytest.mark.yade
def test_single_impacts_report_their_scenes_and_predict_a_rerun(scene, tmp_path, capsys):
    """Two scenes at two energies: summary.json's wall_time adds up the scenes' own times, its
    one-worker prediction is their sum; run again into the same folder, the prediction from the
    earlier run's scene times comes first, before any scene."""
    import json
    from yadebreak.jobs import impacts
    from yadebreak.jobs import options as job_options
    argv = ["--particles", "4", "--scene-particles", "2", "--energies", "100,700", "--jobs", "1",
            "--out", str(tmp_path / "out")]
    impacts.single(job_options.read("single_impact", argv=argv))
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    walls = [w for r in summary["results"] for w in r["scene_walls_s"]]
    assert len(walls) == 4
    for r in summary["results"]:
        assert sum(r["scene_walls_s"]) == pytest.approx(r["scenes_wall_s"], rel=1e-12)
    told = summary["wall_time"]
    assert told["scenes"] == 4 and told["sum_s"] == pytest.approx(sum(walls), rel=1e-12)
    assert told["longest_s"] == max(walls)
    assert told["predicted"][0] == {"workers": 1, "wall_s": pytest.approx(sum(walls), rel=1e-12)}
    capsys.readouterr()
    impacts.single(job_options.read("single_impact", argv=argv + ["--overwrite", "1"]))
    err = capsys.readouterr().err
    assert err.startswith("[yadebreak] wall time, predicted: 4 scenes"), err[:500]
    assert "an earlier run's scene wall times in" in err.splitlines()[0]


def test_scenes_go_out_in_tasks_of_consecutive_scenes_as_the_queue_sends_them():
    """64 scenes of 1 s on 2 workers go out in tasks of 4 (at least 8 tasks per worker): 32 s;
    on 1 worker the process runs them itself (64 s); sets queued together (verify) are each cut
    into their own tasks: a set of 3 s and one of 1 s on 2 workers end together at 3 s."""
    from yadebreak.process.scheduler import TASKS_PER_WORKER, chunk_size
    assert chunk_size(64, 2) == 64 // (TASKS_PER_WORKER * 2) == 4
    assert wall_time.tasks([1.0] * 64, 2) == [4.0] * 16
    got = wall_time.predict([[1.0] * 64], "test", (1, 2))
    assert got.predicted_s == {1: 64.0, 2: 32.0} and got.scenes == 64
    sets = wall_time.predict([[[3.0], [1.0]]], "test", (1, 2))
    assert sets.predicted_s == {1: 4.0, 2: 3.0} and (sets.scenes, sets.longest_s) == (2, 3.0)
