"""Measurement: the mechanistic mill model against direct breakage DEM over the DEM's window
(docs/grinding.md, Section 7), over several seeds.

    /usr/bin/python3 benchmarks/grind_vs_dem.py --material M SPECTRA_RUN DEM_RUN [SPECTRA_RUN DEM_RUN ...]

Each pair: SPECTRA_RUN, a `scripts/ball_mill.py --breakage 0` run (nothing breaks: the spectra
run), and DEM_RUN, the same mill and seed with breakage, finished or stopped early (its last
sample ends the window). The spectra run's stressing events up to the end of that window
(events.jsonl, pair types from the body ids: drum and end walls, then balls, then ore) are binned
as the mill bins them, converted (grinding.from_mill_run) and the model grinds M's feed over the
window. Prints, for each pair, the fraction of the feed left in the feed class (sizes above
feed / sqrt 2) at the DEM's sample times, the first-order rate fitted to each, the broken mass and
the passing at three sieves with their ratios; then, over the pairs, each ratio's mean and
standard deviation and whether it is within 20 %.

The DEM engine's conventions, mirrored in the model on request (BatchGrinder's options):
--t10-at threshold (every breakage's t10 at the fracture threshold, Eq. 9, as the engine breaks
a particle at the first read past its fracture energy) and --dem-dmin (progeny whose own
progeny would be finer than the DEM run's dmin never break again; stressed past their fracture
energy once, they are spread by Eq. 10, Eq. 13). --conventions runs the model four times (as
published, each convention, both) and prints one table of the ratios.

--by-class prints, per size below the feed, the DEM's and the model's stressing past the fracture
energy (rate, specific energy, t10) and the passing at 1.414 mm split into the feed's own
breakages and the re-stressed progeny (docs/grinding.md, Section 7).

Each pair also prints how the DEM's passing at the three sieves splits between resolved spheres
(counted at their size), dummy fines (Eq. 11) and unbreakable spheres stressed past their
fracture energy (Eq. 13): the last exactly from the events, the dummy fines as the expectation
of the family sets at each breakage's t10' (the draws are not logged), resolved spheres the rest;
and the DEM's passing at the finest sieve with its dummy fines spread by Eq. 10 (as the model
spreads all progeny) instead of Eq. 11.
"""
import argparse
import csv
import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))

from yadebreak import model  # noqa: E402
from yadebreak.model import families, milling  # noqa: E402
from yadebreak.studies.grinding import (BatchGrinder, feed_masses, from_mill_run,  # noqa: E402
                                root2_classes)
from yadebreak.criteria import load_material  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("runs", nargs="+", help="SPECTRA_RUN DEM_RUN pairs")
parser.add_argument("--material", required=True)
parser.add_argument("--cells", type=int, default=120)
parser.add_argument("--t10-at", choices=("collision", "threshold"), default="collision",
                    help="t10 of a breakage at e_j / E (the model) or at the threshold (the DEM)")
parser.add_argument("--dem-dmin", action="store_true",
                    help="progeny finer than the DEM run's dmin allows never break again")
parser.add_argument("--conventions", action="store_true",
                    help="run the model as published, with each convention and with both")
parser.add_argument("--by-class", action="store_true",
                    help="per size below the feed: stressing past the fracture energy in the "
                    "DEM and the model, and the passing at 1.41 mm by origin")
args = parser.parse_args()
if len(args.runs) % 2:
    parser.error("give the runs in pairs: SPECTRA_RUN DEM_RUN [SPECTRA_RUN DEM_RUN ...]")

SETTLE_TIME = 0.25      # s of settling before the drum turns (mill.py): mill time = scene time - it


