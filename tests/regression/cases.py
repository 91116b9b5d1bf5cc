"""Regression cases: scenes run as users run them (`yade -n -x scripts/NAME.py ...`), compared with
the events and summary recorded in tests/regression/baseline/NAME/.

    /usr/bin/python3 tests/regression/cases.py record [NAME ...] [--jobs 2] [--nudges 4]
    (say why in the commit; --jobs: runs at a time; --nudges: nudged runs per case)

What a case must hold on any x86-64 machine (`cross_cpu_differences`, the suite's check). Another
CPU rounds some operations differently in the last bit (libm, SIMD sums); a run with fragments
in contact is chaotic, so the difference grows until events move by a step, a damage event comes
or goes and the counts change (bed_auto: 57 events on the recording machine, 60 on another). So:

(a) The run before the first divergence: in each event log (each scene of it), the events up to
    and including the step of the first breakage (before any fragment exists nothing chaotic has
    happened) are the same events: kind, body, step, partner, generation, fragments equal, every
    number within PREFIX_RTOL = 1e-6 of the largest value of that field in the log (fields that
    are zero in exact arithmetic: ROUNDOFF_ATOL). Runs nudged in the last bit agree there to
    5e-12 or better (MEASURED), so 1e-6 leaves room for any CPU's rounding, while a material
    parameter off by a few % moves the first breakage by that much.
(b) Conservation to round-off: every mass_relative_error at most MASS_ATOL = 1e-12 in magnitude
    (recorded: 0 to 1.4e-14).
(c) The rest of the summary. What is fixed before the run starts (the SETUP fields: sizes, energies,
    seeds, the model's values) within RTOL = 1e-9. Every outcome (counts of events and of broken
    particles, broken fractions, steps, simulated time, progeny sizes, t10, ...; and each log's
    count of events of each kind) within a band measured when the baseline was recorded: `record`
    runs the case again with the initial state moved by one ulp (nudged.py, as another CPU would;
    4 seeds) and keeps the outcomes in baseline/NAME/spread.json. The band (`band`) is the range
    of the baseline and those runs, widened on each side by the larger of its own width and
    OUTCOME_FLOOR = 25 % of the baseline's value (for counts at least 1 and COUNT_SIGMAS = 2
    times the square root of the baseline's count, its counting noise): a few runs can miss a
    jump that another CPU makes, and the largest jump measured of a quantity that was steady in
    the others was 13 % (MEASURED); a small count moves further (bed_default's
    unbreakable_stressed events: 11-13 recorded, 16 on another machine). Text outcomes
    (end_reason) must be one of the recorded runs'.
(d) Only on the machine that recorded the baseline: every event and the whole summary within 1e-9
    (`differences`), checked when YADEBREAK_EXACT_REGRESSION=1; spread.json names that machine.

The suite runs each case nudged (CHECK_NUDGE, a seed that `record` does not use), so every run of
the suite is a run "on another CPU"; with YADEBREAK_EXACT_REGRESSION=1 it runs them unchanged.
What (a)-(c) cannot see: a change that leaves every first breakage as it was and moves the
outcomes by less than their bands (how fragments meet later, say); (d) sees it, on the machine
that recorded the baselines.
"""
import concurrent.futures
import hashlib
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))   # tests/: run as a script too
from wall_times import WALL_KEYS  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent.parent
BASELINE = Path(__file__).resolve().parent / "baseline"

#: name -> (script, arguments); small enough for the suite, each path of the engine covered once
CASES = {
    "bed_default": ("bed_impact", []),          # the main job: fast reads, ledger, 3 rings, seed 1
    "bed_spheres_exact": ("bed_impact", ["--rings", "1", "--energy", "1.0", "--dummies", "spheres",
                                         "--read-period", "1", "--seed", "2"]),
    "bed_auto": ("bed_impact", ["--rings", "2", "--energy", "2.0", "--read-period", "auto",
                                "--seed", "3", "--global-damping", "0.3",
                                "--global-damping-time", "5e-4"]),
    # in one scene each (--scene-particles), as they were recorded before scenes of a few existed;
    # in this process (--jobs 1): nudged.py nudges the scenes built here, not a pool worker's
    "single_copper": ("single_impact", ["--particles", "20", "--energies", "150,700",
                                        "--scene-particles", "20", "--jobs", "1"]),
    "single_ab_t10": ("single_impact", ["--material", "ab_t10_ore", "--particles", "16",
                                        "--energies", "250,600", "--scene-particles", "4",
                                        "--jobs", "1"]),
    "drop_weight": ("drop_weight", ["--particles", "4", "--energies", "150,600"]),
    "repeated_copper": ("repeated_impact", ["--particles", "40", "--impacts", "6"]),
    "repeated_ab_t10": ("repeated_impact", ["--material", "ab_t10_ore", "--size", "5.5e-3",
                                            "--energy", "180", "--impacts", "4",
                                            "--particles", "30"]),
}

