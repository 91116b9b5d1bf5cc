"""Benchmark: the instructions yadebreak's own work executes in a scene, counted by valgrind's
callgrind inside YADE's PyRunners only (where every line of yadebreak's per-step Python runs), and
where they go: the Python interpreter, numpy, Boost.Python's conversions of YADE's objects, YADE's
own functions called from Python, the C library.

    /usr/bin/python3 benchmarks/own_instructions.py [--case ab_cloud|collisional|cloud_8000]
                                                    [--tree DIR]

Why instructions: on a shared machine the same run's time moves by tens of percent from one run
to the next, more than a change of a few percent in yadebreak's Python; a count of instructions
repeats to about 0.1 % (the runs are the same but for Python's string hashing), so two trees
compare in one run each. It does not see cache misses: time is still the judge of a speed target
(docs/performance.md).

Cases (issue 45's scenes):
  ab_cloud     the heaviest scene of `scripts/single_impact.py --material ab_t10_ore --size 12mm
               --energies 40,160,640 --particles 200`: 640 J/kg, seed 3, scene 23 (3,150 steps
               read every step; fragments pressed together for thousands of steps)
  collisional  benchmarks/bench_scale.py's collisional scene of 1,000 spheres, the default read
               mode, 400 steps after its warm-up
  cloud_8000   its collisional scene of 8,000 spheres with the material's own fracture energies
               (bench_scale.py's part 7: damage events, no breakage), 200 steps after its warm-up
The scenes' warm-ups are counted too (their reads run in the same runners): compare trees, case
by case, not a case's count with a time per step.

Needs valgrind (Debian: apt-get install valgrind); takes 1-5 minutes a case (callgrind runs the
scene about 50 times slower). `--tree`: the yadebreak checkout to count (default: this one).
"""
import argparse
import collections
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
#: the symbol of YADE's PyRunner::action, whose inside is counted
RUNNER = "*PyRunner::action*"
CASES = ("ab_cloud", "collisional", "cloud_8000")
#: (label, pattern of a shared object's path), first match wins; the rest is "other"
GROUPS = (("Python interpreter", r"/python3\.\d+$|libpython"),
          ("numpy", r"/numpy/"),
          ("Boost.Python", r"libboost_python"),
          ("YADE", r"yade"),
          ("C and maths libraries", r"libc\.so|libm\.so|libstdc\+\+"))


def run_case(case, tree):
    """The case's scene from `tree`, inside this process (under callgrind)."""
    sys.path.insert(0, str(tree))
    if case == "ab_cloud":
        import numpy as np
        from yadebreak import scenes
        spec = scenes.impact_spec("ab_t10_ore", 0.012, float(np.sqrt(2 * 640.0)), 24, 1, 3,
                                  replace=True, time_step_fraction=0.05,
                                  read_period="every_step")
        scenes.run_scenes(spec, [23])
    else:
        from yadebreak import engine     # the tree's, before bench_scale puts its own parent first
        sys.path.insert(0, str(Path(tree) / "benchmarks"))
        import bench_scale
        if case == "collisional":
            bench_scale.prepare("collisional", 1000, "default")
            engine.run_steps(400)
        else:
            bench_scale.prepare("collisional", 8000, "default", breakable=True)
            engine.run_steps(200)


def count(case, tree):
    """(instructions inside the runners, {group: instructions}) of one run under callgrind."""
    if shutil.which("valgrind") is None:
        raise SystemExit("own_instructions.py: valgrind not found (Debian: apt-get install "
                         "valgrind)")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "callgrind.out"
        subprocess.run(["valgrind", "--tool=callgrind", "--collect-atstart=no",
                        f"--toggle-collect={RUNNER}", f"--callgrind-out-file={out}",
                        sys.executable, __file__, "--inner", case, "--tree", str(tree)],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        return self_costs(out.read_text(errors="replace"))


def self_costs(text):
    """Total and per-group self cost (instructions) from a callgrind output: each cost line's
    object is the one of its function (ob=), except the line after calls=, which is a callee's
    inclusive cost and is skipped."""
    names, current, after_call = {}, None, False
    by_object = collections.Counter()
    for line in text.splitlines():
        if line.startswith("ob="):
            current = _name(names, line[3:])
        elif line.startswith(("cob=", "cfi=", "cfn=", "fl=", "fi=", "fe=", "fn=")):
            if line.startswith("cob="):
                _name(names, line[4:])
        elif line.startswith("calls="):
            after_call = True
        elif line[:1].isdigit() or line[:1] in "+-*":
            if after_call:
                after_call = False
                continue
            fields = line.split()
            if len(fields) >= 2:
                by_object[current] += int(fields[1])
    groups = collections.Counter()
    for obj, cost in by_object.items():
        label = next((g for g, pattern in GROUPS if obj and re.search(pattern, obj)), "other")
        groups[label] += cost
    return sum(by_object.values()), groups


def _name(names, field):
    """callgrind's name compression: "(id) name" defines, "(id)" refers."""
    m = re.match(r"\((\d+)\)\s*(.*)", field)
    if not m:
        return field.strip()
    if m.group(2):
        names[m.group(1)] = m.group(2).strip()
    return names.get(m.group(1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=CASES + ("all",), default="all")
    parser.add_argument("--tree", default=str(HERE.parent),
                        help="the yadebreak checkout to count (default: this one)")
    parser.add_argument("--inner", choices=CASES, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.inner:
        run_case(args.inner, Path(args.tree).resolve())
        os._exit(0)                      # past YADE's teardown: nothing more to count
    tree = Path(args.tree).resolve()
    for case in CASES if args.case == "all" else (args.case,):
        total, groups = count(case, tree)
        print(f"{case}: {total / 1e6:,.0f} million instructions inside yadebreak's runners "
              f"({tree})")
        for label, cost in groups.most_common():
            if not cost:
                continue
            print(f"  {label:24s} {cost / 1e6:10,.0f} million  {100 * cost / total:5.1f} %")


if __name__ == "__main__":
    main()
