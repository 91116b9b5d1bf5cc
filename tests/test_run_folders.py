"""A run folder belongs to itself: moved or copied, it resumes from where it lies and writes only
into itself; nothing a run writes names an absolute path; a new run never replaces an earlier
one without --overwrite 1 (YADE, small beds of 7 particles: a few seconds each)."""
import gzip
import hashlib
import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

pytestmark = pytest.mark.yade

ROOT = Path(__file__).resolve().parent.parent
BED = ["--material", "copper_ore", "--rings", "1", "--energy", "0.6", "--seed", "3",
       "--max-time", "0.02", "--checkpoint-every", "0"]
CUT = ["--stop-after", "0.0005"]


def _bed(out, *options, cwd=None, code=0):
    proc = subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / "bed_impact.py"), *BED,
                           *options, "--out", str(out)], capture_output=True, text=True,
                          timeout=300, cwd=cwd)
    assert proc.returncode == code, proc.stdout[-1500:] + proc.stderr[-1500:]
    return proc.stdout + proc.stderr


def _events(out):
    return [json.loads(line) for line in (Path(out) / "events.jsonl").read_text().splitlines()]


def _digests(folder):
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(Path(folder).rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def cut(tmp_path_factory):
    """A bed run stopped as if killed at 0.5 ms, its checkpoint and event log left."""
    out = tmp_path_factory.mktemp("cut") / "bed"
    _bed(out, *CUT)
    assert (out / "checkpoint.yade.gz").is_file()
    return out


@pytest.fixture(scope="module")
def resumed_in_place(cut, tmp_path_factory):
    """The same stopped run resumed where it was written: the reference of the moves."""
    out = tmp_path_factory.mktemp("in_place") / "bed"
    shutil.copytree(cut, out)
    _bed(out, "--resume", "1")
    return out


def test_a_moved_run_folder_resumes_to_the_same_end(cut, resumed_in_place, tmp_path):
    moved = tmp_path / "elsewhere" / "renamed"
    shutil.copytree(cut, tmp_path / "bed")
    moved.parent.mkdir()
    os.rename(tmp_path / "bed", moved)
    _bed(moved, "--resume", "1")
    assert _events(moved) == _events(resumed_in_place)
    summary = json.loads((moved / "summary.json").read_text())
    reference = json.loads((resumed_in_place / "summary.json").read_text())
    assert summary["end_reason"] == "finished"
    for key in ("steps", "breakage_events", "damage_events", "broken_mass_fraction"):
        assert summary[key] == reference[key], key


def test_a_copied_run_folder_resumed_leaves_the_original_byte_identical(cut, tmp_path):
    original = tmp_path / "original"
    shutil.copytree(cut, original)
    before = _digests(original)
    copy = tmp_path / "copy"
    subprocess.run(["cp", "-a", str(original), str(copy)], check=True)
    _bed(copy, "--resume", "1")
    assert _digests(original) == before
    summary = json.loads((copy / "summary.json").read_text())
    events = _events(copy)
    assert sum(e["kind"] == "breakage" for e in events) == summary["breakage_events"]
    assert sum(e["kind"] == "damage" for e in events) == summary["damage_events"]


def _absolute_paths_in(data, folder):
    """Every place of `data` (bytes) that names `folder` or the working folder of the run."""
    return [name for name in {str(folder), str(folder.resolve()), os.getcwd()}
            if name.encode() in data]


@pytest.mark.parametrize("relative", [False, True], ids=["absolute --out", "relative --out"])
def test_nothing_a_run_writes_names_an_absolute_path(tmp_path, relative):
    """The checkpoint (decompressed: YADE's XML with O.tags), the event log and every other file,
    of a stopped run and of the same run finished."""
    out = tmp_path / "bed"
    given = "bed" if relative else out
    _bed(given, *CUT, "--vtk-interval", "2e-4", cwd=tmp_path)
    scene = gzip.decompress((out / "checkpoint.yade.gz").read_bytes())
    assert b"yadebreak:yadebreak" in scene and b"events.jsonl" in scene
    assert _absolute_paths_in(scene, tmp_path) == []
    _bed(given, "--resume", "1", "--vtk-interval", "2e-4", cwd=tmp_path)
    for path in out.rglob("*"):
        if path.is_file():
            assert _absolute_paths_in(path.read_bytes(), tmp_path) == [], path


def test_a_new_run_over_an_earlier_one_is_refused_until_overwrite(cut, tmp_path):
    out = tmp_path / "bed"
    shutil.copytree(cut, out)
    before = _digests(out)
    log = _bed(out, "--rings", "2", code=2)       # a forgotten --resume 1, another option
    assert f"--out = {out} holds an interrupted run (checkpoint.yade.gz of " in log
    assert "continue it with --resume 1, start it over with --overwrite 1" in log
    assert _digests(out) == before                 # nothing replaced
    _bed(out, "--resume", "1", "--overwrite", "1", code=2)
    _bed(out, "--resume", "1")
    finished = _digests(out)
    log = _bed(out, code=2)
    assert f"--out = {out} holds a finished run (finished.json)" in log
    assert _digests(out) == finished
    _bed(out, "--overwrite", "1", *CUT)
    assert not (out / "finished.json").exists() and (out / "checkpoint.yade.gz").is_file()
