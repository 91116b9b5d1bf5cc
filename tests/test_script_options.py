"""Script options: every numeric option is checked before the run (one line naming the option,
the value, the range and the unit; exit code 2; no traceback), units may be written
(`--size 5.5mm`), --help shows units and defaults, and the bed's --resume refuses other arguments
and says when the run had finished. The options are read in this process, as each script reads
them (yadebreak.jobs.options); one script run as users run it shows that the scripts wire
them through."""
import json
import os
import subprocess
from pathlib import Path

import pytest

from yadebreak.jobs import options as job_options
from yadebreak.options.flags import ParamError, numbers, number, script_params

ROOT = Path(__file__).resolve().parent.parent
PYTHON = "/usr/bin/python3"


def _yade(script, *arguments):
    return subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / f"{script}.py"), *arguments],
                          capture_output=True, text=True, timeout=300, cwd=ROOT)


def _one_error_line(proc):
    """The single `[yadebreak] error:` line of a failed run (YADE's own banner lines aside)."""
    assert proc.returncode == 2, proc.stdout[-1500:] + proc.stderr[-1500:]
    return _the_error_line(proc.stdout + proc.stderr)


def _the_error_line(said):
    assert "Traceback" not in said
    lines = [line for line in said.splitlines() if "error" in line.lower()]
    assert len(lines) == 1 and lines[0].startswith("[yadebreak] error: "), lines
    return lines[0]


def _read(script, *arguments):
    """Read the script's options in this process from `arguments`: the exit code if reading
    ended the program (capsys holds what it printed), else None."""
    try:
        job_options.read(script, f"{script}'s description", list(arguments))
    except SystemExit as ended:
        return ended.code
    return None


# (script, arguments, the error line's "option = value", the range, the unit)
BAD_VALUES = [
    ("bed_impact", ["--energy", "-1"], "--energy = -1", "> 0", "(J)"),
    ("bed_impact", ["--size=-5e-3"], "--size = -5e-3", "in [1e-06, 1]", "(m)"),
    ("single_impact", ["--size", "1e-300"], "--size = 1e-300", "in [1e-06, 1]", "(m)"),
    ("bed_impact", ["--rings=-1"], "--rings = -1", "an integer >= 0", "(no unit)"),
    ("bed_impact", ["--layers", "0"], "--layers = 0", "an integer >= 1", "(no unit)"),
    ("bed_impact", ["--energy", "2J/kg"], "--energy = 2J/kg", "> 0", "(J)"),
    ("bed_impact", ["--steel-rolling-friction=-2"], "--steel-rolling-friction = -2",
     "in [-1, 10]", "(no unit)"),
    ("bed_impact", ["--packing", "poured"], "--packing = poured", "with --layers >= 2",
     "(got 1)"),
    ("single_impact", ["--particles", "0"], "--particles = 0", "an integer >= 1", "(no unit)"),
    ("single_impact", ["--energies=-100"], "--energies = -100",
     "distinct numbers separated by commas, each > 0", "(J/kg)"),
    ("drop_weight", ["--max-time", "0"], "--max-time = 0", "> 0", "(s)"),
    ("repeated_impact", ["--energy", "3J"], "--energy = 3J", "> 0", "(J/kg)"),
    ("ball_mill", ["--speed", "1"], "--speed = 1", "in (0, 1)", "(no unit)"),
    ("ball_mill", ["--ball-filling", "0.6"], "--ball-filling = 0.6", "in (0, 0.5]", "(no unit)"),
    ("ball_mill", ["--ore-filling", "0"], "--ore-filling = 0", "in (0, 0.5]", "(no unit)"),
    ("ball_mill", ["--duration", "0"], "--duration = 0", "> 0", "(s)"),
    ("ball_mill", ["--ball-size", "0.2"], "--ball-size = 0.2", "< the drum's radius 0.125", "(m)"),
    ("bed_impact", ["--dmin", "2"], "--dmin = 2", "in [0, 1]", "(m)"),
    # impacts at or above the particles' elastic wave speed sqrt(E/rho) (copper ore: 4213 m/s;
    # the bed's ball of 2.78 kg: 0.5 * 2.78 * 4213^2 = 2.467e7 J)
    ("bed_impact", ["--energy", "1e300"], "--energy = 1e+300", "< 2.467e+07", "(J)"),
    ("bed_impact", ["--speed", "5000"], "--speed = 5000", "< 4213", "(m/s)"),
    ("single_impact", ["--energies", "100,1e9"], "--energies = 100,1e9", "< 8.874e+06", "(J/kg)"),
    ("repeated_impact", ["--energy", "1e7"], "--energy = 1e+07", "< 8.874e+06", "(J/kg)"),
    ("drop_weight", ["--energies", "2e7"], "--energies = 2e7", "< 8.874e+06", "(J/kg)"),
]


