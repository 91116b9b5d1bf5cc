"""Accuracy of the stressing energy read from YADE against read sparsity.

    /usr/bin/python3 benchmarks/bench_energy.py

5.5 mm copper-ore spheres fired normally at a steel wall (time step 5 % of the Rayleigh time,
breakage out of reach): the energy each receives, Ek'/m, against the closed form e v^2/2 (Eq. 4),
reading every contact every step, every 5 and every 10 steps, and with read_period="fast".
Prints the relative errors in % (the README's "What the engine does" quotes them).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

from yadebreak import engine, load_material, scenes  # noqa: E402

SPEEDS = (1.0, 5.0, 14.14, 20.0, 28.28, 100.0)


def errors(read_period):
    engine.forget()
    share = load_material("copper_ore").energy_partition(load_material("steel"))
    brk, ids = scenes.impact_scene("copper_ore", 5.5e-3, speeds=SPEEDS, emin=0.0,
                                   read_period=read_period)
    for i in ids:
        brk.bodies[i].fracture_energy = 1e12
    scenes.run_until_rebound(ids)
    got = {e["id"]: e["specific_energy"] for e in brk.events if e["kind"] == "damage"}
    return [100.0 * (got[i] / (share * v * v / 2) - 1) for i, v in zip(ids, SPEEDS)]


if __name__ == "__main__":
    print("read_period  " + "  ".join(f"{v:7g} m/s" for v in SPEEDS))
    for mode in (1, 5, 10, "fast"):
        print(f"{mode!s:11s}  " + "  ".join(f"{e:+9.2f} %" for e in errors(mode)))
