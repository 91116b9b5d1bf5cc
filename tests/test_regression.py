"""The coupling redesign kept behaviour (issue 14): the scenes of tests/regression/cases.py give the
events and summaries recorded with the engine before it was cut into parts: the same bodies,
steps and fragments, every number within 1e-9 relative. A change of behaviour on purpose
re-records them (`/usr/bin/python3 tests/regression/cases.py record NAME`) and says so."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent / "regression"))
import cases  # noqa: E402

pytestmark = pytest.mark.yade


@pytest.mark.parametrize("name", list(cases.CASES))
def test_same_events_and_summary_as_recorded(tmp_path, name):
    proc = cases.run(name, tmp_path / name)
    assert proc.returncode == 0, proc.stdout[-1500:] + proc.stderr[-1500:]
    expected = cases.outputs(cases.BASELINE / name)
    got = cases.outputs(tmp_path / name)
    assert sorted(got) == sorted(expected)
    found = cases.differences(expected, got)
    assert not found, "\n".join(found)


def test_the_comparison_sees_a_change():
    """A baseline compared with itself passes; a fragment, a step or an energy off fails."""
    base = cases.outputs(cases.BASELINE / "bed_default")
    assert cases.differences(base, base) == []
    event = next(e for e in base["events.jsonl"] if e["kind"] == "breakage")
    for field, change in (("fragments", lambda v: v[:-1]), ("iter", lambda v: v + 1),
                          ("specific_energy", lambda v: v * (1 + 1e-8))):
        changed = {**event, field: change(event[field])}
        assert cases.differences(event, changed), field