@pytest.mark.parametrize("script, arguments, named, accepted, unit", BAD_VALUES)
def test_bad_value_stops_before_the_run_with_one_line(tmp_path, capsys, script, arguments, named,
                                                      accepted, unit):
    out = tmp_path / "out"
    assert _read(script, *arguments, "--out", str(out)) == 2
    said = capsys.readouterr()
    line = _the_error_line(said.out + said.err)
    assert f"{named}: must be {accepted}" in line and unit in line, line
    assert not out.exists()                          # stopped before anything was built


@pytest.mark.parametrize("script", sorted(job_options.JOBS))
def test_an_empty_out_is_refused(capsys, script):
    """--out '' would write into the current folder."""
    assert _read(script, "--out", "") == 2
    said = capsys.readouterr()
    assert _the_error_line(said.out + said.err) == ("[yadebreak] error: --out = '': must be a "
                                                    "non-empty text")


def test_speeds_below_the_wave_speed_are_accepted():
    assert _read("bed_impact", "--energy", "2.4e7", "--out", "x") is None     # 4155 m/s
    assert _read("single_impact", "--energies", "8.8e6", "--out", "x") is None


def test_scenes_go_to_a_worker_per_usable_core_by_default():
    from yadebreak.options.flags import scheduler_of
    cores = len(os.sched_getaffinity(0))
    assert scheduler_of(job_options.read("single_impact", None, [])).count == cores
    assert scheduler_of(job_options.read("single_impact", None, ["--jobs", "1"])).in_process


def test_a_tables_unknown_column_is_named_in_one_line(monkeypatch, capsys):
    """YADE's readParamsFromTable raises NameError for a column without a default."""
    def table_row(defaults):
        raise NameError("Parameter `nosuch' has no default value assigned")
    monkeypatch.setenv("YADE_BATCH", "t.table:2")
    with pytest.raises(SystemExit) as end:
        script_params([SIZE], table_row=table_row)
    assert end.value.code == 2
    said = capsys.readouterr()
    assert _the_error_line(said.out + said.err) == (
        "[yadebreak] error: the table's column 'nosuch' is not an option of this script (its "
        "options: debug, quiet, size)")


@pytest.mark.parametrize("text_value, minutes", [("10", 10.0), ("90s", 1.5), ("90 s", 1.5),
                                                 ("1h", 60.0), ("2 min", 2.0)])
def test_minutes_take_a_time_unit(text_value, minutes):
    from yadebreak.cli import COMMANDS
    option = next(p for p in COMMANDS["grind"].params if p.name == "minutes")
    assert option.convert(text_value) == minutes
    with pytest.raises(ParamError, match=r"--minutes = 5 m: .*\(min\); the unit 'm' is not "):
        option.convert("5 m")


@pytest.mark.parametrize("script", sorted(job_options.JOBS))
def test_each_script_reads_its_own_options_and_runs_its_job(script):
    """Each script is its options (job_options.read of its own name) and one call."""
    text = (ROOT / "scripts" / f"{script}.py").read_text()
    assert f'job_options.read("{script}", __doc__)' in text
    assert len(text.splitlines()) <= 60
    assert _read(script) is None                     # the defaults are accepted


@pytest.mark.yade
def test_a_script_wires_its_options_through(tmp_path):
    """As users run it: a bad value and a cross-check of the bed stop YADE with the one line."""
    out = tmp_path / "out"
    line = _one_error_line(_yade("bed_impact", "--energy", "-1", "--out", str(out)))
    assert line == "[yadebreak] error: --energy = -1: must be > 0 (J)"
    line = _one_error_line(_yade("bed_impact", "--packing", "poured", "--out", str(out)))
    assert "--packing = poured: must be with --layers >= 2 (got 1)" in line
    assert not out.exists()


