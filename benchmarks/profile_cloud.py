"""Where a step of a fragment cloud goes: YADE's own engines (timed by YADE, O.timingEnabled, in
the same run) against yadebreak's parts and, inside them, the contact reading, the zeroed pairs'
updates, judging, replacement, the time step and the event log (cProfile, cumulative).

    /usr/bin/python3 benchmarks/profile_cloud.py [--material copper_ore] [--size 29e-3]
        [--energy 3000] [--particles 1] [--fraction 0.02] [--steps 0]

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
    parser.add_argument("--material", default="copper_ore")
    parser.add_argument("--size", type=float, default=29e-3, help="m")
    parser.add_argument("--energy", type=float, default=3000.0, help="J/kg")
    parser.add_argument("--particles", type=int, default=1)
    parser.add_argument("--fraction", type=float, default=0.02, help="of the Rayleigh time")
    parser.add_argument("--steps", type=int, default=0, help="0: until the fragments are done")
    a = parser.parse_args(sys.argv[1:])
    speed = float(np.sqrt(2.0 * a.energy))
    brk, ids = scenes.impact_scene(a.material, a.size, [speed] * a.particles, seed=3,
                                   time_step_fraction=a.fraction, read_period="every_step")
    O.timingEnabled = True
    profile = cProfile.Profile()
    start, first = time.perf_counter(), O.iter
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
    stats = pstats.Stats(profile).stats
    for label, names, where in PHASES:
        total = sum(entry[3] for (path, _, name), entry in stats.items()
                    if name in names and path.endswith(where))
        print(f"  {label:24s}  {per * total:8.3f} ms")
    print(f"  yadebreak / YADE alone    {(per * wall - yade_alone) / yade_alone:8.2f} x "
          "(the whole step less YADE's engines, over YADE's engines)")


if __name__ == "__main__":
    main()
