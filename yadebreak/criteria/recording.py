"""Recording (attach(breakage=False)): no breakage and no damage; every stressing event is logged
as 'stressing' with its largest specific energy and partner, and the body stays as it was: the
collision spectra of a scene. It wraps the material's own criterion, which draws the fracture
energies (kept for the events' `ratio`) and answers the model side."""
from __future__ import annotations

import numpy as np

from yadebreak.criteria.base import Criterion
from yadebreak.criteria.tavares import Tavares
from yadebreak.model.kinds import BREAKABLE


class Recording(Criterion):
    """The criterion `inner` that never breaks nor weakens a body; reads follow the loading only.
    Not named by material files: criterion_for(material, breakage=False) makes it."""

    event_kind = "stressing"
    default_pause_steps = 0
    judged_one_by_one = Tavares.judged_one_by_one

    def __init__(self, inner):
        super().__init__(inner.material)
        self.inner = inner
        self.order = inner.order
        self.columns = inner.columns
        self.probability_label = inner.probability_label
        self.t10_label = inner.t10_label
        self.repeated_label = inner.repeated_label

    # -- model side: the inner criterion's ------------------------------------------------------
    def _cdf(self, energy, size):
        return self.inner.cdf(energy, size)

    def _ppf(self, u, size):
        return self.inner.ppf(u, size)

    def _rvs(self, rng, size):
        return self.inner.rvs(rng, size)

    def median_fracture_energy(self, size):
        return self.inner.median_fracture_energy(size)

    def probability_once(self, absorbed, size):
        return self.inner.probability_once(absorbed, size)

    def t10(self, ratio, kappa=None):
        return self.inner.t10(ratio, kappa)

    def t10_once(self, absorbed, size):
        return self.inner.t10_once(absorbed, size)

    @property
    def t10_min(self):
        return self.inner.t10_min

    @property
    def t10_ceiling(self):
        return self.inner.t10_ceiling

    def intact_measures(self, e_cum_intact, size):
        return self.inner.intact_measures(e_cum_intact, size)

    def repeated_broken_fraction(self, absorbed, size, impacts):
        return self.inner.repeated_broken_fraction(absorbed, size, impacts)

    # -- engine side ----------------------------------------------------------------------------
    def overridden(self, kappa=None, emax_ratio=None):
        return self.inner.overridden(kappa, emax_ratio)

    def sample(self, rng, sizes):
        return self.inner.sample(rng, sizes)

    @staticmethod
    def judge_one(c, i, ek, specific):
        """Never a breakage, and no threshold to approach: not `rising`, so that "fast" reads keep
        only the pace the loading time asks for (the events' peaks), not the closer reads that a
        body nearing its fracture energy needs."""
        breaks, level, threshold, rising, rise, jump = Tavares.judge_one(c, i, ek, specific)
        if isinstance(breaks, np.ndarray):
            return np.zeros_like(breaks), level, threshold, np.zeros_like(rising), rise, jump
        return False, level, threshold, False, rise, jump

    @staticmethod
    def energy_to_break(table, ids):
        """Nothing breaks."""
        return np.full(len(ids), np.inf)

    def unload(self, table, i):
        """The event's fields; the body unchanged."""
        c = table.columns
        if c["kind"][i] != BREAKABLE:
            return None
        energy = float(c["fracture_energy"][i])
        return {"fracture_energy": energy,
                "ratio": float(c["event_max"][i]) / (float(c["mass"][i]) * energy)}

    def breakage(self, table, i, ek):             # break_body() still breaks
        return self.inner.breakage(table, i, ek)

    def t10_at_threshold(self, table, i, threshold):
        return self.inner.t10_at_threshold(table, i, threshold)

    def force(self, table, i, ratio):
        return self.inner.force(table, i, ratio)


def criterion_for(material, breakage=True, kappa_successive=None, t10_energy="particle",
                  batch_kappa=False):
    """The criterion of a breakable Material for the engine: material.criterion itself (the
    object the model side uses), with Eq. 8's kappa of fragments when kappa_successive is given
    (Tavares; None: the material's), the energy of a breakage's t10' (t10_energy) and
    batch_kappa (attach's kappa='batch'), wrapped in Recording when breakage=False."""
    criterion = material.criterion
    if kappa_successive is not None or t10_energy != "particle" or batch_kappa:
        criterion = criterion.with_settings(kappa_successive, t10_energy, batch_kappa)
    if breakage:
        return criterion
    return Recording(criterion)
