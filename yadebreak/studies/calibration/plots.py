"""The report's figures: each a function (Calibration, pyplot) -> Figure, or None without data.
Model layer: no YADE (matplotlib only, Agg)."""
from __future__ import annotations

import math

import numpy as np

from yadebreak import model


def _measured_cdf(cal, energy, size_mm):
    """Probability of breaking below device energy `energy` (J/kg) at size_mm, fitted model."""
    v, share = cal.values, cal.device.share
    size = size_mm * 1e-3
    if cal.model == "tavares":
        e50 = model.median_fracture_energy(size, v["e_inf"], v["d0"] * 1e-3, v["phi"],
                                           cal.device.k_particle, cal.device.k_device)
        return model.fracture_energy_cdf(share * energy, e50, v["sigma"], v["emax_ratio"])
    e_min = model.ab_t10_min_energy(size, v["e_min_ref"], v["size_ref"] * 1e-3)
    return model.ab_t10_probability(model.ab_t10_single_impact_cum(share * energy, e_min), size,
                                    e_min, v["selection"], v["size_ref"] * 1e-3)


def _fracture_rows(cal):
    """(size mm, measured energy, broken?) of the fracture data, or None."""
    table = cal.tables.get("fracture")
    if table is None:
        return None
    return (table.columns["size"], table.columns["energy"],
            table.columns.get("broken", np.ones(len(table))) == 1)


def fracture_cdfs(cal, plt):
    if _fracture_rows(cal) is None:
        return None
    size, energy, broken = _fracture_rows(cal)
    fig, ax = plt.subplots(figsize=(7, 5))
    for k, s in enumerate(np.unique(size)):
        rows = size == s
        e = np.sort(energy[rows & broken])
        color = f"C{k}"
        ax.step(e, np.arange(1, e.size + 1) / rows.sum(), where="post", color=color, lw=1,
                label=f"{s:g} mm data ({rows.sum()})")
        grid = np.geomspace(energy.min() / 2, energy.max() * 2, 300)
        ax.plot(grid, _measured_cdf(cal, grid, s), color=color, ls="--")
    ax.set(xscale="log", xlabel="specific fracture energy as measured (J/kg)",
           ylabel="cumulative fraction broken",
           title="fracture energies: data (steps), fit (dashed)")
    ax.legend(fontsize=7)
    return fig


def e50_vs_size(cal, plt):
    if _fracture_rows(cal) is None:
        return None
    size, energy, broken = _fracture_rows(cal)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    sizes = np.unique(size)
    med = [np.median(energy[size == s]) if np.mean(broken[size == s]) > 0.5 else np.nan
           for s in sizes]
    ax.plot(sizes, med, "ko", label="class median of the data")
    grid = np.geomspace(sizes.min() / 1.5, sizes.max() * 1.5, 200)
    fitted = [_median_measured(cal, g) for g in grid]
    ax.plot(grid, fitted, "C0-", label="fitted median")
    ax.set(xscale="log", yscale="log", xlabel="particle size (mm)",
           ylabel="median fracture energy as measured (J/kg)", title="E50 against size")
    ax.legend()
    return fig


def _median_measured(cal, size_mm):
    from scipy import optimize
    f = lambda le: float(_measured_cdf(cal, math.exp(le), size_mm)) - 0.5
    return math.exp(optimize.brentq(f, math.log(1e-6), math.log(1e9)))


def t10_vs_energy(cal, plt):
    table, fit = cal.tables.get("t10"), cal.fits.get("t10")
    if table is None or fit is None:
        return None
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    if cal.model == "tavares":
        x = fit.extra["absorbed"] / fit.extra["e50b"]
        ax.plot(x, table.columns["t10"], "ko", ms=4, label="data")
        grid = np.linspace(0, np.nanmax(x) * 1.1, 200)
        a, b = cal.values["A"], cal.values["b_prime"]
        ea, eb = cal.estimates.get("A"), cal.estimates.get("b_prime")
        curve = model.t10(grid, a, b)
        ax.plot(grid, curve, "C0-", label=f"Eq. 7: A = {a:.3g} %, b' = {b:.3g}")
        if ea is not None and eb is not None and ea.se and eb.se:
            r = fit.correlation[0, 1]
            ga = curve / a
            gb = a * grid * np.exp(-b * grid)
            sd = np.sqrt(ga ** 2 * ea.se ** 2 + gb ** 2 * eb.se ** 2
                         + 2 * r * ga * gb * ea.se * eb.se)
            ax.fill_between(grid, curve - 1.96 * sd, curve + 1.96 * sd, alpha=0.25,
                            label="95 % band of the curve (delta method)")
        ax.set(xlabel="absorbed specific energy / E50b", ylabel="t10 (%)")
    else:
        for k, s in enumerate(np.unique(table.columns["size"])):
            rows = table.columns["size"] == s
            e = table.columns["energy"][rows]
            ax.plot(e, table.columns["t10"][rows], "o", color=f"C{k}", label=f"{s:g} mm")
            order = np.argsort(e)
            ax.plot(e[order], 0.5 * cal.values["t10_max"] * fit.extra["probability"][rows][order],
                    "-", color=f"C{k}")
        ax.set(xscale="log", xlabel="specific energy on the device (J/kg)", ylabel="t10 (%)")
    ax.set(title="t10 against energy")
    ax.legend(fontsize=8)
    return fig


def broken_vs_impacts(cal, plt):
    fit = cal.fits.get("repeated")
    if fit is None:
        return None
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for k, s in enumerate(fit.extra["series"]):
        n = np.arange(1, len(s["tested"]) + 1)
        ax.plot(n, 100 * np.array(s["broken_fraction_observed"]), "o", color=f"C{k}",
                label=f"{s['size_mm']:g} mm, {s['energy_J_per_kg']:.3g} J/kg")
        ax.plot(n, 100 * np.array(s["broken_fraction_fitted"]), "-", color=f"C{k}")
    ax.set(xlabel="impact number", ylabel="broken after this impact (%)",
           title=f"repeated impacts: data (dots), gamma = {cal.values['gamma']:.3g} (lines)")
    ax.legend(fontsize=8)
    return fig


def tn_vs_t10(cal, plt):
    table = cal.tables.get("progeny")
    if table is None or cal.beta is None:
        return None
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    grid = np.linspace(0.5, 70, 200)
    for k, n in enumerate(model.N_VALUES):
        rows = table.columns["n"] == n
        ax.plot(table.columns["t10"][rows], table.columns["passing"][rows], "o", color=f"C{k}",
                ms=4)
        ax.plot(grid, model.t_n(grid, *cal.beta[n]), "-", color=f"C{k}", label=f"t{n:g}")
    ax.set(xlabel="t10 (%)", ylabel="t_n (%)", title="progeny: data (dots), Eq. 10 (lines)")
    ax.legend(fontsize=8, ncol=2)
    return fig


FIGURES = [("fracture_cdfs", fracture_cdfs), ("e50_vs_size", e50_vs_size),
           ("t10_vs_energy", t10_vs_energy), ("broken_vs_impacts", broken_vs_impacts),
           ("tn_vs_t10", tn_vs_t10)]
