"""`python3 -m yadebreak grind SPECTRA --material M --feed SIZE_OR_PSD --minutes 10 --out DIR`:
batch (or continuous) grinding from a mill's collision spectra (docs/grinding.md, Section 6).
Every input is checked before the integration starts; a problem is one line naming the option
or file."""
from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np

from yadebreak.model.intervals import PARTICLE_SIZE
from yadebreak.criteria import load_material
from yadebreak.jobs.lifecycle import progress, save_figure, status, write_atomic
from yadebreak.options.flags import UNITS, ParamError, number, number_and_unit
from yadebreak.studies.grinding.classes import (FeedError, class_label, feed_masses, feed_top_sieve, read_psd_csv,
                      root2_classes)
from yadebreak.studies.grinding.population import BatchGrinder, GrindingError
from yadebreak.model.spectra import (SPECTRA_NAME, SpectraError, from_mill_run, read_spectra,
                                     synthetic_spectra, write_spectra)


def load_spectra(source, out):
    """The spectra of `source`: a spectra file; a folder holding spectra.csv; a mill run's
    folder (summary.json and collision_spectra.csv), converted; or 'synthetic:BALL_MM', the
    rule of spectra.synthetic_spectra for balls of BALL_MM mm. Converted and synthetic spectra
    are written to out/spectra.csv."""
    text_source = str(source)
    if text_source.startswith("synthetic:"):
        try:
            ball_mm = float(text_source.partition(":")[2])
        except ValueError:
            ball_mm = math.nan
        if not 0.0 < ball_mm <= 200.0:
            raise SpectraError(f"SPECTRA = {text_source}: accepted synthetic:BALL_MM with a ball "
                               "diameter in (0, 200] mm")
        path = write_spectra(out / SPECTRA_NAME, synthetic_spectra(1e-3 * ball_mm))
        return read_spectra(path), path
    source = Path(source)
    if source.is_dir():
        if (source / SPECTRA_NAME).is_file():
            return read_spectra(source / SPECTRA_NAME), source / SPECTRA_NAME
        spectra = from_mill_run(source, load_material)
        path = write_spectra(out / SPECTRA_NAME, spectra)
        return read_spectra(path), path
    if not source.exists():
        raise SpectraError(f"SPECTRA {source}: no such file or folder")
    return read_spectra(source), source


#: --feed as a size: plain numbers in mm, a length unit may follow, within the particle sizes
FEED_SIZE = number("feed", 5.5, "mm", "", lo=PARTICLE_SIZE.lo * 1e3, hi=PARTICLE_SIZE.hi * 1e3)


def parse_feed(text_value):
    """--feed: a size (a single-size feed: a plain number in mm, or a number with a length unit:
    8mm, '0.008 m') or else a CSV file (size_mm, passing_percent). Returns a size in m or
    (sizes m, passing %)."""
    parts = number_and_unit(text_value)
    if parts is not None:                  # a quantity: a size, in a length unit
        if parts[1] not in ("", *UNITS["mm"]):
            raise FeedError(f"--feed = {text_value}: a size takes a length unit "
                            f"({', '.join(UNITS['mm'])}; a plain number is in mm), or give a "
                            "CSV file (size_mm, passing_percent)")
        try:
            return FEED_SIZE.convert(text_value) * 1e-3
        except ParamError as exc:
            raise FeedError(f"{exc} or a CSV file") from None
    if not Path(text_value).is_file():
        raise FeedError(f"--feed = {text_value}: neither a size (a number in mm, or with a length "
                        "unit: 8mm, '0.008 m') nor a CSV file (size_mm, passing_percent) that "
                        "exists")
    return read_psd_csv(text_value)


def grind(args):
    """The grind command (registered in yadebreak.cli)."""
    out = Path(args.out)
    if args.interval > args.minutes:
        raise FeedError(f"--interval = {args.interval:g} min: accepted up to --minutes "
                        f"({args.minutes:g} min), the time between outputs of that grinding")
    feed = parse_feed(args.feed)
    material = load_material(args.material)
    out.mkdir(parents=True, exist_ok=True)
    spectra, spectra_path = load_spectra(args.spectra, out)
    dem_material = spectra.extra.get("material")
    if dem_material and dem_material != material.name:
        progress(f"note: the spectra come from a mill of {dem_material}; grinding "
                 f"{material.name} in it (--material)")
    classes = root2_classes(feed_top_sieve(feed), args.classes)
    holdup = args.holdup if args.holdup > 0 else spectra.ore_mass_kg
    masses, fines = feed_masses(classes, feed, holdup)
    grinder = BatchGrinder(material, spectra, classes, cells=args.cells,
                           damage=bool(args.damage), holdup_mass=holdup)
    times = np.arange(0.0, args.minutes + 1e-9, args.interval) * 60.0
    if times[-1] < args.minutes * 60.0 * (1 - 1e-12):
        times = np.append(times, args.minutes * 60.0)
    residence = args.residence * 60.0 if args.residence > 0 else None
    mode = f"continuous, residence {args.residence:g} min" if residence else "batch"
    progress(f"{material.name}: {mode}, {args.minutes:g} min on {spectra_path} "
             f"({len(spectra.events)} spectrum rows, "
             f"{spectra.rates_per_s.sum():.4g} collisions/s), {classes.count} classes from "
             f"{class_label(classes.sieves[0])} mm")
    result = grinder.run(masses, fines, times, residence_time_s=residence,
                         progress=lambda t, wall: status(
                             f"t = {t / 60:.2f} of {args.minutes:g} min, wall {wall:.0f} s"))
    s0 = grinder.initial_rates(masses, fines, net=True)
    summary = _write(out, args, material, spectra_path, spectra, classes, result, s0, holdup)
    progress(f"done in {result.runtime_s:.1f} s ({result.steps} steps): after {args.minutes:g} min "
             f"P80 = {summary['p80_mm']:.4g} mm, {summary['specific_energy_kWh_per_t']:.3g} kWh/t "
             f"of collisions, mass error {result.mass_relative_error:.1e}; outputs in {out}")
    return 0


