"""The Tavares UFRJ breakage model as plain, vectorised functions.

Equation numbers are those of docs/model.md (and of Tavares et al., the EDEM
sphere-replacement paper). SI units throughout: sizes in metres, stiffnesses and moduli in
pascals, specific energies in J/kg, masses in kg. t10 and the t_n markers are percentages, as the
paper prints them.

This module imports only numpy, scipy and the standard library: it never imports yade.
"""
from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

import math

import numpy as np
from scipy import special

__all__ = ['N_VALUES', 'TABLE1_BETA_PARAMS', 'DEVICE_STIFFNESS_STEEL', 'X_MIN', 'hertz_stiffness',
           'energy_partition', 'median_fracture_energy', 'fracture_energy_cdf',
           'fracture_energy_logpdf', 'fracture_energy_ppf', 'sample_fracture_energy',
           'breakage_probability', 'damage', 'weakened_fracture_energy', 'parabolic_peak', 't10',
           'median_fracture_energy_broken', 't10_batch', 't10_mean_broken', 'kappa_of_batch',
           't10_primary', 't_n', 't_markers',
           'fines_exponent', 'fines_passing', 'progeny_passing', 'SizeDistribution',
           'dummy_fines_passing', 'size_distribution', 'repeated_impact_broken_fraction',
           'ab_t10_min_energy', 'ab_t10_update', 'ab_t10_probability', 'ab_t10_threshold',
           'ab_t10_t10', 'ab_t10_single_impact_cum', 'ab_t10_repeated_broken_fraction']

#: The seven screen ratios n of Eq. 10 (passing 1/n of the parent size).
N_VALUES = (1.2, 1.5, 2.0, 4.0, 25.0, 50.0, 75.0)

#: Paper Table 1: incomplete-beta parameters (alpha, beta) averaged over 40 materials.
TABLE1_BETA_PARAMS = MappingProxyType({
    1.2: (0.448, 10.508),
    1.5: (0.706, 7.913),
    2.0: (0.959, 5.780),
    4.0: (1.105, 2.619),
    25.0: (0.981, 0.524),
    50.0: (0.956, 0.339),
    75.0: (0.934, 0.255),
})

#: Hertzian stiffness of the steel calibration device (Eq. 3), Pa.
DEVICE_STIFFNESS_STEEL = 230e9

#: Finest resolved relative size of a replacement event, 2**(-9/4) = 0.210 (Table 2).
X_MIN = 2.0 ** (-9.0 / 4.0)


# --------------------------------------------------------------------------- stiffness, Eq. 4
def hertz_stiffness(young, poisson):
    """Hertzian stiffness k = Y / (1 - nu^2) in Pa (docs/model.md Sections 1-2), Y in Pa."""
    young = np.asarray(young, dtype=float)
    poisson = np.asarray(poisson, dtype=float)
    return young / (1.0 - poisson ** 2)


def energy_partition(k_particle, k_other):
    """Eq. 4: share e = 1 / (1 + kp/km) of a contact's energy absorbed by the particle.

    Both stiffnesses in the same unit (Pa). Same material gives 0.5; copper ore on steel 0.806.
    """
    k_particle = np.asarray(k_particle, dtype=float)
    k_other = np.asarray(k_other, dtype=float)
    return 1.0 / (1.0 + k_particle / k_other)


# --------------------------------------------------------------------------- Eqs. 1-3
def median_fracture_energy(size, e_inf, d0, phi, k_particle, k_device=DEVICE_STIFFNESS_STEEL):
    """Eq. 3: median specific fracture energy E50(d) in J/kg.

    E50 = Einf [1 + (d0/d)^phi] / (1 + kp/ks); size and d0 in metres, stiffnesses in Pa.
    """
    size = np.asarray(size, dtype=float)
    return e_inf * (1.0 + (d0 / size) ** phi) / (1.0 + k_particle / k_device)


def fracture_energy_cdf(energy, e50, sigma, emax_ratio):
    """Eqs. 1-2: P(E), the upper-truncated lognormal cdf of specific fracture energy.

    energy and e50 in J/kg; sigma is the standard deviation of ln E*; emax_ratio = Emax/E50 > 1.
    Zero at E <= 0, one at E >= Emax.
    """
    energy, e50, sigma, emax_ratio = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (energy, e50, sigma, emax_ratio)))
    emax = e50 * emax_ratio
    inside = (energy > 0.0) & (energy < emax)
    e_in = np.where(inside, energy, 0.5 * emax)
    # ln E* = ln E - ln(1 - E/Emax); log1p keeps precision near the truncation.
    log_e_star = np.log(e_in) - np.log1p(-e_in / emax)
    p = special.ndtr((log_e_star - np.log(e50)) / sigma)
    p = np.where(inside, p, np.where(energy >= emax, 1.0, 0.0))
    return p[()] if p.ndim == 0 else p


