"""Maximum likelihood with standard errors and profile-likelihood intervals (scipy.optimize).

A fit works on internal coordinates x (ln of a positive parameter, or the parameter itself) with
box bounds, minimising an objective f(x) (a negative log-likelihood). Standard errors come from the
observed information (the numerical Hessian of f at the optimum, delta method to the parameter);
95 % intervals from the profile likelihood: the values of one parameter where
2 (min over the others of f - f_min) = q, q the chi-square(1) 95 % point 3.84 (or, for least
squares, the square of Student's t with the residual degrees of freedom). Model layer: no YADE.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, stats

CHI2_95 = float(stats.chi2.ppf(0.95, 1))
#: objectives return this (or more) where the parameters cannot hold the data
INFEASIBLE = 1e299


def require(names, count, what, path, needed):
    """Refuse a relation the data cannot determine: `count` `what` (particles that broke, energy
    levels, ...) in `path` for the parameters `names`, fewer than `needed`."""
    if count < needed:
        raise FitError(f"parameters {', '.join(names)}: {count} {what} in {path}, at least "
                       f"{needed} are needed to determine them")


class FitError(ValueError):
    """A fit that cannot be made or did not converge: the message names the parameter and why."""


@dataclass(frozen=True)
class Coord:
    """One fitted parameter: its material-file name, unit, and internal coordinate x within
    [lo, hi]. transform "log": x = ln(value); "identity": x = value; "neglog": x = -ln(value),
    a value near 1/x... for Emax/E50, where x = ln(E50/Emax) keeps the optimiser on a smooth
    scale as the truncation vanishes (its lower bound is "no truncation worth the name")."""
    name: str
    unit: str
    transform: str
    lo: float
    hi: float
    #: the Hessian's finite-difference step (relative to max(1, |x|))
    step: float = 1e-4

    def value(self, x):
        if self.transform == "log":
            return math.exp(x)
        if self.transform == "neglog":
            return math.exp(-x)
        return float(x)

    def internal(self, v):
        if self.transform == "log":
            return math.log(v)
        if self.transform == "neglog":
            return -math.log(v)
        return float(v)

    def slope(self, x):
        """d value / d x at x (delta method)."""
        if self.transform == "log":
            return math.exp(x)
        if self.transform == "neglog":
            return -math.exp(-x)
        return 1.0


@dataclass
class Estimate:
    """One parameter's estimate, standard error (observed information) and 95 % interval."""
    name: str
    value: float
    unit: str
    se: float | None
    lo: float
    hi: float
    method: str = "profile likelihood"
    note: str = ""

    def as_json(self):
        def num(v):
            return None if v is None or not math.isfinite(v) else float(v)
        return {"estimate": num(self.value), "standard_error": num(self.se),
                "ci95": [num(self.lo), num(self.hi)],
                "unit": self.unit, "interval_method": self.method,
                **({"note": self.note} if self.note else {})}


@dataclass
class MLResult:
    """A fit's estimates, correlation matrix and the objective at the optimum."""
    coords: list
    x: np.ndarray
    objective: float
    estimates: dict
    correlation: np.ndarray
    cutoff: float
    extra: dict = field(default_factory=dict)

    def values(self):
        return {c.name: c.value(xi) for c, xi in zip(self.coords, self.x)}


def minimise(f, x0, coords):
    """L-BFGS-B from x0 within the coordinates' bounds, then Nelder-Mead polish if it stalled.
    Returns (x, f(x)); FitError when the objective is not finite at the start."""
    bounds = [(c.lo, c.hi) for c in coords]
    x0 = np.clip(np.asarray(x0, float), [b[0] for b in bounds], [b[1] for b in bounds])
    if not np.isfinite(f(x0)):
        raise FitError("the starting values give no finite likelihood: "
                       + ", ".join(f"{c.name} = {c.value(v):.4g}" for c, v in zip(coords, x0)))
    if len(coords) == 1:                # one coordinate: Brent's bounded search, no gradient
        lo, hi = bounds[0]
        width = min(hi - lo, 2.0)       # around the start: the optimum is near it (a scan found it)
        a, b = max(lo, x0[0] - width / 2), min(hi, x0[0] + width / 2)
        res = optimize.minimize_scalar(lambda v: f(np.array([v])), bounds=(a, b),
                                       method="bounded", options={"xatol": 1e-5})
        if lo < a and res.x - a < 1e-5 or b < hi and b - res.x < 1e-5:    # at the window's edge
            res = optimize.minimize_scalar(lambda v: f(np.array([v])), bounds=(lo, hi),
                                           method="bounded", options={"xatol": 1e-5})
        return np.array([res.x]), float(res.fun)
    res = optimize.minimize(f, x0, method="L-BFGS-B", bounds=bounds,
                            options={"maxiter": 500, "ftol": 1e-11, "gtol": 1e-6})
    if not res.success:
        res2 = optimize.minimize(f, res.x, method="Nelder-Mead", bounds=bounds,
                                 options={"maxiter": 4000, "xatol": 1e-8, "fatol": 1e-10})
        if res2.fun <= res.fun:
            res = res2
    return np.asarray(res.x, float), float(res.fun)