def _p80(sieves, passing):
    """Size (m) at 80 % passing, interpolated in ln size; NaN if out of the sieves."""
    asc_p, asc_s = passing[::-1], sieves[::-1]
    if not asc_p[0] <= 80.0 <= asc_p[-1]:
        return float("nan")
    return float(np.exp(np.interp(80.0, asc_p, np.log(asc_s))))


def _write_csv(path, header, rows):
    """A CSV file written whole or not at all (write_atomic)."""
    text = io.StringIO(newline="")
    w = csv.writer(text)
    w.writerow(header)
    w.writerows(rows)
    write_atomic(path, text.getvalue())


def _write(out, args, material, spectra_path, spectra, classes, result, s0, holdup):
    minutes = result.times_s / 60.0
    passing = result.passing_percent
    sieves = classes.sieves
    _write_csv(out / "psd.csv", ["minutes", "size_mm", "passing_percent"],
               [[t, 1e3 * s, p] for t, row in zip(minutes, passing) for s, p in zip(sieves, row)])
    _write_csv(out / "breakage_rate.csv", ["minutes", "class_upper_mm", "class_lower_mm",
                                           "mass_kg", "breakage_rate_per_min"],
               [[t, 1e3 * sieves[k], 1e3 * sieves[k + 1], mass[k], 60.0 * rate[k]]
                for t, mass, rate in zip(minutes, result.masses, result.rates)
                for k in range(classes.count)])
    _write_csv(out / "energy.csv", ["minutes", "collision_energy_kWh_per_t",
                                    "absorbed_energy_kWh_per_t"],
               zip(minutes, result.collision_energy_J_per_kg / 3600.0,
                   result.absorbed_energy_J_per_kg / 3600.0))
    summary = {
        "material": material.name, "spectra": str(spectra_path), "spectra_source": spectra.source,
        "feed": args.feed, "minutes": args.minutes, "mode": "continuous" if args.residence > 0
        else "batch", "residence_minutes": args.residence or None, "holdup_kg": holdup,
        "damage": bool(args.damage), "classes": classes.count, "cells": args.cells,
        "sieves_mm": [1e3 * s for s in sieves],
        "initial_breakage_rate_per_min": [60.0 * v for v in s0],
        "final_passing_percent": passing[-1].tolist(),
        "p80_mm": 1e3 * _p80(sieves, passing[-1]),
        "feed_class_remaining_fraction": float(result.masses[-1, 0] / result.masses[0, 0])
        if result.masses[0, 0] > 0 else None,
        "specific_energy_kWh_per_t": float(result.collision_energy_J_per_kg[-1] / 3600.0),
        "absorbed_energy_kWh_per_t": float(result.absorbed_energy_J_per_kg[-1] / 3600.0),
        "initial_mass": result.initial_mass, "fed_mass": result.fed_mass,
        "discharged_mass": result.discharged_mass,
        "mass_relative_error": result.mass_relative_error, "steps": result.steps,
        "runtime_s": result.runtime_s}
    write_atomic(out / "summary.json", json.dumps(summary, indent=2))
    _plot(out, material, classes, result, s0)
    return summary


def _plot(out, material, classes, result, s0):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    minutes = result.times_s / 60.0
    sieves_mm = 1e3 * classes.sieves
    shown = np.unique(np.linspace(0, len(minutes) - 1, min(len(minutes), 7)).astype(int))
    for k in shown:
        axes[0].semilogx(sieves_mm, result.passing_percent[k], "o-", ms=3,
                         label=f"{minutes[k]:.3g} min")
    axes[0].set(xlabel="size (mm)", ylabel="cumulative passing (%)",
                title=f"{material.name}: product size distribution")
    axes[0].legend(fontsize=8)
    top = result.masses[:, 0] / result.masses[0, 0] if result.masses[0, 0] > 0 else None
    if top is not None:
        axes[1].semilogy(minutes, top, "o-", ms=3, label="model")
        axes[1].semilogy(minutes, np.exp(-s0[0] * result.times_s), "k--",
                         label="first order at the initial rate")
        axes[1].set_ylim(max(1e-4, top.min() / 2), 1.05)
        axes[1].legend(fontsize=8)
    axes[1].set(xlabel="minutes", ylabel="fraction left in the top class",
                title="disappearance of the top class")
    for k in range(min(classes.count, 8)):
        axes[2].semilogy(minutes[1:], 60.0 * result.rates[1:, k], ".-",
                         label=f"{class_label(classes.sieves[k])}-"
                               f"{class_label(classes.sieves[k + 1])} mm")
    axes[2].set(xlabel="minutes", ylabel="breakage rate (1/min)", title="breakage rate per class")
    axes[2].legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, out / "grind.png", dpi=110)
    plt.close(fig)


__all__ = ["grind", "load_spectra", "parse_feed", "SPECTRA_NAME", "FeedError", "GrindingError",
           "SpectraError"]
