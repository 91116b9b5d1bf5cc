"""Benchmark: the engine's cost per step and per breakage event, beside plain YADE.

    /usr/bin/python3 benchmarks/bench_engine.py [--quick]

1. Per step, with breakage out of reach (fracture energies set very high): plain YADE, the floor of
   a no-op PyRunner at every step, yadebreak reading every contact every step (exact), with
   read_period="auto" and with read_period="fast", on the default bed (37 particles, 3.05 J) and
   on a 5-layer, 4-ring bed.
2. Per breakage event: the package's own work for a family drawn at t10' = 10 % in scenes of
   1e3, 1e4 and 3e4 bodies, YADE's extra work on the next step, and yade.bf.replaceSphere
   (YADE's own, 27 sub-spheres) on the same scenes.
Prints figures and ratios measured in this run, and the peak memory.
"""
import resource
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

import numpy as np  # noqa: E402

from yadebreak import engine, scenes  # noqa: E402
from yadebreak.adapter.yade_api import O, utils, wrapper as _wrapper  # noqa: E402

QUICK = "--quick" in sys.argv
# O.run(n, True) waits in 40 ms polls, so steps are timed with engine.run_steps (O.step in a
# loop, the same for every mode); the window is the ball's loading of the bed
STEPS = 3000 if QUICK else 8000
REPEATS = 1 if QUICK else 3


def bed_rate(rings, layers, mode):
    """Microseconds per step during the impact (the best of REPEATS runs), breakage out of
    reach, and the share of that time yadebreak spent reading contacts."""
    best = None
    for _ in range(REPEATS):
        rate = _bed_rate_once(rings, layers, mode)
        best = rate if best is None or rate[0] < best[0] else best
    return best


def _bed_rate_once(rings, layers, mode):
    engine.forget()
    options = {} if mode in ("plain", "noop") else {"read_period": 1 if mode == "exact" else mode}
    # the scenes of issue 9's figures: stacked layers, no rolling friction (bench_rolling.py
    # measures that)
    brk, info = scenes.bed_impact_scene("copper_ore", 5.5e-3, rings, layers, 3.05, seed=1,
                                        packing="lattice", rolling=False, **options)
    for st in brk.bodies.values():
        st.fracture_energy = 1e30
    engines = list(O.engines)
    if mode in ("plain", "noop"):
        engines = [e for e in engines if not isinstance(e, _wrapper.PyRunner)]
        if mode == "noop":
            engines.insert(3, _wrapper.PyRunner(command="pass", iterPeriod=1))
        O.engines = engines
    while not any(O.interactions.withBody(info["ball"])):       # to the first touch
        engine.run_steps(50)
    scenes.hold_release(info)
    read_before = brk.wall_time["read"]
    start = time.perf_counter()
    engine.run_steps(STEPS)
    elapsed = time.perf_counter() - start
    contacts = O.interactions.countReal()
    read_share = (brk.wall_time["read"] - read_before) / elapsed
    return 1e6 * elapsed / STEPS, contacts, read_share


def per_step_table():
    print("\n1. Cost per step during the impact (breakage out of reach)")
    for rings, layers, label in ((3, 1, "default bed (37 particles)"),
                                 (4, 5, "5 layers x 4 rings")):
        rates, shares = {}, {}
        for mode in ("plain", "noop", "exact", "auto", "fast"):
            rates[mode], contacts, shares[mode] = bed_rate(rings, layers, mode)
        plain, floor = rates["plain"], rates["noop"]
        print(f"  {label}: {contacts} contacts")
        print(f"    plain YADE            {plain:8.1f} us/step")
        print(f"    + no-op PyRunner      {floor:8.1f} us/step  ({floor / plain:.2f} x plain)")
        for mode in ("exact", "auto", "fast"):
            own = rates[mode] - floor
            print(f"    yadebreak {mode:5s}       {rates[mode]:8.1f} us/step  "
                  f"({rates[mode] / plain:.2f} x plain; own work beyond the floor "
                  f"{own:.1f} us = {own / plain:.2f} x YADE's step; reading contacts "
                  f"{100 * shares[mode]:.0f} % of the time)")


