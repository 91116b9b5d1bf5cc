"""Where a step of a fragment cloud goes: YADE's own engines (timed by YADE, O.timingEnabled, in
the same run) against yadebreak's parts and, inside them, the contact reading, the zeroed pairs'
updates, judging, replacement, the time step and the event log (cProfile, cumulative).

    /usr/bin/python3 benchmarks/profile_cloud.py [--case copper|iron] [--material M] [--size m]
        [--energy J/kg] [--particles 1] [--fraction 0.02] [--steps 0] [--top 0]
        [--plain] [--floor]

`--case copper` (the default): the 29 mm copper ore at 3000 J/kg of verify's cascade; `--case
iron`: the 10 mm iron_ore_1 at 1000 J/kg of `scripts/single_impact.py`'s top energy (the
explicit options override the case's). `--top N` lists the N functions of most own time.
cProfile slows yadebreak's Python (not YADE's engines): `--plain` runs without it, for the ratio.
`--floor` adds what every-step reading cannot avoid through YADE's Python interface (Floor).

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
    ("read schedule, damping", ("after_read", "release"), "engine/reads.py, stepping.py"),
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
    parser.add_argument("--floor", action="store_true",
                        help="also the floor: what YADE's Python interface costs per step for "
                             "what every-step reading must touch (see Floor)")
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
    floor = Floor(brk) if a.floor else None
    if a.steps:
        engine.run_steps(a.steps)
    else:
        scenes.run_until_rebound(ids, brk=brk, on_check=floor and floor.sample)
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
    if floor is not None:
        floor.report(yade_alone)
    if a.top and not a.plain:
        pstats.Stats(profile).sort_stats("tottime").print_stats(a.top)


class Floor:
    """What every-step reading cannot avoid through YADE's Python interface, per step: YADE's
    count of each body's interactions (how new contacts are found: one C++ call, timed at each
    check of the run), a visit of each zeroed pair awake (its two positions, their distance, its
    two stiffnesses written) and a read of each contact row awake (its overlap and normal
    force), these two at their unit costs timed at the end of the run; the counts of pairs and
    rows awake sampled at each check (every 50 steps); and the two PyRunner calls a step makes,
    at what YADE's least call costs (a runner whose command is `pass`), timed at the end of the
    run (_runner_costs)."""

    def __init__(self, brk):
        self.brk = brk
        self.samples = []                 # (counts s, pairs awake, rows awake)

    def sample(self):
        from yadebreak.adapter.yade_api import utils
        table = self.brk.reader.table
        resting = 0 if table.resting is None else int(table.resting.sum())
        counts = min(_timed(utils.numIntrsOfEachBody, 3))
        self.samples.append((counts, len(self.brk.zeroing.awake), len(table) - resting))

    def report(self, yade_ms):
        s = np.array(self.samples)
        pair, row = self._unit_costs()
        runner, shaped = self._runner_costs()
        counts, pairs, rows = s.mean(axis=0)
        per_step = 1e3 * (counts + pairs * pair + rows * row + 2 * runner)
        print(f"  floor, per step (means of {len(s)} checks): counts {1e3 * counts:.3f} ms; "
              f"{pairs:.0f} pairs awake x {1e6 * pair:.2f} us; {rows:.0f} rows awake x "
              f"{1e6 * row:.2f} us; 2 runner calls x {1e6 * runner:.1f} us (of yadebreak's "
              f"shape: {1e6 * shaped:.1f} us)")
        print(f"  floor                     {per_step:8.3f} ms = {per_step / yade_ms:.2f} x YADE "
              f"alone: whole step at best {1.0 + per_step / yade_ms:.2f} x")

    def _unit_costs(self):
        """Seconds per zeroed-pair visit and per row read, on the scene's objects now."""
        from yadebreak.adapter.yade_api import wrapper
        pairs = []
        for a, b in list(self.brk.zeroing.pairs)[:300]:
            ba, bb = O.bodies[a], O.bodies[b]
            if (ba is None or bb is None or not O.interactions.has(a, b)
                    or not all(isinstance(x.shape, wrapper.Sphere) for x in (ba, bb))):
                continue
            phys = O.interactions[a, b].phys
            pairs.append((ba.state, bb.state, phys, phys.kno, phys.kso))

        def visit():
            for sa, sb, phys, kno, kso in pairs:
                (sa.pos - sb.pos).norm()
                phys.kno = kno                    # the same values: nothing changes
                phys.kso = kso
        table = self.brk.reader.table
        rows = [(g, p) for g, p in zip(table.geoms, table.physs) if g is not None][:300]

        def read():
            for g, p in rows:
                g.penetrationDepth
                p.normalForce.norm()
        pair = min(_timed(visit, 20)) / max(len(pairs), 1)
        row = min(_timed(read, 20)) / max(len(rows), 1)
        return pair, row


    @staticmethod
    def _runner_costs(steps=300, rounds=4):
        """Seconds a PyRunner call costs YADE here with nothing done in it (medians of `rounds`
        runs of `steps` more steps each, beside yadebreak's runners): (the least, a command
        `pass`; a command of the shape of yadebreak's hooks, which import yadebreak by name so
        that a saved scene runs in a fresh process). YADE compiles a runner's command at every
        call, so the shape costs more than `pass`."""
        from yadebreak.adapter.yade_api import wrapper
        shaped = ("__import__('yadebreak.engine.parts.protocol').engine.parts.protocol."
                  "HOOKS.index('after_interactions')")
        costs = {"pass": [], shaped: []}
        for _ in range(rounds):
            for command, out in costs.items():
                idle = wrapper.PyRunner(command=command, iterPeriod=1, updateGlobals=False,
                                        label="floor_idle")
                O.engines = O.engines + [idle]
                engine.run_steps(steps)
                O.engines = [e for e in O.engines if e is not idle]
                out.append(idle.execTime * 1e-9 / steps)
        return float(np.median(costs["pass"])), float(np.median(costs[shaped]))


def _timed(call, repeats):
    out = []
    for _ in range(repeats):
        t = time.perf_counter()
        call()
        out.append(time.perf_counter() - t)
    return out


if __name__ == "__main__":
    main()