#: summary fields fixed before the run starts (inputs and the model's values), by their last name
SETUP = {"material", "size", "rings", "layers", "bed_packing", "bed_height", "bed_settling",
         "particle_particle", "particle_steel", "energy", "ball_speed", "seed", "particles",
         "initial_mass", "final_mass", "capture_radius", "energy_per_bed_mass", "initial_dt",
         "target", "share_e", "specific_energy", "model_probability", "binomial_sigma",
         "t10_model", "model", "relative_sizes", "progeny_passing_model", "speed",
         "half_v_squared", "scenes", "gamma", "model_broken_fraction",
         "expected_absorbed_specific_energy"}
#: event fields that can be zero in exact arithmetic, so that their rounding is their value:
#: compared within this absolute tolerance in (a). fragment_speed_excess (m/s): the fastest
#: fragment's speed less the parent's field, 0 up to ~1e-15 m/s when nothing is damped;
#: elastic_energy_after (J): left in the fragments' contacts, 0 when overlaps are zeroed (the
#: parents' energies are 1e-5 J and more)
ROUNDOFF_ATOL = {"fragment_speed_excess": 1e-9, "elastic_energy_after": 1e-12}
RTOL = 1e-9                 # (c) the set-up; (d) everything, on the recording machine
PREFIX_RTOL = 1e-6          # (a)
MASS_ATOL = 1e-12           # (b)
OUTCOME_FLOOR = 0.25        # (c) see MEASURED
COUNT_SIGMAS = 2.0          # (c) counts: at least this many sqrt(count) (counting noise)
NUDGES = (1, 2, 3, 4)       # record: the seeds of the nudged runs
CHECK_NUDGE = 0             # the suite's nudge (record uses 1, 2, ...)
EXACT = os.environ.get("YADEBREAK_EXACT_REGRESSION") == "1"

#: What the nudges did to the cases recorded before the replacement engine's read-mode change
#: (4 nudged runs each; "prefix": the largest difference in (a), relative to its tolerance's scale):
MEASURED = """
bed_default        (recorded again with the "fast" schedule that follows every tracked body
                   and the bed's in-memory reload every 5 chunks) breakages 29-30, damage
                   events 59-64, steps 108,500-111,700, broken fraction unchanged
bed_auto           (recorded again with the bed's reload) damage events 37-40, breakages 11,
                   steps 83,000, broken fraction unchanged
single_copper      prefix 1e-12; progeny sizes within 3e-9, counts unchanged
single_ab_t10      prefix 4e-12; at 600 J/kg breakages 23-25, damage events 129-139, steps
                   3,300-3,800 (13 %: three runs at 3,800), t10 30.8-31.0 %
drop_weight        prefix 2e-12; no outcome moved by more than 1e-9
bed_spheres_exact  prefix 4e-14; no outcome moved by more than 1e-9
repeated_*         (no fragments) the mean absorbed energy by 1e-14
The 1e-9 comparison (d) of the nudged runs failed in bed_default (87-160 differences, from the
67th event: ratio 0.0028647500347 became 0.0028647500388; 0.0028647500409 on another machine),
bed_auto (62 events against 57), single_copper, single_ab_t10, drop_weight, and in 2 of 4 runs
of bed_spheres_exact: the cases that failed it on that CPU.
"""


def run(name, out, nudge=None, more=()):
    """Run case `name` into folder `out`; return the completed process. nudge: a seed; the
    initial state is then changed in the last bit (tests/regression/nudged.py). more: options
    added to the case's."""
    script, arguments = CASES[name]
    out = Path(out)
    if out.exists():
        shutil.rmtree(out)
    wrapper = [] if nudge is None else [str(Path(__file__).resolve().parent / "nudged.py"),
                                        str(int(nudge))]
    return subprocess.run(["yade", "-n", "-x", *wrapper, str(ROOT / "scripts" / f"{script}.py"),
                           "--out", str(out), *arguments, *more], capture_output=True, text=True,
                          timeout=900, cwd=ROOT)


def outputs(out):
    """{file name: parsed content} of the files a case is compared on."""
    out = Path(out)
    found = {"summary.json": json.loads((out / "summary.json").read_text())}
    for path in sorted(out.glob("events*.jsonl")):
        found[path.name] = [json.loads(line) for line in path.read_text().splitlines()]
    return found


