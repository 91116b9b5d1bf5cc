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

from yadebreak.analysis import reports
from yadebreak.jobs import lifecycle
from yadebreak.jobs.lifecycle import partial_outputs_on_failure, time_left
from yadebreak.options import flags as options
from yadebreak.process import signals

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
    with pytest.raises(lifecycle.StopRequested):       # --stop-after stands for a kill: nothing
        with partial_outputs_on_failure(lambda *end: written.append(end)):
            raise lifecycle.StopRequested()
    assert len(written) == 2


@pytest.mark.parametrize("exception, code", [(RuntimeError("boom"), 1), (KeyboardInterrupt(), 130)])
def test_run_script_turns_a_failure_into_an_exit_code_and_a_line(capsys, exception, code):
    def main():
        raise exception
    shown = warnings.showwarning
    with pytest.raises(SystemExit) as ended:
        lifecycle.run_script(main)
    assert warnings.showwarning is shown            # its warnings' display was scoped to the run
    assert ended.value.code == code
    said = capsys.readouterr()
    assert ("the run failed (RuntimeError: boom)" in said.err if code == 1
            else "interrupted" in said.out)


def test_a_warning_is_shown_once_naming_the_scripts_own_option(capsys):
    from yadebreak.engine.controller import YadebreakWarning
    from yadebreak.engine.reads import ReadSchedule
    schedule = ReadSchedule.__new__(ReadSchedule)
    schedule.period, schedule.mode = 7, "fast"
    remedies = schedule.remedies()
    warning = YadebreakWarning("jump", "energy jumped", remedies, "for an accurate t10'")
    assert str(warning) == "yadebreak: energy jumped: reduce fast_fraction for an accurate t10'"
    # bed_impact exposes --read-period and --time-step-fraction, not fast_fraction
    assert warning.for_script({"read_period", "time_step_fraction"}) == (
        "energy jumped: read every step (--read-period 1) for an accurate t10'")
    assert "(an attach() option)" in warning.for_script(set())

    options.script_params([options.integer("read_period", 1, "how often", lo=1)], argv=[])
    shown = warnings.showwarning
    with lifecycle.warnings_shown_once():           # what run_script does around a run
        warnings.simplefilter("always")
        for _ in range(3):           # e.g. three scenes of a run, each with its own controller
            warnings.warn(YadebreakWarning("jump", "energy jumped", remedies))
    assert warnings.showwarning is shown            # scoped: Python's display is back after it
    lines = [line for line in capsys.readouterr().err.splitlines() if "WARNING" in line]
    assert lines == ["[yadebreak] WARNING: energy jumped: read every step (--read-period 1) "
                     "(shown once)"]


def _bed_args(out, **changes):
    values = dict(material="copper_ore", size=5.5e-3, rings=1, layers=1, energy=0.6, speed=0.0,
                  seed=3, time_step_fraction=0.05, dmin=0.0, global_damping="material",
                  dummies="ledger", read_period="fast", max_time=0.02, out=str(out),
                  checkpoint_every=0.0, vtk_interval=0.0)
    values.update(changes)
    return argparse.Namespace(**values)


@pytest.mark.yade
def test_a_bed_run_that_fails_midway_leaves_its_outputs_and_says_why(scene, tmp_path,
                                                                      monkeypatch):
    from yadebreak.jobs import bed
    from yadebreak import engine as coupling
    real, calls = coupling.run_steps, []

    def failing(n):                     # a batch of steps fails after the first checkpoint
        calls.append(n)
        if len(calls) == bed.SAFE_EVERY + 1:
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
    from yadebreak.jobs import bed
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
    rows = (tmp_path / "report" / "configurations.csv").read_text().splitlines()
    assert len(rows) == 2 and ",2," in rows[1]          # one configuration, 2 runs
    # its error bar (mean 0.2 g, sd 0.1 g) is drawn; with sd > mean it would stop at zero
    assert (tmp_path / "report" / "broken_mass.png").stat().st_size > 0


