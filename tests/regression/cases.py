"""The behaviour kept across the coupling redesign (issue 14): scenes whose events and summaries were
recorded with the engine before it was cut into parts, and must stay the same.

    /usr/bin/python3 tests/regression/cases.py record [NAME ...]   # re-record (say why in the commit)

Each case is a script run as users run it (`yade -n -x scripts/NAME.py ...`). tests/test_regression.py
runs them again and compares: the same events (kind, body, step, fragments, generation) with every
number within 1e-9 relative, and the same summary except wall times.
"""
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
BASELINE = Path(__file__).resolve().parent / "baseline"

#: name -> (script, arguments); small enough for the suite, each path of the engine covered once
CASES = {
    "bed_default": ("bed_impact", []),          # the main job: fast reads, ledger, 3 rings, seed 1
    "bed_spheres_exact": ("bed_impact", ["--rings", "1", "--energy", "1.0", "--dummies", "spheres",
                                         "--read-period", "1", "--seed", "2"]),
    "bed_auto": ("bed_impact", ["--rings", "2", "--energy", "2.0", "--read-period", "auto",
                                "--seed", "3", "--global-damping", "0.3"]),
    # in one scene each (--scene-particles), as they were recorded before scenes of a few existed
    "single_copper": ("single_impact", ["--particles", "20", "--energies", "150,700",
                                        "--scene-particles", "20"]),
    "single_ab_t10": ("single_impact", ["--material", "ab_t10_ore", "--particles", "16",
                                        "--energies", "250,600", "--scene-particles", "16"]),
    "drop_weight": ("drop_weight", ["--particles", "8", "--energies", "150,600"]),
    "repeated_copper": ("repeated_impact", ["--particles", "40", "--impacts", "6"]),
    "repeated_ab_t10": ("repeated_impact", ["--material", "ab_t10_ore", "--size", "5.5e-3",
                                            "--energy", "180", "--impacts", "4",
                                            "--particles", "30"]),
}

#: summary keys that measure the machine, not the model
WALL_KEYS = {"runtime_s", "wall_time_read_s", "wall_time_replace_s", "steps_wall_s"}
RTOL = 1e-9


def run(name, out):
    """Run case `name` into folder `out`; return the completed process."""
    script, arguments = CASES[name]
    out = Path(out)
    if out.exists():
        shutil.rmtree(out)
    return subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / f"{script}.py"),
                           "--out", str(out), *arguments], capture_output=True, text=True,
                          timeout=900, cwd=ROOT)


def outputs(out):
    """{file name: parsed content} of the files a case is compared on."""
    out = Path(out)
    found = {"summary.json": json.loads((out / "summary.json").read_text())}
    for path in sorted(out.glob("events*.jsonl")):
        found[path.name] = [json.loads(line) for line in path.read_text().splitlines()]
    return found


def differences(expected, got, where="", limit=20):
    """Where `got` differs from `expected`: numbers beyond RTOL, anything else not equal."""
    found = []
    if isinstance(expected, dict) and isinstance(got, dict):
        keys = set(expected) | set(got)
        for k in sorted(keys - WALL_KEYS, key=str):
            if k not in expected or k not in got:
                found.append(f"{where}.{k}: only in {'baseline' if k in expected else 'new run'}")
            else:
                found += differences(expected[k], got[k], f"{where}.{k}", limit)
    elif isinstance(expected, list) and isinstance(got, list):
        if len(expected) != len(got):
            found.append(f"{where}: {len(expected)} items in the baseline, {len(got)} now")
        for k, (a, b) in enumerate(zip(expected, got)):
            found += differences(a, b, f"{where}[{k}]", limit)
    elif (isinstance(expected, (int, float)) and isinstance(got, (int, float))
          and not isinstance(expected, bool) and not isinstance(got, bool)
          and isinstance(expected, float) | isinstance(got, float)):
        same = (math.isclose(expected, got, rel_tol=RTOL, abs_tol=1e-300)
                or (math.isnan(expected) and math.isnan(got)))
        if not same:
            found.append(f"{where}: {expected!r} in the baseline, {got!r} now")
    elif expected != got:
        found.append(f"{where}: {expected!r} in the baseline, {got!r} now")
    return found[:limit]


def record(names):
    for name in names:
        out = BASELINE / name
        proc = run(name, out)
        if proc.returncode != 0:
            sys.exit(f"{name} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
        for path in out.iterdir():               # keep only what is compared
            if path.name != "summary.json" and not path.name.startswith("events"):
                path.unlink() if path.is_file() else shutil.rmtree(path)
        print(f"recorded {name}: {sorted(p.name for p in out.iterdir())}", flush=True)


if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] != "record":
        sys.exit(__doc__)
    record(sys.argv[2:] or list(CASES))