def _number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def differences(expected, got, where="", limit=20, rtol=RTOL, atol=None, key=None):
    """Where `got` differs from `expected`: numbers (if either is a float) beyond `rtol` relative
    and atol[field] absolute (atol: {field name: tolerance}), anything else not equal."""
    found = []
    if isinstance(expected, dict) and isinstance(got, dict):
        keys = set(expected) | set(got)
        for k in sorted(keys - WALL_KEYS, key=str):
            if k not in expected or k not in got:
                found.append(f"{where}.{k}: only in {'baseline' if k in expected else 'new run'}")
            else:
                found += differences(expected[k], got[k], f"{where}.{k}", limit, rtol, atol, k)
    elif isinstance(expected, list) and isinstance(got, list):
        if len(expected) != len(got):
            found.append(f"{where}: {len(expected)} items in the baseline, {len(got)} now")
        for k, (a, b) in enumerate(zip(expected, got)):
            found += differences(a, b, f"{where}[{k}]", limit, rtol, atol, key)
    elif (_number(expected) and _number(got)
          and isinstance(expected, float) | isinstance(got, float)):
        same = (math.isclose(expected, got, rel_tol=rtol, abs_tol=(atol or {}).get(key, 1e-300))
                or (math.isnan(expected) and math.isnan(got)))
        if not same:
            found.append(f"{where}: {expected!r} in the baseline, {got!r} now")
    elif expected != got:
        found.append(f"{where}: {expected!r} in the baseline, {got!r} now")
    return found[:limit]


def before_divergence(events):
    """(a) The events of a log up to and including the step of the first breakage, in each scene
    (events without a "scene" are one scene)."""
    first = {}
    for e in events:
        if e["kind"] == "breakage":
            first.setdefault(e.get("scene"), e["iter"])
    return [e for e in events if e["iter"] <= first.get(e.get("scene"), math.inf)]


def prefix_tolerances(events):
    """(a) {field: absolute tolerance}: PREFIX_RTOL of the field's largest magnitude in the log
    (a damage event's small energy is not held to more digits than the log's largest), at least
    its ROUNDOFF_ATOL."""
    atol = dict(ROUNDOFF_ATOL)
    for e in events:
        for k, v in e.items():
            if _number(v) and math.isfinite(v):
                atol[k] = max(atol.get(k, 0.0), PREFIX_RTOL * abs(float(v)))
    return atol


def outcomes(found):
    """{path: value} of what a run measured: every summary leaf but the set-up and wall times,
    and each log's count of events of each kind ("events.jsonl:breakage")."""
    flat = {}

    def walk(x, path):
        if isinstance(x, dict):
            for k, v in x.items():
                if k not in WALL_KEYS and k not in SETUP:
                    walk(v, f"{path}.{k}" if path else k)
        elif isinstance(x, list):
            for k, v in enumerate(x):
                walk(v, f"{path}[{k}]")
        else:
            flat[path] = x

    walk(found["summary.json"], "")
    for file, events in found.items():
        if file != "summary.json":
            for kind in sorted({e["kind"] for e in events}):
                flat[f"{file}:{kind}"] = sum(e["kind"] == kind for e in events)
    return flat


def setup(summary):
    """The summary without its outcomes (kept: the SETUP fields, anywhere in it)."""
    if isinstance(summary, dict):
        return {k: (v if k in SETUP else setup(v)) for k, v in summary.items()
                if k in SETUP or isinstance(v, (dict, list))}
    if isinstance(summary, list):
        return [setup(v) for v in summary if isinstance(v, (dict, list))]
    return summary


def band(values):
    """(c) (low, high) for one more run of a numeric outcome whose recorded runs (the baseline
    first) gave `values`: their range widened on each side by the larger of its own width and
    OUTCOME_FLOOR of the baseline's value (at least 1 for counts)."""
    low, high = min(values), max(values)
    floor = OUTCOME_FLOOR * abs(values[0])
    if all(isinstance(x, int) for x in values):
        floor = max(floor, 1.0, COUNT_SIGMAS * math.sqrt(abs(values[0])))
    half = max(high - low, floor)
    return float(low - half), float(high + half)


def recorded_runs(name):
    """The outcomes of case `name`'s baseline and of its nudged runs (baseline/NAME/spread.json)."""
    path = BASELINE / name / "spread.json"
    if not path.exists():
        raise FileNotFoundError(f"{path} is missing: /usr/bin/python3 tests/regression/cases.py "
                                f"record {name}")
    return [outcomes(outputs(BASELINE / name))] + json.loads(path.read_text())["runs"]