def fracture_energy_logpdf(energy, e50, sigma, emax_ratio):
    """Eqs. 1-2 differentiated: ln p(E), the log density (ln of 1/(J/kg)) of specific fracture energy.

    p(E) = phi(z) / sigma * d ln E*/dE, z = (ln E* - ln E50) / sigma, d ln E*/dE = Emax / (E (Emax - E)).
    -inf outside 0 < E < Emax. The likelihood of a measured fracture energy (calibration).
    """
    # plain broadcasting (no broadcast_arrays): a likelihood calls this thousands of times
    energy = np.asarray(energy, dtype=float)
    emax = np.asarray(e50, dtype=float) * emax_ratio
    inside = (energy > 0.0) & (energy < emax)
    e_in = np.where(inside, energy, 0.5 * emax)
    log_e = np.log(e_in)
    log_e_star = log_e - np.log1p(-e_in / emax)
    z = (log_e_star - np.log(e50)) / sigma
    # ln(1/E + 1/(Emax - E)) = ln E* - 2 ln E
    out = np.where(inside, -0.5 * z * z - np.log(sigma * math.sqrt(2.0 * math.pi))
                   + log_e_star - 2.0 * log_e, -np.inf)
    return out[()] if out.ndim == 0 else out


def fracture_energy_ppf(u, e50, sigma, emax_ratio):
    """Inverse of Eqs. 1-2: the specific fracture energy (J/kg) at cumulative probability u.

    E* = E50 exp(sigma * Phi^-1(u)) (Phi^-1(u) = sqrt(2) erfinv(2u - 1)), E = E* Emax / (Emax + E*).
    u = 0 gives 0 and u = 1 gives Emax.
    """
    u, e50, sigma, emax_ratio = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (u, e50, sigma, emax_ratio)))
    emax = e50 * emax_ratio
    with np.errstate(over="ignore", divide="ignore"):
        # Emax/E* = (Emax/E50) exp(-sigma z); written this way E -> Emax as z -> +inf without inf/inf.
        ratio = emax_ratio * np.exp(-sigma * special.ndtri(u))
        e = emax / (1.0 + ratio)
    return e[()] if e.ndim == 0 else e


def sample_fracture_energy(rng, e50, sigma, emax_ratio, size=None):
    """Draw specific fracture energies (J/kg) from Eqs. 1-2 with a numpy Generator.

    Inversion sampling: u ~ U(0, 1] (1 - rng.random(), so that u = 0 never gives E = 0).
    """
    shape = size if size is not None else np.broadcast(
        np.asarray(e50), np.asarray(sigma), np.asarray(emax_ratio)).shape
    u = 1.0 - rng.random(shape)
    return fracture_energy_ppf(u, e50, sigma, emax_ratio)


def breakage_probability(specific_energy, e50, sigma, emax_ratio):
    """Probability that a fresh particle breaks under specific energy e Ek/mp (J/kg): P(E < e Ek/mp).

    The same function as Eqs. 1-2, named for what scripts plot against simulations.
    """
    return fracture_energy_cdf(specific_energy, e50, sigma, emax_ratio)


# --------------------------------------------------------------------------- Eqs. 5-6
def _damage_residual(log_d, log_r, gamma):
    """ln r(D) - ln r for D = exp(log_d): Eq. 6 solved for the ratio, increasing in D on (0, 1)."""
    d = np.exp(log_d)
    p = 5.0 / (2.0 * gamma)
    return p * log_d + np.log(2.0 * gamma + 5.0 - 5.0 * d) - np.log(2.0 * gamma) - log_r


