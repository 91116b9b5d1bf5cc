"""Run time of high-energy single impacts, and what plain YADE costs on the same fragment cloud.

    /usr/bin/python3 benchmarks/bench_high_energy.py [--particles 50] [--energy 3000]

Copper ore 10 mm fired at a steel plate (5 % of the Rayleigh time, every-step reading, the
single-impact script's scene), run until the fragments are done, with zeroed pairs visited every
step (zeroing_tolerance 0) and with the default tolerance. Then the default run again, stopped at
the step where its cascade is densest (a third of the steps the first run took), where yadebreak's
cost per step is compared with plain YADE's on the same bodies and interactions (the engine
detached, 20 steps, before the un-zeroed overlaps push the fragments apart). Prints one line per
run and the ratio; docs/high_energy.md quotes them.
"""
import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

import numpy as np  # noqa: E402

from yadebreak import engine, load_material, scenes  # noqa: E402
from yadebreak.analysis import reports  # noqa: E402
from yadebreak.engine import run_steps  # noqa: E402
from yadebreak.adapter.yade_api import O  # noqa: E402

SIZE = 10e-3


def scene(particles, energy, **options):
    engine.forget()
    return scenes.impact_scene("copper_ore", SIZE, [np.sqrt(2 * energy)] * particles, seed=1,
                               **options)


def full_run(particles, energy, **options):
    start = time.perf_counter()
    brk, ids = scene(particles, energy, **options)
    steps = scenes.run_until_rebound(ids, brk=brk)
    wall = time.perf_counter() - start
    result = reports.breakage_result(brk, ids, load_material("copper_ore"), SIZE, energy,
                                     load_material("steel"))
    print(f"{options!s:28s} {steps:6d} steps {wall:7.1f} s {1e3 * wall / steps:6.2f} ms/step  "
          f"t10 {result.get('t10_simulated', float('nan')):5.2f} % (model "
          f"{result['t10_model']:.2f} %), {len(brk.breakage_events)} breakages", flush=True)
    return steps


def per_step(steps):
    start = time.perf_counter()
    run_steps(steps)
    return 1e3 * (time.perf_counter() - start) / steps


def at_the_peak(particles, energy, at):
    brk, _ = scene(particles, energy)
    run_steps(at)
    with_engine = per_step(100)
    bodies, contacts = len([b for b in O.bodies if b is not None]), O.interactions.countReal()
    engine.detach()
    plain = per_step(20)
    print(f"at step {at}: {bodies} bodies, {contacts} interactions: yadebreak "
          f"{with_engine:.2f} ms/step, plain YADE {plain:.2f} ms/step, ratio "
          f"{with_engine / plain:.2f}", flush=True)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--particles", type=int, default=50)
    parser.add_argument("--energy", type=float, default=3000.0, help="J/kg")
    a = parser.parse_args()
    print(f"copper ore {1e3 * SIZE:g} mm, {a.particles} particles at {a.energy:g} J/kg")
    full_run(a.particles, a.energy, zeroing_tolerance=0.0)
    steps = full_run(a.particles, a.energy)
    at_the_peak(a.particles, a.energy, steps // 3)
