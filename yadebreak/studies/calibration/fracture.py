"""Fracture energies of single particles (Eqs. 1-3) by maximum likelihood over all size classes.

Data: one particle a row, its specific fracture energy as the impact load cell measures it (the
scale of Eq. 3's Einf), or, with broken = 0, the highest energy it survived (right-censored).
The measured energy is turned into the particle's own as the library does (Eq. 3's 1/(1 + kp/ks),
kp the particle's Hertzian stiffness, ks the device's): E = e E_measured, e = 1/(1 + kp/ks), and
E follows Eqs. 1-2 with the median E50(d) of Eq. 3. The likelihood is
sum over broken rows of ln p(E) + ln e, plus sum over censored rows of ln(1 - P(E)).
(As E and E50 both carry e, Einf, d0, phi, sigma and Emax/E50 do not depend on kp and ks.)
Model layer: no YADE.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from yadebreak import model
from yadebreak.model.intervals import PARTICLE_SIZE
from yadebreak.studies.calibration.mle import Coord, FitError, fit, require

#: the fitted coordinates: ln Einf, ln d0 (mm), phi, ln sigma, ln(E50/Emax) (Emax/E50 up to 1e4)
COORDS = {
    "e_inf": Coord("e_inf", "J/kg", "log", math.log(1e-3), math.log(1e6)),
    # d0 within the range a material file accepts
    "d0": Coord("d0", "mm", "log", math.log(PARTICLE_SIZE.lo * 1e3),
                math.log(PARTICLE_SIZE.hi * 1e3)),
    "phi": Coord("phi", "-", "identity", 0.0, 10.0),
    "sigma": Coord("sigma", "-", "log", math.log(0.02), math.log(10.0)),
    "emax_ratio": Coord("emax_ratio", "-", "neglog", math.log(1e-4), math.log(0.9)),
}
MIN_CLASSES = 3


@dataclass(frozen=True)
class Device:
    """The stiffness correction of Eq. 3: kp (particle) and ks (device), Pa. kp = 0 leaves the
    energies as measured (the fitted parameters are the same either way)."""
    k_particle: float = 0.0
    k_device: float = model.DEVICE_STIFFNESS_STEEL

    @property
    def share(self):
        """e = 1 / (1 + kp/ks) (Eq. 4 against the device)."""
        return float(model.energy_partition(self.k_particle, self.k_device))


def class_medians(params, sizes_mm, device):
    """Eq. 3: the particle's own E50 (J/kg) at each size (mm)."""
    return model.median_fracture_energy(np.asarray(sizes_mm) * 1e-3, params["e_inf"],
                                        params["d0"] * 1e-3, params["phi"], device.k_particle,
                                        device.k_device)


def measured_cdf(energy, size_mm, params, device):
    """Probability that a particle of size_mm (mm) breaks below `energy` as measured (J/kg)."""
    return model.fracture_energy_cdf(device.share * np.asarray(energy, float),
                                     class_medians(params, size_mm, device), params["sigma"],
                                     params["emax_ratio"])


def log_likelihood(params, size_mm, energy, broken, device):
    """Eqs. 1-3 over every row (censored rows: ln(1 - P)). size_mm as (unique sizes, index of
    each row's size) or one size per row."""
    sizes, index = size_mm if isinstance(size_mm, tuple) else np.unique(size_mm,
                                                                           return_inverse=True)
    share = device.share
    e50 = class_medians(params, sizes, device)[index]
    absorbed = share * energy
    sigma, ratio = params["sigma"], params["emax_ratio"]
    ll = np.sum(model.fracture_energy_logpdf(absorbed[broken], e50[broken], sigma, ratio))
    ll += np.count_nonzero(broken) * math.log(share)
    if not broken.all():
        p = model.fracture_energy_cdf(absorbed[~broken], e50[~broken], sigma, ratio)
        ll += np.sum(np.log1p(-np.minimum(p, 1.0 - 1e-16)))
    return float(ll)


@dataclass
class FractureFit:
    """The fit: its MLResult, the values used (fitted and fixed), the classes and their tests."""
    result: object
    params: dict
    fixed: dict
    classes: list
    device: Device
    rows: int


