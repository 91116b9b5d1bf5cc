"""The bonded agglomerate's impact on a rigid plane behind scripts/agglomerate_impact.py
(a job: its scene from scenes/agglomerate.py, its outputs). docs/bonded.md: the model and the case.

The agglomerate is built (bonds.pack_in_sphere), bonded (scenes.agglomerate), dropped at --speed
onto a steel plane and followed for --duration seconds from its first touch (t = 0, as the
document's video frames). Every --sample-interval it records the damage ratio, the bonds broken
by mode, the bonds at >= 80 % of a strength, the kinetic energy and the debris that has left the
agglomerate; at the end, the fragments (connected components of the surviving bonds).

Checkpoints as the bed's and the mill's (--checkpoint-every s of wall time, into
<out>/checkpoint.yade.gz, the BondWatch's state with the scene); --resume 1 goes on from the last
one: bonds_broken.csv is rewritten from the checkpoint's broken bonds (the lines a killed run wrote
after it are dropped, then written again as the run breaks them) and the time series goes on from
the checkpoint's rows.
"""
from __future__ import annotations

import csv
import json
import math
import time

import numpy as np
from scipy.spatial import cKDTree

from yadebreak.model import bonds
from yadebreak.jobs import paraview
from yadebreak.engine.parts.bonds import WATCH_LEVEL
from yadebreak.scenes import agglomerate as bonded
from yadebreak.scenes.agglomerate import agglomerate_scene
from yadebreak.engine.scene import run_steps
from yadebreak.scenes import view
from yadebreak.jobs import skeleton
from yadebreak.jobs.lifecycle import resume_arguments

#: the document's agglomerate: 4,104 spheres in a 30 mm mould; --particles keeps its packing
#: density (spheres' volume over the mould's)
DOCUMENT_PARTICLES = 4104
DOCUMENT_DIAMETER = 30e-3
#: times the document reports (ms after the first touch): bonds at >= 80 % of the tensile
#: strength peak; debris leaves the fracture zone
DOCUMENT_PEAK_MS = 0.26
DOCUMENT_DEBRIS_MS = 0.44
#: a detached sphere farther than this many mean diameters from the largest fragment has left it
DEBRIS_GAP = 1.0
#: spheres at or above this damage ratio form the damaged zone (the document's Fig. 12d: > 0.1)
DAMAGED = 0.1
#: steps between two renewals of the contacts (bonded.renew_contacts), at the first sample after
#: them; checkpoints are written there. 200: 1-2 % of the run's time at 4,104 spheres, and
#: SIGTERM is answered within 200 steps (5 s of the document's case)
RENEW_STEPS = 200

SERIES_FIELDS = ["time_ms", "damage_ratio", "broken_tension", "broken_shear",
                 "broken_compression", "above80_tension", "above80_shear", "above80_compression",
                 "kinetic_energy_J", "debris_spheres"]


def solid_fraction_of_document(spheres):
    """The spheres' volume over the mould's in the document's agglomerate (4,104 spheres of the
    material's size distribution in a 30 mm mould)."""
    mould = bonds.mould_diameter_for(DOCUMENT_PARTICLES, spheres, 1.0)
    return (mould / DOCUMENT_DIAMETER) ** 3


def material_of(args):
    """The material of --material with --radius-multiplier applied."""
    material = bonds.load_agglomerate_material(args.material)
    if args.radius_multiplier > 0:
        material = material.with_binder(radius_multiplier=args.radius_multiplier)
    return material


def build(args):
    """(material, packing): the material with --radius-multiplier applied, and the agglomerate's
    spheres packed in their mould (seeded by --seed)."""
    material = material_of(args)
    rng = np.random.default_rng(args.seed)
    diameters = bonds.sphere_diameters(args.particles, material.spheres, rng)
    mould = bonds.mould_diameter_for(args.particles, material.spheres,
                                     solid_fraction_of_document(material.spheres))
    return material, bonds.pack_in_sphere(diameters, mould, rng)