def window_spectra(run_dir, t_end, folder):
    """The spectra run's events with mill time <= t_end as a mill run's folder (summary.json,
    collision_spectra.csv) in `folder`, binned as mill.collision_spectra bins them."""
    run_dir = Path(run_dir)
    summary = json.loads((run_dir / "summary.json").read_text())
    n_drum = summary["bodies_start"] - summary["balls"] - summary["ore_particles"] - 2
    first_ball, first_ore = n_drum + 2, n_drum + 2 + summary["balls"]
    events = [json.loads(line) for line in open(run_dir / "events.jsonl")]
    events = [e for e in events if e.get("kind") in ("damage", "breakage", "stressing")
              and e["time"] - SETTLE_TIME <= t_end and e.get("partner", -1) >= 0]
    energy = np.array([e["specific_energy"] for e in events])
    kind = np.array(["ore-liner" if e["partner"] < first_ball else "ball-ore"
                     if e["partner"] < first_ore else "ore-ore" for e in events])
    edges = np.geomspace(energy[energy > 0].min(), energy.max() * (1 + 1e-9), 25)
    rates = {k: milling.event_spectrum(energy[kind == k], t_end, edges)[0]
             for k in ("ball-ore", "ore-ore", "ore-liner")}
    with open(Path(folder) / "collision_spectra.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["energy_low_J_per_kg", "energy_high_J_per_kg"]
                   + [f"{k}_per_s" for k in rates])
        for j in range(len(edges) - 1):
            w.writerow([edges[j], edges[j + 1]] + [rates[k][j] for k in rates])
    (Path(folder) / "summary.json").write_text(json.dumps({**summary, "simulated_time": t_end}))
    return len(events)


def at_sieves(passing, sieves, classes):
    """The model's passing (%) at the DEM's sieves, linear in ln size between its own."""
    asc = classes.sieves[::-1]
    return np.array([np.interp(np.log(sieves), np.log(asc), p[::-1], left=0.0, right=100.0)
                     for p in passing])


def ratio(a, b):
    return a / b if b else float("nan")


def dem_dmin(dem_run, dem):
    """The DEM run's dmin (m): its --dmin, or the mill's default, a third of the feed size."""
    finished = Path(dem_run) / "finished.json"
    given = 0.0
    if finished.exists():
        given = json.loads(finished.read_text())["arguments"].get("dmin", 0.0)
    return given if given > 0 else dem["size"] / 3.0


def dem_split(dem_run, material, sieves):
    """The DEM product's mass (kg) passing `sieves` (m) by origin: (resolved spheres at their
    size, dummy fines spread by Eq. 11, unbreakable spheres stressed past their fracture energy
    spread by Eq. 13, their total). Unbreakable: exact from the events; dummies: each breakage's
    family set (nearest its t10') in expectation, radii scaled as the engine scales them;
    resolved: the family sets' non-dummy spheres in expectation, less the stressed unbreakables
    at their size."""
    events = [json.loads(line) for line in open(Path(dem_run) / "events.jsonl")]
    table = families.table_for(material)
    beta = material.beta_params
    resolved, dummies = np.zeros(len(sieves)), np.zeros(len(sieves))
    for e in (e for e in events if e["kind"] == "breakage"):
        parent = 2.0 * e["radius"]
        fs = table.sets[table.nearest(e["t10"])]
        scale = fs.volumes ** (-1.0 / 3.0)                          # exact mass per family
        for counts, p, k in zip(fs.counts, fs.probabilities, scale):
            volume = counts * families.CLASS_VOLUMES * k ** 3          # parent volume units
            size = families.RELATIVE_SIZES * k * parent
            real = np.arange(families.N_CLASSES) != families.DUMMY
            passes = size[None, :] <= sieves[:, None]
            resolved += p * e["mass"] * (passes & real[None, :]) @ volume
            dummies += (p * e["mass"] * volume[families.DUMMY]
                        * model.dummy_fines_passing(sieves, parent, e["t10"], beta)[0])
    stressed = np.zeros(len(sieves))
    for e in (e for e in events if e["kind"] == "unbreakable_stressed"):
        d = 2.0 * e["radius"]
        resolved -= e["mass"] * (d <= sieves)
        stressed += e["mass"] * model.progeny_passing(e["t10"], beta, sieves / d) / 100.0
    return resolved, dummies, stressed, resolved + dummies + stressed


def eq10_fines(dem_run, material, sieves):
    """kg of the DEM's breakages' progeny passing `sieves` (m) by Eq. 10 at each breakage's t10'
    (the sieves below the dummy size X_MIN x parent, where all of it is dummy fines, which the
    DEM spreads by Eq. 11 instead)."""
    events = (json.loads(line) for line in open(Path(dem_run) / "events.jsonl"))
    return sum(e["mass"] * model.progeny_passing(e["t10"], material.beta_params,
                                                 np.asarray(sieves) / (2.0 * e["radius"])) / 100.0
               for e in events if e["kind"] == "breakage")


def dem_stressed_once(dem_run):
    """kg of unbreakable spheres the DEM stressed past their fracture energy."""
    return sum(json.loads(line)["mass"] for line in open(Path(dem_run) / "events.jsonl")
               if '"unbreakable_stressed"' in line)