def damage(ratio, gamma):
    """Eq. 6: the damage D in [0, 1) for ratio r = Ek'_max / (mp E) in [0, 1) and gamma > 0.

    D = [2 gamma / (2 gamma - 5 D + 5) * r]^(2 gamma / 5) is implicit. Solved for D as the inverse of
    the explicit, strictly increasing r(D) = D^(5/(2 gamma)) (2 gamma + 5 - 5 D) / (2 gamma): the
    root is unique on (0, 1) and lies in [g(0), g(1)] with g the right-hand side, a bracket no wider
    than one unit in ln D. Safeguarded Newton on ln D, vectorised; exact to round-off.
    r <= 0 gives 0. r >= 1 is a breakage, not damage: it returns 1.
    """
    if type(ratio) is float and type(gamma) is float:     # a closing event: np.ndim's
        return _damage_one(ratio, gamma)                  # dispatch would cost more
    if np.ndim(ratio) == 0 and np.ndim(gamma) == 0:
        return _damage_one(float(ratio), float(gamma))
    ratio, gamma = np.broadcast_arrays(np.asarray(ratio, dtype=float), np.asarray(gamma, dtype=float))
    out = np.zeros(ratio.shape)
    active = (ratio > 0.0) & (ratio < 1.0)
    out[ratio >= 1.0] = 1.0
    if np.any(active):
        r = ratio[active]
        g = gamma[active]
        log_r = np.log(r)
        q = 2.0 * g / 5.0
        lo = q * (log_r + np.log(2.0 * g / (2.0 * g + 5.0)))   # ln g(0)
        hi = q * log_r                                         # ln g(1)
        y = 0.5 * (lo + hi)
        for _ in range(100):
            f = _damage_residual(y, log_r, g)
            lo = np.where(f < 0.0, y, lo)
            hi = np.where(f >= 0.0, y, hi)
            d = np.exp(y)
            slope = 5.0 / (2.0 * g) - 5.0 * d / (2.0 * g + 5.0 - 5.0 * d)
            with np.errstate(divide="ignore", invalid="ignore"):
                y_new = y - f / slope
            # the bracket's ends are earlier iterates: a converged Newton step lands on one, so
            # only a step beyond them is outside (else bisection would walk away from the root)
            outside = ~np.isfinite(y_new) | (y_new < lo) | (y_new > hi)
            y_new = np.where(outside, 0.5 * (lo + hi), y_new)
            # converged: the step, or the residual, is at round-off (else a few ratios would
            # bounce between the bracket's ends for the full 100 iterations)
            done = ((np.abs(y_new - y) <= 1e-15 * np.maximum(1.0, np.abs(y)))
                    | (np.abs(f) <= 1e-14 * np.maximum(1.0, np.abs(log_r))))
            y = np.where(np.abs(f) <= 1e-14 * np.maximum(1.0, np.abs(log_r)), y, y_new)
            if np.all(done):
                break
        out[active] = np.minimum(np.exp(y), np.nextafter(1.0, 0.0))
    return out[()] if out.ndim == 0 else out


def _damage_one(ratio, gamma):
    """damage() for one ratio: the same safeguarded Newton on Python floats (a stressing event
    closes with one call; numpy's cost per call would be most of it)."""
    if not ratio > 0.0:
        return 0.0
    if ratio >= 1.0:
        return 1.0
    log_r = math.log(ratio)
    q = 2.0 * gamma / 5.0
    p = 5.0 / (2.0 * gamma)
    lo = q * (log_r + math.log(2.0 * gamma / (2.0 * gamma + 5.0)))
    hi = q * log_r
    converged = 4e-16 * max(1.0, abs(log_r))             # a residual at round-off

    def residual(y, d):                                  # d = exp(y)
        return p * y + math.log(2.0 * gamma + 5.0 - 5.0 * d) - math.log(2.0 * gamma) - log_r
    d = math.exp(lo)
    if abs(residual(lo, d)) <= converged:
        # D so small (below about 1e-14) that the root is ln g(0) to round-off: Newton's steps
        # land on that end of the bracket and bisection would take some fifty steps to get there
        # (light touches of tough particles at process scale: 25 us a closing event)
        return min(d, math.nextafter(1.0, 0.0))
    y = 0.5 * (lo + hi)
    for _ in range(100):
        d = math.exp(y)
        f = residual(y, d)
        if abs(f) <= converged:                        # a root to round-off: Newton would only
            break                                      # bounce off the bracket from here
        if f < 0.0:
            lo = y
        else:
            hi = y
        slope = 5.0 / (2.0 * gamma) - 5.0 * d / (2.0 * gamma + 5.0 - 5.0 * d)
        y_new = y - f / slope if slope != 0.0 else math.nan
        if not (math.isfinite(y_new) and lo < y_new < hi):
            y_new = 0.5 * (lo + hi)
        done = abs(y_new - y) <= 1e-15 * max(1.0, abs(y))
        y = y_new
        if done:
            break
    return min(math.exp(y), math.nextafter(1.0, 0.0))


