"""Benchmark: what rolling friction per contact pair costs (issue 18, coupling/rolling.py).

    /usr/bin/python3 benchmarks/bench_rolling.py [--quick]

During the ball's loading of the bed, with breakage out of reach (fracture energies set very
high, so that every mode runs the same kind of scene): microseconds per step without rolling
friction (the same settled bed, the moment and the part taken out), with it (YADE's contact
moment, and the part that gives new contacts their pair's values every 10 steps, the default), and
with the part at every step; the part's own time from YADE's engine timing. On the default bed (37 particles, one layer) and a poured bed of 5 layers x 3 rings
(169 particles; settled once, then from the cache). Medians of REPEATS runs, in one process.
"""
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

from yadebreak import engine, scenes  # noqa: E402
from yadebreak.adapter.yade_api import O  # noqa: E402
from yadebreak.engine.parts import protocol  # noqa: E402

QUICK = "--quick" in sys.argv
STEPS = 3000 if QUICK else 10000
REPEATS = 1 if QUICK else 3
MODES = ("none", "every 10 steps", "every step")


def _rate(layers, mode):
    """(us per step, the rolling part's own us per step, real contacts at the end)."""
    engine.forget()
    brk, info = scenes.bed_impact_scene("copper_ore", 5.5e-3, 3, layers, 3.05, seed=1)
    for st in brk.bodies.values():
        st.fracture_energy = 1e30
    if mode == "none":                # the same settled bed, without the moment or the part
        protocol.uninstall("rolling")
        loop = next(e for e in O.engines if type(e).__name__ == "InteractionLoop")
        loop.lawDispatcher.functors[0].includeMoment = False
    elif mode == "every step":
        protocol.set_trigger("rolling", 1)
    # the runner after Newton's step calls the rolling part alone here: its time is the part's
    part = (None if mode == "none" else
            next(e for e in O.engines if getattr(e, "label", "") == protocol.runner_label(
                protocol.AFTER_NEWTON)))
    while not any(O.interactions.withBody(info["ball"])):       # to the first touch
        engine.run_steps(50)
    scenes.hold_release(info)
    O.timingEnabled = True
    own_before = 0 if part is None else part.execTime
    start = time.perf_counter()
    engine.run_steps(STEPS)
    elapsed = time.perf_counter() - start
    own = 0.0 if part is None else (part.execTime - own_before) * 1e-9
    O.timingEnabled = False
    return 1e6 * elapsed / STEPS, 1e6 * own / STEPS, O.interactions.countReal()


def main():
    print(f"Rolling friction's cost per step during the impact ({STEPS} steps, median of "
          f"{REPEATS})")
    for layers, label in ((1, "default bed, 37 particles"), (5, "poured 5 layers x 3 rings")):
        rates = {}
        for mode in MODES:
            runs = [_rate(layers, mode) for _ in range(REPEATS)]
            rates[mode] = (statistics.median(r[0] for r in runs),
                           statistics.median(r[1] for r in runs), runs[-1][2])
        base = rates["none"][0]
        print(f"  {label} ({rates['none'][2]} contacts at the end):")
        for mode in MODES:
            step, own, _ = rates[mode]
            extra = "" if mode == "none" else (f"  ({step / base:.2f} x without; the part's own "
                                               f"work {own:.2f} us/step)")
            print(f"    {mode:15s} {step:8.1f} us/step{extra}")


if __name__ == "__main__":
    main()