def hessian(f, x, steps):
    """Central-difference Hessian of f at x with the given steps per coordinate."""
    k = len(x)
    h = np.zeros((k, k))
    f0 = f(x)
    for i in range(k):
        ei = np.zeros(k)
        ei[i] = steps[i]
        h[i, i] = (f(x + ei) - 2 * f0 + f(x - ei)) / steps[i] ** 2
        for j in range(i):
            ej = np.zeros(k)
            ej[j] = steps[j]
            h[i, j] = h[j, i] = (f(x + ei + ej) - f(x + ei - ej) - f(x - ei + ej)
                                 + f(x - ei - ej)) / (4 * steps[i] * steps[j])
    return h


def _free(coords, x):
    """Coordinates not at a bound (at a bound the Hessian says nothing)."""
    span = np.array([c.hi - c.lo for c in coords])
    tol = 1e-6 * np.where(np.isfinite(span), span, 1.0)
    return np.array([(xi - c.lo > tol[i]) and (c.hi - xi > tol[i])
                     for i, (c, xi) in enumerate(zip(coords, x))])


def covariance(f, x, coords):
    """Inverse of the observed information over the free coordinates (NaN rows for those at a
    bound; all NaN when the Hessian is not positive definite)."""
    free = _free(coords, x)
    k = len(x)
    cov = np.full((k, k), np.nan)
    if not free.any():
        return cov
    idx = np.flatnonzero(free)
    steps = np.array([coords[i].step for i in idx]) * np.maximum(1.0, np.abs(x[idx]))
    h = hessian(lambda y: f(_put(x, idx, y)), x[idx], steps)
    try:
        chol = np.linalg.cholesky(h)
    except np.linalg.LinAlgError:
        # a flat or ridged optimum: no standard errors; the profile intervals still tell (they
        # run to the bounds where the data do not determine a parameter)
        return cov
    inv = np.linalg.inv(chol)
    cov[np.ix_(idx, idx)] = inv.T @ inv
    return cov


def _put(x, idx, y):
    z = np.array(x, float)
    z[idx] = y
    return z


def profile_interval(f, x_hat, f_hat, j, coords, cov, cutoff, restarts=None):
    """The 95 % profile-likelihood interval of coordinate j, as internal (lo, hi).

    Follows the signed root r(t) = sqrt(2 (f_p(x_j + t) - f_hat)), nearly linear in t, to
    r = sqrt(cutoff): steps along that line from the Wald step until r passes it, then Brent's
    method inside the bracket. At each step the nuisance coordinates are re-optimised from the
    quadratic prediction, the optimum and the last step's optimum (and, near the cutoff, from
    `restarts`). A side that reaches its bound first returns the bound."""
    target = math.sqrt(cutoff)
    k = len(x_hat)
    others = [i for i in range(k) if i != j]
    c = coords[j]
    sd = math.sqrt(cov[j, j]) if np.isfinite(cov[j, j]) and cov[j, j] > 0 else 0.1 * max(
        1.0, abs(x_hat[j]))
    out = []
    for sign in (-1.0, 1.0):
        bound = c.lo if sign < 0 else c.hi
        room = abs(bound - x_hat[j])
        if room < 1e-9:
            out.append(x_hat[j])
            continue
        # the quadratic prediction of the nuisance coordinates (0 for those at a bound)
        slope = (np.nan_to_num(cov[others, j] / cov[j, j]) if np.isfinite(cov[j, j])
                 and cov[j, j] > 0 else np.zeros(len(others)))
        nuis = None

        seen = {0.0: 0.0}

        def r_at(t):
            nonlocal nuis
            if t in seen:               # Brent re-asks the bracket's ends: keep their values
                return seen[t]
            step = sign * t
            # start from the quadratic prediction, and from the last step's optimum moved along
            guesses = [x_hat[others] + slope * step, x_hat[others]]
            if nuis is not None:
                guesses.append(nuis[1] + slope * (step - nuis[0]))
            best = None
            for guess in guesses:
                y, fy = _profile_min(f, x_hat, j, x_hat[j] + step, others, guess, coords)
                if best is None or fy < best[1]:
                    best = (y, fy)
            # near the cutoff, where the interval's end is decided, the nuisance parameters may
            # sit in a local optimum: the fit's own starting values, x_j held, are tried too
            if restarts is not None and 2.0 * (best[1] - f_hat) > 0.5 * cutoff:
                for guess in restarts(j, x_hat[j] + step):
                    y, fy = _profile_min(f, x_hat, j, x_hat[j] + step, others,
                                         np.asarray(guess, float)[others], coords)
                    if fy < best[1]:
                        best = (y, fy)
            nuis = (step, best[0])
            seen[t] = math.sqrt(max(2.0 * (best[1] - f_hat), 0.0))
            return seen[t]

        # bracket [t_in, t_out] with r(t_in) < target <= r(t_out), stepping along the line from
        # 0 through the last point (r is nearly linear in t), then Brent's method inside it
        t_in, t_out = 0.0, None
        t = min(target * sd, room)
        found = None
        for _ in range(40):
            r = r_at(t)
            if abs(r - target) < 0.02 * target:
                found = t
                break
            if r >= target:
                t_out = t
                break
            if t >= room:
                found = room            # still inside at the bound: the interval reaches it
                break
            t_in = t
            t = min(max(t * target / r if r > 0.05 * target else 4.0 * t, 1.5 * t), 4.0 * t, room)
        if found is None and t_out is not None:
            found = optimize.brentq(lambda s: r_at(s) - target, t_in, t_out,
                                    xtol=max(0.01 * sd, 1e-9), rtol=1e-4, maxiter=60)
        if found is None:
            raise FitError(f"parameter {c.name}: its profile-likelihood interval did not converge")
        out.append(bound if found >= room else x_hat[j] + sign * found)
    return out[0], out[1]