def cross_cpu_differences(name, got, runs=None, limit=20):
    """What run outputs `got` of case `name` break of (a), (b), (c) (the module docstring).
    runs: the recorded outcomes (default: recorded_runs(name))."""
    expected = outputs(BASELINE / name)
    runs = recorded_runs(name) if runs is None else runs
    found = []
    if sorted(got) != sorted(expected):
        found.append(f"files {sorted(got)}, the baseline has {sorted(expected)}")
    for file in sorted(set(expected) & set(got) - {"summary.json"}):
        found += differences(before_divergence(expected[file]), before_divergence(got[file]),
                             f"{file} before the first divergence", limit, PREFIX_RTOL,
                             prefix_tolerances(expected[file]))
    found += [f"{path}: {value!r}, more than {MASS_ATOL} (mass not conserved)"
              for path, value in outcomes(got).items()
              if path.split(".")[-1].startswith("mass_relative_error") and _number(value)
              and not abs(value) <= MASS_ATOL]
    found += differences(setup(expected["summary.json"]), setup(got["summary.json"]),
                         "summary.json (set-up)", limit)
    measured = outcomes(got)
    for path in sorted(set(runs[0]) | set(measured)):
        values = [r.get(path) for r in runs]
        if path not in measured or path not in runs[0]:
            found.append(f"{path}: only in {'baseline' if path in runs[0] else 'new run'}")
        elif path.split(".")[-1].startswith("mass_relative_error"):
            continue                                         # (b)
        elif all(_number(v) for v in values) and _number(measured[path]):
            low, high = band(values)
            if not low <= measured[path] <= high:
                found.append(f"{path}: {measured[path]!r}, outside [{low:.6g}, {high:.6g}] "
                             f"(recorded runs: {', '.join(f'{v:.6g}' for v in values)})")
        elif measured[path] not in values:
            found.append(f"{path}: {measured[path]!r}, the recorded runs gave {values}")
    return found[:limit]


def machine():
    """What the exact comparison (d) depends on: the CPU (its model and a digest of its feature
    flags: AVX2, AVX-512 ... choose the library's code paths) and the libraries that round."""
    info = {}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            info.setdefault(key.strip(), value.strip())
    except OSError:
        pass
    flags = hashlib.sha1(info.get("flags", "").encode()).hexdigest()[:12]
    return {"cpu": info.get("model name") or platform.processor(), "cpu_flags_sha1": flags,
            "glibc": "-".join(platform.libc_ver()), "numpy": np.__version__,
            "python": platform.python_version()}


def record(names, jobs=1, nudges=NUDGES):
    """Re-record each case: its baseline (events, summary) and spread.json (the outcomes of its
    runs nudged with the seeds `nudges`, the machine). Returns the problems found: a nudged run
    that breaks (a) or (b), or falls outside the band made from the other runs (then the band
    rule is too tight)."""
    problems = []
    for name in names:
        out = BASELINE / name
        with tempfile.TemporaryDirectory(prefix=f"yadebreak-{name}-") as tmp, \
                concurrent.futures.ThreadPoolExecutor(jobs) as pool:
            folders = [out] + [Path(tmp) / str(k) for k in nudges]
            procs = list(pool.map(lambda a: run(name, a[0], a[1]),
                                  zip(folders, [None, *nudges])))
            for folder, proc in zip(folders, procs):
                if proc.returncode != 0:
                    sys.exit(f"{name} ({folder}) failed:\n{proc.stdout[-2000:]}\n"
                             f"{proc.stderr[-2000:]}")
            for path in out.iterdir():               # keep only what is compared
                if path.name != "summary.json" and not path.name.startswith("events"):
                    path.unlink() if path.is_file() else shutil.rmtree(path)
            nudged = [outputs(f) for f in folders[1:]]
        runs = [outcomes(found) for found in nudged]
        (out / "spread.json").write_text(json.dumps(
            {"about": "outcomes of runs nudged in the last bit (tests/regression/cases.py)",
             "machine": machine(), "nudges": list(nudges), "runs": runs}, indent=1) + "\n")
        base = outcomes(outputs(out))
        for k, found in enumerate(nudged):
            others = [base] + runs[:k] + runs[k + 1:]
            problems += [f"{name}, nudge {nudges[k]}: {p}"
                         for p in cross_cpu_differences(name, found, others)]
        print(f"recorded {name}: {sorted(p.name for p in out.iterdir())}", flush=True)
    return problems


if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] != "record":
        sys.exit(__doc__)
    rest, counts = sys.argv[2:], {"--jobs": 1, "--nudges": len(NUDGES)}
    for option in counts:
        if option in rest:
            at = rest.index(option)
            value = rest[at + 1] if at + 1 < len(rest) else ""
            if not value.isdigit() or int(value) < (1 if option == "--jobs" else 2):
                sys.exit(f"record: {option} = {value!r}: a whole number, at least "
                         f"{1 if option == '--jobs' else 2}")
            counts[option] = int(value)
            del rest[at:at + 2]
    unknown = sorted(set(rest) - set(CASES))
    if unknown:
        sys.exit(f"record: unknown case(s) {unknown}; the cases: {', '.join(CASES)}")
    found = record(rest or list(CASES), counts["--jobs"],
                   tuple(range(1, counts["--nudges"] + 1)))
    if found:
        sys.exit("recorded, but a nudged run breaks the cross-CPU check (widen the rule):\n"
                 + "\n".join(found))
