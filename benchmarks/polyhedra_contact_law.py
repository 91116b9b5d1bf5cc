"""Which contact law for polyhedra: Hertz-Mindlin through ScGeom, or YADE's volumetric law (issue 43).

    /usr/bin/python3 benchmarks/polyhedra_contact_law.py [--size 0.02] [--speeds 1,5,15]
        [--fraction 0.02] [--seed 1] [--max-steps 20000]

A 20 mm copper ore cube and a random convex body of the same size (24 random directions, seeded)
fired face, edge and corner first at a fixed steel plate (a polyhedron; a YADE Wall too for the
volumetric law), undamped (every restitution 1), time step a fraction of the body's Rayleigh time.
Per case: the kinetic energy fired, the peak of the work of the normal contact force
(sum F_n d(delta), scenes/polyhedra.follow_impact), the peak the engine's ContactReader counts
(Hertz-Mindlin only: it reads ScGeom and kno), the rebound energy, the peak approach of the
contact point and whether the run was stable (finite, the contact ended, rebound within 5 % of
the energy fired). The volumetric law's kn is E*/size (a flat punch of the body's width: the same
order of stiffness as Hertz). Then a 10 mm steel ball on the cube (Ig2_Sphere_Polyhedra_ScGeom),
a cube hitting the plate off its centre, and whether the two laws can meet in one scene.
docs/polyhedra.md quotes the table.
"""
import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

import numpy as np  # noqa: E402

from yadebreak import load_material  # noqa: E402
from yadebreak.scenes import polyhedra as poly  # noqa: E402
from yadebreak.adapter.yade_api import O, utils, wrapper as w  # noqa: E402

HEAD = (f"{'case':34s} {'law':11s} {'v m/s':>5s} {'E0 J':>10s} {'W peak/E0':>9s} "
        f"{'reader/E0':>9s} {'rebound/E0':>10s} {'approach um':>11s} {'steps':>6s} "
        f"{'touch um':>8s}  stable")


def stable(impact, rec):
    return (rec.finite and rec.ended
            and abs(rec.rebound / impact.kinetic_energy - 1.0) < 0.05)


def line(case, law, speed, impact, rec):
    e0 = impact.kinetic_energy
    reader = "-" if math.isnan(rec.reader_peak) else f"{rec.reader_peak / e0:.5f}"
    touch = "-" if math.isnan(rec.touch_gap) else f"{rec.touch_gap * 1e6:.1f}"
    return (f"{case:34s} {law:11s} {speed:5.1f} {e0:10.4g} {rec.work_peak / e0:9.5f} "
            f"{reader:>9s} {rec.rebound / e0:10.5f} {rec.approach_peak * 1e6:11.2f} "
            f"{rec.contact_steps:6d} {touch:>8s}  {'yes' if stable(impact, rec) else 'NO'}")


def volumetric_kn(size):
    """Each material's kn (N/m3): twice E*/size, so that the pair (in series) has E*/size."""
    particle, steel = load_material("copper_ore"), load_material("steel")
    e_star = 1.0 / (1.0 / particle.hertz_stiffness + 1.0 / steel.hertz_stiffness)
    return 2.0 * e_star / size


def impacts(args):
    shapes = {"cube": poly.box_vertices(args.size, args.size, args.size),
              "random": poly.random_convex_vertices(args.size, np.random.default_rng(args.seed))}
    kn = volumetric_kn(args.size)
    for shape, vertices in shapes.items():
        for contact in poly.CONTACTS:
            for speed in args.speeds:
                for law, extra in (("mindlin", {}), ("volumetric", {}),
                                   ("vol. wall", {"wall": True})):
                    impact = poly.polyhedron_impact_scene(
                        vertices, speed, contact, law=law.replace("vol. wall", "volumetric"),
                        fraction=args.fraction, volumetric_stiffness=kn, **extra)
                    rec = poly.follow_impact(impact, args.max_steps, read=law == "mindlin")
                    print(line(f"{shape} {contact}", law, speed, impact, rec), flush=True)


def others(args):
    cube = poly.box_vertices(args.size, args.size, args.size)
    for contact in poly.CONTACTS:
        for speed in args.speeds:
            impact = poly.ball_on_polyhedron_scene(cube, speed, contact, fraction=args.fraction)
            rec = poly.follow_impact(impact, args.max_steps)
            print(line(f"10 mm ball on cube {contact}", "mindlin", speed, impact, rec), flush=True)
    offset = 2.0 * args.size
    for law in ("mindlin", "volumetric"):
        impact = poly.polyhedron_impact_scene(cube, 5.0, "face", law=law, fraction=args.fraction,
                                              volumetric_stiffness=volumetric_kn(args.size),
                                              offset=offset)
        rec = poly.follow_impact(impact, args.max_steps, read=law == "mindlin")
        print(line(f"cube face, plate centre {offset * 1e3:.0f} mm off", law, 5.0, impact, rec))
        vel = O.bodies[impact.particle].state.vel
        print(f"    rebound velocity ({vel[0]:.3f}, {vel[1]:.3f}, {vel[2]:.3f}) m/s")