def weakened_fracture_energy(energy, ratio, gamma):
    """Eq. 5: E' = E (1 - D), D from Eq. 6 at ratio r = Ek'_max / (mp E); energies in J/kg. On a
    float energy, a float (a stressing event closes with one call)."""
    if type(energy) is not float:
        energy = np.asarray(energy, dtype=float)
    return energy * (1.0 - damage(ratio, gamma))


def parabolic_peak(t0, x0, t1, x1, t2, x2):
    """Largest value of the parabola through (t0, x0), (t1, x1), (t2, x2), t0 < t1 < t2: the peak
    overlap between reads of a contact that grew, then shrank (Eq. 14's integral up to the peak).
    Falls back to x1 when the three points are not concave or the vertex lies outside [t0, t2].
    Plain floats: called once per contact and impact."""
    h0, h1 = t1 - t0, t2 - t1
    if h0 <= 0.0 or h1 <= 0.0:
        return x1
    s0, s1 = (x1 - x0) / h0, (x2 - x1) / h1
    curvature = (s1 - s0) / (h0 + h1)            # half the second derivative
    if curvature >= 0.0:
        return x1
    # x(t) = x1 + b (t - t1) + curvature (t - t1)^2, b the centred slope at t1
    b = s0 + curvature * h0
    t_peak = -b / (2.0 * curvature)
    if not -h0 <= t_peak <= h1:
        return x1
    return x1 + b * t_peak + curvature * t_peak * t_peak


# --------------------------------------------------------------------------- Eqs. 7-9
def t10(ratio, A, b_prime, kappa=1.0):
    """Eq. 8: t10' (%) of one particle broken at ratio = Ek' / (mp E) (E its own fracture energy).

    t10' = A [1 - exp(-b' ratio / kappa)]. With ratio = (Ek/mp) / E50b this is Eq. 7, and with
    ratio = 1, Eq. 9 (primary breakage). Bounded by A, increasing in ratio.
    """
    ratio = np.asarray(ratio, dtype=float)
    return A * -np.expm1(-b_prime * ratio / kappa)


def median_fracture_energy_broken(specific_energy, e50, sigma, emax_ratio):
    """Eq. 7's E50b (J/kg): the median fracture energy of the particles that break when each
    receives `specific_energy` (J/kg, absorbed): the P/2 quantile of Eqs. 1-2, P the broken
    fraction. NaN where nothing breaks. Check (paper, Fig. 1): at 534.1 J/kg 71 % break and
    E50b = 258.0 J/kg, the 35.5th percentile."""
    p = fracture_energy_cdf(specific_energy, e50, sigma, emax_ratio)
    with np.errstate(invalid="ignore"):
        e50b = np.where(p > 0.0, fracture_energy_ppf(0.5 * p, e50, sigma, emax_ratio), np.nan)
    return e50b[()] if e50b.ndim == 0 else e50b


def t10_batch(specific_energy, e50b, A, b_prime):
    """Eq. 7: t10 (%) of a batch of particles each given `specific_energy` (J/kg), of which the
    broken ones have the median fracture energy e50b (J/kg, median_fracture_energy_broken):
    t10 = A [1 - exp(-b' (Ek/mp) / E50b)]. Both energies on the same footing (here: absorbed)."""
    return t10(np.asarray(specific_energy, dtype=float) / e50b, A, b_prime)


def t10_mean_broken(specific_energy, e50, sigma, emax_ratio, A, b_prime, kappa=1.0, nodes=64):
    """Eq. 8 (%) averaged over the particles that break when each absorbs `specific_energy`
    (J/kg, a scalar): their fracture energies are Eqs. 1-2 below it, so the mean is over the
    probability u in (0, P) of E(u) = fracture_energy_ppf(u) (Gauss-Legendre, `nodes` points).
    At kappa = 1 it exceeds Eq. 7 (t10_batch over E50b) by up to exp(sigma^2 / 2) where t10 is
    small (the mean of 1/E over a lognormal): the gap that the paper's kappa closes. NaN where
    nothing breaks."""
    energy, weight = _broken_quadrature(specific_energy, e50, sigma, emax_ratio, nodes)
    if energy is None:
        return math.nan
    return float(weight @ t10(specific_energy / energy, A, b_prime, kappa))