class Agglomerate(skeleton.Job):
    """The agglomerate falls to its first touch, then is followed for --duration, sampled every
    --sample-interval. Every RENEW_STEPS steps, at a sample, the contacts are renewed as a load
    would (bonded.renew_contacts): only there may a checkpoint be written or SIGINT or SIGTERM
    stop the run, so that a run resumed from it goes on exactly as this one."""

    checkpoint_every = -1.0           # library use without --checkpoint-every: none

    def __init__(self, args, quiet=False):
        super().__init__(args, quiet)
        self.started = time.time()    # this invocation's start (the last line's wall time)

    def build(self):
        args, began = self.args, time.time()
        self.material, self.packing = build(args)
        view.reset()
        self.scene = agglomerate_scene(self.material, self.packing, seed=args.seed,
                                       speed=args.speed,
                                       time_step_fraction=args.time_step_fraction,
                                       check_period=args.check_period, duration=args.duration)
        bonds_initial = len(self.scene.watch.mode)
        self.say(f"{args.particles} spheres in a {2e3 * self.packing.mould_radius:.1f} mm mould, "
                 f"{bonds_initial} bonds ({2 * bonds_initial / args.particles:.2f} per sphere), "
                 f"dt {view.time_step():.3g} s, built in {time.time() - began:.1f} s")
        self.loop = {"series": [], "runtime_s": 0.0, "impact_s": 0.0, "renew_at": 0}

    def resume(self, path):
        self.scene, data = skeleton.load_checked(path, bonded.load_checkpoint, self.args)
        self.loop = data["loop"]
        self.packing = bonds.Packing(**{k: np.array(v) if isinstance(v, list) else v
                                        for k, v in self.loop.pop("packing").items()})
        self.scene.impact_seconds = self.loop["impact_s"]
        self.material = material_of(self.args)
        self.say(f"resumed from {path} at t = {self.loop['series'][-1]['time_ms']:.4f} ms "
                 f"after the touch, iteration {view.iteration()}, "
                 f"{self.scene.watch.broken_count()} bonds broken")
        return self.loop["runtime_s"]

    def open(self):
        scene, packing = self.scene, self.packing
        self.bonds_initial = len(scene.watch.mode)
        self.log = FailureLog(self.out / "bonds_broken.csv", scene.watch, packing)
        scene.watch.on_failure = self.log.write
        self.frames = paraview.series(self.out / "paraview", None, self.args.vtk_interval,
                                      resume=getattr(self.args, "resume", False),
                                      wall_patch=((0.0, 0.0, 0.0),
                                                  paraview.WALL_MARGIN * packing.mould_radius),
                                      sphere_arrays=lambda ids: _paraview_arrays(ids, scene))
        self.began = None             # wall time of the first advance (after the touch)

    def advance(self):
        args, scene, packing, loop = self.args, self.scene, self.packing, self.loop
        watch, series = scene.watch, loop["series"]
        if self.began is None:
            self.chunk = max(1, int(round(args.sample_interval / view.time_step())))
            if watch.touch_time is None:      # to the first touch: the impact's t = 0
                while watch.touch_time is None:
                    run_steps(1)
                    if view.now() > 1.0:
                        raise RuntimeError("the agglomerate never reached the plane in 1 s")
                series.append(_sample(scene, packing))
            self.began, self.impact_before = time.time(), scene.impact_seconds
        self.renewed = False
        now, dt = view.now(), view.time_step()
        if not now - watch.touch_time < args.duration - 0.5 * dt:
            return "finished"
        left = int(math.ceil((args.duration - (now - watch.touch_time)) / dt - 1e-9))
        run_steps(min(self.chunk, max(left, 1)))
        series.append(_sample(scene, packing))
        self.frames()
        scene.impact_seconds = self.impact_before + time.time() - self.began
        if view.iteration() >= loop["renew_at"]:
            bonded.renew_contacts()
            loop["renew_at"] = view.iteration() + RENEW_STEPS
            self.renewed = True
        return None

    def at_safe_point(self):
        return self.renewed

    def elapsed(self):
        return view.now()

    def status(self):
        row = self.loop["series"][-1]
        return (f"t = {row['time_ms']:.3f} ms of {self.args.duration * 1e3:g}: damage ratio "
                f"{row['damage_ratio']:.3f}, broken {row['broken_tension']} tension / "
                f"{row['broken_shear']} shear / {row['broken_compression']} compression")

    def done(self):
        return self.loop["series"][-1]["time_ms"] * 1e-3 / self.args.duration

    def save(self, path, wall_s):
        """The scene with its BondWatch, the loop state and the run's arguments."""
        state = {**self.loop, "runtime_s": wall_s, "impact_s": self.scene.impact_seconds,
                 "packing": {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                             for k, v in vars(self.packing).items()}}
        bonded.save_checkpoint(path, self.scene, {"loop": state,
                                                  "arguments": resume_arguments(self.args)})

    def close(self):
        self.frames.close()

    def stopped(self):
        self.log.close()

    def outputs(self, end_reason, end_message, runtime_s):
        self.log.close()
        return _outputs(self.args, self.out, self.material, self.packing, self.scene,
                        self.loop["series"], runtime_s, end_reason, end_message)

    def finished(self, summary):
        watch = self.scene.watch
        self.say(f"{watch.broken_count()} of {self.bonds_initial} bonds broken (tension "
                 f"{watch.broken_count(bonds.TENSION)}, shear {watch.broken_count(bonds.SHEAR)}, "
                 f"compression {watch.broken_count(bonds.COMPRESSION)}), mean damage ratio "
                 f"{summary['damage_ratio']:.3f}; wrote {self.out}/summary.json in "
                 f"{time.time() - self.started:.0f} s")


