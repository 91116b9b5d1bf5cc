"""Single impacts in one scene against independent scenes of a few particles (issue 16, item 7).

    /usr/bin/python3 benchmarks/bench_single_impacts.py [--particles 50] [--energy 160]
        [--material ab_t10_ore] [--size 12e-3] [--scenes 0,10,1]

The single-impact script's scenes (every-step reading, 5 % of the Rayleigh time): the particles
fired at a steel plate in scenes of N each (0: all in one scene, as the script did before),
each scene run until its fragments are done. Prints, per scene size, the wall time, the steps,
the broken fraction with its binomial sigma, t10 against the model, and the speed-up against one
scene, all measured in this run; docs/high_energy.md quotes them.
"""
import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

import numpy as np  # noqa: E402

from yadebreak import engine, load_material, scenes  # noqa: E402
from yadebreak.analysis import reports  # noqa: E402


def run(material, size, energy, particles, per_scene):
    engine.forget()
    start = time.perf_counter()
    tally, _ = scenes.single_impacts(material, size, np.sqrt(2 * energy), particles,
                                            per_scene or particles, 1)
    wall = time.perf_counter() - start
    result = reports.breakage_result_of(tally, load_material(material), energy,
                                        load_material("steel"))
    return wall, tally.steps, result


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--particles", type=int, default=50)
    parser.add_argument("--energy", type=float, default=160.0, help="J/kg")
    parser.add_argument("--material", default="ab_t10_ore")
    parser.add_argument("--size", type=float, default=12e-3, help="m")
    parser.add_argument("--scenes", default="0,10,1",
                        help="particles per scene to compare, 0 for all in one; the first is the "
                             "reference of the speed-ups")
    args = parser.parse_args()
    print(f"{args.particles} particles of {args.material} ({1e3 * args.size:g} mm) at "
          f"{args.energy:g} J/kg on steel", flush=True)
    reference = None
    for per_scene in [int(k) for k in args.scenes.split(",")]:
        wall, steps, r = run(args.material, args.size, args.energy, args.particles, per_scene)
        reference = reference or wall
        t10 = r.get("t10_simulated")
        print(f"scenes of {per_scene or args.particles:4d}: {wall:7.1f} s, {steps:7d} steps, "
              f"broken {100 * r['broken_fraction']:5.1f} % (model {100 * r['model_probability']:.1f}"
              f" +- {100 * r['binomial_sigma']:.1f} %), t10 "
              f"{'-' if t10 is None else f'{t10:.2f}'} % (model {r['t10_model'] or float('nan'):.2f}"
              f" %), speed-up {reference / wall:.2f}x", flush=True)


if __name__ == "__main__":
    main()