def _pair_scene(particle_kind, wall_kind, ip2s, geoms, laws):
    """A cube falling on a wall with a second cube falling on it: the three pairs meet."""
    O.reset()
    O.materials.append(getattr(w, particle_kind)(young=52e9, poisson=0.25, density=2930,
                                                 label="particle"))
    O.materials.append(getattr(w, wall_kind)(young=210e9, poisson=0.3, density=7800,
                                             label="target"))
    O.bodies.append(utils.wall(0.0, axis=2, sense=1, material="target"))
    cube = poly.box_vertices(0.02, 0.02, 0.02)
    low = O.bodies.append(poly.polyhedron(cube, "particle", (0, 0, 0.0101), (0, 0, -1.0)))
    high = O.bodies.append(poly.polyhedron(cube, "particle", (0, 0, 0.0303), (0, 0, -3.0)))
    O.engines = [w.ForceResetter(),
                 w.InsertionSortCollider([w.Bo1_Polyhedra_Aabb(), w.Bo1_Wall_Aabb()],
                                         verletDist=0.0),
                 w.InteractionLoop(geoms, ip2s, laws), w.NewtonIntegrator(damping=0.0)]
    O.dt = 2e-7
    return low, high


def _trials():
    geoms = [w.Ig2_Polyhedra_Polyhedra_ScGeom(), w.Ig2_Wall_Polyhedra_PolyhedraGeom()]
    laws = [w.Law2_ScGeom_MindlinPhys_Mindlin(), w.Law2_PolyhedraGeom_PolyhedraPhys_Volumetric()]
    trials = [
        ("all PolyhedraMat, both Ip2", "PolyhedraMat", "PolyhedraMat",
         [w.Ip2_FrictMat_FrictMat_MindlinPhys(), w.Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys()]),
        ("cubes FrictMat, wall PolyhedraMat", "FrictMat", "PolyhedraMat",
         [w.Ip2_FrictMat_FrictMat_MindlinPhys(), w.Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys(),
          w.Ip2_FrictMat_PolyhedraMat_FrictPhys()]),
        ("cubes FrictMat, wall PolyhedraMat, no FrictPhys Ip2", "FrictMat", "PolyhedraMat",
         [w.Ip2_FrictMat_FrictMat_MindlinPhys(), w.Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys()]),
    ]
    return geoms, laws, trials


def coexist(k):
    """Trial k of _trials, in this process (YADE ends the process on a dispatch error)."""
    geoms, laws, trials = _trials()
    name, particle_kind, wall_kind, ip2s = trials[k]
    low, high = _pair_scene(particle_kind, wall_kind, ip2s, geoms, laws)
    seen = set()
    for _ in range(200):
        O.run(100, True)
        seen |= {(type(i.geom).__name__, type(i.phys).__name__) for i in O.interactions
                 if i.isReal}
    print(f"ran 20000 steps; cubes' vz {O.bodies[low].state.vel[2]:.3f}, "
          f"{O.bodies[high].state.vel[2]:.3f} m/s; pairs seen {sorted(seen)}")


def coexistence():
    """Hertz-Mindlin between polyhedra (ScGeom) and the volumetric law with a Wall in one scene:
    each trial in a process of its own."""
    import subprocess
    for k, trial in enumerate(_trials()[2]):
        out = subprocess.run([sys.executable, sys.argv[0], "--coexist", str(k)],
                             capture_output=True, text=True)
        said = [ln for ln in (out.stdout + out.stderr).splitlines()
                if ln.startswith("ran ") or "FATAL" in ln or "Error" in ln
                or "Assertion" in ln]
        print(f"  {trial[0]}: exit {out.returncode}; " + " | ".join(said)[:400], flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=float, default=0.02, help="m")
    parser.add_argument("--speeds", default="1,5,15", help="m/s, comma-separated")
    parser.add_argument("--fraction", type=float, default=0.02, help="of the Rayleigh time")
    parser.add_argument("--seed", type=int, default=1, help="the random shape's")
    parser.add_argument("--max-steps", type=int, default=20000)
    parser.add_argument("--coexist", type=int, default=None, help=argparse.SUPPRESS)
    parser.add_argument("--only", choices=("impacts", "others", "coexistence"), default=None)
    args = parser.parse_args()
    if args.coexist is not None:
        return coexist(args.coexist)
    args.speeds = [float(v) for v in args.speeds.split(",")]
    print(HEAD)
    if args.only in (None, "impacts"):
        impacts(args)
    if args.only in (None, "others"):
        others(args)
    if args.only in (None, "coexistence"):
        print("Can Hertz-Mindlin (polyhedra among themselves) and the volumetric law (with a Wall) "
              "meet in one scene?")
        coexistence()


if __name__ == "__main__":
    main()