def run(args, quiet=False):
    """The whole run: build (or resume), impact, outputs. Returns the summary (a dict), None if
    it stopped early on purpose (--stop-after, tests)."""
    return skeleton.run(Agglomerate(args, quiet))


def _sample(scene, packing):
    """One row of the time series (SERIES_FIELDS)."""
    watch = scene.watch
    damage = watch.damage_ratios()
    return {"time_ms": (view.now() - watch.touch_time) * 1e3,
            "damage_ratio": float(np.nanmean(damage)),
            "broken_tension": watch.broken_count(bonds.TENSION),
            "broken_shear": watch.broken_count(bonds.SHEAR),
            "broken_compression": watch.broken_count(bonds.COMPRESSION),
            "above80_tension": int(watch.above[0]), "above80_shear": int(watch.above[1]),
            "above80_compression": int(watch.above[2]),
            "kinetic_energy_J": view.kinetic_energy(),
            "debris_spheres": debris_count(watch, _positions(scene.sphere_ids),
                                           2.0 * float(packing.radii.mean()))}


def _positions(ids):
    return np.array([view.position(int(i)) for i in ids])


def debris_count(watch, positions, mean_diameter):
    """Spheres of the fragments other than the largest that are farther than DEBRIS_GAP mean
    diameters (surface to surface, taken as centre distance less one diameter) from every sphere
    of the largest fragment: debris that has left the agglomerate."""
    labels, counts = watch.fragments()
    largest = labels == int(np.argmax(counts))
    if largest.all():
        return 0
    dist, _ = cKDTree(positions[largest]).query(positions[~largest])
    return int(np.count_nonzero(dist - mean_diameter > DEBRIS_GAP * mean_diameter))


