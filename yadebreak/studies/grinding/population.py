"""The population balance of batch grinding with the breakage model of docs/model.md
(docs/grinding.md, Sections 4-5). SI units: m, kg, s, J, J/kg; t10 in %.

State: for every size class, the mass of its particles on a grid of specific fracture energies
(cells uniform in ln E): the class's fracture-energy distribution, fresh (Eqs. 1-3 at the class's
size) when particles arrive and shifted to lower energies by damage (Eqs. 5-6) as the survivors
are stressed; plus the fines below the finest class, kept as one mass.

One step of dt s: every class loses to stressing the fraction lambda_ij dt of its particles per
spectrum row j (capture.py: lambda_ij = nu_j m_mono(d_i) / M), each stressed at the specific
energy e_j of that row (one for all caught particles). In a cell of fracture energy E:
- e_j >= E (the part of the cell below ln e_j): breakage; t10 from Eq. 8 at e_j / E, progeny
  by Eq. 10 over the classes below (fresh particles) and the fines;
- drift_ratio <= e_j / E < 1: a survivor, its E weakened to E (1 - D), Eq. 6 at r = e_j / E;
- e_j / E < drift_ratio: many such mild stressings per step, each weakening by less than
  D(drift_ratio): applied as their mean rate of weakening, d ln E / dt = sum lambda ln(1 - D).
Mass moves between cells, classes and fines and is never created: it is conserved to round-off.

Two switches mirror the conventions of the DEM engine (off by default): t10_at="threshold" takes
every breakage's t10 at the fracture threshold (ratio 1, Eq. 9) instead of at e_j / E;
progeny_dmin makes progeny whose own progeny would be finer than it (0.210 d < progeny_dmin)
unbreakable: never damaged, and the first stressing past their fracture energy records its t10
and stops their stressing; the product spreads them by Eq. 10 at that t10 (Eq. 13).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from yadebreak import model
from yadebreak.model.capture import CaptureModel
from yadebreak.studies.grinding.classes import SizeClasses
from yadebreak.studies.grinding.grid import DamageTable, FractureGrid
from yadebreak.studies.grinding.progeny import Progeny


class GrindingError(ValueError):
    """Input the grinding model cannot use (one line naming the option or field)."""


@dataclass
class GrindResult:
    """Histories at the output times. masses (T, classes) kg, fines (T,) kg: the product (with
    progeny_dmin, once-broken unbreakable progeny spread by Eq. 10, Eq. 13); rates (T, classes)
    1/s over the interval ending at each time (NaN at t = 0 and for empty classes); passing (T,
    sieves) %; specific energies (T,) J/kg of ore; once_broken (T,) kg: unbreakable progeny
    stressed past their fracture energy (0 without progeny_dmin)."""

    classes: SizeClasses
    times_s: np.ndarray
    masses: np.ndarray
    fines: np.ndarray
    rates: np.ndarray
    collision_energy_J_per_kg: np.ndarray
    absorbed_energy_J_per_kg: np.ndarray
    initial_mass: float
    fed_mass: float
    discharged_mass: float
    steps: int
    runtime_s: float
    once_broken: np.ndarray = None

    @property
    def passing_percent(self):
        """Cumulative % passing each sieve (the holdup; for a continuous mill at steady state
        the product)."""
        below = np.cumsum(self.masses[:, ::-1], axis=1)[:, ::-1]        # mass in classes k..end
        total = self.masses.sum(axis=1) + self.fines
        passing = np.concatenate([below, np.zeros((len(total), 1))], axis=1) + self.fines[:, None]
        return 100.0 * passing / total[:, None]

    @property
    def mass_relative_error(self):
        """|holdup + discharged - initial - fed| / (initial + fed) at the end."""
        final = float(self.masses[-1].sum() + self.fines[-1])
        supplied = self.initial_mass + self.fed_mass
        return abs(final + self.discharged_mass - supplied) / supplied


def _check_material(material):
    if not material.breakable or material.is_ab_t10 or material.beta_params is None:
        raise GrindingError(f"--material {material.name}: the grinding model needs a breakable "
                            "material with the Tavares parameters (e_inf, d0, phi, sigma, gamma, "
                            "A, b_prime) and [breakage.beta]")


class BatchGrinder:
    """Batch (or continuous, with residence_time_s) grinding of `material` in a mill described
    by `spectra` (spectra.Spectra) over `classes` (classes.SizeClasses).

    cells: fracture-energy cells per class; drift_ratio: e/E below which stressings count as a
    mean weakening rate; max_stressed: the largest fraction of a cell stressed (above
    drift_ratio) in one step; damage: False keeps every survivor's E (no Eqs. 5-6);
    breakage_matrix: (classes + 1, classes) fractions of a class's broken mass (column) going to
    each class and the fines (row), replacing Eqs. 8-10 (tests, classical models);
    holdup_mass: kg of ore the spectra act on (default: the spectra's ore mass).

    Conventions of the DEM engine, for comparing with it (default off: the model as published):
    t10_at: "collision" (default) takes a breakage's t10 from Eq. 8 at e_j / E; "threshold" at
    the fracture threshold, ratio 1 (Eq. 9's t10_min), as the engine does when it breaks a
    particle at the first read past its fracture energy. progeny_dmin (m): progeny of a class
    whose own progeny would be finer than it (X_MIN d < progeny_dmin, the engine's dmin rule)
    are unbreakable: never damaged, and the first stressing past their fracture energy (fresh,
    Eqs. 1-3 at their class's size) records a t10 (by t10_at) and ends their stressing; they stay
    in the charge at their size and the product spreads them by Eq. 10 at that t10 (Eq. 13).
    Feed particles always break.
    """

    def __init__(self, material, spectra, classes, cells=120, drift_ratio=0.2,
                 max_stressed=0.05, damage=True, breakage_matrix=None, holdup_mass=None,
                 t10_at="collision", progeny_dmin=None):
        _check_material(material)
        if not 0.0 < drift_ratio < 1.0:
            raise GrindingError(f"drift_ratio = {drift_ratio}: accepted 0 < drift_ratio < 1")
        if not 0.0 < max_stressed <= 0.5:
            raise GrindingError(f"max_stressed = {max_stressed}: accepted (0, 0.5]")
        if t10_at not in ("collision", "threshold"):
            raise GrindingError(f"t10_at = {t10_at!r}: accepted 'collision' or 'threshold'")
        if progeny_dmin is not None and not progeny_dmin > 0.0:
            raise GrindingError(f"progeny_dmin = {progeny_dmin} m: accepted > 0 (or None: off)")
        if breakage_matrix is not None and (t10_at != "collision" or progeny_dmin is not None):
            raise GrindingError("breakage_matrix: replaces Eqs. 8-10, so t10_at and progeny_dmin "
                                "cannot be used with it")
        self.t10_at = t10_at
        self.progeny_dmin = progeny_dmin
        # classes whose progeny are unbreakable (the engine's rule: X_MIN d < dmin)
        self.unbreakable_class = (np.zeros(classes.count, bool) if progeny_dmin is None
                                  else model.X_MIN * classes.sizes < progeny_dmin)
        self.material, self.spectra, self.classes = material, spectra, classes
        self.n, self.cells = classes.count, int(cells)
        self.sizes = classes.sizes
        self.all_sizes = np.append(self.sizes, classes.fines_size)   # capture counts the fines
        self.max_stressed, self.damage_on = max_stressed, damage
        self.log_drift = math.log(drift_ratio)
        self.holdup = float(spectra.ore_mass_kg if holdup_mass is None else holdup_mass)
        self.capture = CaptureModel(material.density, spectra.ball_diameter_m,
                                    spectra.ore_coverage)
        self.grid = FractureGrid(material.criterion, self.sizes, cells)
        self.log_e, self.width, self.fresh = self.grid.log_e, self.grid.width, self.grid.fresh
        self.damage_table = DamageTable(material.params.gamma, damage)
        self.log_keep = self.damage_table.log_keep
        self.breakage = Progeny(material, classes, t10_at, breakage_matrix, GrindingError)
        self.t10_grid = self.breakage.t10_grid
        self._mill()

    # -- set-up ------------------------------------------------------------------------------
    def _mill(self):
        """Per spectrum row: rate nu (1/s), energy given to the ore (J, Eq. 4 share against steel
        for 'collision' spectra), geometry; lambda[i, j] the fraction of class i stressed per s."""
        s = self.spectra
        self.rate = s.rates_per_s
        share = 1.0
        if s.energy_basis == "collision":
            share = 1.0 / (1.0 + self.material.hertz_stiffness / _steel_stiffness())
        self.energy = s.energy_J * share
        self.plane = s.plane
        mono = self.capture.monolayer_mass(self.sizes[:, None], self.plane[None, :])
        self.lam = self.rate[None, :] * mono / self.holdup                  # (n, J)
        self.collision_power = float(np.sum(self.rate * s.energy_J))        # W

    # -- state ---------------------------------------------------------------------------------
    def fresh_state(self, class_masses, fines=0.0):
        """Masses (n, K) of fresh particles for `class_masses` kg per class, and the fines."""
        class_masses = np.asarray(class_masses, dtype=float)
        return class_masses[:, None] * self.fresh, float(fines)

    def _initial(self, class_masses, fines):
        cells, fines = self.fresh_state(class_masses, fines)
        if self.progeny_dmin is None:
            return _State(cells, fines)
        return _State(cells, fines, np.zeros_like(cells),
                      np.zeros((self.n, len(self.t10_grid))))

    def product(self, state):
        """(mass per class, fines) in kg of the product: what a sieve sees, once-broken unbreakable
        progeny spread by Eq. 10 at their t10 (Eq. 13)."""
        masses, fines = state.cells.sum(axis=1), state.fines
        if state.unbreakable is None:
            return masses, fines
        spread = np.einsum("ig,igl->l", state.spent, self.breakage.table)
        return masses + state.unbreakable.sum(axis=1) + spread[:self.n], fines + spread[self.n]

    def stressing(self, cells, fines):
        """Per spectrum row, the specific energy e_j (J/kg) of each caught particle for the
        charge's present composition, and nbar_j (capture.py)."""
        return self._stressing_of(cells.sum(axis=1), fines)

    def _stressing_of(self, class_masses, fines):
        """stressing() for the charge's mass per class (kg, at their physical sizes) and fines."""
        total = class_masses.sum() + fines
        fractions = np.append(class_masses, fines) / total
        e = self.capture.specific_energy(self.energy, fractions, self.all_sizes, self.plane)
        nbar = self.capture.expected_count(fractions, self.all_sizes, self.plane)
        return e, nbar

    def _rates(self, class_masses, fines):
        """The step's rates: ln r (n, J, K), stochastic rates q (n, J, K), their sum Q (n, K),
        the drift of ln E (n, K), e_j, nbar_j."""
        e, nbar = self._stressing_of(class_masses, fines)
        log_r = np.log(e)[None, :, None] - self.log_e[:, None, :]
        big = log_r >= self.log_drift
        q = np.where(big, self.lam[:, :, None], 0.0)
        drift = np.where(big, 0.0, self.lam[:, :, None] * self.log_keep(np.minimum(log_r, 0.0)))
        return log_r, q, q.sum(axis=1), drift.sum(axis=1), e, nbar

    def _largest_step(self, state, total, drift):
        """The longest step (s) in which no class has more than max_stressed of its mass
        stressed (above drift_ratio) and no cell holding mass drifts by more than a quarter of
        a cell. Weighted by mass: nearly empty cells (far down the grid, where every event breaks)
        do not limit the step; the exponential loss keeps them exact anyway."""
        cells = state.cells
        mass = cells.sum(axis=1)
        limit = math.inf
        per_class = _stressed_share(cells, total)
        if state.unbreakable is not None:
            per_class = np.maximum(per_class, _stressed_share(state.unbreakable, total))
        if per_class.max() > 0:
            limit = self.max_stressed / per_class.max()
        holding = cells > 1e-6 * np.maximum(mass[:, None], 1e-300)
        speed = np.max(np.where(holding, np.abs(drift) / self.width[:, None], 0.0))
        if speed > 0:
            limit = min(limit, 0.25 / speed)
        return limit

    def step(self, state, dt_max):
        """Advance `state` by at most dt_max s (less if _largest_step says so). Returns
        (state, dt, broken-out mass per class (kg, net of progeny staying in the class),
        energy given to caught ore (J))."""
        n = self.n
        physical = state.cells.sum(axis=1)
        if state.unbreakable is not None:     # stressed-once progeny stay in the charge whole
            physical = physical + state.unbreakable.sum(axis=1) + state.spent.sum(axis=1)
        log_r, q, total, drift, e, nbar = self._rates(physical, state.fines)
        dt = min(dt_max, self._largest_step(state, total, drift))
        new, broken, log_b = self._stress(state.cells, log_r, q, total, drift * dt, dt,
                                          self.damage_on)
        broken_class = broken.sum(axis=(1, 2))
        matrix = self.breakage.matrix
        if matrix is not None:
            progeny = matrix @ broken_class
            same = np.diag(matrix[:n]) * broken_class
        else:
            weights = self._t10_weights(broken, self.breakage.t10(log_b))   # (n, G)
            per_class = self.breakage.spread(weights)                      # (n, n+1)
            progeny = per_class.sum(axis=0)
            same = np.diag(per_class[:, :n])
        left = broken_class - same
        fines = state.fines + progeny[n]
        energy = float(np.sum(self.rate * self.energy * -np.expm1(-nbar))) * dt
        if state.unbreakable is None:
            new += progeny[:n, None] * self.fresh
            return _State(new, fines), dt, left, energy
        # unbreakable progeny: no damage; a stressing past E records t10 and ends their stressing
        unb, broken_u, log_bu = self._stress(state.unbreakable, log_r, q, total,
                                             np.zeros_like(self.log_e), dt, False)
        once = self._t10_weights(broken_u, self.breakage.t10(log_bu))     # (n, G)
        spread = self.breakage.spread(once)
        left = left + once.sum(axis=1) - np.diag(spread[:, :n])            # as a sieve sees it
        to_unb = np.where(self.unbreakable_class, progeny[:n], 0.0)
        new += (progeny[:n] - to_unb)[:, None] * self.fresh
        unb += to_unb[:, None] * self.fresh
        return _State(new, fines, unb, state.spent + once), dt, left, energy

    def _stress(self, cells, log_r, q, total, shift, dt, damage):
        """One step's stressing of a pool of particles (n, K): every cell loses the fraction
        1 - exp(-Q dt), shared among the rows by their rates; of a row's part, the share of the
        cell below ln e_j breaks (the cell's mass uniform in ln E), the rest survives at its mean
        ln E, weakened by Eq. 6 if `damage`; the unstressed part drifts by `shift` (n, K).
        Returns (the survivors on the grid (n, K), broken mass (n, J, K), the broken part's mean
        ln(e_j / E) (n, J, K))."""
        stressed = -np.expm1(-total * dt)                                  # (n, K)
        with np.errstate(invalid="ignore", divide="ignore"):
            f = np.where(total[:, None, :] > 0, q * (stressed / total)[:, None, :], 0.0)
        half = 0.5 * self.width[:, None, None]
        phi = np.clip(log_r / (2.0 * half) + 0.5, 0.0, 1.0)               # broken part of a cell
        mass = cells[:, None, :]
        broken = f * phi * mass                                            # (n, J, K)
        survive = f * (1.0 - phi) * mass
        # survivors of the stressed part: their mean ln E (the cell above ln e), weakened
        log_e = self.log_e[:, None, :]
        log_ej = log_r + log_e
        log_s = 0.5 * (np.maximum(log_ej, log_e - half) + log_e + half)
        target_s = log_s + shift[:, None, :]
        if damage:
            target_s = target_s + self.log_keep(np.minimum(log_ej - log_s, 0.0))
        keep = cells * (1.0 - stressed)
        new = self.grid.deposit(keep, self.log_e + shift, survive, target_s)
        log_b = log_ej - 0.5 * (log_e - half + np.minimum(log_ej, log_e + half))
        return new, broken, log_b

    def _t10_weights(self, broken, t10):
        """Broken mass per class (n, J, K) on the t10 grid: (n, G) (Progeny.weights)."""
        return self.breakage.weights(broken, t10)

    # -- time integration --------------------------------------------------------------------
    def run(self, class_masses, fines, output_times_s, residence_time_s=None, progress=None):
        """Integrate from t = 0 to each of `output_times_s` (ascending, s). With
        residence_time_s: a continuous, perfectly mixed mill fed at holdup/residence with the
        initial composition (fresh) and discharging the holdup at the same rate.
        progress(t_s, wall_s) is called about every 5 s of wall time."""
        start = time.time()
        out_t = np.asarray(output_times_s, dtype=float)
        state = self._initial(class_masses, fines)
        feed = state
        initial = float(state.cells.sum() + state.fines)
        masses, fines_h, rates = [state.cells.sum(axis=1)], [state.fines], [np.full(self.n, np.nan)]
        e_coll, e_abs, once = [0.0], [0.0], [0.0]
        t, steps, fed, discharged, absorbed = 0.0, 0, 0.0, 0.0, 0.0
        last = start
        for t_out in out_t[1:] if out_t[0] == 0.0 else out_t:
            left_class = np.zeros(self.n)
            exposure = np.zeros(self.n)
            while t < t_out * (1 - 1e-12):
                dt = t_out - t
                if residence_time_s:
                    dt = min(dt, 0.05 * residence_time_s)
                before = self.product(state)[0]
                state, dt, left, energy = self.step(state, dt)
                if residence_time_s:
                    out_share = -math.expm1(-dt / residence_time_s)
                    discharged += out_share * state.total()
                    state = state.mixed(out_share, feed)
                    fed += out_share * initial
                exposure += _mean_mass(before, self.product(state)[0]) * dt
                left_class += left
                absorbed += energy
                t += dt
                steps += 1
                now = time.time()
                if progress is not None and now - last > 5.0:
                    progress(t, now - start)
                    last = now
            product, product_fines = self.product(state)
            masses.append(product)
            fines_h.append(product_fines)
            once.append(0.0 if state.spent is None else float(state.spent.sum()))
            with np.errstate(invalid="ignore", divide="ignore"):
                rates.append(np.where(exposure > 0, left_class / exposure, np.nan))
            e_coll.append(self.collision_power * t / self.holdup)
            e_abs.append(absorbed / self.holdup)
        times = out_t if out_t[0] == 0.0 else np.concatenate([[0.0], out_t])
        return GrindResult(self.classes, times, np.array(masses), np.array(fines_h),
                           np.array(rates), np.array(e_coll), np.array(e_abs), initial, fed,
                           discharged, steps, time.time() - start, np.array(once))

    def initial_rates(self, class_masses, fines=0.0, net=False, quantiles=20000):
        """Each class's breakage rate (1/s) at t = 0 from the fresh distributions (Eqs. 1-3),
        without integrating: S_i = sum_j lambda_ij P_i(e_j), every breakage counted (gross). With
        net: only the broken mass that leaves the class, the fresh distribution taken at
        `quantiles` evenly spaced quantiles, each broken particle's t10 from Eq. 8 (or Eq. 9 for
        t10_at="threshold") and its progeny's share below the class from Eq. 10 (what a sieve
        analysis of the class sees)."""
        cells, fines = self.fresh_state(class_masses, fines)
        e, _ = self.stressing(cells, fines)
        if not net:
            p = self.material.criterion.cdf(e[None, :], self.sizes[:, None])
            return (self.lam * p).sum(axis=1)
        u = (np.arange(quantiles) + 0.5) / quantiles
        out = np.zeros(self.n)
        for i, d in enumerate(self.sizes):
            energy = self.material.criterion.ppf(u, d)                         # (Q,)
            ratio = e[:, None] / energy[None, :]                               # (J, Q)
            leaving = 1.0 - self.breakage.retained(
                i, self.breakage.t10_at_ratio(np.maximum(ratio, 1.0)))
            out[i] = np.sum(self.lam[i] * np.mean(np.where(ratio >= 1.0, leaving, 0.0), axis=1))
        return out


@dataclass
class _State:
    """The charge: breakable particles on each class's fracture-energy grid (n, K) kg, the fines
    kg; with progeny_dmin, the unbreakable progeny not yet stressed past their fracture energy
    (n, K) kg and those that were, on the t10 grid (n, G) kg (kept whole in the charge, spread
    by Eq. 10 in the product)."""

    cells: np.ndarray
    fines: float
    unbreakable: np.ndarray = None
    spent: np.ndarray = None

    def total(self):
        extra = 0.0 if self.unbreakable is None else self.unbreakable.sum() + self.spent.sum()
        return float(self.cells.sum() + self.fines + extra)

    def mixed(self, share, feed):
        """The charge after `share` of it is discharged and replaced by `feed`."""
        keep = 1.0 - share
        if self.unbreakable is None:
            return _State(self.cells * keep + share * feed.cells,
                          self.fines * keep + share * feed.fines)
        return _State(self.cells * keep + share * feed.cells,
                      self.fines * keep + share * feed.fines,
                      self.unbreakable * keep + share * feed.unbreakable,
                      self.spent * keep + share * feed.spent)


def _stressed_share(cells, total):
    """Per class, the share of its mass (n, K) stressed per s at the rates Q (n, K); 0 if empty."""
    mass = cells.sum(axis=1)
    stressed = (total * cells).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(mass > 0, stressed / mass, 0.0)


def _mean_mass(before, after):
    """Mean mass over a step from its two ends: the logarithmic mean (exact for a class decaying
    exponentially within the step), the plain mean where either end is empty or they are equal."""
    with np.errstate(invalid="ignore", divide="ignore"):
        log_mean = (before - after) / np.log(before / after)
    plain = 0.5 * (before + after)
    usable = (before > 0) & (after > 0) & (np.abs(before - after) > 1e-9 * plain)
    return np.where(usable, log_mean, plain)


def _steel_stiffness():
    from yadebreak.criteria import load_material
    return load_material("steel").hertz_stiffness


__all__ = ["BatchGrinder", "GrindResult", "GrindingError"]