def test_families_command_checks_t10(tmp_path):
    command = [PYTHON, "-m", "yadebreak", "families", "--t10", "500", "--out",
               str(tmp_path / "f.png")]
    proc = subprocess.run(command, capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert _one_error_line(proc) == "[yadebreak] error: --t10 = 500: must be in (0, 100] (%)"
    assert not (tmp_path / "f.png").exists()
    proc = subprocess.run(command + ["--debug", "1"], capture_output=True, text=True, timeout=120,
                          cwd=ROOT)
    assert proc.returncode != 0 and "Traceback" in proc.stderr       # --debug shows it


SIZE = number("size", 5.5e-3, "m", "particle size", lo=0, lo_open=True, hi=1)
ENERGY = number("energy", 3.05, "J", "impact energy", lo=0, lo_open=True)
ENERGIES = numbers("energies", "100,200,400", "J/kg", "specific energies", lo=0, lo_open=True)


@pytest.mark.parametrize("size", ["5.5mm", "5.5e-3", "0.0055", "5.5e-3m", "0.55cm", "5.5 mm",
                                  "5.5e-3 m"])
def test_a_size_means_the_same_with_or_without_its_unit(size):
    assert script_params([SIZE], argv=["--size", size]).size == 5.5e-3
    assert script_params([SIZE], argv=[]).size == 5.5e-3
    assert script_params([SIZE], argv=["--size", "5.3mm"]).size == 5.3e-3   # not 5.3 * 1e-3


def test_energies_take_their_own_unit_only():
    args = script_params([ENERGY, ENERGIES], argv=["--energy", "3.05J",
                                                   "--energies", "100J/kg, 200 J/kg,4e2"])
    assert args.energy == 3.05 and args.energies == "100,200,4e2"   # as plain J/kg, as always
    with pytest.raises(ParamError, match=r"--energy = 3.05J/kg: must be > 0 \(J\)"):
        ENERGY.convert("3.05J/kg")
    with pytest.raises(ParamError, match=r"--energies = 100J: .* \(J/kg\)"):
        ENERGIES.convert("100J")
    with pytest.raises(ParamError, match="distinct"):
        ENERGIES.convert("100,100")
    with pytest.raises(ParamError, match=r"--size = 5.5: must be in \(0, 1\] \(m\); plain numbers"):
        SIZE.convert("5.5")


def test_yade_batch_values_are_checked_the_same_way():
    """readParamsFromTable gives numbers, or strings for quoted cells: both go through convert."""
    assert SIZE.convert(0.0055) == 5.5e-3 and SIZE.convert("5.5mm") == 5.5e-3
    assert ENERGIES.convert(150) == "150"
    for bad in (-1, float("nan"), True, "abc"):
        with pytest.raises(ParamError, match="--energy = "):
            ENERGY.convert(bad)


@pytest.mark.parametrize("script, shown", [
    ("bed_impact", ["--size SIZE", "(m), a unit may follow the number: m, cm, mm, um",
                    "default 0.0055 m", "> 0 (J)", "default 3.05 J", "default 3 "]),
    ("single_impact", ["each > 0 (J/kg)", "default 100,200,400 J/kg", "default 250"]),
    ("drop_weight", ["default 0.003 s", "default 150,600 J/kg"]),
    ("repeated_impact", ["> 0 (J/kg)", "default 94.7 J/kg", "default 0.0375 m"]),
])
def test_help_shows_units_and_defaults(capsys, script, shown):
    assert _read(script, "--help") == 0
    text = " ".join(capsys.readouterr().out.split())          # argparse wraps lines
    for s in shown:
        assert s in text, s


@pytest.mark.yade
def test_bed_resume_refuses_other_arguments_and_says_when_finished(scene, tmp_path, capsys):
    """The bed's options read as its script reads them, run as its script runs them
    (run_script), in this process."""
    from yadebreak import engine
    from yadebreak.jobs import bed
    from yadebreak.jobs.lifecycle import run_script

    def _bed(out, *extra):
        """(exit code, what the run printed)."""
        engine.forget()
        scene.reset()
        args = job_options.read("bed_impact", None, ["--rings", "1", "--energy", "0.5", "--out",
                                                     str(out), *extra])
        try:
            run_script(bed.run, args)
            code = 0
        except SystemExit as ended:
            code = ended.code
        said = capsys.readouterr()
        return code, said.out + said.err

    def _refused(out, *extra):
        code, said = _bed(out, *extra)
        assert code == 2, said[-1500:]
        return _the_error_line(said)

    code, said = _bed(tmp_path, "--checkpoint-every", "0", "--stop-after", "1e-4")   # 0.1 ms
    assert code == 0, said[-1500:]
    assert (tmp_path / "checkpoint.yade.gz").exists() and not (tmp_path / "summary.json").exists()

    line = _refused(tmp_path, "--resume", "1", "--energy", "0.6")
    assert "other values of ['energy']" in line, line

    code, said = _bed(tmp_path, "--resume", "1", "--size", "5.5mm")      # the same arguments
    assert code == 0, said[-1500:]
    assert "resumed from" in said
    summary = (tmp_path / "summary.json").read_text()
    assert not (tmp_path / "checkpoint.yade.gz").exists()             # finished: no checkpoint

    code, said = _bed(tmp_path, "--resume", "1")
    assert code == 0 and "had finished: nothing to resume" in said
    assert (tmp_path / "summary.json").read_text() == summary         # not rewritten
    line = _refused(tmp_path, "--resume", "1", "--energy", "0.6", "--rings", "2")
    assert "other values of ['energy', 'rings']" in line, line
    assert json.loads(summary)["energy"] == 0.5
