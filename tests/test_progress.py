"""A long run says how it goes: a line on stderr at least every STATUS_EVERY seconds, also from
inside one long scene (its simulated time), with a steady estimate of the time left; --quiet 1
silences it, and results stay on stdout."""
import pytest

from yadebreak.jobs import lifecycle
from yadebreak.jobs import options as job_options


def test_the_time_left_is_steady_when_a_scene_ends_late():
    """Two scenes of ten took 10 s, then the third 30 s: the raw estimate jumps from 40 to 93 s;
    the steady one moves by a third of that jump."""
    left = lifecycle.Remaining()
    assert left(10.0, 0.2) == "about 40 s left"
    raw = 40.0 * 0.7 / 0.3                             # 40 s for 30 %: 93 s left
    steady = 0.7 * (40.0 - 30.0) + 0.3 * raw
    assert left(40.0, 0.3) == f"about {steady:.0f} s left"
    assert lifecycle.Remaining()(1.0, 0.01) == "time left unknown"


@pytest.mark.yade
@pytest.mark.parametrize("quiet", [False, True])
def test_single_impacts_say_how_they_go_inside_a_long_scene(scene, tmp_path, capsys, monkeypatch,
                                                           quiet):
    from yadebreak.jobs import impacts
    monkeypatch.setattr(lifecycle, "STATUS_EVERY", 0.2)
    args = job_options.read("single_impact", argv=[
        "--particles", "4", "--scene-particles", "4", "--energies", "700", "--jobs", "1",
        "--time-step-fraction", "0.01", "--quiet", str(int(quiet)), "--out",
        str(tmp_path / "out")])
    impacts.single(args)
    said = capsys.readouterr()
    inside = [line for line in said.err.splitlines()
              if line.startswith("[yadebreak] 700 J/kg: 0/1 scenes done, scene 1 at ")]
    assert "700 J/kg: " in said.out and "wrote" in said.out          # results: stdout
    if quiet:
        assert not inside and "scenes done" not in said.err
    else:
        assert len(inside) >= 2, said.err[-2000:]
        times = [float(line.split(" at ")[1].split(" us")[0]) for line in inside]
        assert times == sorted(times) and times[-1] > times[0]      # the scene's clock runs


class _SlowChunks:
    """A job of three chunks of 0.35 s each (a large scene's chunk of steps), progress every
    0.1 s: the skeleton's lines must come while a chunk runs, not only between chunks."""

    def __init__(self, out, quiet):
        import argparse
        from yadebreak.jobs import skeleton

        class Job(skeleton.Job):
            report_every = 0.1
            checkpoint_every = -1.0
            chunks = 0

            def build(self):
                pass

            def advance(self):
                import time
                if self.chunks == 3:
                    return "finished"
                time.sleep(0.35)
                self.chunks += 1
                return None

            def elapsed(self):
                return self.chunks

            def status(self):
                return f"chunk {self.chunks + 1} of 3"

            def done(self):
                return self.chunks / 3

            def outputs(self, end_reason, end_message, runtime_s):
                return {"end_reason": end_reason}

        self.job = Job(argparse.Namespace(out=str(out)), quiet=quiet)


@pytest.mark.parametrize("quiet", [False, True])
def test_a_job_says_how_it_goes_within_one_long_chunk(tmp_path, capsys, monkeypatch, quiet):
    from yadebreak.jobs import skeleton
    from yadebreak.options import flags
    monkeypatch.setattr(flags, "_QUIET", quiet)        # as --quiet would set it
    summary = skeleton.run(_SlowChunks(tmp_path / "out", quiet).job)
    assert summary == {"end_reason": "finished"}
    lines = [line for line in capsys.readouterr().err.splitlines() if " of 3, wall " in line]
    if quiet:
        assert not lines
    else:
        first = [line for line in lines if line.startswith("[yadebreak] chunk 1 of 3")]
        assert len(first) >= 2, lines                  # within the first chunk (0.35 s)
        assert len(lines) >= 6