def _starts(size_mm, energy, broken, fixed):
    """Starting values: per-class medians of ln E (broken rows), Eq. 3 through them: for each phi
    of a grid, the d0 that fits them best (the likelihood can have several optima when d0 lies
    near or below the finest class, where Einf, d0 and phi trade off)."""
    sizes = np.unique(size_mm)
    med = np.array([np.median(np.log(energy[(size_mm == s) & broken])) for s in sizes])
    spread = [np.std(np.log(energy[(size_mm == s) & broken])) for s in sizes]
    sigma = float(np.clip(np.nanmean([v for v in spread if v > 0] or [0.8]), 0.1, 3.0))
    out = []
    for phi in (0.5, 1.0, 2.0, 4.0) if "phi" not in fixed else (fixed["phi"],):
        best = None
        for d0 in np.geomspace(0.01, 100, 17) if "d0" not in fixed else (fixed["d0"],):
            shape = np.log1p((d0 / sizes) ** phi)
            ln_einf = float(np.mean(med - shape))
            err = float(np.sum((med - shape - ln_einf) ** 2))
            if best is None or err < best[0]:
                best = (err, math.exp(ln_einf), d0)
        out.append({"e_inf": best[1], "d0": best[2], "phi": phi, "sigma": sigma,
                    "emax_ratio": fixed.get("emax_ratio", 20.0)})
    return out


def fit_fracture(table, device=Device(), fixed=None, intervals=True):
    """Fit Eqs. 1-3 to a fracture Table. `fixed`: {name: value} held (e.g. emax_ratio, or d0 and phi
    with fewer than 3 size classes, from a base material). Returns a FractureFit."""
    fixed = dict(fixed or {})
    size_mm = table.columns["size"]
    energy = table.columns["energy"]
    broken = table.columns.get("broken", np.ones(len(table))) == 1
    sizes = np.unique(size_mm)
    if len(sizes) < MIN_CLASSES and not {"d0", "phi"} <= set(fixed):
        raise FitError(f"parameters d0, phi (Eq. 3): {len(sizes)} size class(es) in {table.path}, "
                       f"at least {MIN_CLASSES} are needed to fit them (or give --base to take "
                       "them from a material)")
    names = [n for n in COORDS if n not in fixed]
    require(names, int(broken.sum()), "particles that broke", table.path, len(names) + 1)
    coords = [COORDS[n] for n in names]
    starts = [{**s, **fixed} for s in _starts(size_mm, energy, broken, fixed)]

    def params_of(x):
        return {**fixed, **{c.name: c.value(v) for c, v in zip(coords, x)}}

    classes = np.unique(size_mm, return_inverse=True)

    def nll(x):
        ll = log_likelihood(params_of(x), classes, energy, broken, device)
        return -ll if np.isfinite(ll) else 1e300

    def internal(s):
        return np.array([c.internal(s[c.name]) for c in coords])

    def restarts(j, xj):
        """The starts with parameter j held (the profile may cross into another optimum)."""
        held = {**fixed, coords[j].name: coords[j].value(xj)}
        return [internal({**s, **held}) for s in _starts(size_mm, energy, broken, held)]

    result = fit(nll, [internal(s) for s in starts], coords, intervals=intervals,
                 restarts=restarts)
    params = params_of(result.x)
    return FractureFit(result, params, fixed, class_tests(params, size_mm, energy, broken,
                                                          device) if intervals else [],
                       device, len(table))


def class_tests(params, size_mm, energy, broken, device):
    """Per size class: counts, the fitted median as measured, and a Kolmogorov-Smirnov test of the
    broken rows against the fitted distribution (conditional on breaking below the lowest censoring
    energy of the class, when some rows are censored). p-values are approximate: the parameters
    were fitted to the same data (they err on the side of accepting)."""
    out = []
    for s in np.unique(size_mm):
        rows = size_mm == s
        e_b = energy[rows & broken]
        censored = energy[rows & ~broken]
        cap = censored.min() if censored.size else math.inf
        p_cap = float(measured_cdf(cap, s, params, device)) if censored.size else 1.0
        e_test = e_b[e_b < cap]
        ks = stats.kstest(e_test, lambda e: np.asarray(measured_cdf(e, s, params, device))
                          / p_cap) if e_test.size >= 3 else None
        e50 = float(class_medians(params, s, device))
        median_measured = float(model.fracture_energy_ppf(0.5, e50, params["sigma"],
                                                          params["emax_ratio"])) / device.share
        out.append({"size_mm": float(s), "particles": int(rows.sum()),
                    "broken": int((rows & broken).sum()), "censored": int(censored.size),
                    "median_measured_J_per_kg": median_measured,
                    "e50_J_per_kg": e50 / device.share,
                    "ks_statistic": None if ks is None else float(ks.statistic),
                    "ks_p_value": None if ks is None else float(ks.pvalue)})
    return out