class FailureLog:
    """bonds_broken.csv, a line per broken bond as it breaks (a run that dies keeps it): bond
    row, its spheres (packing indices), time after the first touch (ms), mode, and the bond's
    midpoint as built (m, the agglomerate's centre at the origin)."""

    FIELDS = ["bond", "sphere_a", "sphere_b", "time_ms", "mode", "x", "y", "z"]

    def __init__(self, path, watch, packing):
        """A new file, holding the bonds `watch` has broken so far (a resumed run: those of its
        checkpoint, in the order they broke; lines a killed run wrote after it are dropped)."""
        self.file = open(path, "w", newline="")
        self.writer = csv.writer(self.file)
        self.writer.writerow(self.FIELDS)
        self.watch = watch
        pairs = watch.net.pairs
        self.midpoints = 0.5 * (packing.positions[pairs[:, 0]] + packing.positions[pairs[:, 1]])
        broken = np.flatnonzero(watch.mode != bonds.INTACT)
        # a step breaks its bonds in ascending row order (BondWatch._break)
        broken = broken[np.lexsort((broken, watch.failed_at[broken]))]
        for t in np.unique(watch.failed_at[broken]):
            rows = broken[watch.failed_at[broken] == t]
            self.write(rows, watch.mode[rows], t)

    def write(self, rows, modes, now):
        t = (now - self.watch.touch_time) * 1e3
        pairs = self.watch.net.pairs
        for r, m in zip(rows, modes):
            x, y, z = self.midpoints[r]
            self.writer.writerow([int(r), int(pairs[r, 0]), int(pairs[r, 1]), f"{t:.6g}",
                                  bonds.MODES[m], f"{x:.6g}", f"{y:.6g}", f"{z:.6g}"])
        self.file.flush()

    def close(self):
        if not self.file.closed:
            self.file.close()


def _paraview_arrays(ids, scene):
    """damage ratio and fragment label of each sphere of the frame (the plane: -1)."""
    damage = scene.watch.damage_ratios()
    labels, _ = scene.watch.fragments()
    row = {int(b): k for k, b in enumerate(scene.sphere_ids)}
    k = np.array([row.get(int(i), -1) for i in ids])
    known = k >= 0
    out_damage = np.full(len(ids), -1.0)
    out_damage[known] = np.nan_to_num(damage[k[known]], nan=0.0)
    out_label = np.full(len(ids), -1, np.int64)
    out_label[known] = labels[k[known]]
    return [("damage_ratio", out_damage, "Float64"), ("fragment", out_label, "Int64")]


# -- what the run found ----------------------------------------------------------------------------
def zone_measures(packing, damage):
    """Where the damage is, in the agglomerate as built (centre at the origin, the plane below);
    heights are above the agglomerate's lowest point over its diameter (0 bottom, 1 top).
      damaged_fraction: share of spheres with damage ratio >= DAMAGED
      damaged_height: the 95th percentile height of the damaged spheres
      upper_half_damaged: share of the spheres above the centre that are damaged
      damaged_share_by_height: in ten bands of height (0-0.1, ..., 0.9-1), the share of the
        band's spheres that are damaged: a zone that fills the agglomerate's section at the
        plane and narrows upwards (a cone) falls from near 1 to 0."""
    big_r = packing.mould_radius
    height = (packing.positions[:, 2] + big_r) / (2 * big_r)
    damaged = np.nan_to_num(damage, nan=0.0) >= DAMAGED
    band = np.minimum((height * 10).astype(int), 9)
    spheres = np.bincount(band, minlength=10)
    hit = np.bincount(band, weights=damaged, minlength=10)
    return {"damaged_fraction": float(damaged.mean()),
            "damaged_height": float(np.percentile(height[damaged], 95)) if damaged.any() else 0.0,
            "upper_half_damaged": float(damaged[height > 0.5].mean()),
            "damaged_share_by_height": [float(h / s) if s else 0.0 for h, s in zip(hit, spheres)]}


def size_distribution(diameters, mass_fractions, top):
    """The fragments' cumulative size distribution: [{size_m, passing}] at sieves of a root-2
    series from `top` (m) down to a fortieth of it, passing = mass share (-) of the fragments whose
    equivalent diameter is below the sieve."""
    sieves = top / np.sqrt(2.0) ** np.arange(12)
    return [{"size_m": float(x), "passing": float(mass_fractions[diameters < x].sum())}
            for x in sieves]


