"""Stability at the extremes, a fast subset of scripts/extremes.py's matrix (issue 7): no NaN or
infinity, mass conserved to 1e-9, no fragment faster than its parent's rigid field, no kinetic
energy created (no gravity), and the run ends. Cases whose fast run takes over 6 s here stay in
the script only (sigma 0.01 and 3, Emax/E50 = 1.001, the 200 mm particle)."""
import pytest

pytestmark = pytest.mark.yade

SLOW = {"size 200 mm at 10 m/s", "Emax/E50 = 1.001", "sigma = 0.01", "sigma = 3"}


def _names():
    from yadebreak.adapter.yadepath import ensure_yade_importable
    if not ensure_yade_importable():
        return []
    from yadebreak.jobs import extremes
    return [c.name for c in extremes.cases() if c.name not in SLOW]


@pytest.mark.parametrize("name", _names())
def test_extreme_case_is_finite_conservative_and_ends(scene, name):
    from yadebreak.jobs import extremes
    (case,) = [c for c in extremes.cases() if c.name == name]
    r = extremes.run_case(case, fast=True)
    assert r["finite"], r
    assert r["mass_error"] <= 1e-9, r
    assert r["fragment_speed_excess"] <= 1e-9, r
    assert r["kinetic_after"] <= r["kinetic_before"] * (1 + 1e-6) + 1e-9, r
    assert r["ended"], r
    assert r["max_breakages_one_step"] >= case.expect.get("min_breakages_one_step", 0), r
    assert r["ok"]


def test_a_case_filter_that_matches_nothing_is_refused_in_one_line(tmp_path, capsys):
    """--only naming no case: one line with the cases' names, exit 2, nothing written."""
    import argparse
    from yadebreak.jobs import extremes
    args = argparse.Namespace(only="nosuchcase", fast=True, out=str(tmp_path / "out"))
    with pytest.raises(SystemExit) as ended:
        extremes.run(args)
    assert ended.value.code == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("[yadebreak] error: --only = nosuchcase: no "
                                                   "case's name holds it; the cases: ")
    assert "Ab-T10, S x 1e-3" in lines[0] and not (tmp_path / "out").exists()


def test_the_matrix_run_as_a_units_job_gives_each_case_s_own_run(scene, tmp_path, capsys):
    """scripts/extremes.py's run (a skeleton.Units job, one case per unit) on two fast cases:
    extremes.json holds what run_case gives each alone, to the last digit (but the time taken),
    the table is printed, and the run is marked finished."""
    import argparse
    import json
    from yadebreak.jobs import extremes
    args = argparse.Namespace(only="gamma = ", fast=True, out=str(tmp_path / "out"))
    assert extremes.run(args) == 0
    rows = json.loads((tmp_path / "out" / "extremes.json").read_text())
    alone = [extremes.run_case(c, fast=True) for c in extremes.cases() if "gamma = " in c.name]
    assert [r["case"] for r in rows] == ["gamma = 0.5", "gamma = 50"]
    assert ([{k: v for k, v in r.items() if k != "wall_s"} for r in rows]
            == [json.loads(json.dumps({k: v for k, v in r.items() if k != "wall_s"}))
                for r in alone])
    assert "| gamma = 50 |" in capsys.readouterr().out
    assert (tmp_path / "out" / "finished.json").is_file()
