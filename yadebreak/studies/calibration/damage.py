"""Repeated impacts: the damage accumulation coefficient gamma (Eqs. 5-6) by the binomial
likelihood of the counts.

A series fires particles of one size at one energy again and again; row k gives the particles
tested at impact k and those broken by it. With the fracture-energy distribution (Eqs. 1-3, fitted
or from a base material) and gamma, model.repeated_impact_broken_fraction gives F_k, the fraction
broken after k impacts; a particle that survived k - 1 impacts breaks at impact k with
h_k = (F_k - F_(k-1)) / (1 - F_(k-1)), and broken_k ~ Binomial(tested_k, h_k).
The interval of gamma is conditional on the fracture parameters. Model layer: no YADE.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import stats

from yadebreak import model
from yadebreak.studies.calibration.mle import Coord, fit, require

#: the Hessian's step in ln gamma spans many quadrature points (F_k is interpolated between them)
COORDS = [Coord("gamma", "-", "log", math.log(0.2), math.log(200.0), step=0.02)]
#: quantiles of the fracture-energy distribution in the quadrature of F_k: its error
#: (interpolated between quadrature points: below 1e-6 in F at 500) is far below the binomial
#: scatter of 100 particles
QUANTILES = 500


def series(table):
    """[(size_mm, energy, tested array, broken array)] ordered by impact."""
    c = table.columns
    out = []
    for size, energy in sorted(set(zip(c["size"], c["energy"]))):
        rows = np.flatnonzero((c["size"] == size) & (c["energy"] == energy))
        rows = rows[np.argsort(c["impact"][rows])]
        out.append((float(size), float(energy), c["tested"][rows], c["broken"][rows]))
    return out


def hazards(size_mm, energy, impacts, fracture_params, gamma, device):
    """h_k, k = 1..impacts: the chance that a survivor of k - 1 impacts breaks at impact k."""
    e50 = model.median_fracture_energy(size_mm * 1e-3, fracture_params["e_inf"],
                                       fracture_params["d0"] * 1e-3, fracture_params["phi"],
                                       device.k_particle, device.k_device)
    f = model.repeated_impact_broken_fraction(device.share * energy, float(e50),
                                              fracture_params["sigma"],
                                              fracture_params["emax_ratio"], gamma, impacts,
                                              quantiles=QUANTILES)
    before = np.concatenate([[0.0], f[:-1]])
    with np.errstate(divide="ignore", invalid="ignore"):
        h = (f - before) / (1.0 - before)
    return np.clip(np.nan_to_num(h, nan=1.0), 1e-12, 1.0 - 1e-12), f


def fit_gamma(table, fracture_params, device, intervals=True, start=None):
    """Fit gamma to a repeated-impacts Table; returns the MLResult (extra: per series the counts,
    the fitted F_k and a deviance goodness-of-fit test). start: a gamma to search around (the
    full data's, for a bootstrap replicate) instead of a scan."""
    require(["gamma"], int(np.count_nonzero(table.columns["impact"] >= 2)),
            "rows of impacts after the first (damage shows only there)", table.path, 1)
    groups = series(table)

    def nll(x):
        g = math.exp(x[0])
        total = 0.0
        for size, energy, tested, broken in groups:
            h, _ = hazards(size, energy, len(tested), fracture_params, g, device)
            total -= float(np.sum(stats.binom.logpmf(broken, tested, h)))
        return total if np.isfinite(total) else 1e300

    # a coarse scan first: the likelihood of gamma can be flat far from its optimum
    if start is None:
        grid = np.log([1.0, 2.5, 5.0, 10.0, 30.0])
        x0 = grid[int(np.argmin([nll([v]) for v in grid]))]
    else:
        x0 = math.log(start)
    result = fit(nll, [x0], COORDS, intervals=intervals)
    gamma = result.estimates["gamma"].value
    if intervals:
        result.extra["series"] = [series_test(s, fracture_params, gamma, device) for s in groups]
    return result


def series_test(group, fracture_params, gamma, device):
    """One series' counts, the fitted broken fractions and a deviance (G) test of the binomial
    counts against the fitted hazards (degrees of freedom: impacts - 1 with one shared parameter;
    approximate with few particles)."""
    size, energy, tested, broken = group
    h, f = hazards(size, energy, len(tested), fracture_params, gamma, device)
    expected = tested * h
    with np.errstate(divide="ignore", invalid="ignore"):
        g = 2.0 * np.sum(np.where(broken > 0, broken * np.log(broken / expected), 0.0)
                         + np.where(tested - broken > 0, (tested - broken)
                                    * np.log((tested - broken) / (tested - expected)), 0.0))
    dof = max(len(tested) - 1, 1)
    observed = 1.0 - np.cumprod(1.0 - broken / tested)
    return {"size_mm": size, "energy_J_per_kg": energy, "tested": tested.tolist(),
            "broken": broken.tolist(), "broken_fraction_observed": observed.tolist(),
            "broken_fraction_fitted": f.tolist(), "deviance": float(g),
            "p_value": float(stats.chi2.sf(g, dof))}
