"""Interrupted script runs continue with --resume 1 and give what an uninterrupted run gives
(issue 7). The scripts run as users run them: yade -n -x scripts/<name>.py ..."""
import json
import subprocess
from pathlib import Path

import pytest

pytestmark = pytest.mark.yade

ROOT = Path(__file__).resolve().parent.parent


def _script(name, out, *extra):
    proc = subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / f"{name}.py"),
                           "--out", str(out), *extra], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-1500:] + proc.stderr[-1500:]
    return proc.stdout


@pytest.mark.parametrize("name, arguments", [
    ("repeated_impact", ["--material", "ab_t10_ore", "--size", "5.5e-3", "--energy", "180",
                         "--impacts", "4", "--particles", "30"]),
    ("single_impact", ["--material", "limestone", "--energies", "60,120", "--particles", "30"]),
    ("drop_weight", ["--material", "limestone", "--energies", "60,120", "--particles", "6",
                     "--max-time", "3e-4"]),
])
def test_interrupted_script_resumes_to_the_same_result(tmp_path, name, arguments):
    _script(name, tmp_path / "whole", *arguments)
    _script(name, tmp_path / "cut", *arguments, "--stop-after", "1")
    assert not (tmp_path / "cut" / "summary.json").exists()        # it did stop early
    log = _script(name, tmp_path / "cut", *arguments, "--resume", "1")
    assert "resum" in log
    whole = json.loads((tmp_path / "whole" / "summary.json").read_text())
    cut = json.loads((tmp_path / "cut" / "summary.json").read_text())
    for d in (whole, cut):
        d.pop("runtime_s")
    if name in ("single_impact", "drop_weight"):
        for d in (whole, cut):
            for r in d["results"]:
                r.pop("steps_wall_s", None)
    assert cut == whole


def test_resume_with_other_arguments_is_refused(tmp_path):
    args = ["--material", "limestone", "--energies", "60,120", "--particles", "20"]
    _script("single_impact", tmp_path, *args, "--stop-after", "1")
    proc = subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / "single_impact.py"),
                           "--out", str(tmp_path), *args[:-1], "30", "--resume", "1"],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode != 0
    assert "other values of ['particles']" in proc.stdout + proc.stderr