def _broken_quadrature(specific_energy, e50, sigma, emax_ratio, nodes):
    """Gauss-Legendre nodes (fracture energies, J/kg) and weights (sum 1) over the particles
    that break at `specific_energy`; (None, None) where none does."""
    p = float(fracture_energy_cdf(specific_energy, e50, sigma, emax_ratio))
    if not p > 0.0:
        return None, None
    x, w = np.polynomial.legendre.leggauss(nodes)
    return fracture_energy_ppf(0.5 * p * (x + 1.0), e50, sigma, emax_ratio), 0.5 * w


def kappa_of_batch(specific_energy, e50, sigma, emax_ratio, A, b_prime, nodes=64):
    """The kappa of Eq. 8 at which its mean over the particles that break at `specific_energy`
    (J/kg, absorbed; t10_mean_broken) is Eq. 7 at that energy: the paper's definition of kappa
    ("Values of kappa were found to vary from about 0.95 to exp(sigma^2/2)", Section 2.2),
    computed from Eqs. 1-2 and 7-8 instead of the empirical expressions it cites. NaN where
    nothing breaks."""
    from scipy.optimize import brentq
    target = float(t10_batch(specific_energy, median_fracture_energy_broken(
        specific_energy, e50, sigma, emax_ratio), A, b_prime))
    energy, weight = _broken_quadrature(specific_energy, e50, sigma, emax_ratio, nodes)
    if energy is None or not np.isfinite(target):
        return math.nan
    ratio = specific_energy / energy

    def gap(log_kappa):          # Eq. 8's mean less Eq. 7, falling as kappa grows
        return float(weight @ t10(ratio, A, b_prime, math.exp(log_kappa))) - target
    return math.exp(brentq(gap, math.log(0.05), math.log(20.0), xtol=1e-12))


def t10_primary(A, b_prime, kappa=1.0):
    """Eq. 9: the smallest t10' (%) of a breakage, at Ek'/(mp E) = 1."""
    return t10(1.0, A, b_prime, kappa)


# --------------------------------------------------------------------------- Eq. 10
def t_n(t10_percent, alpha, beta):
    """Eq. 10: t_n = 100 I_x(alpha_n, beta_n) (%), x = t10 / 100."""
    x = np.clip(np.asarray(t10_percent, dtype=float) / 100.0, 0.0, 1.0)
    return 100.0 * special.betainc(alpha, beta, x)


def t_markers(t10_percent, beta_params):
    """All seven t_n of Eq. 10, as an array of shape t10.shape + (7,), ordered as N_VALUES."""
    t10_percent = np.asarray(t10_percent, dtype=float)
    return np.stack([t_n(t10_percent, *beta_params[n]) for n in N_VALUES], axis=-1)


def _passing_anchors(t10_percent, beta_params):
    """Anchor points (ln x ascending, passing % with shape t10.shape + (9,)) of the progeny curve.

    x = 1/75 ... 1/25, 1/10 (t10), 1/4 ... 1/1.2, 1 (100 %). Made non-decreasing in x, because a
    fitted marker may cross its neighbour at extreme t10.
    """
    t10_percent = np.asarray(t10_percent, dtype=float)
    markers = t_markers(t10_percent, beta_params)            # ordered 1.2 ... 75 (coarse to fine)
    fine_to_coarse = np.concatenate([
        markers[..., :3:-1],                                  # 75, 50, 25
        t10_percent[..., None],                               # 10
        markers[..., 3::-1],                                  # 4, 2, 1.5, 1.2
        np.full(t10_percent.shape + (1,), 100.0)], axis=-1)
    fine_to_coarse = np.minimum(np.maximum.accumulate(fine_to_coarse, axis=-1), 100.0)
    n_fine_to_coarse = np.array([75.0, 50.0, 25.0, 10.0, 4.0, 2.0, 1.5, 1.2, 1.0])
    return -np.log(n_fine_to_coarse), fine_to_coarse


def fines_exponent(t10_percent, beta_params):
    """Eq. 12: Gaudin-Schuhmann exponent lambda = ln(t4 / t75) / ln(75 / 4) at this t10'."""
    t10_percent = np.asarray(t10_percent, dtype=float)
    t4 = t_n(t10_percent, *beta_params[4.0])
    t75 = t_n(t10_percent, *beta_params[75.0])
    return np.log(t4 / t75) / np.log(75.0 / 4.0)


