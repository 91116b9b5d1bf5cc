"""The Tavares UFRJ criterion (docs/model.md, Eqs. 1-8): a body breaks when the specific energy
it absorbs, Ek'/m, passes its fracture energy E, drawn from an upper-truncated lognormal (Eqs.
1-3); an event that ends without breakage weakens it (Eqs. 5-6); a breakage's t10' is Eq. 8."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from yadebreak import model
from yadebreak.criteria.base import Criterion
from yadebreak.model.intervals import PARTICLE_SIZE, YOUNG_MODULUS
from yadebreak.model.kinds import BREAKABLE
from yadebreak.model.materials import Key


@dataclass(frozen=True)
class TavaresParams:
    """The Tavares parameters of a material (docs/model.md Table 2), SI."""

    e_inf: float              # J/kg, Eq. 3
    d0: float                 # m, Eq. 3
    phi: float                # Eq. 3
    sigma: float              # Eq. 1
    emax_ratio: float         # Emax / E50, Eq. 2
    gamma: float              # Eq. 6
    A: float                  # %, Eq. 8
    b_prime: float            # Eq. 8
    kappa: float              # Eq. 8
    device_stiffness: float   # Pa, Eq. 3: the device the fracture energies were measured with

    def criterion(self, material):
        """The criterion of a material with these parameters."""
        return Tavares(material)


class Tavares(Criterion):
    """The Tavares UFRJ criterion of one material. kappa_successive: Eq. 8's kappa for fragments
    (generation >= 1); None: the material's for every event. t10_energy: the fracture energy in a
    breakage's t10', "particle" (the body's own, Eq. 8) or "e50b" (Eq. 7 over E50b)."""

    name = "tavares"
    keys = (
        Key("e_inf", 0.0, False, math.inf, False, "J/kg"),
        Key.of("d0", PARTICLE_SIZE, "mm", 1e-3),
        Key("phi", 0.0, True, 10.0, True, "-"),
        Key("sigma", 0.0, False, 10.0, True, "-"),
        Key("emax_ratio", 1.0, False, math.inf, False, "-", default=100.0),
        Key("gamma", 0.0, False, 1000.0, True, "-"),
        Key("A", 0.0, False, 100.0, True, "%"),
        Key("b_prime", 0.0, False, math.inf, False, "-"),
        Key("kappa", 0.0, False, math.inf, False, "-", default=1.0),
        Key.of("device_stiffness", YOUNG_MODULUS, "GPa", 1e9,
               default=model.DEVICE_STIFFNESS_STEEL / 1e9),
    )
    Params = TavaresParams
    calibrated = ("e_inf", "d0", "phi", "sigma", "emax_ratio", "gamma", "A", "b_prime")
    probability_label = "model (Eqs. 1-4)"
    t10_label = "model: Eq. 7, e Ek/mp over E50b of the broken particles"
    repeated_label = "model (Eqs. 1-6), gamma = {gamma:g}"

    #: the EDEM paper has no pause after a breakage
    default_pause_steps = 0
    #: measured: judge_one costs about 1 us per body, judge with the judge's numpy path 25 us per
    #: read plus 0.2 us per body
    judged_one_by_one = 24

    def __init__(self, material, kappa_successive=None, t10_energy="particle",
                 batch_kappa=False):
        super().__init__(material)
        self.kappa_successive = kappa_successive
        self.t10_energy = t10_energy
        self.batch_kappa = batch_kappa

    def with_settings(self, kappa_successive=None, t10_energy="particle", batch_kappa=False):
        return Tavares(self.material, kappa_successive, t10_energy, batch_kappa)

    # -- model side -----------------------------------------------------------------------------
    def median_fracture_energy(self, size):
        """Eq. 3: E50 (J/kg) at size `size` (m), against the material's device stiffness."""
        p = self.params
        return model.median_fracture_energy(size, p.e_inf, p.d0, p.phi,
                                            self.material.hertz_stiffness, p.device_stiffness)

    @property
    def device_stiffness(self):
        """The device of the file's fracture energies (Pa; steel's by default)."""
        return self.params.device_stiffness

    def _cdf(self, energy, size):
        p = self.params
        return model.fracture_energy_cdf(energy, self.median_fracture_energy(size), p.sigma,
                                         p.emax_ratio)

    def _ppf(self, u, size):
        p = self.params
        return model.fracture_energy_ppf(u, self.median_fracture_energy(size), p.sigma,
                                         p.emax_ratio)

    def _rvs(self, rng, size):
        p = self.params
        return model.sample_fracture_energy(rng, self.median_fracture_energy(size), p.sigma,
                                            p.emax_ratio, size=size.shape)

    def probability_once(self, absorbed, size):
        """P that a fresh particle of size `size` (m) breaks when it absorbs `absorbed` (J/kg)."""
        return self.cdf(absorbed, size)

    def t10(self, ratio, kappa=None):
        """Eq. 8 (%); ratio = Ek' / (mp E); kappa None: the material's."""
        p = self.params
        return model.t10(ratio, p.A, p.b_prime, p.kappa if kappa is None else kappa)

    def t10_once(self, absorbed, size):
        """Eq. 7 (%) at `absorbed` (J/kg) over E50b of the particles of size `size` (m) that
        break at it."""
        p = self.params
        e50b = model.median_fracture_energy_broken(absorbed, self.median_fracture_energy(size),
                                                   p.sigma, p.emax_ratio)
        return model.t10_batch(absorbed, e50b, p.A, p.b_prime)

    @property
    def t10_min(self):
        """Eq. 9 (%); with batch_kappa at kappa = exp(sigma^2 / 2), the paper's largest (the
        family table's floor)."""
        p = self.params
        kappa = math.exp(p.sigma ** 2 / 2.0) if self.batch_kappa else p.kappa
        return float(model.t10_primary(p.A, p.b_prime, kappa))

    def kappa_of_batch(self, absorbed, size):
        """The kappa at which Eq. 8's mean over the particles of size `size` (m) that break at
        `absorbed` (J/kg) is Eq. 7 (model.kappa_of_batch)."""
        p = self.params
        return model.kappa_of_batch(absorbed, float(self.median_fracture_energy(size)), p.sigma,
                                    p.emax_ratio, p.A, p.b_prime)

    @property
    def t10_ceiling(self):
        """A (%), Eq. 8's largest t10'."""
        return self.params.A

    def intact_measures(self, e_cum_intact, size):
        """What the intact particles of an impact test carry for its result: nothing here."""
        return {}

    def repeated_broken_fraction(self, absorbed, size, impacts):
        """Eqs. 1-6: the fraction of particles of size `size` (m) broken after each of
        `impacts` loadings, each absorbing `absorbed` (J/kg), damage weakening the survivors."""
        p = self.params
        e50 = float(self.median_fracture_energy(size))
        return model.repeated_impact_broken_fraction(absorbed, e50, p.sigma, p.emax_ratio,
                                                     p.gamma, impacts)

    # -- engine side ----------------------------------------------------------------------------
    def overridden(self, kappa=None, emax_ratio=None):
        """The material with attach()'s overrides of kappa (Eq. 8) and Emax/E50 (Eq. 2)."""
        changes = {k: v for k, v in (("kappa", kappa), ("emax_ratio", emax_ratio)) if v is not None}
        return self.material.with_params(**changes) if changes else self.material

    @staticmethod
    def judge_one(c, i, ek, specific):
        """Eq. 1 on body i (an id and scalars, or ids and arrays: the same operations), from the
        columns `c`: (breaks, level, threshold, rising, rise, jump) as in Judgement."""
        before = c["specific_energy"][i]
        threshold = c["fracture_energy"][i]
        rise = specific - before
        return specific > threshold, specific, threshold, specific > before, rise, rise

    @staticmethod
    def energy_to_break(table, ids):
        """Eq. 1's criterion: an event breaks the body if its Ek'/m passes E (after damage)."""
        return table.columns["fracture_energy"][ids]

    def unload(self, table, i):
        """Eqs. 5-6 with the event's largest Ek' (breakable bodies only): unload_all of one."""
        return self.unload_all(table, [i])[0]

    def unload_all(self, table, ids):
        """Eqs. 5-6 with each event's largest Ek' (breakable bodies only), for the bodies `ids`
        at once: the columns gathered and written with numpy, Eq. 6 solved body by body on
        floats (model.damage's one-ratio solver)."""
        c = table.columns
        rows = np.asarray(ids, np.int64)
        before = c["fracture_energy"][rows]
        ratios = c["event_max"][rows] / (c["mass"][rows] * before)
        damaged = (c["kind"][rows] == BREAKABLE).nonzero()[0]
        gamma = self.params.gamma
        energies, ratios = before.tolist(), ratios.tolist()
        after = [model.weakened_fracture_energy(energies[k], ratios[k], gamma)
                 for k in damaged.tolist()]
        weakened, at = np.array(after, float), rows[damaged]
        c["fracture_energy"][at] = weakened
        c["damage"][at] = 1.0 - weakened / c["fracture_energy_initial"][at]
        fields = [None] * len(rows)
        for k, a in zip(damaged.tolist(), after):
            fields[k] = {"fracture_energy": energies[k], "fracture_energy_after": a,
                         "ratio": ratios[k]}
        return fields

    def breakage(self, table, i, ek):
        """(ratio = Ek' / (m E), t10', {}): Eq. 8 at that ratio, with kappa_successive for
        fragments when it is set; t10_energy "e50b": Eq. 7 at Ek'/m over E50b of the body's
        size (Rocky's Eqs. 2-47 and 2-48)."""
        c = table.columns
        mass = float(c["mass"][i])
        ratio = ek / (mass * float(c["fracture_energy"][i]))
        if self.t10_energy == "e50b":
            return ratio, float(self.t10_once(ek / mass, 2.0 * float(c["radius"][i]))), {}
        kappa = (None if self.kappa_successive is None or c["generation"][i] == 0
                 else self.kappa_successive)
        if kappa is None and self.batch_kappa:
            kappa = self.kappa_of_batch(ek / mass, 2.0 * float(c["radius"][i]))
            return ratio, float(self.t10(ratio, kappa)), {"kappa": kappa}
        return ratio, float(self.t10(ratio, kappa)), {}

    def t10_at_threshold(self, table, i, threshold):
        """Eq. 8 at Ek' = m `threshold` (ratio 1 when `threshold` is the body's E)."""
        return self.breakage(table, i, threshold * float(table.columns["mass"][i]))[1]

    def force(self, table, i, ratio):
        return ratio * float(table.columns["mass"][i]) * float(table.columns["fracture_energy"][i])
