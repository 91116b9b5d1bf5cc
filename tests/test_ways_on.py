"""Every refusal names a way on that works: from each state a run folder can be in (empty; a lock
only; interrupted before its first checkpoint and after one; finished; a damaged checkpoint), the
command the message suggests is run as it says, and it succeeds; a run that dies in its first
seconds can be resumed. The bed (checkpoints) in this process; single impacts (partial results)
follow the same rules through PartialResults (tests/test_failures.py)."""
import argparse
import re

import pytest

from yadebreak.jobs import lifecycle

pytestmark = pytest.mark.yade

#: the smallest default-like bed: one ring, 0.6 J (seconds per run)
BED = dict(material="copper_ore", size=5.5e-3, rings=1, layers=1, energy=0.6, speed=0.0, seed=3,
           time_step_fraction=0.05, dmin=0.0, global_damping="material", dummies="ledger",
           read_period="fast", max_time=0.02, checkpoint_every=60.0, vtk_interval=0.0,
           stop_after=0.0, resume=False, overwrite=False)


def _bed(out, capsys, **changes):
    """bed_impact's run_script in this process: (exit code, the [yadebreak] error line or '')."""
    from yadebreak import engine
    from yadebreak.jobs import bed
    engine.forget()
    args = argparse.Namespace(**{**BED, "out": str(out), **changes})
    try:
        lifecycle.run_script(bed.run, args)
        code = 0
    except SystemExit as ended:
        code = ended.code
    errors = [line for line in capsys.readouterr().err.splitlines() if "error:" in line]
    return code, errors[-1] if errors else ""


def _follow(out, capsys, said):
    """Run what the refusal `said` suggests first (--resume 1 or --overwrite 1): it succeeds."""
    way = re.search(r"--(resume|overwrite) 1", said)
    assert way, said
    code, error = _bed(out, capsys, **{way.group(1): True})
    assert code == 0, (said, error)
    assert (out / "finished.json").exists() and (out / "summary.json").exists()
    assert not (out / ".yadebreak.lock").exists()        # a finished run leaves no lock


def test_each_state_of_a_run_folder_says_a_way_on_that_works(scene, tmp_path, capsys):
    out = tmp_path / "bed"
    # killed before its first checkpoint (as if at 30 us of simulated time: 2 chunks, the first
    # safe point is at the 5th)
    code, _ = _bed(out, capsys, stop_after=3e-5)
    assert code == 0 and not (out / "checkpoint.yade.gz").exists()
    code, said = _bed(out, capsys)
    assert code == 2 and "--resume 1" not in said          # nothing to continue: start over
    _follow(out, capsys, said)
    # --resume 1 there too: with no checkpoint the run starts again, to the same end
    whole = (out / "events.jsonl").read_text()
    _bed(out, capsys, overwrite=True, stop_after=3e-5)
    assert _bed(out, capsys, resume=True)[0] == 0
    assert (out / "events.jsonl").read_text() == whole
    # killed after a checkpoint (the first comes at the first safe point, seconds in)
    _bed(out, capsys, overwrite=True, stop_after=4e-4)
    assert (out / "checkpoint.yade.gz").exists()
    code, said = _bed(out, capsys)
    assert code == 2 and "continue it with --resume 1" in said
    _follow(out, capsys, said)
    assert (out / "events.jsonl").read_text() == whole
    # finished: --resume 1 says so (exit 0); a plain run is refused, naming --overwrite 1 only
    assert _bed(out, capsys, resume=True)[0] == 0
    code, said = _bed(out, capsys)
    assert code == 2 and "finished run" in said and "--resume 1" not in said
    _follow(out, capsys, said)
    # a damaged checkpoint: --resume 1 refuses it and names --overwrite 1
    _bed(out, capsys, overwrite=True, stop_after=4e-4)
    (out / "checkpoint.yade.gz").write_bytes(b"damaged")
    code, said = _bed(out, capsys, resume=True)
    assert code == 2 and "is damaged" in said
    _follow(out, capsys, said)
    assert (out / "events.jsonl").read_text() == whole
