"""Measurement: how a multi-layer bed comes apart under the ball, stacked or poured (issue 18).

    /usr/bin/python3 benchmarks/bed_dispersal.py [--layers 5] [--rings 3] [--material copper_ore]

For a lattice (layers stacked in the hollows, 3000 damped settling steps) and a poured bed
(settled under gravity until at rest; from the cache after the first run), with rolling friction,
breakage out of reach (fracture energies set very high, as in the README's Known limits), the ball
at 3.05 J: the bed's kinetic energy at the touch, the particle-particle contacts at the touch and
0.2 and 1 ms later, the fastest particle of the lower half of the bed within 0.2 and 1 ms, and the
ball's speed then. Prints one block per packing.
"""
import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

from yadebreak import engine, scenes  # noqa: E402
from yadebreak.scenes import poured_bed  # noqa: E402
from yadebreak.adapter.yade_api import O  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--layers", type=int, default=5)
parser.add_argument("--rings", type=int, default=3)
parser.add_argument("--material", default="copper_ore")
args = parser.parse_args()


def particle_contacts(particles):
    ids = set(particles)
    return sum(1 for i in O.interactions if i.isReal and i.id1 in ids and i.id2 in ids)


def fastest_lower(particles, height):
    return max((O.bodies[i].state.vel.norm() for i in particles
                if O.bodies[i] is not None and O.bodies[i].state.pos[2] < height / 2.0),
               default=0.0)


for packing in ("lattice", "poured"):
    engine.forget()
    brk, info = scenes.bed_impact_scene(args.material, 5.5e-3, args.rings, args.layers, 3.05,
                                        seed=1, packing=packing)
    for st in brk.bodies.values():
        st.fracture_energy = 1e30
    particles, ball = info["particles"], O.bodies[info["ball"]]
    while True:
        before = poured_bed.kinetic_energy(particles)
        engine.run_steps(20)
        if any(O.interactions.withBody(info["ball"])):
            break
    scenes.hold_release(info)
    touch, height = O.time, info["bed_height"]
    rows = [("touch", particle_contacts(particles), 0.0, ball.state.vel[2])]
    fastest = 0.0
    for mark in (2e-4, 1e-3):
        while O.time < touch + mark:
            engine.run_steps(50)
            fastest = max(fastest, fastest_lower(particles, height))
        rows.append((f"+{1e3 * mark:g} ms", particle_contacts(particles), fastest,
                     ball.state.vel[2]))
    print(f"{packing}: {len(particles)} particles of {args.material}, {args.layers} layers x "
          f"{args.rings} rings, bed {1e3 * height:.1f} mm high; kinetic energy at the touch "
          f"{before:.2e} J")
    for label, contacts, speed, vz in rows:
        print(f"  {label:8s} particle-particle contacts {contacts:4d} ({100 * contacts / rows[0][1]:.0f} %)"
              f", fastest lower-half particle so far {speed:5.2f} m/s, ball {vz:+.3f} m/s")