def fines_passing(x, x_top, exponent):
    """Eq. 11: fraction B(x) = (x / x_top)^lambda (0-1) of a fines mass finer than x, capped at 1."""
    x = np.asarray(x, dtype=float)
    ratio = np.clip(x / x_top, 0.0, 1.0)
    return ratio ** exponent


def progeny_passing(t10_percent, beta_params, x):
    """Cumulative percent of progeny mass passing relative size x (0 < x, fraction of parent size).

    From the seven t_n of Eq. 10, t10 at x = 0.1 and 100 % at x = 1, interpolated linearly in
    passing against ln x; below x = 1/75 the Gaudin-Schuhmann tail of Eq. 11 with the exponent of
    Eq. 12 continues the curve. Broadcasts t10 (shape S) against x (shape X) to S + X when both are
    arrays of more than one element; scalars broadcast as usual.
    """
    t10_arr = np.asarray(t10_percent, dtype=float)
    x_arr = np.asarray(x, dtype=float)
    log_anchor, passing_anchor = _passing_anchors(t10_arr.reshape(-1), beta_params)
    lam = fines_exponent(t10_arr.reshape(-1), beta_params)
    log_x = np.log(np.clip(x_arr.reshape(-1), 1e-300, None))
    out = np.empty((passing_anchor.shape[0], log_x.size))
    for i in range(passing_anchor.shape[0]):
        row = np.interp(log_x, log_anchor, passing_anchor[i])
        below = log_x < log_anchor[0]
        row[below] = passing_anchor[i, 0] * np.exp(lam[i] * (log_x[below] - log_anchor[0]))
        out[i] = row
    out[:, x_arr.reshape(-1) <= 0.0] = 0.0
    out[:, x_arr.reshape(-1) >= 1.0] = 100.0
    shape = t10_arr.shape + x_arr.shape
    return out.reshape(shape)[()] if shape == () else out.reshape(shape)


# --------------------------------------------------------------------------- Section 7, Eqs. 11-13
@dataclass(frozen=True)
class SizeDistribution:
    """A cumulative product size distribution: mass (kg) finer than or equal to each size (m)."""

    sizes: np.ndarray
    passing_mass: np.ndarray
    total_mass: float

    @property
    def passing_percent(self):
        """Cumulative mass percent passing each size."""
        return 100.0 * self.passing_mass / self.total_mass


def dummy_fines_passing(sizes, parent_size, t10_percent, beta_params, fines="gaudin_schuhmann"):
    """Fraction (0-1) of an event's dummy mass finer than each size (m): the unresolved fines.

    fines="gaudin_schuhmann" (the paper): Eq. 11 below X_MIN of the parent with lambda from
    Eq. 12. fines="eq10": Eq. 10's own curve below X_MIN, renormalised to 1 at X_MIN, which keeps
    t10 exact (the paper's extension overstates passing at x = 0.1 by 10-20 % near primary
    breakage: 2.31 % against 1.94 % for copper ore at t10' = 1.94 %).
    """
    sizes = np.atleast_1d(np.asarray(sizes, dtype=float))
    parent_size = np.atleast_1d(np.asarray(parent_size, dtype=float))
    t10_percent = np.atleast_1d(np.asarray(t10_percent, dtype=float))
    if fines == "gaudin_schuhmann":
        lam = fines_exponent(t10_percent, beta_params)
        return fines_passing(sizes[None, :], X_MIN * parent_size[:, None], lam[:, None])
    if fines == "eq10":
        out = np.empty((len(parent_size), len(sizes)))
        for k, (d, t) in enumerate(zip(parent_size, t10_percent)):
            x = np.minimum(sizes / d, X_MIN)
            out[k] = progeny_passing(t, beta_params, x) / progeny_passing(t, beta_params, X_MIN)
        return out
    raise ValueError(f"fines = {fines!r}: accepted 'gaudin_schuhmann' or 'eq10'")


