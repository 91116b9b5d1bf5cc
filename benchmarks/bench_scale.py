"""Benchmark: the engine's cost at process scale, beside plain YADE.

    /usr/bin/python3 benchmarks/bench_scale.py [--quick] [--sizes 1000,10000,100000] [--repeats 3]
                                               [--mill-only] [--per-step-only] [--events-only]
                                               [--threads-only]

Two scenes of 5.5 mm copper-ore spheres in a steel box, each built for N bodies:
- dense: a column on a cubic lattice (each sphere touching its neighbours), under gravity, pressed
  by a piston moving down at 0.05 m/s; about three contacts per body;
- collisional: a jittered cubic lattice (solid fraction 0.39) with random velocities of 3 m/s and
  no gravity: a dense granular gas, a few percent of the bodies in contact at a time.
Each scene runs in plain YADE (no yadebreak), with yadebreak's default (read_period="fast"), and
with every contact read every step (read_period="every_step"), first with breakage out of reach
(fracture energies set very high), then, for the collisional scene, with breakage in reach
(25 m/s). Then: the cost of one breakage event at each size, the default ball mill in each
mode (and as the grinding model's spectra run: attach(breakage=False)), attach() at each size,
and yadebreak's memory per body.
Part 1 also runs a floor: plain YADE with a PyRunner at the default's mean read period that only
touches each ore contact's overlap and normal force (as on the mill, part 4, but with the time of
finding the contacts left out): a lower bound of any reader in Python; what the default costs
above it is yadebreak's own work. Prints microseconds per step and ratios measured in this run;
--quick runs 1e3 and 1e4 bodies, --per-step-only part 1 alone. Part 7 (--threads-only: it alone)
runs both scenes with the material's own fracture energies (damage events at 3 m/s, breakage out
of reach) under YADE's OpenMP on 1 and 2 threads, and on 2 threads with OMP_WAIT_POLICY=PASSIVE
(threads that sleep, not spin, while the engine's Python runs), each in a process of its own,
with the median of the ratios of runs made one after the other (steadier than the ratio of the
medians on a shared machine) and yadebreak's own time per step inside its PyRunners (YADE's engine
timing): what it adds, apart from what it does to YADE's own engines. Its floor also makes the two
passes in C++ that a read of a cloud makes (interaction counts, the most energetic body). Then, in
one plain collisional scene, a Python runner as long as the default's read at its period, alive and
dead in turn every 40 steps: how much longer YADE's own engines take beside it, with a runner that
touches nothing of YADE's (spin) and one that streams memory (sweep).
"""
import argparse
import gc
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

import numpy as np  # noqa: E402

from yadebreak import engine, scenes  # noqa: E402
from yadebreak.adapter.yade_api import (O, engine_time, interaction_counts, utils,  # noqa: E402
                                        wrapper as _w)
from yadebreak.options.table import Config  # noqa: E402
from yadebreak.engine.parts import protocol  # noqa: E402
from yadebreak.engine.stepping import smallest_rayleigh_time  # noqa: E402

RADIUS = 2.75e-3
#: steps run before the timing (dense: a quarter of it beyond 1e3 bodies; collisional: three
#: times it): the lattice's first contacts settle, the collisions begin
WARM_UP = 200
#: the modes compared: attach() options, None for plain YADE
MODES = {"plain": None, "default": {}, "every step": {"read_period": "every_step"},
         "spectra run": {"breakage": False}}


def _box(lo, hi):
    """Five steel walls (floor and sides) around [lo, hi] (m)."""
    walls = [utils.wall(lo[2], axis=2, sense=1, material="steel")]
    for axis in (0, 1):
        walls.append(utils.wall(lo[axis], axis=axis, sense=1, material="steel"))
        walls.append(utils.wall(hi[axis], axis=axis, sense=-1, material="steel"))
    return O.bodies.append(walls)


