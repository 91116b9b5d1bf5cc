"""Failures that help (issue 16, item 8): a run that fails or stops leaves its partial outputs and a
summary saying how it ended; the time left is never nan or negative; warnings are shown once and
name the script's own option; error bars stay at or above zero; a partial sweep is gathered."""
import argparse
import json
import math
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from yadebreak import reports, scriptargs
from yadebreak.scriptargs import partial_outputs_on_failure, time_left

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("elapsed, done", [(10.0, 0.0), (10.0, 0.01), (10.0, float("nan")),
                                           (10.0, -0.5), (10.0, 1.7), (10.0, 1.0),
                                           (float("nan"), 0.5), (10.0, 0.5)])
def test_time_left_is_never_nan_or_negative(elapsed, done):
    text = time_left(elapsed, done)
    assert "nan" not in text and "-" not in text
    if text != "time left unknown":
        assert float(text.split()[1]) >= 0.0
    if done == 0.5 and math.isfinite(elapsed):
        assert text == "about 10 s left"           # as long again as it took so far


def test_error_bars_stop_at_zero_and_at_one_hundred_percent():
    values = np.array([1.0, 50.0, 99.0, 0.0])
    yerr = reports.bounded_errors(values, [5.0, 5.0, 5.0, 3.0], 0.0, 100.0)
    assert (values - yerr[0] >= 0.0).all() and (values + yerr[1] <= 100.0).all()
    np.testing.assert_allclose(yerr[0], [1.0, 5.0, 5.0, 0.0])
    np.testing.assert_allclose(yerr[1], [5.0, 5.0, 1.0, 3.0])


def test_a_failure_writes_the_partial_outputs_and_goes_on():
    written = []
    with pytest.raises(ZeroDivisionError):
        with partial_outputs_on_failure(lambda *end: written.append(end)):
            1 / 0
    assert written == [("error", "ZeroDivisionError: division by zero")]
    with pytest.raises(KeyboardInterrupt):
        with partial_outputs_on_failure(lambda *end: written.append(end)):
            raise KeyboardInterrupt
    assert written[-1][0] == "interrupted"
    with pytest.raises(scriptargs.StopRequested):       # --stop-after stands for a kill: nothing
        with partial_outputs_on_failure(lambda *end: written.append(end)):
            raise scriptargs.StopRequested()
    assert len(written) == 2


@pytest.mark.parametrize("exception, code", [(RuntimeError("boom"), 1), (KeyboardInterrupt(), 130)])
def test_run_script_turns_a_failure_into_an_exit_code_and_a_line(capsys, exception, code):
    def main():
        raise exception
    shown = warnings.showwarning
    try:
        with pytest.raises(SystemExit) as ended:
            scriptargs.run_script(main)
    finally:
        warnings.showwarning = shown
    assert ended.value.code == code
    said = capsys.readouterr()
    assert ("the run failed (RuntimeError: boom)" in said.err if code == 1
            else "interrupted" in said.out)


def test_a_warning_is_shown_once_naming_the_scripts_own_option(capsys):
    from yadebreak.coupling.controller import YadebreakWarning
    from yadebreak.coupling.stepping import ReadSchedule
    schedule = ReadSchedule.__new__(ReadSchedule)
    schedule.period, schedule.mode = 7, "fast"
    remedies = schedule.remedies()
    warning = YadebreakWarning("jump", "energy jumped", remedies, "for an accurate t10'")
    assert str(warning) == "yadebreak: energy jumped: reduce fast_fraction for an accurate t10'"
    # bed_impact exposes --read-period and --time-step-fraction, not fast_fraction
    assert warning.for_script({"read_period", "time_step_fraction"}) == (
        "energy jumped: read every step (--read-period 1) for an accurate t10'")
    assert "(an attach() option)" in warning.for_script(set())

    scriptargs.script_params([scriptargs.integer("read_period", 1, "how often", lo=1)], argv=[])
    shown = warnings.showwarning
    try:
        scriptargs._show_warnings_once()
        with warnings.catch_warnings():
            warnings.simplefilter("always")
            warnings.showwarning = scriptargs.warnings.showwarning
            for _ in range(3):       # e.g. three scenes of a run, each with its own controller
                warnings.warn(YadebreakWarning("jump", "energy jumped", remedies))
    finally:
        warnings.showwarning = shown
    lines = [line for line in capsys.readouterr().err.splitlines() if "WARNING" in line]
    assert lines == ["[yadebreak] WARNING: energy jumped: read every step (--read-period 1) "
                     "(shown once)"]


def _bed_args(out, **changes):
    values = dict(material="copper_ore", size=5.5e-3, rings=1, layers=1, energy=0.6, speed=0.0,
                  seed=3, time_step_fraction=0.05, dmin=0.0, global_damping=0.0,
                  dummies="ledger", read_period="fast", max_time=0.02, out=str(out),
                  checkpoint_every=0.0, vtk_interval=0.0)
    values.update(changes)
    return argparse.Namespace(**values)