def size_distribution(sizes, resolved=None, dummies=None, unbreakable=None, beta_params=None,
                      fines="gaudin_schuhmann"):
    """Section 7 (Eqs. 11-13): the full product size distribution after a run.

    sizes: the sieve sizes (m) at which the cumulative passing mass is wanted.
    resolved: (diameters m, masses kg) of resolved spheres, counted at their own size.
    dummies: (masses kg, parent diameters m, event t10' %): each dummy mass is the event's
        unresolved fines below X_MIN of its parent, spread by Eq. 11 with lambda from Eq. 12.
    unbreakable: (diameters m, masses kg, t10' %) of resolved-unbreakable spheres: each is spread
        by Eq. 13 (Eq. 10 at its recorded t10'); a NaN t10' (never stressed to breakage) keeps it
        at its own size.
    beta_params: the material's incomplete-beta parameters (needed for dummies and unbreakable).
    fines: how dummy masses are spread (see dummy_fines_passing).
    Mass is conserved: passing at a size above every particle equals the total mass.
    """
    sizes = np.atleast_1d(np.asarray(sizes, dtype=float))
    passing = np.zeros(sizes.shape)
    total = 0.0
    if resolved is not None:
        diam, mass = (np.atleast_1d(np.asarray(a, dtype=float)) for a in resolved)
        order = np.argsort(diam)
        cum = np.concatenate([[0.0], np.cumsum(mass[order])])
        passing += cum[np.searchsorted(diam[order], sizes, side="right")]
        total += float(mass.sum())
    if (dummies is not None or unbreakable is not None) and beta_params is None:
        raise ValueError("size_distribution: beta_params is required to spread dummy and "
                         "unbreakable masses")
    if dummies is not None:
        mass, parent, t10_event = (np.atleast_1d(np.asarray(a, dtype=float)) for a in dummies)
        if mass.size:
            passing += mass @ dummy_fines_passing(sizes, parent, t10_event, beta_params, fines)
            total += float(mass.sum())
    if unbreakable is not None:
        diam, mass, t10_rec = (np.atleast_1d(np.asarray(a, dtype=float)) for a in unbreakable)
        if mass.size:
            stressed = np.isfinite(t10_rec)
            if np.any(~stressed):
                order = np.argsort(diam[~stressed])
                cum = np.concatenate([[0.0], np.cumsum(mass[~stressed][order])])
                passing += cum[np.searchsorted(diam[~stressed][order], sizes, side="right")]
            for d, m, t in zip(diam[stressed], mass[stressed], t10_rec[stressed]):
                passing += m * progeny_passing(t, beta_params, sizes / d) / 100.0
            total += float(mass.sum())
    return SizeDistribution(sizes=sizes, passing_mass=passing, total_mass=total)


def repeated_impact_broken_fraction(absorbed_energy, e50, sigma, emax_ratio, gamma, impacts,
                                    quantiles=20000):
    """Fraction broken after each of `impacts` identical impacts (paper Fig. 11's model twin).

    absorbed_energy: Ek'/mp of every impact (J/kg). Each particle's fracture energy (Eqs. 1-2,
    taken at evenly spaced quantiles, a deterministic quadrature) is weakened after every impact
    it survives (Eqs. 5-6); it breaks at the first impact whose energy exceeds it.
    Returns an array of length `impacts`.
    The survivors' energies stay in the order of their quantiles (Eqs. 5-6 weaken a stronger
    particle to a still stronger one), so the fraction broken at impact k is the quantile where the
    survivors' energies cross the impact's: interpolated between quadrature points, it is a
    continuous function of gamma and the distribution's parameters (what a likelihood needs).
    """
    u = (np.arange(quantiles) + 0.5) / quantiles
    energy = fracture_energy_ppf(u, e50, sigma, emax_ratio)
    alive = np.ones(quantiles, dtype=bool)
    out = np.empty(impacts)
    for k in range(impacts):
        e_alive, u_alive = energy[alive], u[alive]
        if e_alive.size == 0:
            out[k:] = 1.0
            break
        if absorbed_energy <= e_alive[0]:       # nobody new breaks
            out[k] = out[k - 1] if k else 0.0
        elif absorbed_energy >= e_alive[-1]:
            out[k:] = 1.0
            break
        else:
            out[k] = float(np.interp(absorbed_energy, e_alive, u_alive))
        alive &= energy > absorbed_energy
        energy[alive] = weakened_fracture_energy(energy[alive], absorbed_energy / energy[alive], gamma)
    return out


# --------------------------------------------------------------------------- Section 9: Ab-T10
# The Rocky manual's cumulative-energy criterion (docs/model.md Section 9, the Rocky manual and white paper). Sizes L
# in metres, specific energies in J/kg, the selection function coefficient S in kg/J, t10 in %.

