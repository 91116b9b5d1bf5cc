"""What breakage of polyhedra costs: per step, yadebreak's parts against YADE's own engines in the
same run (O.timingEnabled); per breakage event, the replacement (tessellation and insertion)
against the parent's cells and neighbours.

    /usr/bin/python3 benchmarks/polyhedra_cost.py [--material copper_ore] [--size 29e-3]
        [--energy 1000] [--particles 2] [--seed 3]
    /usr/bin/python3 benchmarks/polyhedra_cost.py --events 1 [--ratio 2.0]

Each particle is fired in a scene of its own (scenes.polyhedra.volumetric_impact_scene, the
single-impact script's scene) and run until its fragments are done. Prints, per scene and
overall, ms per step of YADE's engines and of yadebreak's runners, breakages and ms per event.
With --events 1: one event's cost against the parent's neighbours: a cube of --size in a
cubic grid of 0, 6 or 26 touching cubes, broken at Ek'/(m E) = --ratio (controller.break_body,
the same draws each time); median of 5 of the replacement (tessellation and insertion).
"""
import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

import numpy as np  # noqa: E402

from yadebreak import scenes  # noqa: E402
from yadebreak.adapter.yade_api import O, engine_time, wrapper  # noqa: E402
from yadebreak.scenes.polyhedra import volumetric_impact_scene  # noqa: E402


def one(a, seed):
    """One particle's scene: (steps, YADE's ms, yadebreak's ms, breakages, replace s, cells)."""
    brk, ids = volumetric_impact_scene(a.material, a.size, [float(np.sqrt(2.0 * a.energy))],
                                       seed=seed)
    first, began = O.iter, time.perf_counter()
    with engine_time() as yade:          # the runners are timed in the block too
        scenes.run_until_rebound(ids, brk=brk)
    wall = time.perf_counter() - began
    steps = O.iter - first
    ours = sum(e.execTime for e in O.engines if isinstance(e, wrapper.PyRunner)) * 1e-9
    events = brk.breakage_events
    cells = sum(len(e["fragments"]) for e in events)
    return steps, yade.seconds, ours, wall, len(events), brk.wall_time["replace"], cells


def event_cost(a, neighbours):
    """(ms of one forced breakage, cells) of a cube among `neighbours` touching cubes."""
    from yadebreak.engine import attach
    from yadebreak.scenes import polyhedra as poly
    times = []
    for _ in range(5):
        O.reset()
        poly.polyhedra_materials({"ore": a.material}, volumetric=True, size=a.size)
        O.engines = poly.volumetric_engines()
        cube = poly.box_vertices(a.size, a.size, a.size)
        offsets = [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)
                   if (i, j, k) != (0, 0, 0) and (neighbours == 26 or abs(i) + abs(j) + abs(k) == 1)]
        pid = O.bodies.append(poly.polyhedron(cube, "ore"))
        for o in offsets[:neighbours]:
            O.bodies.append(poly.polyhedron(cube, "ore", tuple(a.size * x for x in o), fixed=True))
        O.dt = 1e-7
        brk = attach({"ore": a.material}, seed=a.seed, time_step_fraction=None)
        O.run(2, True)
        began = time.perf_counter()
        event = brk.break_body(pid, ratio=a.ratio)
        times.append(time.perf_counter() - began)
    return 1e3 * float(np.median(times)), len(event["fragments"])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--material", default="copper_ore")
    parser.add_argument("--size", type=float, default=29e-3, help="m, sieve size")
    parser.add_argument("--energy", type=float, default=1000.0, help="J/kg")
    parser.add_argument("--particles", type=int, default=2)
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--events", type=int, default=0, help="1: one event's cost")
    parser.add_argument("--ratio", type=float, default=2.0, help="--events: Ek'/(m E)")
    a = parser.parse_args(sys.argv[1:])
    if a.events:
        print(f"one breakage of a {1e3 * a.size:g} mm {a.material} cube at Ek'/(m E) = "
              f"{a.ratio:g}, median of 5")
        for n in (0, 6, 26):
            ms, cells = event_cost(a, n)
            print(f"  {n:2d} neighbours: {ms:7.1f} ms, {cells} cells")
        return
    rows = [one(a, a.seed + k) for k in range(a.particles)]
    print(f"{a.material}, {1e3 * a.size:g} mm polyhedra at {a.energy:g} J/kg, one per scene")
    print("scene  steps   YADE ms/step  yadebreak ms/step  ratio  wall s  breakages  cells  "
          "ms/event")
    for k, (steps, yade, ours, wall, n, replace, cells) in enumerate(rows):
        per_event = 1e3 * replace / n if n else float("nan")
        print(f"{k:5d} {steps:6d} {1e3 * yade / steps:13.3f} {1e3 * ours / steps:18.3f} "
              f"{ours / yade:6.2f} {wall:7.1f} {n:10d} {cells:6d} {per_event:9.1f}")
    steps, yade, ours, wall, n, replace, cells = (sum(r[i] for r in rows) for i in range(7))
    print(f"all   {steps:6d} {1e3 * yade / steps:13.3f} {1e3 * ours / steps:18.3f} "
          f"{ours / yade:6.2f} {wall:7.1f} {n:10d} {cells:6d} "
          f"{1e3 * replace / max(n, 1):9.1f}")
    print(f"particles in 10 minutes at this energy: {600.0 * a.particles / wall:.0f}")


if __name__ == "__main__":
    main()