def _lattice(n, pitch, column=1):
    """n points on a cubic lattice of `pitch` (m), `column` times taller than wide."""
    side = int(np.ceil((n / column) ** (1.0 / 3.0)))
    height = int(np.ceil(n / side ** 2))
    k = np.arange(n)
    return np.column_stack([k % side, (k // side) % side, k // side ** 2]) * pitch + RADIUS, side, height


def build(kind, n, seed=1):
    """The scene `kind` ("dense" or "collisional") of n spheres, without yadebreak."""
    O.reset()
    engine.forget()
    ip2, _ = engine.add_materials({"ore": "copper_ore", "steel": "steel"})
    rng = np.random.default_rng(seed)
    if kind == "dense":
        pitch = 2 * RADIUS * (1 - 2e-4)           # neighbours overlap by 1 um: in contact
        centres, side, height = _lattice(n, pitch, column=4)
    else:
        pitch = 2 * RADIUS * 1.1                  # solid fraction 0.39
        centres, side, height = _lattice(n, pitch)
        # jittered by up to 0.045 diameters per axis (no overlap): collisions from the start
        centres = centres + rng.uniform(-0.09, 0.09, centres.shape) * RADIUS
    hi = np.array([side * pitch, side * pitch, height * pitch]) + RADIUS * 0.01
    _box(np.full(3, -RADIUS * (0.01 if kind == "dense" else 1.0)), hi)
    ids = O.bodies.append([utils.sphere(tuple(p), RADIUS, material="ore") for p in centres])
    if kind == "dense":
        top = float(centres[:, 2].max()) + RADIUS * (1 - 1e-4)
        piston = utils.wall(top, axis=2, sense=-1, material="steel")
        piston.state.vel = (0.0, 0.0, -0.05)
        O.bodies.append(piston)
        gravity = (0.0, 0.0, -9.81)
    else:
        v = rng.normal(size=(n, 3))
        v *= 3.0 / np.linalg.norm(v, axis=1)[:, None]
        for i, vi in zip(ids, v):
            O.bodies[i].state.vel = tuple(vi)
        gravity = (0.0, 0.0, 0.0)
    O.engines = scenes.hertz_engines(ip2, gravity=gravity)
    # attach()'s own time step, so that plain YADE steps alike
    O.dt = Config.from_options().time_step.time_step_fraction * smallest_rayleigh_time()
    return ids


def prepare(kind, n, mode, breakable=False, speed=None, **extra):
    """Build the scene, attach yadebreak in `mode` (with `extra` attach() options), and run it
    past its first contacts. Returns the controller (None in plain YADE) and the seconds attach()
    took."""
    ids = build(kind, n)
    if speed is not None:
        for i in ids:
            b = O.bodies[i]
            b.state.vel = b.state.vel * (speed / b.state.vel.norm())
    options = MODES[mode] if MODES[mode] is None else {**MODES[mode], **extra}
    brk, attach_s = None, 0.0
    if options is not None:
        t0 = time.perf_counter()
        brk = engine.attach({"ore": "copper_ore"}, seed=1, **options)
        attach_s = time.perf_counter() - t0
        if not breakable:
            for st in brk.bodies.values():
                st.fracture_energy = 1e30
    engine.run_steps(3 * WARM_UP if kind == "collisional" else
                       WARM_UP if n <= 1000 else WARM_UP // 4)
    return brk, attach_s


def steps_for(n):
    """Steps timed: 1000 at 1e3 bodies, 200 at 1e4 and beyond (a "fast" read comes at least
    every 200 steps)."""
    return 1000 if n <= 1000 else 200


def rate(kind, n, mode, steps, breakable=False, speed=None):
    """(us per step, real contacts, breakages, attach() s, reads made: None in plain YADE) over
    `steps` steps."""
    brk, attach_s = prepare(kind, n, mode, breakable, speed)
    reads = _reads()
    gc.collect()
    t0 = time.perf_counter()
    engine.run_steps(steps)
    elapsed = time.perf_counter() - t0
    broken = len(brk.breakage_events) if brk is not None else 0
    return (1e6 * elapsed / steps, O.interactions.countReal(), broken, attach_s,
            None if brk is None else _reads() - reads)


def _reads():
    """The reads the engine (attach()'s default label) has made so far."""
    return protocol.runs("breakage", "yadebreak")


def floor_rate(kind, n, steps, period):
    """us per step of the scene in plain YADE with only the floor's read (_floor) every `period`
    steps, finding the contacts left out."""
    prepare(kind, n, "plain")
    gc.collect()
    return _floor(steps, period, finding=False)


def per_step(sizes, repeats):
    print(f"\n1. Cost per step, breakage out of reach (us per step, the median of {repeats} runs "
          f"up to 1e4 bodies, the modes in turn; ratio to plain YADE). floor: plain YADE with "
          f"the mill's floor read (part 4) at the default's mean read period in that round")
    attach_times = {}
    for kind in ("dense", "collisional"):
        for n in sizes:
            steps = steps_for(n)
            runs = {mode: [] for mode in (*MODES, "floor")}
            for _ in range(repeats if n <= 10000 else 1):
                for mode in MODES:
                    us, contacts, _, attach_s, reads = rate(kind, n, mode, steps)
                    runs[mode].append(us)
                    if mode == "default":
                        attach_times[n] = attach_s
                        period = max(1, round(steps / max(reads, 1)))
                runs["floor"].append(floor_rate(kind, n, steps, period))
            rates = {mode: float(np.median(v)) for mode, v in runs.items()}
            plain = rates["plain"]
            print(f"  {kind:11s} {n:7d} bodies, {contacts:6d} contacts, {steps} steps: plain "
                  f"{plain:9.1f}; " + "; ".join(f"{m} {rates[m]:9.1f} ({rates[m] / plain:.2f}x)"
                                                for m in rates if m != "plain")
                  + f" (the default read every {period} steps)")
    return attach_times


def with_breakage(sizes):
    print("\n2. The collisional scene with breakage in reach (25 m/s)")
    for n in sizes:
        steps = steps_for(n)
        rates, broken = {}, {}
        for mode in MODES:
            rates[mode], _, broken[mode], _, _ = rate("collisional", n, mode, steps, True, 25.0)
        plain = rates["plain"]
        print(f"  {n:7d} bodies, {steps} steps: plain {plain:9.1f}; " + "; ".join(
            f"{m} {rates[m]:9.1f} ({rates[m] / plain:.2f}x, {broken[m]} breakages)"
            for m in MODES if m != "plain"))


def event_cost(sizes):
    print("\n3. One breakage event (family at t10' = 10 %) in the dense scene: yadebreak's own work")
    for n in sizes:
        for dummies in ("spheres", "ledger"):
            brk, _ = prepare("dense", n, "default", dummies=dummies)
            mat = brk.material["ore"]
            p = mat.params
            ratio = -p.kappa / p.b_prime * np.log(1 - 10.0 / p.A)   # Eq. 8 at 10 %
            tracked = sorted(brk.state.tracked)
            victims = [tracked[len(tracked) // 2 + 7 * k] for k in range(7)]
            dt, before = O.dt, brk.wall_time["replace"]
            brk.break_body(victims[0], ratio=ratio)      # the first lowers O.dt: apart
            first = brk.wall_time["replace"] - before
            own, sizes_made = [], []
            for v in victims[1:]:
                before = brk.wall_time["replace"]
                event = brk.break_body(v, ratio=ratio)
                own.append(brk.wall_time["replace"] - before)
                sizes_made.append(len(event["fragments"]))
            print(f"  {n:7d} bodies, dummies as {dummies:7s}: {1e3 * np.median(own):.2f} ms per "
                  f"event (median of 6, {1e3 * min(own):.2f}-{1e3 * max(own):.2f}; "
                  f"{min(sizes_made)}-{max(sizes_made)} spheres made); the first, which "
                  f"lowers O.dt {dt / O.dt:.0f}-fold (the leapfrog kept exact for every body "
                  f"in contact), {1e3 * first:.1f} ms")


#: part 7's settings of YADE's OpenMP, each a child process's environment
THREADS = {"1 thread": {"OMP_NUM_THREADS": "1"}, "2 threads": {"OMP_NUM_THREADS": "2"},
           "2 threads, passive": {"OMP_NUM_THREADS": "2", "OMP_WAIT_POLICY": "PASSIVE"}}


def threads(sizes, repeats):
    """Part 7: one child process per THREADS entry (OpenMP reads its settings at start)."""
    print(f"\n7. The materials' own fracture energies (damage events, no breakage) under YADE's "
          f"OpenMP threads: us per step, median of {repeats} (plain / default, ratio of the "
          f"medians, median of the ratios of runs made one after the other)")
    for n in sizes:
        for name, env in THREADS.items():
            child = subprocess.run(
                [sys.executable, __file__, "--threads-child", "--sizes", str(n), "--repeats",
                 str(repeats)], env={**os.environ, **env}, capture_output=True, text=True,
                check=True)
            got = json.loads(child.stdout.strip().splitlines()[-1])
            print(f"  {n:7d} bodies, {name:18s}: " + "; ".join(
                f"{kind} {np.median(r['plain']):8.1f} / {np.median(r['default']):8.1f} "
                f"({np.median(r['default']) / np.median(r['plain']):.2f}x, paired "
                f"{np.median(np.divide(r['default'], r['plain'])):.2f}x, "
                f"+{np.median(r['default']) - np.median(r['plain']):.0f} us, of which "
                f"{np.median(r['own']):.0f} us in yadebreak's PyRunners; YADE's engines "
                f"{np.median(r['yade plain']):.0f} / {np.median(r['yade default']):.0f} us; "
                f"{r['damage']} damage events; floor every {r['period']} steps "
                f"{np.median(r['floor']):.1f}, "
                f"{np.median(r['floor']) / np.median(r['plain']):.2f}x, "
                f"paired {np.median(np.divide(r['floor'], r['plain'])):.2f}x, "
                f"{np.median(r['floor own']):.0f} us in its PyRunner, YADE's engines "
                f"{np.median(r['yade floor']):.0f} us)"
                for kind, r in got.items()))
            beside = got["collisional"]["beside"]
            print(f"  {n:7d} bodies, {name:18s}: YADE's engines beside a Python runner as long "
                  f"as the default's read, collisional, us more per step (quartiles of "
                  f"{PAIRS} pairs of {SEGMENT}-step segments, runner alive and dead): " + "; ".join(
                      f"{how} " + " / ".join(f"{v:+.0f}" for v in q) for how, q in beside.items()))
        print("  floor: plain YADE with a read every k steps (k the default's mean read period) "
              "that only makes a cloud's two passes in C++ (counts of interactions, the most "
              "energetic body) and touches each contact's overlap and force: what any Python "
              "read at that period costs")
        print("  beside: spin, a loop on the clock that touches nothing of YADE's; sweep, passes "
              "over a 32 MB array (memory traffic)")


#: part 7's toggled runs: segments of this many steps, in this many pairs (a runner alive, dead)
SEGMENT, PAIRS = 40, 40
#: what part 7's toggled runner does for as long as yadebreak's read takes: a loop on the clock
#: (Python that touches nothing of YADE's), or whole sweeps over a 32 MB array until the time is
#: up (memory traffic; a sweep takes about 1.5 ms here, a read 3.5-4.5)
BUSY = ("spin", "sweep")
_SWEPT = np.zeros(4 << 20)


def _busy(seconds, how):
    """Work for `seconds` (s) in this process as BUSY says."""
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        if how == "sweep":
            np.add(_SWEPT, 1.0, out=_SWEPT)


def _beside(kind, n, period, seconds, how):
    """How much longer YADE's own engines take per step (us) beside a Python runner every
    `period` steps that works `seconds` (_busy `how`): one plain scene, the runner alive and dead
    in turn for SEGMENT steps, PAIRS pairs, which cancels the drift of a shared machine. Returns
    the quartiles of the paired differences."""
    prepare(kind, n, "plain")
    sys.modules["__main__"]._busy = _busy
    runner = _w.PyRunner(iterPeriod=period, command=f"_busy({seconds!r}, {how!r})", dead=True)
    O.engines = O.engines + [runner]
    diffs = []
    for p in range(PAIRS):
        per_step = {}
        for alive in ((True, False) if p % 2 else (False, True)):
            runner.dead = not alive
            with engine_time() as yade:            # YADE's engines, the runner left out
                engine.run_steps(SEGMENT)
            per_step[alive] = 1e6 * yade.seconds / SEGMENT
        diffs.append(per_step[True] - per_step[False])
    return np.percentile(diffs, [25, 50, 75]).tolist()


def _threads_child(n, repeats):
    """Part 7 in this process: each scene in plain YADE and with the default, in turn; one JSON
    line {kind: {plain, default: us per step of each run, in turn; own: us per step inside
    yadebreak's PyRunners in each default run, "yade plain", "yade default": in YADE's other
    engines (YADE's engine timing); floor, "floor own", "yade floor": the floor's read (_floor
    with its passes) at the default's mean read period `period` (steps), per step in all, in its
    PyRunner and in YADE's engines; damage: events in the last default run}}."""
    out = {}
    steps = steps_for(n)
    for kind in ("dense", "collisional"):
        runs = {"plain": [], "default": [], "own": [], "yade plain": [], "yade default": [],
                "floor": [], "floor own": [], "yade floor": []}
        period = None                             # the default's mean read period (steps)
        for _ in range(repeats):
            for mode in ("plain", "default", "floor"):  # the floor once the default ran
                if mode == "floor":
                    prepare(kind, n, "plain")
                    gc.collect()
                    O.timingEnabled = True
                    runs[mode].append(_floor(steps, period, finding=False, passes=True))
                    O.timingEnabled = False
                    read = [isinstance(e, _w.PyRunner) for e in O.engines]
                    for key, own in (("floor own", True), ("yade floor", False)):
                        runs[key].append(1e-3 * sum(
                            e.execTime for e, r in zip(O.engines, read) if r == own) / steps)
                    continue
                prepare(kind, n, mode, breakable=True)
                gc.collect()
                reads = _reads() if mode == "default" else 0
                O.timingEnabled = True            # from here on: the timed steps only
                t0 = time.perf_counter()
                engine.run_steps(steps)
                runs[mode].append(1e6 * (time.perf_counter() - t0) / steps)
                O.timingEnabled = False
                if mode == "default":
                    period = max(1, round(steps / max(1, _reads() - reads)))
                    damage = sum(e["kind"] == "damage" for e in engine.controller_of().events)
                ours = [isinstance(e, _w.PyRunner) and e.label.startswith("yadebreak")
                        for e in O.engines]
                runs["yade " + mode].append(1e-3 * sum(
                    e.execTime for e, own in zip(O.engines, ours) if not own) / steps)
                if mode == "default":
                    runs["own"].append(1e-3 * sum(
                        e.execTime for e, own in zip(O.engines, ours) if own) / steps)
        out[kind] = dict(runs)
        out[kind]["period"] = period
        out[kind]["damage"] = damage
        if kind == "collisional":                 # YADE's engines beside a read this long
            read_s = 1e-6 * float(np.median(runs["own"])) * period
            out[kind]["beside"] = {how: _beside(kind, n, period, read_s, how) for how in BUSY}
    print(json.dumps(out))


def _mill_args(out):
    """The default mill of scripts/ball_mill.py."""
    from argparse import Namespace
    return Namespace(material="limestone", size=8e-3, ball_size=25e-3, drum_diameter=0.25,
                     drum_length=0.1, lifters=8, lifter_height=10e-3, lifter_width=10e-3,
                     speed=0.75, ball_filling=0.3, ore_filling=0.1, duration=1.0,
                     stiffness_scale=1e-3, time_step_fraction=0.05,
                     read_period="fast", seed=1, sample_interval=0.02, vtk_interval=0.0,
                     checkpoint_every=-1.0, resume=False, stop_after=0.0, out=str(out))


def mill(steps=3000, repeats=1):
    """The default mill once settled, run from the same saved state in each mode."""
    import tempfile
    from yadebreak import load_material
    from yadebreak.jobs import mill as mill_scene
    print(f"\n4. The default ball mill (scripts/ball_mill.py), from the charge settled (median of "
          f"{repeats})")
    with tempfile.TemporaryDirectory() as out:
        args = _mill_args(out)
        engine.forget()
        mill_scene.mill_scene(args, mill_scene._options(args, Path(out)),
                              load_material(args.material))
        saved = str(Path(out) / "settled.yade.gz")
        engine.save(saved)
        runs = {mode: [] for mode in MODES}
        for _ in range(repeats):
            for mode, options in MODES.items():
                engine.forget()
                O.load(saved)
                if options != {}:                       # plain YADE, or attached afresh
                    engine.detach()
                    if options is not None:
                        engine.attach({"ore": "limestone"}, seed=1, dmin=args.size / 3,
                                        **options)
                t0 = time.perf_counter()
                engine.run_steps(steps)
                runs[mode].append(1e6 * (time.perf_counter() - t0) / steps)
            for k in FLOOR_PERIODS:
                O.load(saved)
                engine.detach()
                runs.setdefault(f"floor, every {k}", []).append(_floor(steps, k))
        rates = {mode: float(np.median(v)) for mode, v in runs.items()}
        plain = rates["plain"]
        print(f"  {len(O.bodies)} bodies, {O.interactions.countReal()} contacts, {steps} steps: "
              f"plain {plain:9.1f}; " + "; ".join(f"{m} {rates[m]:9.1f} ({rates[m] / plain:.2f}x)"
                                                  for m in rates if m != "plain"))
        print("  floor, every k: a Python reader that only touches each ore contact's overlap "
              "and normal force every k steps (the contacts taken from YADE every 100 steps; "
              "no bookkeeping, nothing recorded): a lower bound of any reader in Python")


#: read periods (steps) of the floor measured on the mill
FLOOR_PERIODS = (1, 2, 5)
_ORE_CONTACTS = []


def _touch_ore_contacts():
    """The floor's read: each ore contact's two numbers (a PyRunner's command calls it)."""
    for geom, phys in _ORE_CONTACTS:
        geom.penetrationDepth
        phys.normalForce.norm()


def _passes():
    """The floor's read of a cloud read "fast": _touch_ore_contacts, and the two passes in C++
    that no Python read of it avoids: YADE's count of each body's interactions, over every
    potential interaction (how a read finds new contacts without a pass in Python), and the
    most energetic body, over every body (the schedule's closing speed)."""
    interaction_counts()
    utils.kineticEnergy(True)
    _touch_ore_contacts()


def _floor(steps, period, finding=True, passes=False):
    """us per step of the scene with only the floor's read every `period` steps; `finding`: the
    time of taking the contacts from YADE every 100 steps counted (the mill), else left out (a
    bound below any reader, however it finds its contacts: part 1); `passes`: the read also makes
    the two passes in C++ that a "fast" read of a cloud makes (_passes)."""
    ore = {b.id for b in O.bodies if b is not None and b.material.label == "ore"}
    touch = "_passes()" if passes else "_touch_ore_contacts()"
    O.engines = O.engines + [_w.PyRunner(iterPeriod=period, command=touch)]
    sys.modules["__main__"]._touch_ore_contacts = _touch_ore_contacts
    sys.modules["__main__"]._passes = _passes
    left_out = 0.0
    t0 = time.perf_counter()
    for done in range(0, steps, 100):
        found = time.perf_counter()
        # YADE's objects kept, as the engine's reader keeps them (an erased contact's are dropped)
        _ORE_CONTACTS[:] = [(i.geom, i.phys) for i in O.interactions.all(True)
                            if i.id1 in ore or i.id2 in ore]
        if not finding:
            left_out += time.perf_counter() - found
        engine.run_steps(min(100, steps - done))
    return 1e6 * (time.perf_counter() - t0 - left_out) / steps


def _rss():
    """Resident memory of this process now (bytes)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize()


def memory(n):
    """yadebreak's memory per body: resident memory of the dense scene with yadebreak attached and
    run, less that of the same scene in plain YADE."""
    prepare("dense", n, "plain")
    gc.collect()
    plain = _rss()
    brk, _ = prepare("dense", n, "default")
    engine.run_steps(200)
    gc.collect()
    own = _rss() - plain
    print(f"\n6. Memory, dense scene of {n} bodies: yadebreak adds {own / 2 ** 20:.0f} MB "
          f"({own / n / 1024:.2f} kB per body; YADE's scene alone {plain / 2 ** 20:.0f} MB)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="1e3 and 1e4 bodies only")
    parser.add_argument("--sizes", default=None, help="comma-separated body counts")
    parser.add_argument("--repeats", type=int, default=3,
                        help="runs of each mode up to 1e4 bodies and on the mill (median)")
    parser.add_argument("--mill-only", action="store_true", help="only the ball mill (part 4)")
    parser.add_argument("--per-step-only", action="store_true",
                        help="only the cost per step with breakage out of reach (part 1)")
    parser.add_argument("--events-only", action="store_true",
                        help="only the cost of a breakage event (part 3)")
    parser.add_argument("--threads-only", action="store_true",
                        help="only the materials' own fracture energies on 1 and 2 threads "
                             "(part 7)")
    parser.add_argument("--threads-child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(sys.argv[1:])
    if args.mill_only:
        return mill(repeats=args.repeats)
    sizes = ([int(float(s)) for s in args.sizes.split(",")] if args.sizes
             else [1000, 10000] if args.quick else [1000, 10000, 100000])
    if args.threads_child:
        return _threads_child(sizes[0], args.repeats)
    if args.events_only:
        return event_cost(sizes)
    if args.threads_only:
        return threads(sizes, args.repeats)
    attach_times = per_step(sizes, args.repeats)
    if args.per_step_only:
        return None
    with_breakage(sizes)
    event_cost(sizes)
    mill(repeats=args.repeats)
    print("\n5. attach() on the dense scene: " + ", ".join(
        f"{n} bodies {t:.2f} s" for n, t in attach_times.items()))
    memory(max(sizes))
    threads([min(sizes)], args.repeats)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak memory of this process {peak:.0f} MB")


if __name__ == "__main__":
    main()