def ab_t10_min_energy(size, e_min_ref, size_ref):
    """Eq. 9.1: e_min(L) = e_min,ref L_ref / L (J/kg), the energy below which nothing is counted."""
    return e_min_ref * size_ref / np.asarray(size, dtype=float)


def ab_t10_update(e_t, e_prev, e_cum, e_max, e_min):
    """Eq. 9.2: one step of the cumulative specific energy. Returns (e_cum, e_max) after the step.

    e_t: specific energy (J/kg) of the particle's present loading, e_prev: its value at the previous
    step. e_cum grows while e_t > e_min and e_t > e_max, and e_max follows e_t; e_max resets to 0
    when the particle unloads below e_min, so a new loading counts again.
    The increment is e_t - max(e_prev, e_max, e_min): docs/model.md's e_t - e_prev on every step of a
    loading, except two where that form depends on the step size. On the step that crosses e_min
    it would also count the rise from e_prev up to e_min, energy below the threshold (up to one
    step's rise: 3-7 % of e_cum in single impacts at dt = 5 % of the Rayleigh time); on the first
    step of a reload past the earlier peak it would count again the part below e_max, which the
    e_max condition exists to exclude. Counted from max(e_prev, e_max, e_min), one loading from 0
    to e leaves exactly e - e_min at any step size, the small-step limit of the literal form.
    All arguments broadcast.
    """
    e_t, e_prev, e_cum, e_max, e_min = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (e_t, e_prev, e_cum, e_max, e_min)))
    grows = (e_t > e_min) & (e_t > e_max)
    new_cum = np.where(grows, e_cum + e_t - np.maximum(np.maximum(e_prev, e_max), e_min), e_cum)
    new_max = np.where(grows, e_t, np.where(e_t < e_min, 0.0, e_max))
    if new_cum.ndim == 0:
        return new_cum[()], new_max[()]
    return new_cum, new_max


def ab_t10_probability(e_cum, size, e_min, selection, size_ref):
    """Eq. 9.3: P(e_cum) = 1 - exp(-S (L / L_ref) (e_cum - e_min)), zero for e_cum <= e_min.

    A particle breaks when P(e_cum) exceeds its strength, drawn uniform in (0, 1) at its creation;
    P is therefore also the cdf of the e_cum at which particles of size L break.
    """
    x = selection * np.asarray(size, dtype=float) / size_ref
    p = -np.expm1(-x * np.maximum(np.asarray(e_cum, dtype=float) - e_min, 0.0))
    return p[()] if np.ndim(p) == 0 else p


def ab_t10_threshold(strength, size, e_min, selection, size_ref):
    """Eq. 9.3 inverted: the e_cum (J/kg) at which a particle of strength u in [0, 1) breaks,
    e_min - ln(1 - u) L_ref / (S L)."""
    x = selection * np.asarray(size, dtype=float) / size_ref
    e = e_min - np.log1p(-np.asarray(strength, dtype=float)) / x
    return e[()] if np.ndim(e) == 0 else e


def ab_t10_t10(e_cum, size, e_min, selection, size_ref, t10_max):
    """Eq. 9.4: t10 = M [1 - exp(-S (L / L_ref) (e_cum - e_min))] (%), M = t10_max (%)."""
    return t10_max * ab_t10_probability(e_cum, size, e_min, selection, size_ref)


def ab_t10_single_impact_cum(specific_energy, e_min):
    """e_cum left by one loading that rises from 0 to `specific_energy` (J/kg): the part above
    e_min (Eq. 9.2)."""
    return np.maximum(np.asarray(specific_energy, dtype=float) - e_min, 0.0)


def ab_t10_repeated_broken_fraction(absorbed_energy, size, e_min, selection, size_ref, impacts):
    """Fraction broken after each of `impacts` identical impacts of absorbed specific energy
    `absorbed_energy` (J/kg): e_cum after k impacts is k times one impact's (Eq. 9.2), and a
    particle breaks at the first impact where P(e_cum) (Eq. 9.3) passes its uniform strength, so
    the fraction broken after k impacts is P(e_cum after k). Returns an array of length `impacts`."""
    k = np.arange(1, impacts + 1)
    e_cum = k * ab_t10_single_impact_cum(absorbed_energy, e_min)
    return ab_t10_probability(e_cum, size, e_min, selection, size_ref)
