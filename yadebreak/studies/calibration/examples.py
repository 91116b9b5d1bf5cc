"""Synthetic laboratory data drawn from a material: the example files of docs/examples/calibration/
and the round-trip tests. Every draw comes from the seeded numpy Generator passed in.

    /usr/bin/python3 -m yadebreak.studies.calibration.examples --material copper_ore --seed 1 \\
        --out docs/examples/calibration

Energies are the specific impact energies on the steel calibration device, the scale of Eq. 3's
Einf (the particle absorbs the share e = 1/(1 + kp/ks) of them, Eq. 4). Model layer: no YADE.
"""
from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np

from yadebreak import model
from yadebreak.criteria import load_material

#: realistic test programmes: sizes (mm), particles per class, energies (J/kg)
FRACTURE_SIZES_MM = (2.0, 4.0, 8.0, 16.0, 32.0)
T10_SIZES_MM = (4.0, 8.0, 16.0)
PROGENY_T10 = (5.0, 10.0, 15.0, 20.0, 30.0, 40.0)


def device_share(material):
    """e = 1/(1 + kp/ks): the share of the device's energy the particle absorbs (Eq. 3 / Eq. 4)."""
    ks = material.criterion.device_stiffness
    return float(model.energy_partition(material.hertz_stiffness, ks))


def measured_fracture_energy(material, u, size_mm):
    """The device energy (J/kg) at which a particle of strength quantile u breaks in one loading:
    Tavares: its fracture energy (Eqs. 1-3) over e; Ab-T10: the single loading whose e_cum
    (the part above e_min) reaches its threshold (Eqs. 9.1-9.3), over e."""
    size = np.asarray(size_mm, float) * 1e-3
    threshold = material.fracture_energy_ppf(u, size)
    if material.is_ab_t10:
        threshold = threshold + material.min_energy(size)
    return threshold / device_share(material)


def fracture_rows(material, rng, sizes_mm=FRACTURE_SIZES_MM, particles=60, cap_quantile=None):
    """One row per particle: (size_mm, energy, broken). With cap_quantile, the load cell's highest
    energy in each class is the class's quantile at that probability: a particle that would
    need more survives (broken = 0, energy = the cap, a censored row)."""
    rows = []
    for s in sizes_mm:
        e = measured_fracture_energy(material, 1.0 - rng.random(particles), s)
        if cap_quantile is not None:
            cap = float(measured_fracture_energy(material, cap_quantile, s))
            rows += [(s, min(v, cap), int(v < cap)) for v in e]
        else:
            rows += [(s, float(v), 1) for v in e]
    return rows


def t10_model(material, energy, size_mm):
    """The library's t10 (%) of particles of size_mm given `energy` on the device (Eq. 7 with E50b;
    Ab-T10: M P / 2, the mean of Eq. 9.4 over the broken ones)."""
    return material.t10_model(device_share(material) * np.asarray(energy, float),
                              np.asarray(size_mm, float) * 1e-3)


def t10_rows(material, rng, sizes_mm=T10_SIZES_MM, energies=None, noise_percent=1.5):
    """(size_mm, energy, t10 %) at each size and energy, with Gaussian scatter of noise_percent."""
    rows = []
    for s in sizes_mm:
        e50 = float(measured_fracture_energy(material, 0.5, s))
        for e in (energies if energies is not None else e50 * np.geomspace(1.0, 150.0, 6)):
            t = float(t10_model(material, e, s))
            rows.append((s, float(e), float(np.clip(t + noise_percent * rng.standard_normal(),
                                                     0.05, 99.0))))
    return rows


def repeated_rows(material, rng, series=((16.0, 0.4), (16.0, 0.6)), particles=100, impacts=8):
    """(size_mm, energy, impact, tested, broken): each series fires `particles` particles of one
    size `impacts` times at a fraction of their class's median device energy, by Monte Carlo
    (Tavares: Eqs. 5-6 weaken a survivor after each impact; Ab-T10: e_cum adds up, Eq. 9.2)."""
    rows = []
    share = device_share(material)
    for s, frac in series:
        size = s * 1e-3
        energy = float(measured_fracture_energy(material, 0.5, s)) * frac
        absorbed = share * energy
        u = 1.0 - rng.random(particles)
        e = material.fracture_energy_ppf(u, np.full(particles, size))
        alive = np.ones(particles, bool)
        cum = np.zeros(particles)
        for k in range(1, impacts + 1):
            tested = int(alive.sum())
            if tested == 0:
                break
            if material.is_ab_t10:
                cum = cum + float(model.ab_t10_single_impact_cum(absorbed,
                                                                 material.min_energy(size)))
                now = alive & (cum > e)
            else:
                now = alive & (absorbed > e)
                survivors = alive & ~now
                e[survivors] = model.weakened_fracture_energy(e[survivors], absorbed / e[survivors],
                                                              material.params.gamma)
            alive &= ~now
            rows.append((s, energy, k, tested, int(now.sum())))
    return rows


def progeny_rows(material, rng, t10_values=PROGENY_T10, noise=0.04):
    """(t10, n, passing %) from Eq. 10 with the material's table: the mass between successive
    sieves scattered by a lognormal factor (sd `noise`), so that passing stays ordered."""
    rows = []
    n_values = np.array(model.N_VALUES)
    for t in t10_values:
        passing = model.t_markers(t, material.beta_params)         # coarse (1.2) to fine (75)
        fine_to_coarse = np.concatenate([passing[::-1], [100.0]])
        masses = np.diff(np.concatenate([[0.0], fine_to_coarse]))
        masses = masses * np.exp(noise * rng.standard_normal(masses.size))
        cum = np.cumsum(masses)[:-1] / masses.sum() * 100.0
        for n, p in zip(n_values[::-1], cum):
            rows.append((t, float(n), float(p)))
    return rows


HEADERS = {"fracture": ("size_mm", "energy_J_per_kg", "broken"),
           "t10": ("size_mm", "energy_J_per_kg", "t10_percent"),
           "repeated": ("size_mm", "energy_J_per_kg", "impact", "tested", "broken"),
           "progeny": ("t10_percent", "n", "passing_percent")}


def write_csv(path, kind, rows, comment=""):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as fh:
        if comment:
            fh.write(f"# {comment}\n")
        w = csv.writer(fh)
        w.writerow(HEADERS[kind])
        for r in rows:
            w.writerow([f"{v:.6g}" if isinstance(v, float) else v for v in r])
    return path


def make_examples(material_name, out, seed=1):
    """Write fracture_energies.csv, t10.csv, repeated_impacts.csv and progeny.csv drawn from
    `material_name` with numpy Generator(seed); returns the paths."""
    mat = load_material(material_name)
    rng = np.random.default_rng(seed)
    out = Path(out)
    what = f"drawn from material {mat.name} with seed {seed} (yadebreak.studies.calibration.examples)"
    paths = [write_csv(out / "fracture_energies.csv", "fracture",
                       fracture_rows(mat, rng, cap_quantile=0.95), what),
             write_csv(out / "t10.csv", "t10", t10_rows(mat, rng), what)]
    if not mat.is_ab_t10:
        paths.append(write_csv(out / "repeated_impacts.csv", "repeated", repeated_rows(mat, rng),
                               what))
    paths.append(write_csv(out / "progeny.csv", "progeny", progeny_rows(mat, rng), what))
    return paths


def main(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m yadebreak.studies.calibration.examples",
                                description=__doc__.split("\n\n")[0])
    p.add_argument("--material", default="copper_ore")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--out", default="docs/examples/calibration")
    a = p.parse_args(argv)
    for path in make_examples(a.material, a.out, a.seed):
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