@pytest.mark.yade
def test_a_bed_run_that_fails_midway_leaves_its_outputs_and_says_why(scene, tmp_path,
                                                                      monkeypatch):
    from yadebreak import bed, coupling
    real, calls = coupling.run_steps, []

    def failing(n):                     # the fourth batch of steps fails, mid-impact
        calls.append(n)
        if len(calls) == 4:
            raise RuntimeError("the solver gave up")
        real(n)
    monkeypatch.setattr(coupling, "run_steps", failing)
    with pytest.raises(RuntimeError):
        bed.run(_bed_args(tmp_path), quiet=True)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["end_reason"] == "error"
    assert summary["end_message"] == "RuntimeError: the solver gave up"
    assert summary["final_mass"] == pytest.approx(summary["initial_mass"], rel=1e-12)
    for name in ("events.jsonl", "size_distribution.csv", "bed_top_view.png",
                 "checkpoint.yade.gz"):           # the checkpoint: --resume 1 goes on from it
        assert (tmp_path / name).exists(), name
    assert not (tmp_path / "finished.json").exists()


@pytest.mark.yade
def test_a_bed_run_stopped_by_max_time_says_so(scene, tmp_path):
    from yadebreak import bed
    _, summary = bed.run(_bed_args(tmp_path, max_time=2e-4), quiet=True)
    assert summary["end_reason"] == "time_limit"
    assert "--max-time 0.0002 s" in summary["end_message"]
    # it stops at the first check past max_time: within one batch of (at most 400) steps
    assert 0.0 < summary["simulated_time"] - 2e-4 <= 400 * summary["final_dt"]


def test_gather_sweep_gathers_a_partial_sweep(tmp_path):
    sweep = tmp_path / "sweep"
    base = {"material": "copper_ore", "rings": 1, "layers": 1, "energy": 3.05,
            "broken_mass": 1e-4, "broken_mass_fraction": 0.1, "capture_radius": 0.0,
            "runtime_s": 1.0}
    for name, changes in [("a_s1", {}), ("a_s2", {"broken_mass": 3e-4}),
                          ("a_s3", {"end_reason": "error", "end_message": "RuntimeError: x"})]:
        (sweep / name).mkdir(parents=True)
        (sweep / name / "summary.json").write_text(json.dumps({**base, **changes}))
    (sweep / "a_s4").mkdir()                               # started, died before its summary
    table = tmp_path / "t.table"
    table.write_text("# a table\nmaterial seed description\n'copper_ore' 1 a_s1\n"
                     "'copper_ore' 2 a_s2\n'copper_ore' 3 a_s3\n'copper_ore' 4 a_s4\n"
                     "'copper_ore' 5 a_s5\n")
    proc = subprocess.run([sys.executable, str(ROOT / "scripts" / "gather_sweep.py"), "--sweep",
                           str(sweep), "--out", str(tmp_path / "report"), "--table", str(table)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "unfinished: a_s3 (error: RuntimeError: x)" in proc.stdout
    assert "unfinished: a_s4 (no summary.json)" in proc.stdout
    assert "unfinished: a_s5 (not run)" in proc.stdout
    assert "2 runs in 1 configurations (3 unfinished" in proc.stdout
    rows = (tmp_path / "report" / "sweep.csv").read_text().splitlines()
    assert len(rows) == 2 and ",2," in rows[1]          # one configuration, 2 runs
    # its error bar (mean 0.2 g, sd 0.1 g) is drawn; with sd > mean it would stop at zero
    assert (tmp_path / "report" / "broken_mass.png").stat().st_size > 0


@pytest.mark.yade
def test_a_small_bed_says_why_it_took_longer(scene, tmp_path, capsys):
    """One ring under 1.5 J (7 particles) breaks finer than the default bed: the run reports the
    energy per kg of bed at the start, and at the end the fall of the time step and the finest
    fragment that caused it, from its own summary."""
    from yadebreak import bed
    _, summary = bed.run(_bed_args(tmp_path, energy=1.5), quiet=False)
    said = capsys.readouterr().out
    per_kg = summary["energy"] / summary["initial_mass"]
    assert summary["energy_per_bed_mass"] == pytest.approx(per_kg, rel=1e-12)
    assert f"({summary['energy']:g} J, {per_kg:.0f} J per kg of bed)" in said
    assert summary["final_dt"] < 0.5 * summary["initial_dt"]
    assert summary["finest_sphere_size"] < 5.5e-3 / 2
    line = [x for x in said.splitlines() if "the time step fell" in x]
    assert len(line) == 1
    assert f"{summary['initial_dt'] / summary['final_dt']:.0f}-fold" in line[0]
    assert f"{1e3 * summary['finest_sphere_size']:.2f} mm" in line[0]
    assert bed.why_it_took_longer({**summary, "final_dt": summary["initial_dt"]}) is None