def _profile_min(f, x_hat, j, xj, others, guess, coords):
    def g(y):
        z = np.array(x_hat, float)
        z[j] = xj
        z[others] = y
        return f(z)
    if not others:
        return np.array([]), g(np.array([]))
    sub = [coords[i] for i in others]
    # an infeasible guess (1e300: data beyond a truncation) falls back on the optimum's values
    usable = g(np.clip(guess, [c.lo for c in sub], [c.hi for c in sub])) < INFEASIBLE
    return minimise(g, guess if usable else x_hat[others], sub)


def fit(f, x0, coords, cutoff=CHI2_95, intervals=True, restarts=None):
    """Minimise f from x0 (one start, or a list of starts: the best optimum is kept); standard
    errors, correlations and (unless intervals=False) profile intervals of every coordinate.
    restarts(j, xj): starting points (internal, all coordinates) with coordinate j held at xj,
    tried at every step of its profile where the likelihood may have several optima.
    Returns an MLResult with Estimate per parameter name."""
    starts = [x0] if np.ndim(x0) == 1 else list(x0)
    x, fx = min((minimise(f, s, coords) for s in starts), key=lambda r: r[1])
    if not np.isfinite(fx):
        raise FitError(f"parameters {', '.join(c.name for c in coords)}: the fit did not "
                       "converge (no finite likelihood)")
    # point estimates only (bootstrap replicates): no Hessian either
    cov = covariance(f, x, coords) if intervals else np.full((len(x), len(x)), np.nan)
    estimates = {}
    sd = np.sqrt(np.where(np.diag(cov) > 0, np.diag(cov), np.nan))
    corr = cov / np.outer(sd, sd)
    for j, c in enumerate(coords):
        se = abs(c.slope(x[j])) * sd[j] if np.isfinite(sd[j]) else None
        if intervals:
            lo, hi = profile_interval(f, x, fx, j, coords, cov, cutoff, restarts)
        else:
            lo = hi = x[j]
        v_lo, v_hi = sorted((c.value(lo), c.value(hi)))
        note = "" if np.isfinite(sd[j]) else ("at a bound of its range: no standard error"
                                              if not _free(coords, x)[j] else "no standard "
                                              "error: the information matrix is singular")
        estimates[c.name] = Estimate(c.name, c.value(x[j]), c.unit, se, v_lo, v_hi, note=note)
    # correlations between the parameters: the internal ones, signs turned for decreasing maps
    signs = np.array([np.sign(c.slope(xi)) if np.isfinite(c.slope(xi)) else 1.0
                      for c, xi in zip(coords, x)])
    corr = corr * np.outer(signs, signs)
    return MLResult(coords, x, fx, estimates, corr, cutoff)


def least_squares(residuals, x0, coords, intervals=True):
    """Least squares as a likelihood with the scatter's variance profiled out: minimise the
    residual sum of squares S(x), then take f = (m - p)/2 S(x)/S_min, whose curvature gives the
    usual s^2 (J^T J)^-1 and whose profile intervals, with the cutoff t^2 (m - p degrees of
    freedom), are the exact ones of a linear model (m residuals, p parameters)."""
    def rss(x):
        r = residuals(x)
        v = float(np.dot(r, r))
        return v if np.isfinite(v) else 1e300
    m, p = len(residuals(np.asarray(x0, float))), len(coords)
    if m <= p:
        raise FitError(f"parameters {', '.join(c.name for c in coords)}: {m} data points for "
                       f"{p} parameters: at least {p + 1} are needed")
    x, s_min = minimise(rss, x0, coords)
    s_min = max(s_min, 1e-300)
    result = fit(lambda y: 0.5 * (m - p) * rss(y) / s_min, x, coords,
                 cutoff=float(stats.t.ppf(0.975, m - p)) ** 2, intervals=intervals)
    result.extra.update({"rss": s_min, "points": m, "residual_sd": math.sqrt(s_min / (m - p))})
    return result
