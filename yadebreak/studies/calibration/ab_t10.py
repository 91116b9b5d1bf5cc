"""Ab-T10 (docs/model.md Section 9) from single-particle fracture energies: the selection function
coefficient S and the minimum energy e_min,ref (Eqs. 9.1-9.3), by maximum likelihood.

A particle of size L loaded once from 0 up to the measured device energy E absorbs a = e E
(e = 1/(1 + kp/ks)) and keeps e_cum = a - e_min(L) (Eq. 9.2); it breaks when P(e_cum) (Eq. 9.3)
reaches its strength, uniform in (0, 1). So a - 2 e_min(L) is exponential with rate S L/L_ref:
ln p(E) = ln(S L/L_ref) + ln(1 - P) + ln e for broken rows, ln(1 - P) for censored ones.
e_min,ref is a threshold: the likelihood grows with it up to the largest value the data allow
(every broken particle above 2 e_min), which is its estimate. It has no standard error; its
interval is the profile-likelihood one with the chi-square(2) cutoff 5.99, the law of the
likelihood ratio of a threshold (2 Exp(1)); that of S uses chi-square(1). L_ref is a convention:
the base material's, else the median size of the data. Model layer: no YADE.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import optimize, stats

from yadebreak import model
from yadebreak.studies.calibration.mle import CHI2_95, Coord, Estimate, FitError, MLResult, require

CHI2_95_2DOF = float(stats.chi2.ppf(0.95, 2))
COORDS = [Coord("e_min_ref", "J/kg", "identity", 0.0, math.inf),
          Coord("selection", "kg/J", "log", math.log(1e-9), math.log(1e3))]


def log_likelihood(e_min_ref, selection, size_mm, energy, broken, device, size_ref_mm):
    size = size_mm * 1e-3
    e_min = model.ab_t10_min_energy(size, e_min_ref, size_ref_mm * 1e-3)
    e_cum = model.ab_t10_single_impact_cum(device.share * energy, e_min)
    p = model.ab_t10_probability(e_cum, size, e_min, selection, size_ref_mm * 1e-3)
    survive = np.log1p(-np.minimum(p, 1.0 - 1e-16))
    rate = selection * size_mm / size_ref_mm
    # a broken row below 2 e_min has no density (the threshold is above it)
    below = broken & (device.share * energy < 2.0 * e_min)
    if below.any():
        return -math.inf
    return float(np.sum(survive) + np.sum(np.log(rate[broken]))
                 + broken.sum() * math.log(device.share))


def fit_ab_t10(table, device, size_ref_mm, intervals=True):
    """Fit e_min,ref and S to a fracture Table; returns an MLResult (estimates by name)."""
    size_mm, energy = table.columns["size"], table.columns["energy"]
    broken = table.columns.get("broken", np.ones(len(table))) == 1
    require(["e_min_ref", "selection"], int(broken.sum()), "particles that broke", table.path, 3)
    # the largest e_min,ref with every broken particle at or above 2 e_min(L)
    # (less a relative 1e-12, so that round-off keeps that particle on the allowed side)
    e_hat = float(np.min(device.share * energy[broken] * size_mm[broken])
                  / (2.0 * size_ref_mm)) * (1.0 - 1e-12)

    def best_s(e):
        res = optimize.minimize_scalar(
            lambda ls: -log_likelihood(e, math.exp(ls), size_mm, energy, broken, device,
                                       size_ref_mm), bounds=(math.log(1e-9), math.log(1e3)),
            method="bounded", options={"xatol": 1e-10})
        return res.x, -res.fun

    ls_hat, ll_hat = best_s(e_hat)
    if not np.isfinite(ll_hat):
        raise FitError("parameters e_min_ref, selection: the fit did not converge")

    def ll_s(ls):
        return log_likelihood(e_hat, math.exp(ls), size_mm, energy, broken, device, size_ref_mm)

    h = 1e-4
    curv = -(ll_s(ls_hat + h) - 2 * ll_hat + ll_s(ls_hat - h)) / h ** 2
    sd_ls = 1.0 / math.sqrt(curv) if curv > 0 else math.nan
    s_hat = math.exp(ls_hat)
    est = {}
    if intervals:
        drop = 0.5 * CHI2_95

        def side(sign):
            g = lambda ls: ll_hat - ll_s(ls) - drop
            step = 2.0 * sd_ls
            while g(ls_hat + sign * step) < 0:
                step *= 2.0
            return optimize.brentq(g, ls_hat, ls_hat + sign * step, xtol=1e-8)
        s_lo, s_hi = math.exp(side(-1)), math.exp(side(+1))
        drop2 = 0.5 * CHI2_95_2DOF
        g0 = ll_hat - best_s(0.0)[1] - drop2
        e_lo = 0.0 if g0 <= 0 else optimize.brentq(lambda e: ll_hat - best_s(e)[1] - drop2,
                                                   0.0, e_hat, xtol=1e-6 * max(e_hat, 1e-9))
    else:
        s_lo = s_hi = s_hat
        e_lo = e_hat
    est["e_min_ref"] = Estimate("e_min_ref", e_hat, "J/kg", None, e_lo, e_hat,
                                method="profile likelihood (chi-square 2: a threshold)",
                                note="a threshold: the largest value the data allow; no "
                                     "standard error")
    est["selection"] = Estimate("selection", s_hat, "kg/J", s_hat * sd_ls, s_lo, s_hi)
    corr = np.array([[1.0, np.nan], [np.nan, 1.0]])
    return MLResult(COORDS, np.array([e_hat, ls_hat]), -ll_hat, est, corr, CHI2_95,
                    extra={"size_ref_mm": size_ref_mm})