@pytest.mark.yade
def test_a_small_bed_says_why_it_took_longer(scene, tmp_path, capsys):
    """One ring under 1.5 J (7 particles) breaks finer than the default bed: the run reports the
    energy per kg of bed at the start, and at the end the fall of the time step and the finest
    fragment that caused it, from its own summary."""
    from yadebreak.jobs import bed
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


# -- faults lose nothing: one run per --out, signals, damaged files, a full disk, workers ----------
def _run_script(main, args):
    """run_script in this process: (exit code or None, stdout, stderr) via capsys by the caller."""
    return lifecycle.run_script(main, args)


def _one_line(text):
    lines = [line for line in text.splitlines() if line.strip()]
    assert len(lines) == 1, text
    return lines[0]


def _read_only_folder(path):
    """A read-only tmpfs at `path` (root writes through chmod 555), or None where mount is
    refused; unmounted by the caller."""
    import subprocess
    path.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "ro,size=64k", "tmpfs", str(path)],
                          capture_output=True)
    return path if done.returncode == 0 else None


@pytest.mark.parametrize("where", ["a file", "a read-only folder"])
def test_an_out_that_cannot_be_written_ends_in_one_line_exit_1(tmp_path, capsys, where):
    import subprocess
    if where == "a file":
        out = tmp_path / "summary.txt"
        out.write_text("a user's file")
        expected = "NotADirectoryError: [Errno 20] a file, not a folder"
    else:
        if _read_only_folder(tmp_path / "ro") is None:
            pytest.skip("no read-only file system can be mounted here")
        out = tmp_path / "ro" / "run"
        expected = "Read-only file system"
    ran = []
    try:
        with pytest.raises(SystemExit) as ended:
            _run_script(ran.append, argparse.Namespace(out=str(out)))
    finally:
        if where != "a file":
            subprocess.run(["umount", str(tmp_path / "ro")], check=True)
    assert ended.value.code == 1 and ran == []
    line = _one_line(capsys.readouterr().err)
    assert line.startswith(f"[yadebreak] error: --out = {out}: cannot be written (")
    assert expected in line and line.endswith("); nothing was run")
    if where == "a file":
        assert out.read_text() == "a user's file"


