"""Rocky's Ab-T10 criterion (docs/model.md Section 9, Eqs. 9.1-9.4): e_cum grows by Eq. 9.2 and
a body breaks when it passes the threshold drawn at its creation (Eq. 9.3, kept as its fracture
energy); a breakage's t10 is Eq. 9.4 at e_cum."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from yadebreak import model
from yadebreak.criteria.base import Criterion
from yadebreak.model.intervals import PARTICLE_SIZE
from yadebreak.model.kinds import BREAKABLE
from yadebreak.model.materials import Key

#: Ab-T10 events with t10 below this (%) take the family set at this t10 (see t10_min): below it
#: the 11 classes cannot follow Eq. 10 within 2 % (2.6 % at t10 = 1 %).
AB_T10_T10_FLOOR = 2.0


@dataclass(frozen=True)
class AbT10Params:
    """The Ab-T10 parameters of a material (docs/model.md Section 9), SI."""

    e_min_ref: float     # J/kg, Eq. 9.1 at size_ref
    size_ref: float      # m
    selection: float     # S, kg/J, Eq. 9.3
    t10_max: float       # M, %, Eq. 9.4

    def criterion(self, material):
        """The criterion of a material with these parameters."""
        return AbT10(material)


class AbT10(Criterion):
    """Rocky's Ab-T10 criterion of one material."""

    name = "ab_t10"
    keys = (
        Key("e_min_ref", 0.0, True, math.inf, False, "J/kg"),
        Key.of("size_ref", PARTICLE_SIZE, "mm", 1e-3),
        Key("selection", 0.0, False, math.inf, False, "kg/J"),
        Key("t10_max", 0.0, False, 100.0, True, "%"),
    )
    Params = AbT10Params
    calibrated = ("e_min_ref", "size_ref", "selection", "t10_max")
    #: Eq. 9.2's state of each body (J/kg): e_min at its size (Eq. 9.1), e_cum, the event's
    #: largest e_t so far and e_t at the previous read
    columns = {"e_min": (np.float64, 0.0), "e_cum": (np.float64, 0.0),
               "e_max": (np.float64, 0.0), "e_prev": (np.float64, 0.0)}
    probability_label = "model P(e_cum), e_cum = e Ek/mp - e_min (Eqs. 4, 9.1-9.3)"
    t10_label = "model: Eq. 9.4"
    repeated_label = "model P(e_cum), e_cum = k (e Ek/mp - e_min) (Eqs. 9.1-9.3)"

    #: Eq. 9.2 is one call for all the Ab-T10 bodies read, settled after the Tavares ones
    order = 1
    #: Rocky's pause after a breakage event (Rocky manual, 2.4.2)
    default_pause_steps = 25
    #: Eq. 9.2 (model.ab_t10_update, numpy on any shape) costs about 20 us per body one by one,
    #: the numpy path about 40 us per read for up to 50 bodies: equal near 2 bodies
    judged_one_by_one = 2

    # -- model side -----------------------------------------------------------------------------
    def min_energy(self, size):
        """Eq. 9.1: e_min (J/kg) at size `size` (m)."""
        p = self.params
        return model.ab_t10_min_energy(size, p.e_min_ref, p.size_ref)

    def _cdf(self, energy, size):
        """Eq. 9.3: P(e_cum threshold < `energy`)."""
        p = self.params
        return model.ab_t10_probability(energy, size, self.min_energy(size), p.selection,
                                        p.size_ref)

    def _ppf(self, u, size):
        """Eq. 9.3 inverted: the e_cum threshold of strength u."""
        p = self.params
        return model.ab_t10_threshold(u, size, self.min_energy(size), p.selection, p.size_ref)

    def _rvs(self, rng, size):
        """The e_cum threshold of a strength drawn uniform in [0, 1)."""
        return self.ppf(rng.random(size.shape), size)

    def probability_once(self, absorbed, size):
        """P(e_cum) of the e_cum one loading absorbing `absorbed` (J/kg) leaves (Eqs. 9.2-9.3)."""
        return self.cdf(model.ab_t10_single_impact_cum(absorbed, self.min_energy(size)), size)

    def t10(self, ratio, kappa=None):
        raise ValueError(f"material '{self.material.name}' uses Ab-T10: its t10 comes from e_cum "
                         "(t10_of_cumulative_energy), not from Eq. 8")

    def t10_of_cumulative_energy(self, e_cum, size):
        """Eq. 9.4: t10 (%) of a particle of size `size` (m) broken at e_cum (J/kg)."""
        p = self.params
        return model.ab_t10_t10(e_cum, size, self.min_energy(size), p.selection, p.size_ref,
                                p.t10_max)

    def t10_once(self, absorbed, size):
        """The mean of Eq. 9.4 (%) over the particles that break after one loading absorbing
        `absorbed` (J/kg): M P / 2; NaN where none breaks."""
        e_cum = model.ab_t10_single_impact_cum(absorbed, self.min_energy(size))
        t10 = 0.5 * self.t10_of_cumulative_energy(e_cum, size)
        return np.where(t10 > 0.0, t10, np.nan)

    @property
    def t10_min(self):
        """No floor in Eq. 9.4: AB_T10_T10_FLOOR (%), or M / 2 when smaller."""
        return min(AB_T10_T10_FLOOR, 0.5 * self.params.t10_max)

    @property
    def t10_ceiling(self):
        """M (%), Eq. 9.4's largest t10."""
        return self.params.t10_max

    def intact_measures(self, e_cum_intact, size):
        """The mean e_cum (J/kg) the intact particles of an impact test carry (what the broken
        ones would have reached) and P of it."""
        if not e_cum_intact:
            return {}
        e_cum = float(np.mean(e_cum_intact))
        return {"e_cum_measured": e_cum, "p_of_e_cum_measured": float(self.cdf(e_cum, size))}

    def repeated_broken_fraction(self, absorbed, size, impacts):
        """Eqs. 9.1-9.3: the fraction broken after each of `impacts` loadings, each absorbing
        `absorbed` (J/kg), e_cum adding up over the impacts."""
        p = self.params
        return model.ab_t10_repeated_broken_fraction(absorbed, size, float(self.min_energy(size)),
                                                     p.selection, p.size_ref, impacts)

    # -- engine side ----------------------------------------------------------------------------
    def sample(self, rng, sizes):
        """The thresholds (J/kg) and each new body's e_min (Eq. 9.1)."""
        return self.rvs(rng, sizes), {"e_min": self.min_energy(sizes)}

    @staticmethod
    def judge_one(c, i, ek, specific):
        """Eq. 9.2 on body i, then the threshold (see Tavares.judge_one)."""
        before = c["e_prev"][i]
        cum_before = c["e_cum"][i]
        cum, top = model.ab_t10_update(specific, before, cum_before, c["e_max"][i], c["e_min"][i])
        c["e_cum"][i], c["e_max"][i], c["e_prev"][i] = cum, top, specific
        threshold = c["fracture_energy"][i]
        return cum > threshold, cum, threshold, specific > before, specific - before, cum - cum_before

    @staticmethod
    def energy_to_break(table, ids):
        """No bound: Eq. 9.2 accumulates, so any event may be the one that passes the threshold."""
        return np.zeros(len(ids))

    def unload(self, table, i):
        """Eq. 9.2 at the unloading: e_t = 0 < e_min resets e_max; e_cum keeps the damage."""
        c = table.columns
        e_cum, e_max = (float(v) for v in model.ab_t10_update(
            0.0, c["e_prev"][i].item(), c["e_cum"][i].item(), c["e_max"][i].item(),
            c["e_min"][i].item()))
        c["e_cum"][i], c["e_max"][i], c["e_prev"][i] = e_cum, e_max, 0.0
        if c["kind"][i] != BREAKABLE:
            return None
        energy = float(c["fracture_energy"][i])
        c["damage"][i] = e_cum / energy
        return {"e_cum": e_cum, "fracture_energy": energy,
                "ratio": float(c["event_max"][i]) / (float(c["mass"][i]) * energy)}

    def breakage(self, table, i, ek):
        """Eq. 9.4 at the body's e_cum."""
        c = table.columns
        e_cum = float(c["e_cum"][i])
        t10 = float(self.t10_of_cumulative_energy(e_cum, 2.0 * float(c["radius"][i])))
        return e_cum / float(c["fracture_energy"][i]), t10, {"e_cum": e_cum}

    def t10_at_threshold(self, table, i, threshold):
        """Eq. 9.4 at e_cum = `threshold`."""
        return float(self.t10_of_cumulative_energy(threshold,
                                                   2.0 * float(table.columns["radius"][i])))

    def force(self, table, i, ratio):
        c = table.columns
        c["e_cum"][i] = ratio * c["fracture_energy"][i]     # as if e_cum had reached it
        return ratio * float(c["mass"][i]) * float(c["fracture_energy"][i])