def compare(spectra_run, dem_run, material, t10_at="collision", with_dmin=False, verbose=True):
    """Print the comparison of one pair; returns {measure: model / DEM}."""
    say = print if verbose else (lambda *a, **k: None)
    dem = json.loads((Path(dem_run) / "summary.json").read_text())
    with open(Path(dem_run) / "size_distribution.csv", newline="") as f:
        rows = list(csv.reader(f))
    header, table = rows[0], np.array([[float(v) for v in r] for r in rows[1:]])
    times = table[:, 0]
    with tempfile.TemporaryDirectory() as folder:
        counted = window_spectra(spectra_run, times[-1], folder)
        spectra = from_mill_run(folder, load_material)
    dem_sieves = np.array([float(h.split("_")[1][:-2]) * 1e-3 for h in header[1:]])
    dem_passing = table[:, 1:]
    d0 = dem["size"]
    classes = root2_classes(d0 * 2 ** 0.25, 16)
    masses, fines = feed_masses(classes, d0, dem["initial_mass"])
    grinder = BatchGrinder(material, spectra, classes, cells=args.cells,
                           holdup_mass=dem["initial_mass"], t10_at=t10_at,
                           progeny_dmin=dem_dmin(dem_run, dem) if with_dmin else None)
    result = grinder.run(masses, fines, np.concatenate([[0.0], times]))
    model_passing = result.passing_percent[1:]
    model_at = at_sieves(model_passing, dem_sieves, classes)
    lower = d0 / math.sqrt(2.0)
    k_lower = int(np.argmin(np.abs(dem_sieves - lower)))
    dem_left = 1.0 - dem_passing[:, k_lower] / 100.0
    model_left = 1.0 - model_at[:, k_lower] / 100.0
    say(f"spectra: {spectra_run}, {counted} stressing events in the window "
          f"({spectra.rates_per_s.sum():.4g} collisions/s); DEM: "
          f"{dem_run} ({dem['breakage_events']} breakages, window {times[-1]:.3f} s)")
    say("time s | feed class left, DEM | model | model / DEM")
    for t, a, b in list(zip(times, dem_left, model_left))[::max(1, len(times) // 10)] + [
            (times[-1], dem_left[-1], model_left[-1])]:
        say(f"{t:.3f} | {a:.4f} | {b:.4f} | {ratio(b, a):.3f}")
    s_dem, _ = milling.first_order_breakage_rate(times, dem_left)
    s_model, _ = milling.first_order_breakage_rate(times, model_left)
    say(f"first-order rate of the feed class (1/s): DEM {s_dem:.4g}, model {s_model:.4g}, "
          f"ratio {ratio(s_model, s_dem):.3f}")
    say(f"broken mass fraction (below {1e3 * lower:.3g} mm): DEM {1 - dem_left[-1]:.4f}, model "
          f"{1 - model_left[-1]:.4f}, ratio {ratio(1 - model_left[-1], 1 - dem_left[-1]):.3f}")
    out = {"rate": ratio(s_model, s_dem),
           "broken mass": ratio(1 - model_left[-1], 1 - dem_left[-1])}
    for k in (k_lower + 1, k_lower + 2, k_lower + 4):
        a, b = dem_passing[-1, k], model_at[-1, k]
        say(f"passing {1e3 * dem_sieves[k]:.4g} mm: DEM {a:.3f} %, model {b:.3f} %, ratio "
              f"{ratio(b, a):.3f}")
        out[f"passing {1e3 * dem_sieves[k]:.3g} mm"] = ratio(b, a)
    say(f"model ({t10_at}{', dmin' if with_dmin else ''}): {result.steps} steps, "
        f"{result.runtime_s:.1f} s, mass error {result.mass_relative_error:.1e}, stressed once "
        f"(unbreakable) {100 * result.once_broken[-1] / result.initial_mass:.2f} % of the charge "
        f"(DEM {100 * dem_stressed_once(dem_run) / dem['initial_mass']:.2f} %)")
    # the DEM's passing by origin; the families' sphere sizes 2^(-k/4) d0 fall on its root-2
    # sieves: a sphere of class k stands for the mass between 2^(-k/4) and 2^(-(k-1)/4) d0 (Eq.
    # 10's mass retained on the sieve 2^(-k/4) d0) but sits on that sieve, so read at 0.99 x
    # sieve the expectation counts it retained, as Eq. 10 (and the model) does
    picked = [k_lower, k_lower + 1, k_lower + 2, k_lower + 4]
    sieves = dem_sieves[picked]
    split = dem_split(dem_run, material, sieves)
    finer, coarser = (dem_split(dem_run, material, sieves * f)[3] for f in (0.99, 1.01))
    total = 100.0 / dem["initial_mass"]
    say("DEM passing by origin, % of the charge: sieve mm | resolved spheres | dummy fines "
        "(Eq. 11) | unbreakables stressed (Eq. 13) | sum (expected) | DEM | expected at "
        "0.99 / 1.01 x sieve")
    for k, (s, idx) in enumerate(zip(sieves, picked)):
        say(f"{1e3 * s:.4g} | {total * split[0][k]:.3f} | {total * split[1][k]:.3f} | "
            f"{total * split[2][k]:.3f} | {total * split[3][k]:.3f} | "
            f"{dem_passing[-1, idx]:.3f} | {total * finer[k]:.3f} / {total * coarser[k]:.3f}")
    retained = {"broken mass": ratio(100.0 - 100.0 * model_left[-1], total * finer[0])}
    for k, idx in enumerate(picked[1:], start=1):
        retained[f"passing {1e3 * dem_sieves[idx]:.3g} mm"] = ratio(model_at[-1, idx],
                                                                   total * finer[k])
    # the same at the model's own sieves (no interpolation between them): the feed class's
    # lower sieve and three finer ones
    own = classes.sieves[[1, 2, 3, 5]]
    dem_own = total * dem_split(dem_run, material, own * 0.99)[3]
    model_own = result.passing_percent[-1, [1, 2, 3, 5]]
    say("at the model's sieves, mm | DEM (expected, spheres on a sieve retained) | model: "
        + ", ".join(f"{1e3 * s:.3g} | {a:.3f} | {b:.3f}" for s, a, b in zip(own, dem_own,
                                                                              model_own)))
    at_own = {f"passing {1e3 * s:.3g} mm": ratio(b, a) for s, a, b in zip(own, dem_own, model_own)}
    # the finest sieve lies below the dummy size (X_MIN d0): the DEM spreads its dummies by Eq. 11,
    # the model by Eq. 10; read with the dummies by Eq. 10 instead (the rest as read)
    finest, idx = sieves[-1], picked[-1]
    eq10_read = dem_passing[-1, idx] + total * (eq10_fines(dem_run, material, [finest])[0]
                                                - split[1][-1])
    say(f"DEM at {1e3 * finest:.4g} mm with its dummy fines spread by Eq. 10 instead of Eq. 11: "
        f"{eq10_read:.3f} % (as read {dem_passing[-1, idx]:.3f} %)")
    dummies_eq10 = {f"passing {1e3 * finest:.3g} mm": ratio(model_at[-1, idx], eq10_read)}
    return {"as read": out, "retained": retained, "own sieves": at_own,
            "dummies by Eq. 10": dummies_eq10}


class _Recorder(BatchGrinder):
    """BatchGrinder that adds up, per class and t10 node, the mass broken in the breakable pool
    and the mass of unbreakable progeny stressed past their fracture energy (for --by-class)."""

    def __init__(self, *a, **k):
        super().__init__(*a, **k)
        self.broken_t10 = np.zeros((self.n, len(self.t10_grid)))
        self.once_t10 = np.zeros_like(self.broken_t10)
        self._pool = self.broken_t10

    def _stress(self, cells, log_r, q, total, shift, dt, damage):
        # step() stresses the breakable pool (with damage) before the unbreakable one
        self._pool = self.broken_t10 if damage or not self.damage_on else self.once_t10
        return super()._stress(cells, log_r, q, total, shift, dt, damage)

    def _t10_weights(self, broken, t10):
        weights = super()._t10_weights(broken, t10)
        self._pool += weights
        return weights


def _dem_by_class(dem_run, material):
    """The DEM side of --by-class: the feed's stressing events and breakages, and per family class
    k (size 2^(-k/4) d0) the rate (1/s) and median specific energy (J/kg) at which unbreakable
    progeny are first stressed past their fracture energy."""
    dem = json.loads((Path(dem_run) / "summary.json").read_text())
    t_end, d0, charge = dem["simulated_time"], dem["size"], dem["initial_mass"]

    def mill_time(e):
        return e["time"] - SETTLE_TIME

    def k_of(radius):                       # the family class of a sphere: size 2^(-k/4) d0
        return int(round(-4.0 * math.log2(2.0 * radius / d0)))

    events = [json.loads(line) for line in open(Path(dem_run) / "events.jsonl")]
    events = [e for e in events if 0.0 <= mill_time(e) <= t_end]
    feed = [e for e in events if e["kind"] in ("damage", "breakage")
            and abs(2.0 * e["radius"] - d0) < 1e-9 * d0]
    broken = [e for e in feed if e["kind"] == "breakage"]
    once = [e for e in events if e["kind"] == "unbreakable_stressed"]
    alive_s = dem["ore_particles"] * t_end - sum(t_end - mill_time(e) for e in broken)
    out = {"DEM feed stressings /particle/s": len(feed) / alive_s,
           "DEM feed share past E %": 100.0 * len(broken) / len(feed),
           "DEM feed t10 %": float(np.mean([e["t10"] for e in broken])),
           "DEM broken %": 100.0 * sum(e["mass"] for e in broken) / charge}
    # progeny mass per class (the families' expectation at each breakage's t10') times its time
    # in the window, kg s, less the time after a body's first stressing past E (no longer at risk)
    table = families.table_for(material)
    exposure, born = np.zeros(families.N_CLASSES), {}
    for e in broken:
        fs = table.sets[table.nearest(e["t10"])]
        volumes = fs.probabilities @ (fs.counts * families.CLASS_VOLUMES)
        exposure += e["mass"] * volumes / volumes.sum() * (t_end - mill_time(e))
        born.update((f, mill_time(e)) for f in e.get("fragments", []))
    stressed = np.zeros(families.N_CLASSES)
    energies = [[] for _ in range(families.N_CLASSES)]
    for e in once:
        k = k_of(e["radius"])
        energies[k].append(e["specific_energy"])
        stressed[k] += e["mass"]
        exposure[k] -= e["mass"] * (t_end - mill_time(e))
    lag = np.array([mill_time(e) - born[e["id"]] for e in once if e["id"] in born])
    out.update({
        "DEM stressed once %": 100.0 * stressed.sum() / charge,
        "DEM once t10 %": float(np.average([e["t10"] for e in once],
                                           weights=[e["mass"] for e in once])),
        "DEM once within 2 ms of birth %": 100.0 * float(np.mean(lag < 2e-3)),
        "DEM once within 20 ms of birth %": 100.0 * float(np.mean(lag < 2e-2)),
        "DEM once lag median ms": 1e3 * float(np.median(lag)),
        "DEM past-E rate /s by k": np.where(exposure > 0.0,
                                            stressed / np.maximum(exposure, 1e-300), np.nan),
        "DEM median e past E J/kg by k": np.array([np.median(v) if v else np.nan
                                                   for v in energies])})
    return out


def _feed_energy(run_dir, first_progeny, level=1.0):
    """How hard a run's feed particles are stressed: the share (%) of their stressing events at or
    above `level` J/kg (about E50 at the feed size for limestone_weak) in each half of the run's
    window, and in its second half the share of events whose partner is a progeny sphere (id >=
    first_progeny) and the share above `level` among those and among the others."""
    summary_ = json.loads((Path(run_dir) / "summary.json").read_text())
    t_end, d0 = summary_["simulated_time"], summary_["size"]
    events = [json.loads(line) for line in open(Path(run_dir) / "events.jsonl")]
    feed = [e for e in events if e["kind"] in ("damage", "breakage", "stressing")
            and abs(2.0 * e["radius"] - d0) < 1e-9 * d0
            and 0.0 <= e["time"] - SETTLE_TIME <= t_end]
    late = np.array([e["time"] - SETTLE_TIME >= 0.5 * t_end for e in feed])
    hard = np.array([e["specific_energy"] >= level for e in feed])
    progeny = np.array([e.get("partner", -1) >= first_progeny for e in feed])

    def percent(flags, among):
        return 100.0 * flags[among].mean() if among.any() else float("nan")

    return {"feed events >= 1 J/kg, first half %": percent(hard, ~late),
            "feed events >= 1 J/kg, second half %": percent(hard, late),
            "second half: progeny partner %": percent(progeny, late),
            "second half: >= 1 J/kg with a progeny partner %": percent(hard, late & progeny),
            "second half: >= 1 J/kg with another partner %": percent(hard, late & ~progeny)}


def _model_by_class(spectra_run, dem_run, material, sieve):
    """The model side of --by-class over the DEM run's window: at t = 0 the feed's stressing and,
    per family size, the rate (1/s) and median specific energy (J/kg) of stressing past the
    fracture energy; after the window, as published and with the dmin rule, the feed's broken
    mass and t10 and the passing at `sieve` (m) from the feed's own breakages (Eq. 10) and the
    rest."""
    dem = json.loads((Path(dem_run) / "summary.json").read_text())
    t_end, d0, charge = dem["simulated_time"], dem["size"], dem["initial_mass"]
    with tempfile.TemporaryDirectory() as folder:
        window_spectra(spectra_run, t_end, folder)
        spectra = from_mill_run(folder, load_material)
    classes = root2_classes(d0 * 2 ** 0.25, 16)
    masses, fines = feed_masses(classes, d0, charge)
    out = {}
    for name, dmin in (("model", None), ("model dmin", dem_dmin(dem_run, dem))):
        g = _Recorder(material, spectra, classes, cells=args.cells, holdup_mass=charge,
                      progeny_dmin=dmin)
        if dmin is None:                    # t = 0: the same for both
            out.update(_model_past_e(g, masses, fines, families.CLASS_SIZES * d0))
        result = g.run(masses, fines, [0.0, t_end])
        w0 = g.broken_t10[0]
        primary = 100.0 / charge * w0 @ model.progeny_passing(g.t10_grid, material.beta_params,
                                                              sieve / g.sizes[0]) / 100.0
        total = at_sieves(result.passing_percent[-1:], np.array([sieve]), classes)[0, 0]
        out.update({f"{name} feed t10 %": float(w0 @ g.t10_grid / w0.sum()),
                    f"{name} broken %": 100.0 * float(w0.sum()) / charge,
                    f"{name} primary at sieve %": float(primary),
                    f"{name} rest at sieve %": float(total - primary),
                    f"{name} at sieve %": float(total)})
        if dmin is None:
            out["model fragments broken %"] = 100.0 * float(g.broken_t10[1:].sum()) / charge
        else:
            once = g.once_t10.sum(axis=0)
            out["model stressed once %"] = 100.0 * float(once.sum()) / charge
            out["model once t10 %"] = float(once @ g.t10_grid / once.sum())
    return out


def _model_past_e(grinder, masses, fines, sizes):
    """At t = 0 (fresh feed): the feed's stressing rate per particle (1/s) and share past its
    fracture energy (%), and at each of `sizes` (m) the rate of stressing past the fracture
    energy (1/s) and those events' median specific energy (J/kg)."""
    mat = grinder.material
    cells, f0 = grinder.fresh_state(masses, fines)
    e, _ = grinder.stressing(cells, f0)                                     # (J,) J/kg
    lam = grinder.rate[None, :] * grinder.capture.monolayer_mass(
        sizes[:, None], grinder.plane[None, :]) / grinder.holdup           # (sizes, J)
    past = lam * mat.fracture_energy_cdf(e[None, :], sizes[:, None])
    order = np.argsort(e)
    cum = np.cumsum(past[:, order], axis=1)
    lam0 = grinder.lam[0]
    return {"model feed stressings /particle/s": float(lam0.sum()),
            "model feed share past E % (t=0)": 100.0 * float(
                (lam0 * mat.fracture_energy_cdf(e, grinder.sizes[0])).sum() / lam0.sum()),
            "model past-E rate /s by k": past.sum(axis=1),
            "model median e past E J/kg by k": np.array(
                [e[order][np.searchsorted(c, 0.5 * c[-1])] for c in cum])}


def by_class(spectra_run, dem_run, material, sieve):
    """--by-class for one pair: _dem_by_class, _model_by_class and the DEM's passing at `sieve`
    (m, below the dummy size) by origin: its breakages' progeny by Eq. 10, its dummy fines as
    read (Eq. 11), its stressed unbreakables (Eq. 13), as read. % of the charge."""
    dem = json.loads((Path(dem_run) / "summary.json").read_text())
    to_percent = 100.0 / dem["initial_mass"]
    split = dem_split(dem_run, material, np.array([sieve]))
    with open(Path(dem_run) / "size_distribution.csv", newline="") as f:
        rows = list(csv.reader(f))
    column = [i for i, h in enumerate(rows[0]) if h.startswith("passing_")
              and abs(float(h.split("_")[1][:-2]) * 1e-3 - sieve) < 1e-6][0]
    first_progeny = dem["bodies_start"]
    return {**_dem_by_class(dem_run, material),
            **{f"DEM {k}": v for k, v in _feed_energy(dem_run, first_progeny).items()},
            **{f"spectra run {k}": v for k, v in
               _feed_energy(spectra_run, first_progeny).items() if "partner" not in k},
            **_model_by_class(spectra_run, dem_run, material, sieve),
            "DEM primary at sieve % (Eq. 10)": to_percent * float(
                eq10_fines(dem_run, material, [sieve])[0]),
            "DEM dummy fines at sieve %": to_percent * float(split[1][0]),
            "DEM stressed once at sieve %": to_percent * float(split[2][0]),
            "DEM at sieve %": float(rows[-1][column])}


def summary(ratios):
    """Each ratio's mean +- sd over the pairs."""
    out = {}
    for key in ratios[0]:
        values = np.array([r[key] for r in ratios])
        sd = values.std(ddof=1) if len(values) > 1 else float("nan")
        out[key] = (values.mean(), sd, values)
    return out


def print_table(rows, title):
    """One line per model variant: each ratio's mean +- sd over the pairs."""
    keys = list(next(iter(rows.values())))
    print(title)
    print("model | " + " | ".join(keys))
    for name, row in rows.items():
        print(name + " | " + " | ".join(f"{m:.2f} +- {sd:.2f}" for m, sd, _ in row.values()))


material = load_material(args.material)
pairs = list(zip(args.runs[::2], args.runs[1::2]))
if args.by_class:
    found = [by_class(s, d, material, 2.0 ** -0.5 * 2e-3) for s, d in pairs]
    for key in found[0]:
        values = np.array([f[key] for f in found], dtype=float)
        if values.ndim == 1:
            print(f"{key}: {values.mean():.4g} +- {values.std(ddof=1):.2g} "
                  f"({', '.join(f'{v:.4g}' for v in values)})")
        else:
            print(f"{key} (k = 0.., size 2^(-k/4) x feed): "
                  + ", ".join(f"{v:.3g}" for v in values.mean(axis=0)[:10]))
    sys.exit(0)
if args.conventions:
    variants = [("as published", "collision", False), ("t10 at threshold", "threshold", False),
                ("dmin rule", "collision", True), ("both", "threshold", True)]
    tables = {"as read": {}, "retained": {}, "own sieves": {}, "dummies by Eq. 10": {}}
    for name, t10_at, with_dmin in variants:
        runs = [compare(s, d, material, t10_at, with_dmin, verbose=False) for s, d in pairs]
        for reading, rows in tables.items():
            rows[name] = summary([r[reading] for r in runs])
    print_table(tables["as read"], f"model / DEM over {len(pairs)} pair(s), mean +- standard "
                "deviation, the DEM as its size_distribution.csv reads")
    print()
    print_table(tables["retained"], "the DEM read with every resolved sphere retained on the "
                "sieve it sits on (the families' expectation at 0.99 x sieve), window's end")
    print()
    print_table(tables["own sieves"], "the same at the model's own sieves (no interpolation)")
    print()
    print_table(tables["dummies by Eq. 10"], "the DEM as read, its dummy fines spread by Eq. 10 "
                "(as the model spreads all progeny) instead of Eq. 11")
    sys.exit(0)
runs = []
for spectra_run, dem_run in pairs:
    runs.append(compare(spectra_run, dem_run, material, args.t10_at, args.dem_dmin))
    print()
print(f"over {len(runs)} pair(s): model / DEM, mean +- standard deviation (target: within 20 %)")
for key, (mean, sd, values) in summary([r["as read"] for r in runs]).items():
    print(f"  {key}: {mean:.3f} +- {sd:.3f} ({', '.join(f'{v:.3f}' for v in values)}); "
          f"{'within' if abs(mean - 1) <= 0.2 else 'outside'} 20 %")
for reading, title in (("retained", "the DEM read with every resolved sphere retained on the "
                        "sieve it sits on"), ("own sieves", "the same at the model's sieves"),
                       ("dummies by Eq. 10", "the DEM with its dummy fines spread by Eq. 10")):
    print(f"against {title}:")
    for key, (mean, sd, values) in summary([r[reading] for r in runs]).items():
        print(f"  {key}: {mean:.3f} +- {sd:.3f} ({', '.join(f'{v:.3f}' for v in values)})")