def test_a_second_run_into_an_out_in_use_is_refused_and_a_killed_one_leaves_no_lock(tmp_path,
                                                                                    capsys):
    holder = subprocess.Popen(
        ["nice", "-n", "5", sys.executable, "-c", "import sys, time; sys.path.insert(0, "
         "sys.argv[1]); from yadebreak.jobs.lifecycle import lock_out; lock_out(sys.argv[2]); "
         "print('locked', flush=True); time.sleep(120)", str(ROOT), str(tmp_path)],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        ran = []
        with pytest.raises(SystemExit) as ended:
            _run_script(ran.append, argparse.Namespace(out=str(tmp_path)))
        assert ended.value.code == 2 and ran == []          # refused before the run began
        line = _one_line(capsys.readouterr().err)
        assert line == (f"[yadebreak] error: --out = {tmp_path}: another run is writing there "
                        f"(process {holder.pid}, started " + line.split(", started ")[1])
    finally:
        holder.kill()                                        # kill -9: the kernel frees the lock
        holder.wait()
    assert _run_script(lambda args: "ran", argparse.Namespace(out=str(tmp_path))) == "ran"
    assert lifecycle._LOCKS == {}                 # released when the run is over


def test_a_signal_ends_the_run_as_interrupted_with_its_outputs(tmp_path, capsys):
    """A signal within stop_points only asks to stop: the loop ends at its next stop point, with
    its checkpoint (save) and its summary (partial_outputs_on_failure), exit code 128 + signal."""
    import os
    import signal
    written, saved, steps = [], [], []

    def main(args):
        with lifecycle.partial_outputs_on_failure(lambda *end: written.append(end)), \
                lifecycle.stop_points():
            for step in range(5):
                if step == 2:                                # the scheduler's wall-time limit
                    os.kill(os.getpid(), signal.SIGTERM)
                steps.append(step)                           # the step in hand is finished
                lifecycle.stop_point(lambda: saved.append(step))
    with pytest.raises(SystemExit) as ended:
        _run_script(main, argparse.Namespace(out=str(tmp_path)))
    assert ended.value.code == 143
    assert steps == [0, 1, 2] and saved == [2]
    assert written == [("interrupted", "stopped by SIGTERM")]
    said = capsys.readouterr()
    assert said.err == "" and said.out.splitlines()[-1].startswith(
        "[yadebreak] interrupted (SIGTERM): ")       # (before it: YADE's greeting, if imported)
    assert signal.getsignal(signal.SIGTERM) is not signals.on_signal       # restored


def test_a_second_signal_stops_at_once(tmp_path):
    import os
    import signal
    reached = []

    def main(args):
        with lifecycle.stop_points():
            os.kill(os.getpid(), signal.SIGINT)         # asks: the loop would stop at its point
            reached.append("after the first")
            os.kill(os.getpid(), signal.SIGINT)         # insists: stops here
            reached.append("after the second")
    with pytest.raises(SystemExit) as ended:
        _run_script(main, argparse.Namespace(out=str(tmp_path)))
    assert ended.value.code == 130 and reached == ["after the first"]


@pytest.mark.yade
def test_ctrl_c_inside_a_pyrunner_ends_as_interrupted_not_as_a_pyrunner_error(scene, tmp_path,
                                                                              capsys):
    """The signal strikes while YADE runs a PyRunner's Python: the step goes on to its end, and the
    run stops after it as interrupted (exit 130), not as YADE's PyRunner error."""
    from yade import wrapper
    from yadebreak import engine as coupling
    scene.engines = [wrapper.ForceResetter(), wrapper.PyRunner(       # the signal, then more
        command="import os, signal; os.kill(os.getpid(), signal.SIGINT); from yade import O; "
                "O.tags['ran'] = str(int(O.tags['ran']) + 1)", iterPeriod=1, initRun=True)]
    scene.dt = 1e-6
    scene.tags["ran"] = "0"
    written = []

    def main(args):
        with lifecycle.partial_outputs_on_failure(lambda *end: written.append(end)), \
                lifecycle.stop_points():
            for _ in range(3):
                coupling.run_steps(1)
                lifecycle.stop_point()
    with pytest.raises(SystemExit) as ended:
        _run_script(main, argparse.Namespace(out=str(tmp_path)))
    said = capsys.readouterr()
    assert ended.value.code == 130 and scene.iter == 1
    assert int(scene.tags["ran"]) == scene.iter          # every PyRunner call ran to its end
    assert written == [("interrupted", "stopped by Ctrl-C, SIGINT")]
    assert "PyRunner" not in said.out + said.err


def test_a_signal_wrapped_in_an_error_is_still_an_interruption(tmp_path):
    """A signal outside stop_points raises where it strikes; inside a PyRunner YADE turns it into a
    RuntimeError: the run still ends as interrupted."""
    import os
    import signal
    written = []
    handlers = signals.catch_signals()
    try:
        with signals.stop_points():
            os.kill(os.getpid(), signal.SIGINT)         # received: the run is asked to stop
        with pytest.raises(RuntimeError):
            with lifecycle.partial_outputs_on_failure(lambda *end: written.append(end)):
                raise RuntimeError("PyRunner error.\nCOMMAND: ...\nKeyboardInterrupt")
    finally:
        signals.restore_signals(handlers)
    assert written == [("interrupted", "stopped by Ctrl-C, SIGINT")]


def _partial_results(tmp_path, **changes):
    """partial.json of a run at 100 J/kg, 10 particles of copper ore 5.5 mm on steel, 3 broken."""
    from yadebreak import load_material
    mat, steel = load_material("copper_ore"), load_material("steel")
    args = argparse.Namespace(material="copper_ore", particles=10, energies="100", resume=False,
                              stop_after=0)
    result = {"specific_energy": 100.0, "particles": 10, "broken_fraction": 0.3,
              "model_probability": float(mat.breakage_probability(100.0, 5.5e-3, partner=steel)),
              "t10_simulated": 4.0, **changes}
    lifecycle.PartialResults(tmp_path, args).add(100.0, result)
    args.resume = True

    def validate(key, result):
        from yadebreak.analysis import reports
        reports.check_breakage_result(result, mat, 5.5e-3, float(key), steel, args.particles)
    return args, validate


@pytest.mark.parametrize("damage, why", [
    (lambda b: b[:len(b) // 2], "is damaged (JSONDecodeError"),
    (lambda b: b"\xff\xfe" + b[2:], "is damaged (UnicodeDecodeError"),
    (lambda b: b"", "is damaged (JSONDecodeError"),
    (lambda b: b.replace(b'"broken_fraction": 0.3', b'"broken_fraction": 0.99'),
     "was changed after it was written"),
])
def test_a_damaged_partial_file_is_refused_in_one_line(tmp_path, damage, why):
    args, validate = _partial_results(tmp_path)
    path = tmp_path / "partial.json"
    path.write_bytes(damage(path.read_bytes()))
    with pytest.raises(lifecycle.ScriptError) as refused:
        lifecycle.PartialResults(tmp_path, args, validate)
    assert str(refused.value).startswith(f"--resume: {path} ") and why in str(refused.value)
    assert "\n" not in str(refused.value)


@pytest.mark.parametrize("changes, why", [
    ({"broken_fraction": 0.99, "particles": -3}, "particles = -3, not 10"),
    ({"broken_fraction": 0.35}, "broken_fraction = 0.35 is not a count of 10 particles"),
    ({"broken_fraction": 1.5}, "broken_fraction = 1.5: must be a number in [0, 1]"),
    ({"model_probability": 0.5}, "model_probability = 0.5, the model gives"),
])
def test_a_result_this_run_could_not_have_written_is_refused(tmp_path, changes, why):
    """With its digest made to match (the edit is not seen by it), the values themselves are
    checked against the run's arguments and the model."""
    args, validate = _partial_results(tmp_path, **changes)
    assert lifecycle.PartialResults(tmp_path, args).done    # no check without validate
    with pytest.raises(lifecycle.ScriptError, match="is not one this run could have written"):
        lifecycle.PartialResults(tmp_path, args, validate)
    with pytest.raises(lifecycle.ScriptError) as refused:
        lifecycle.PartialResults(tmp_path, args, validate)
    assert why in str(refused.value)


def test_a_sound_partial_file_resumes(tmp_path):
    args, validate = _partial_results(tmp_path)
    assert lifecycle.PartialResults(tmp_path, args, validate).done["100.0"]["particles"] == 10


@pytest.mark.yade
@pytest.mark.parametrize("damage", ["truncated", "empty", "garbage"])
def test_a_damaged_checkpoint_is_refused_in_one_line_claiming_nothing(scene, tmp_path, capsys,
                                                                      damage):
    from yadebreak.jobs import bed, mill
    from yadebreak import engine as coupling
    assert bed.run(_bed_args(tmp_path, checkpoint_every=0.0, stop_after=1e-4), quiet=True)[1] \
        is None
    path = tmp_path / "checkpoint.yade.gz"
    good = path.read_bytes()
    path.write_bytes({"truncated": good[:len(good) // 2], "empty": b"",
                      "garbage": bytes(range(256)) * 40}[damage])
    mill_out = tmp_path / "mill"
    mill_out.mkdir()
    (mill_out / "checkpoint.yade.gz").write_bytes(path.read_bytes())
    for run, args in ((bed.run, _bed_args(tmp_path, resume=True)),
                      (mill.run, argparse.Namespace(        # what it reads before the file
                          size=6e-3, ball_size=15e-3, drum_diameter=0.12, lifter_height=6e-3,
                          resume=True, out=str(mill_out)))):
        coupling.forget()
        scene.reset()
        with pytest.raises(SystemExit) as ended:
            _run_script(run, args)
        assert ended.value.code == 2
        said = capsys.readouterr()
        line = _one_line(said.err)
        assert line.startswith(f"[yadebreak] error: --resume: {args.out}/checkpoint.yade.gz is "
                               "damaged (") and "kept" not in line and "summary" not in line
        assert not (Path(args.out) / "summary.json").exists()


def _full_disk(after):
    """A writer that fills the disk: the first `after` calls write, the next ones raise ENOSPC
    (having written part of their file, as a full disk does)."""
    import errno
    calls = []

    def write(real):
        def writer(path, *rest):
            calls.append(path)
            if len(calls) > after:
                Path(str(path)).write_bytes(b"\x1f\x8b part")
                raise OSError(errno.ENOSPC, "No space left on device", str(path))
            return real(path, *rest)
        return writer
    return write, calls


@pytest.mark.yade
def test_a_full_disk_stops_the_run_in_one_line_keeping_the_last_checkpoint(scene, tmp_path,
                                                                             capsys, monkeypatch):
    """Checkpoints at every chunk of steps; the third one finds the disk full: the run stops with
    one line naming what it wrote, summary.json says why, and the second checkpoint, whole, goes
    on with --resume 1 to the end of the run."""
    from yadebreak.jobs import bed
    from yadebreak import engine as coupling
    from yadebreak.engine import scene as engine
    full, calls = _full_disk(after=2)
    monkeypatch.setattr(engine, "save", full(engine.save))
    with pytest.raises(SystemExit) as ended:
        _run_script(bed.run, _bed_args(tmp_path, checkpoint_every=0.0, vtk_interval=1e-4))
    assert ended.value.code == 1 and len(calls) == 3
    line = _one_line(capsys.readouterr().err)
    assert line.startswith("[yadebreak] error: the disk is full (OSError: [Errno 28] No space "
                           "left on device: ")
    assert (f"kept in {tmp_path}: summary.json (end_reason 'error'), checkpoint.yade.gz (of "
            in line)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["end_reason"] == "error" and "[Errno 28]" in summary["end_message"]
    assert sorted(p.name for p in tmp_path.iterdir() if "tmp" in p.name) == []
    monkeypatch.undo()
    coupling.forget()
    scene.reset()
    _, resumed = bed.run(_bed_args(tmp_path, resume=True), quiet=True)
    assert resumed["end_reason"] == "finished"
    assert resumed["final_mass"] == pytest.approx(resumed["initial_mass"], rel=1e-12)


@pytest.mark.yade
def test_a_disk_full_of_frames_and_summaries_says_nothing_was_summarised(scene, tmp_path, capsys,
                                                                        monkeypatch):
    """No frame and no summary can be written: the line says so and names only what exists."""
    from yadebreak.jobs import bed, paraview
    full, calls = _full_disk(after=1)                   # the first frame, then nothing
    monkeypatch.setattr(paraview, "write_atomic", full(paraview.write_atomic))
    monkeypatch.setattr(bed, "write_atomic", full(bed.write_atomic))
    with pytest.raises(SystemExit) as ended:
        _run_script(bed.run, _bed_args(tmp_path, checkpoint_every=-1.0, vtk_interval=1e-4))
    assert ended.value.code == 1
    line = _one_line(capsys.readouterr().err)
    assert line.startswith("[yadebreak] error: the disk is full (OSError: [Errno 28] ")
    assert line.endswith("; no summary.json was written") and "checkpoint" not in line
    assert not (tmp_path / "summary.json").exists()


@pytest.mark.yade
def test_impact_workers_die_with_their_parent(tmp_path):
    """single_impact --jobs 2 killed with -9: its local cluster and the cluster's workers go with
    it (within 10 s)."""
    import os
    import signal
    import time
    proc = subprocess.Popen(["nice", "-n", "5", "yade", "-n", "-x",
                             str(ROOT / "scripts" / "single_impact.py"), "--out", str(tmp_path),
                             "--energies", "400", "--particles", "200", "--jobs", "2"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def children(pid):
        found = []
        for stat in Path("/proc").glob("[0-9]*/stat"):
            try:
                fields = stat.read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                found.append(int(stat.parent.name))
        return found

    def descendants(pid):
        below = children(pid)
        return below + [d for c in below for d in descendants(c)]

    def workers_of(pid):        # the cluster's worker processes, multiprocessing's spawn
        return [d for d in descendants(pid)
                if b"spawn_main" in Path(f"/proc/{d}/cmdline").read_bytes()]
    try:
        deadline = time.time() + 60
        while len(workers_of(proc.pid)) < 2 and time.time() < deadline:
            time.sleep(0.2)
        family = descendants(proc.pid)
        assert len(workers_of(proc.pid)) == 2
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    deadline = time.time() + 10
    while any(Path(f"/proc/{w}").exists() for w in family) and time.time() < deadline:
        time.sleep(0.1)
    alive = [w for w in family if Path(f"/proc/{w}").exists()
             and Path(f"/proc/{w}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"]
    assert alive == []


@pytest.mark.yade
@pytest.mark.parametrize("signum, code, name", [(15, 143, "SIGTERM"), (2, 130, "Ctrl-C, SIGINT")])
def test_a_signalled_bed_run_ends_interrupted_with_a_checkpoint(scene, tmp_path, signum, code,
                                                                name):
    """SIGTERM (a scheduler's wall-time limit) or SIGINT (Ctrl-C) once the impact runs: exit code
    128 + signal, one line naming what is kept, summary.json 'interrupted' and a whole checkpoint
    of the state it summarises (resuming from a checkpoint: tests/test_resume.py)."""
    import os
    bed = ["nice", "-n", "5", "yade", "-n", "-x", str(ROOT / "scripts" / "bed_impact.py"), "--out",
           str(tmp_path), "--rings", "1", "--energy", "0.6", "--vtk-interval", "0"]
    proc = subprocess.Popen(bed, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for line in proc.stdout:
        if "particles of copper_ore" in line:             # the scene is built, the ball falls
            os.kill(proc.pid, signum)
            break
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == code, out + err
    last = out.strip().splitlines()[-1]
    assert last.startswith(f"[yadebreak] interrupted ({name}): kept in {tmp_path}: summary.json "
                           "(end_reason 'interrupted'), checkpoint.yade.gz (of "), last
    assert "Traceback" not in err
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["end_reason"] == "interrupted" and summary["end_message"] == f"stopped by {name}"
    from yadebreak import engine as coupling
    _, state = lifecycle.read_checkpoint(tmp_path / "checkpoint.yade.gz",
                                          coupling.load_checkpoint)   # whole, where it stopped
    assert scene.time == pytest.approx(summary["simulated_time"], rel=1e-12)
    assert scene.iter == summary["steps"] and state["arguments"]["rings"] == 1


@pytest.mark.yade
def test_a_failed_impact_worker_stops_the_run_with_its_last_words(tmp_path):
    """A scene that fails on a worker (here a material file that is not there), tried again
    once (--retries 1): the run stops with an error that carries the worker's own message, and
    the folder of the scenes done stays beside the event log."""
    from yadebreak import scenes
    from yadebreak.process.scheduler import Scheduler
    log = tmp_path / "events.jsonl"
    missing = tmp_path / "no_such_material.toml"
    # both scenes fail alike: whichever fails its second time first stops the run
    with pytest.raises(RuntimeError, match=r"scenes (\d)-\1 failed 2 times \(--retries 1\)") \
            as failed:
        scenes.single_impacts(str(missing), 5.5e-3, 20.0, 2, 1, 3,
                              scheduler=Scheduler.parse("local:2"), event_log=str(log))
    assert "no_such_material" in str(failed.value)
    assert f"the scenes done are kept in {tmp_path / 'events.workers'}" in str(failed.value)
    assert (tmp_path / "events.workers").is_dir()


# -- python3 -m yadebreak verify and the folder commands: bad input and a read-only --out ------
@pytest.mark.parametrize("arguments, line", [
    (["--figures", ""], "--figures = '': must be a non-empty text"),
    (["--figures", " , "], "--figures = ' , ': names no figure; accepted probability, targets, "
     "sizes, repeated, progeny, drop_weight, t10, time_step, cs, damping"),
    (["--materials", "nosuch"], "--materials = nosuch: unknown material 'nosuch'"),
    (["--out", ""], "--out = '': must be a non-empty text"),
])
def test_verify_refuses_bad_input_in_one_line(tmp_path, capsys, arguments, line):
    from yadebreak.cli import main
    out = tmp_path / "v"
    with pytest.raises(SystemExit) as end:
        main(["verify", "--out", str(out), *arguments])
    err = capsys.readouterr().err.strip().splitlines()
    assert end.value.code == 2 and len(err) == 1 and err[0].startswith(f"[yadebreak] error: "
                                                                       f"{line}"), err
    assert not out.exists()


def test_a_read_only_out_ends_a_command_in_one_line(tmp_path, capsys, monkeypatch):
    """mkdir of --out refused (a read-only file system; chmod does not stop root): one line, exit
    code 1, for the commands that write a folder."""
    import errno
    from yadebreak.cli import main

    def read_only(self, *args, **kwargs):
        raise OSError(errno.EROFS, "Read-only file system", str(self))
    monkeypatch.setattr(Path, "mkdir", read_only)
    out = tmp_path / "ro"
    for command in (["demo"], ["grind", "synthetic:30"], ["verify", "--quick", "1"],
                    ["fit", str(ROOT / "docs" / "examples" / "calibration" / "t10.csv"), "--base",
                     "copper_ore"]):
        with pytest.raises(SystemExit) as end:
            main([*command, "--out", str(out)])
        err = capsys.readouterr().err.strip().splitlines()
        assert end.value.code == 1 and err == [f"[yadebreak] error: --out = {out}: cannot be "
                                               f"written (OSError: [Errno 30] Read-only file "
                                               f"system: '{out}'); nothing was run"], err


def test_a_command_run_again_into_its_out_is_refused_until_overwrite(tmp_path, capsys):
    """The commands that write a run folder (demo here; grind, fit and verify alike) keep a
    finished run: run again into it, one line and exit code 2, its files untouched."""
    from yadebreak.cli import main
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out)]) == 0
    assert (out / "finished.json").is_file()
    kept = {p.name: p.read_bytes() for p in out.iterdir()}
    capsys.readouterr()
    with pytest.raises(SystemExit) as end:
        main(["demo", "--out", str(out), "--material", "granulite"])
    line = _one_line(capsys.readouterr().err)
    assert end.value.code == 2 and line == (
        f"[yadebreak] error: --out = {out} holds a finished run (finished.json): start it over "
        "with --overwrite 1, or choose another --out")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == kept
    assert main(["demo", "--out", str(out), "--material", "granulite", "--overwrite", "1"]) == 0
    assert (out / "model_granulite.png").is_file()


def test_an_append_that_fails_leaves_the_file_as_it_was(tmp_path, monkeypatch):
    """The disk fills halfway through an append (the events of a scene merged into an energy's
    log): the file is cut back to its whole lines, and the error goes on."""
    import errno
    import io
    path = tmp_path / "events.jsonl"
    path.write_text('{"a": 1}\n')

    class HalfFull(io.TextIOWrapper):
        def write(self, text):
            super().write(text[: len(text) // 2])
            self.flush()
            raise OSError(errno.ENOSPC, "No space left on device")

    def open_half_full(file, mode="r"):
        return HalfFull(io.open(file, mode + "b"))
    from yadebreak.process import files
    monkeypatch.setattr(files, "open", open_half_full, raising=False)
    with pytest.raises(OSError):
        lifecycle.append_whole(path, '{"b": 2}\n{"c": 3}\n')
    assert path.read_text() == '{"a": 1}\n'
    monkeypatch.undo()
    lifecycle.append_whole(path, '{"b": 2}\n')
    assert path.read_text() == '{"a": 1}\n{"b": 2}\n'