def cloud(n, dummies="spheres"):
    """n spheres of 5.5 mm on a loose cubic grid (no contacts), and a controller."""
    O.reset()
    engine.forget()
    ip2, _ = engine.add_materials({"ore": "copper_ore"})
    side = int(np.ceil(n ** (1 / 3)))
    pitch = 6e-3
    grid = [(i * pitch, j * pitch, k * pitch) for i in range(side) for j in range(side)
            for k in range(side)][:n]
    O.bodies.append([utils.sphere(p, 2.75e-3, material="ore") for p in grid])
    O.engines = scenes.hertz_engines(ip2)
    brk = engine.attach({"ore": "copper_ore"}, seed=1, time_step_fraction=None,
                          dummies=dummies)
    O.dt = 1e-7
    engine.run_steps(3)
    return brk, side, pitch


def event_table():
    print("\n2. Cost of one breakage event (family at t10' = 10 %, up to 30 spheres)")
    counts = (1000, 10000) if QUICK else (1000, 10000, 30000)
    for n, dummies in [(n, d) for n in counts for d in ("spheres", "ledger")]:
        brk, side, pitch = cloud(n, dummies)
        mid = n // 2
        victims = [mid + k for k in range(0, 40, 4)]
        t_step = time.perf_counter()
        engine.run_steps(20)           # not O.run(20, True): its 40 ms wait would be the figure
        normal_step = (time.perf_counter() - t_step) / 20
        own, extra, sizes = [], [], []
        for v in victims[:5]:
            mat = brk.material["ore"]
            # ratio whose Eq. 8 gives t10' = 10 %
            ratio = -mat.params.kappa / mat.params.b_prime * np.log(1 - 10.0 / mat.params.A)
            before = brk.wall_time["replace"]
            ev = brk.break_body(v, ratio=ratio)
            own.append(brk.wall_time["replace"] - before)
            sizes.append(len(ev["fragments"]))
            t0 = time.perf_counter()
            O.step()
            extra.append(time.perf_counter() - t0 - normal_step)
        print(f"  {n:6d} bodies, dummies as {dummies}: yadebreak {1e3 * np.median(own):.2f} ms per event "
              f"(families of {min(sizes)}-{max(sizes)} spheres); YADE's next step "
              f"+{1e3 * np.median(extra):.2f} ms over a normal step ({1e3 * normal_step:.2f} ms)")
        if dummies == "ledger":
            continue
        try:
            from yade.bf import bf
        except ImportError:
            print("    yade.bf not available")
            continue
        refused, times = 0, []
        for v in victims[5:10]:
            t0 = time.perf_counter()
            left = bf.replaceSphere(v, radius_ratio=3)
            times.append(time.perf_counter() - t0)
            refused += left is not None
        print(f"    yade.bf.replaceSphere: {1e3 * np.median(times):.1f} ms per event "
              f"({np.median(times) / np.median(own):.0f} x yadebreak), refused {refused} of 5")


def end_to_end():
    """The default bed impact as `make demo` runs it (fast mode, ledger), and with every contact read
    every step: wall time and its shares."""
    import argparse
    import tempfile
    from yadebreak.jobs import bed
    print("\n3. The default bed impact end to end (target 3 minutes), where the time goes")
    for read, dummies in (("fast", "ledger"), (1, "spheres")):
        engine.forget()
        with tempfile.TemporaryDirectory() as out:
            args = argparse.Namespace(material="copper_ore", size=5.5e-3, rings=3, layers=1,
                                      energy=3.05, speed=0.0, seed=1, time_step_fraction=0.05,
                                      dmin=0.0, global_damping="material", dummies=dummies,
                                      read_period=read, max_time=0.004 if QUICK else 0.02,
                                      checkpoint_every=-1, out=out)
            _, s = bed.run(args, quiet=True)
        total = s["runtime_s"]
        read_s, replace_s = s["wall_time_read_s"], s["wall_time_replace_s"]
        print(f"  read_period={read!s:4s} dummies={dummies:7s}: {total:6.1f} s ({180 / total:.1f}x under "
              f"3 min), {s['breakage_events']} breakages, broken {100 * s['broken_mass_fraction']:.1f} %; "
              f"reading contacts {100 * read_s / total:.0f} %, replacement {100 * replace_s / total:.0f} %, "
              f"YADE and the rest {100 * (total - read_s - replace_s) / total:.0f} %")


if __name__ == "__main__":
    per_step_table()
    event_table()
    end_to_end()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\npeak memory {peak:.0f} MB")
