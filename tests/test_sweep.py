"""Sweeps on Dask (issue 19): the table read as YADE reads it, a LocalCluster of 2 workers
running a table of tiny runs (every line done, outputs where expected, parameters as under
yade-batch, a failing line reported with its message while the others finish), a killed sweep
resumed, and sweep.csv gathered from the summaries."""
import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from yadebreak.studies import sweep

from wall_times import timeless  # tests/wall_times.py

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "scripts" / "single_impact.py"

TABLE = """# tiny single impacts
material particles energies seed description
'copper_ore' 1 '300' 1 cu_a
'copper_ore' 1 '600' 2 cu_b
'copper_ore' 1 '-5' 3 bad_energy   # refused by the script: exit 2
'copper_ore' 2 '300' 4 cu_c
"""


def _table(tmp_path, text=TABLE, name="tiny.table"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.yade
def test_tables_are_read_as_yade_reads_them(tmp_path):
    from yade import utils
    text = """# no description column: built from the !-marked columns
a b! !OMP_NUM_THREADS c!
1 2.5 1 'x'    # a comment
= 3 = 'y'

4 = 1 'y'
4 = 1 'y'
"""
    path = _table(tmp_path, text)
    ours = sweep.read_table(path)
    theirs = utils.TableParamReader(str(path)).paramDict()
    assert [line.number for line in ours] == sorted(theirs)
    for line in ours:
        expected = dict(theirs[line.number])
        assert line.description == expected.pop("description")
        assert line.env == {"OMP_NUM_THREADS": expected.pop("!OMP_NUM_THREADS")}
        assert line.values == expected
    assert ours[3].description == "b=3,c=y__line=7__"       # a repeated description


def test_table_errors_name_the_file_and_line(tmp_path):
    with pytest.raises(sweep.SweepError, match=r"bad.table:3: 1 values for 2 columns"):
        sweep.read_table(_table(tmp_path, "a description\n1 x\n2\n", "bad.table"))
    with pytest.raises(sweep.SweepError, match=r":3: description 'x' repeats"):
        sweep.read_table(_table(tmp_path, "a description\n1 x\n2 x\n", "dup.table"))
    with pytest.raises(sweep.SweepError, match="cannot name a folder"):
        sweep.read_table(_table(tmp_path, "a description\n1 x/y\n", "slash.table"))
    with pytest.raises(sweep.SweepError, match="no such file"):
        sweep.read_table(tmp_path / "none.table")


def test_a_repeated_column_is_refused_naming_the_file_line_and_column(tmp_path):
    """yade-batch would run such a table with the last of the two values: refused before any
    run, whether the repeat is marked '!' or not."""
    table = _table(tmp_path, "# energies\n\nenergy seed energy\n1 2 3\n", "twice.table")
    with pytest.raises(sweep.SweepError, match=r"twice.table:3: column 3, 'energy', repeats "
                                               r"column 1") as info:
        sweep.read_table(table)
    assert "\n" not in str(info.value)
    with pytest.raises(sweep.SweepError, match=r":1: column 2, 'a', repeats column 1"):
        sweep.read_table(_table(tmp_path, "a! a\n1 2\n", "marked.table"))
    proc = subprocess.run([sys.executable, "-m", "yadebreak", "sweep", str(table), str(SCRIPT),
                           "--out", str(tmp_path / "out")], capture_output=True, text=True,
                          cwd=ROOT, timeout=120)
    assert proc.returncode == 2 and not (tmp_path / "out" / "sweep.json").exists()
    assert proc.stderr.strip().splitlines() == [
        f"[yadebreak] error: table {table}:3: column 3, 'energy', repeats column 1 (each "
        "parameter once)"]


def test_flatten_gives_dotted_names():
    assert sweep.flatten({"a": 1, "results": [{"b": 2, "c": [3, 4]}], "d": {"e": None}}) == {
        "a": 1, "results.0.b": 2, "results.0.c.0": 3, "results.0.c.1": 4, "d.e": None}


def test_bad_scheduler_is_refused_in_one_line():
    from yadebreak.process.scheduler import SchedulerError
    for spec in ("local:x", "local:0", "cluster"):
        with pytest.raises(SchedulerError, match="--scheduler"):
            sweep.connect(spec)


def _sweep(*args, timeout=600):
    return subprocess.run([sys.executable, "-m", "yadebreak", "sweep", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, cwd=ROOT)


@pytest.mark.yade
def test_a_table_runs_on_two_workers(tmp_path):
    pytest.importorskip("distributed")
    table, out = _table(tmp_path), tmp_path / "out"
    proc = _sweep(table, SCRIPT, "--out", out, "--scheduler", "local:2")
    assert proc.returncode == 1, proc.stderr[-2000:]             # a line failed
    assert "dashboard http" in proc.stderr                       # progress: stderr
    status = {r["description"]: r for r in json.loads((out / "sweep.json").read_text())["lines"]}
    assert {d: r["state"] for d, r in status.items()} == {
        "cu_a": "done", "cu_b": "done", "bad_energy": "failed", "cu_c": "done"}
    bad = status["bad_energy"]
    assert bad["exit_code"] == 2 and "--energies = -5" in bad["message"]
    assert bad["attempts"] == 1                                   # a refused line: not retried
    assert "--energies = -5" in proc.stdout                      # reported at the end
    assert len({r["worker"] for r in status.values()}) == 2       # both workers ran lines
    for d in ("cu_a", "cu_b", "cu_c"):
        assert status[d]["line"] == {"cu_a": 3, "cu_b": 4, "cu_c": 6}[d]
        summary = json.loads((out / d / "summary.json").read_text())
        assert summary["end_reason"] == "finished"
        assert (out / d / "log.txt").exists()
    # the line's values reached the script
    cu_c = json.loads((out / "cu_c" / "summary.json").read_text())
    assert cu_c["results"][0]["particles"] == 2 and cu_c["results"][0]["specific_energy"] == 300
    # sweep.csv: a row per line, the table's values and the summaries flattened
    with open(out / "sweep.csv") as f:
        rows = {r["description"]: r for r in csv.DictReader(f)}
    assert set(rows) == set(status)
    assert rows["cu_b"]["table.energies"] == "600"
    assert float(rows["cu_b"]["results.0.specific_energy"]) == 600
    assert rows["bad_energy"]["state"] == "failed" and rows["bad_energy"]["material"] == ""
    assert float(rows["cu_a"]["results.0.broken_fraction"]) == json.loads(
        (out / "cu_a" / "summary.json").read_text())["results"][0]["broken_fraction"]


@pytest.mark.yade
def test_a_line_gives_what_yade_batch_gives(tmp_path):
    """The same table line under yade-batch and under the sweep: the same summary (but for the
    wall time)."""
    pytest.importorskip("distributed")
    table = _table(tmp_path, "material particles energies seed description\n"
                             "'copper_ore' 3 '400' 7 line_one\n")
    batch = tmp_path / "batch"
    batch.mkdir()
    proc = subprocess.run(["yade-batch", "-j", "1", "--log", str(batch / "%.log"), str(table),
                           str(SCRIPT)], capture_output=True, text=True, timeout=600, cwd=batch)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    theirs = json.loads((batch / "out" / "sweep" / "line_one" / "summary.json").read_text())
    out = tmp_path / "out"
    assert _sweep(table, SCRIPT, "--out", out, "--scheduler", "local:1").returncode == 0
    ours = json.loads((out / "line_one" / "summary.json").read_text())
    assert timeless(ours) == timeless(theirs)


def _ctrl_c_as_in_a_terminal():
    """SIGINT back to its default in the child: a parent that ignores it (pytest-xdist's workers
    do) would otherwise hand the sweep an ignored Ctrl-C, as nohup does on purpose."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.yade
def test_a_killed_sweep_resumes_keeping_the_lines_done(tmp_path):
    pytest.importorskip("distributed")
    lines = "".join(f"'copper_ore' 1 '300' {k} run_{k}\n" for k in range(1, 6))
    table = _table(tmp_path, "material particles energies seed description\n" + lines)
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "yadebreak", "sweep", str(table), str(SCRIPT),
                             "--out", str(out), "--scheduler", "local:1"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT,
                            preexec_fn=_ctrl_c_as_in_a_terminal)
    status_file = out / "sweep.json"
    deadline = time.time() + 300
    while time.time() < deadline:
        time.sleep(0.3)
        if status_file.exists():
            try:
                rows = json.loads(status_file.read_text())["lines"]
            except json.JSONDecodeError:
                continue
            if sum(r["state"] == "done" for r in rows) >= 2:
                break
    proc.send_signal(signal.SIGINT)                          # Ctrl-C
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stdout + stderr
    rows = {r["description"]: r for r in json.loads(status_file.read_text())["lines"]}
    done = {d for d, r in rows.items() if r["state"] == "done"}
    assert 2 <= len(done) < 5
    assert all(r["state"] in ("done", "interrupted", "pending") for r in rows.values())
    stamps = {d: os.stat(out / d / "summary.json").st_mtime_ns for d in done}
    again = _sweep(table, SCRIPT, "--out", out, "--scheduler", "local:2")
    assert again.returncode == 0, again.stdout + again.stderr
    assert f"{5 - len(done)} of 5 lines to run ({len(done)} done before)" in again.stderr
    rows = {r["description"]: r for r in json.loads(status_file.read_text())["lines"]}
    assert all(r["state"] == "done" for r in rows.values())
    for d in done:                                            # not run again
        assert os.stat(out / d / "summary.json").st_mtime_ns == stamps[d]
        assert rows[d]["attempts"] == 1
    # a third call has nothing to do
    third = _sweep(table, SCRIPT, "--out", out)
    assert third.returncode == 0 and "all 5 lines" in third.stderr


def test_another_table_in_the_same_folder_is_refused(tmp_path):
    out = tmp_path / "out"
    a = _table(tmp_path, "x description\n1 a\n", "a.table")
    b = _table(tmp_path, "x description\n1 a\n", "b.table")
    sweep.SweepStatus(out, a, SCRIPT, sweep.read_table(a))
    with pytest.raises(sweep.SweepError, match="holds a sweep of"):
        sweep.SweepStatus(out, b, SCRIPT, sweep.read_table(b))


def test_gather_of_a_yade_batch_folder(tmp_path):
    table = _table(tmp_path, "energy description\n1.0 e1\n2.0 e2\n")
    out = tmp_path / "sweep"
    (out / "e1").mkdir(parents=True)
    (out / "e1" / "summary.json").write_text(json.dumps({"broken": 0.5, "r": [{"t": 1}]}))
    proc = subprocess.run([sys.executable, "-m", "yadebreak", "gather", str(table), "--out",
                           str(out)], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    with open(out / "sweep.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(r["description"], r["state"], r["broken"], r["r.0.t"], r["table.energy"])
            for r in rows] == [("e1", "done", "0.5", "1", "1.0"), ("e2", "not run", "", "", "2.0")]