def _first_time(series, key, above=0):
    for row in series:
        if row[key] > above:
            return row["time_ms"]
    return None


def _outputs(args, out, material, packing, scene, series, runtime_s, end_reason, end_message):
    """summary.json, timeseries.csv and the plots; returns the summary."""
    watch = scene.watch
    damage = watch.damage_ratios()
    labels, counts = watch.fragments()
    fragment_mass = bonds.fragment_masses(labels, scene.masses)
    order = np.argsort(fragment_mass)[::-1]
    total = float(scene.masses.sum())
    sizes = bonds.equivalent_diameters(fragment_mass[order], material.spheres.density)
    peak = max(series, key=lambda r: r["above80_tension"]) if series else None
    impact_seconds = scene.impact_seconds
    summary = {
        "material": material.name, "particles": int(args.particles),
        "agglomerate_diameter": 2 * packing.mould_radius, "mass": total,
        "porosity": 1.0 - bonds.solid_fraction_within(packing.positions, packing.radii,
                                                      packing.mould_radius),
        "porosity_core": 1.0 - bonds.solid_fraction_within(
            packing.positions, packing.radii, packing.mould_radius - 2 * packing.radii.mean()),
        "bonds_initial": len(watch.mode),
        "bonds_per_sphere": 2 * len(watch.mode) / args.particles,
        "bonds_broken_tension": watch.broken_count(bonds.TENSION),
        "bonds_broken_shear": watch.broken_count(bonds.SHEAR),
        "bonds_broken_compression": watch.broken_count(bonds.COMPRESSION),
        "damage_ratio": float(np.nanmean(damage)),
        "radius_multiplier": material.binder.radius_multiplier,
        "speed": args.speed, "seed": args.seed, "time_step": view.time_step(),
        "duration": args.duration, "steps": int(view.iteration()),
        "fragments": {"count": int(len(counts)),
                      "largest_mass_fraction": float(fragment_mass[order[0]] / total),
                      "single_spheres": int(np.count_nonzero(counts == 1)),
                      "equivalent_diameters_m": [float(x) for x in sizes[:50]],
                      "mass_fractions": [float(x) for x in fragment_mass[order[:50]] / total],
                      "size_distribution": size_distribution(sizes, fragment_mass[order] / total,
                                                             2 * packing.mould_radius)},
        "findings": {
            "peak_above80_tension_ms": peak["time_ms"] if peak else None,
            "peak_above80_tension": peak["above80_tension"] if peak else None,
            "document_peak_ms": DOCUMENT_PEAK_MS,
            "debris_leaves_ms": _first_time(series, "debris_spheres"),
            "debris_half_ms": (_first_time(series, "debris_spheres",
                                           0.5 * series[-1]["debris_spheres"] - 1e-9)
                               if series and series[-1]["debris_spheres"] else None),
            "document_debris_ms": DOCUMENT_DEBRIS_MS,
            **zone_measures(packing, damage)},
        "cost": {"runtime_s": runtime_s, "impact_s": impact_seconds,
                 "criterion_s": watch.seconds, "checks": watch.checks,
                 "bonds_read": watch.bonds_read, "check_period": watch.check_period},
        "end_reason": end_reason, "end_message": end_message,
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    with open(out / "timeseries.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, SERIES_FIELDS)
        writer.writeheader()
        writer.writerows(series)
    if series:
        plot_series(series, out / "agglomerate_impact.png", summary)
        plot_damage(packing, damage, watch, out / "damage_section.png")
    return summary


def plot_series(series, path, summary):
    """Damage ratio, broken bonds by mode, bonds at >= 80 % of a strength and kinetic energy
    against time, with the document's reported times marked."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t = np.array([r["time_ms"] for r in series])
    col = {k: np.array([r[k] for r in series]) for k in SERIES_FIELDS}
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5), sharex=True)
    ax = axes[0, 0]
    ax.plot(t, col["damage_ratio"], color="k")
    ax.set_ylabel("mean damage ratio (-)")
    ax.set_title("(a) damage ratio (document's Fig. 13a)")
    ax = axes[0, 1]
    for key, c in (("broken_tension", "C3"), ("broken_shear", "C0"),
                   ("broken_compression", "C2")):
        ax.plot(t, col[key], color=c, label=key.split("_")[1])
    ax.set_ylabel("broken bonds")
    ax.set_title("(b) bonds broken by mode (Fig. 17)")
    ax.legend()
    ax = axes[1, 0]
    ax.plot(t, col["above80_tension"], color="C3", label="tension")
    ax.plot(t, col["above80_shear"], color="C0", label="shear")
    ax.axvline(DOCUMENT_PEAK_MS, color="0.5", ls="--",
               label=f"document's peak {DOCUMENT_PEAK_MS} ms")
    ax.set_ylabel(f"bonds at >= {WATCH_LEVEL:.0%} of strength")
    ax.set_title("(c) bonds near failure (Fig. 18)")
    ax.legend()
    ax = axes[1, 1]
    ax.plot(t, col["kinetic_energy_J"] * 1e3, color="k", label="kinetic energy")
    ax.axvline(DOCUMENT_DEBRIS_MS, color="0.5", ls="--",
               label=f"document: debris leaves, {DOCUMENT_DEBRIS_MS} ms")
    debris = summary["findings"]["debris_leaves_ms"]
    if debris is not None:
        ax.axvline(debris, color="C1", ls=":", label=f"here: debris leaves, {debris:.3f} ms")
    ax.set_ylabel("kinetic energy (mJ)")
    ax.set_title("(d) kinetic energy (Fig. 13b)")
    ax.legend()
    for ax in axes[1]:
        ax.set_xlabel("time after the first touch (ms)")
    fig.suptitle(f"{summary['particles']} spheres, {summary['bonds_initial']} bonds, "
                 f"{summary['speed']:g} m/s, lambda = {summary['radius_multiplier']:g}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_damage(packing, damage, watch, path):
    """A vertical slice through the impact axis (|y| < one diameter), spheres as built coloured
    by damage ratio, and the broken bonds' midpoints seen from below (the document's Figs. 11-12
    and 16)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle
    pos, r = packing.positions * 1e3, packing.radii * 1e3
    near = np.abs(pos[:, 1]) < 2 * r.mean()
    values = np.nan_to_num(damage, nan=0.0)
    fig, axes = plt.subplots(1, 2, figsize=(11, 5.2))
    ax = axes[0]
    patches = PatchCollection([Circle((x, z), rr) for (x, _, z), rr in zip(pos[near], r[near])],
                              cmap="inferno_r", edgecolor="0.6", linewidth=0.2)
    patches.set_array(values[near])
    patches.set_clim(0, 1)
    ax.add_collection(patches)
    fig.colorbar(patches, ax=ax, label="damage ratio")
    big = packing.mould_radius * 1e3
    _square(ax, big, "z (mm), the plane below", "slice |y| < 2 radii, as built")
    ax = axes[1]
    broken = watch.mode != 0
    mid = 0.5 * (pos[watch.net.pairs[:, 0]] + pos[watch.net.pairs[:, 1]])
    t = watch.failed_at[broken]
    if broken.any():
        sc = ax.scatter(mid[broken, 0], mid[broken, 1], c=(t - watch.touch_time) * 1e3, s=4,
                        cmap="viridis")
        fig.colorbar(sc, ax=ax, label="time broken (ms after the touch)")
    _square(ax, big, "y (mm)", "broken bonds seen from below (Fig. 16b)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _square(ax, half, ylabel, title):
    """An equal-aspect view of the agglomerate's section (half its width in mm)."""
    ax.set_xlim(-half, half)
    ax.set_ylim(-half, half)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
