"""Where a step of a fragment cloud goes: YADE's own engines (timed by YADE, O.timingEnabled, in
the same run) against yadebreak's parts and, inside them, the contact reading, the zeroed pairs'
updates, judging, replacement, the time step and the event log (cProfile, cumulative).

    /usr/bin/python3 benchmarks/profile_cloud.py [--case copper|iron] [--material M] [--size m]
        [--energy J/kg] [--particles 1] [--fraction 0.02] [--steps 0] [--top 0]
        [--plain]

`--case copper` (the default): the 29 mm copper ore at 3000 J/kg of verify's cascade; `--case
iron`: the 10 mm iron_ore_1 at 1000 J/kg of `scripts/single_impact.py`'s top energy (the
explicit options override the case's). `--top N` lists the N functions of most own time.
cProfile slows yadebreak's Python (not YADE's engines): `--plain` runs without it, for the ratio.

One scene of `--particles` particles fired at a steel plate at `--energy` J/kg, contacts read
every step at `--fraction` of the Rayleigh time (verify's fragmentation settings), run until the
fragments are done (or `--steps`). Prints ms per step of each; "YADE alone" is the sum of YADE's
own engines in this run.
"""
import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

import numpy as np  # noqa: E402

from yadebreak import engine, scenes  # noqa: E402
from yadebreak.adapter.yade_api import O, wrapper  # noqa: E402

#: --case -> (material, size m, energy J/kg)
CASES = {"copper": ("copper_ore", 29e-3, 3000.0), "iron": ("iron_ore_1", 10e-3, 1000.0)}
#: (label, the functions whose cumulative time it is), inside yadebreak's parts
PHASES = (
    ("contact reading", ("read",), "engine/contacts/reader.py"),
    ("zeroed pairs' updates", ("apply",), "engine/zeroing.py"),
    ("judging", ("judge",), "engine/judging.py"),
    ("replacement", ("_break_all",), "engine/controller.py"),
    ("event log", ("record",), "engine/state.py"),
    ("time step and damping", ("after_read", "release"), "engine/stepping.py"),
)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=sorted(CASES), default="copper")
    parser.add_argument("--material")
    parser.add_argument("--size", type=float, help="m")
    parser.add_argument("--energy", type=float, help="J/kg")
    parser.add_argument("--particles", type=int, default=1)
    parser.add_argument("--fraction", type=float, default=0.02, help="of the Rayleigh time")
    parser.add_argument("--steps", type=int, default=0, help="0: until the fragments are done")
    parser.add_argument("--top", type=int, default=0, help="list the N functions of most own time")
    parser.add_argument("--plain", action="store_true", help="no cProfile: the ratio only")
    a = parser.parse_args(sys.argv[1:])
    case = CASES[a.case]
    a.material = a.material or case[0]
    a.size = a.size or case[1]
    a.energy = a.energy or case[2]
    speed = float(np.sqrt(2.0 * a.energy))
    brk, ids = scenes.impact_scene(a.material, a.size, [speed] * a.particles, seed=3,
                                   time_step_fraction=a.fraction, read_period="every_step")
    O.timingEnabled = True
    profile = cProfile.Profile()
    start, first = time.perf_counter(), O.iter
    if not a.plain:
        profile.enable()
    if a.steps:
        engine.run_steps(a.steps)
    else:
        scenes.run_until_rebound(ids, brk=brk)
    profile.disable()
    wall = time.perf_counter() - start
    steps = O.iter - first
    per = 1e3 / steps
    print(f"{a.material} {1e3 * a.size:g} mm, {a.particles} particle(s) at {a.energy:g} J/kg: "
          f"{steps} steps, {len(brk.breakage_events)} breakages, "
          f"{sum(b is not None for b in O.bodies)} bodies at the end, {wall:.1f} s")
    print(f"  whole step                {per * wall:8.3f} ms")
    yade_alone = 0.0
    for e in O.engines:
        ms = e.execTime * 1e-6 / steps
        if not isinstance(e, wrapper.PyRunner):
            yade_alone += ms
        print(f"  {type(e).__name__:24s}  {ms:8.3f} ms  {getattr(e, 'label', '')}")
    print(f"  YADE alone                {yade_alone:8.3f} ms")
    stats = {} if a.plain else pstats.Stats(profile).stats
    for label, names, where in (() if a.plain else PHASES):
        total = sum(entry[3] for (path, _, name), entry in stats.items()
                    if name in names and path.endswith(where))
        print(f"  {label:24s}  {per * total:8.3f} ms")
    print(f"  whole step / YADE alone   {per * wall / yade_alone:8.2f} x")
    if a.top and not a.plain:
        pstats.Stats(profile).sort_stats("tottime").print_stats(a.top)


if __name__ == "__main__":
    main()
