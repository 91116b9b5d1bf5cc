"""The Criterion base: what every breakage criterion answers, for the model (its fracture-energy
distribution and t10) and for the engine (judge, unload, breakage), and the one registry of the
criteria a material file may name (`breakage.model`).

A criterion owns what is its own: its [breakage] keys with their ranges and units (`keys`), the
frozen dataclass of its parameters (`Params`, one field per key, SI; a Material holds one as
`params`), the per-body columns it keeps in the engine's body table (`columns`), and its model
and engine sides. Public methods check and convert their input, then call the criterion's hooks
(scipy.stats' shape): a criterion writes `_cdf`, `_ppf` and `_rvs`, and the engine-side methods
below. The registry is registry.CRITERIA, one line per criterion (docs/architecture.md, "A new
criterion").

Model side, energies in J/kg and sizes in m, numpy arrays of any shape:
    cdf(energy, size), ppf(u, size), rvs(rng, size)    the fracture-energy distribution
    median_fracture_energy(size), probability_once(absorbed, size), t10(ratio), t10_once(...),
    t10_min, t10_ceiling, intact_measures(...), repeated_broken_fraction(...)
Engine side, on the columns of the engine's body table (engine/state.BodyTable), no yade:
    judge(table, ids, ek, specific) -> Judgement   which of the bodies read now break
    judge_one(columns, i, ek, specific) -> tuple   the same function on one body (scalars)
    unload(table, i) -> event fields or None        a stressing event ended without breakage
    unload_all(table, ids) -> [fields or None]      the same for the events a read closes
    breakage(table, i, ek) -> (ratio, t10, extra)   the t10' of a breakage
    t10_at_threshold(table, i, threshold) -> t10    the t10' of a breakage right at the threshold
    force(table, i, ratio) -> ek                    a breakage imposed by break_body()
    sample(rng, sizes) -> (fracture energies, extra columns)   state of a new body
    energy_to_break(table, ids) -> J/kg             the least one event must bring to break them
"""
from __future__ import annotations

import numpy as np

from yadebreak.criteria.judgement import Judgement
from yadebreak.model.equations import DEVICE_STIFFNESS_STEEL


class Criterion:
    """One breakage criterion of one material (`self.material`, a model.materials.Material)."""

    #: the file's breakage.model naming this criterion (None: not named by files)
    name = None
    #: its [breakage] keys (model.materials.Key: range and unit in the file, factor to SI,
    #: default), besides those every criterion shares (model.materials.SHARED_BREAKAGE_KEYS)
    keys = ()
    #: its parameters: a frozen dataclass with one field per key (SI) and criterion(material)
    Params = None
    #: the per-body columns it keeps in the engine's body table, beyond the shared ones
    #: (engine/state.py): name -> (numpy dtype, value of a new row)
    columns = {}
    #: the keys `python3 -m yadebreak fit` estimates from laboratory data or else takes from a
    #: base material (the others come from the base or their default)
    calibrated = ()
    #: the plots' legends of the model's breakage probability, t10 and repeated impacts
    probability_label = t10_label = repeated_label = ""
    #: bodies of a lower order are settled first in a read (Controller._settle)
    order = 0
    #: steps after its creation during which a fragment counts no energy
    default_pause_steps = 0
    #: reads of up to this many bodies are judged one by one (judging.Judge)
    judged_one_by_one = 1
    #: what unload()'s events are logged as
    event_kind = "damage"

    def __init__(self, material):
        self.material = material
        self.params = material.params

    # -- the material file --------------------------------------------------------------------
    @classmethod
    def file_keys(cls):
        """The names of its [breakage] keys."""
        return frozenset(k.name for k in cls.keys)

    @classmethod
    def parse(cls, table, where, problems):
        """Its Params from a file's [breakage] `table` (checked, in SI), or None with every
        problem appended to `problems` (`where` names the table in them)."""
        values = {k.name: k.read(table, where, problems) for k in cls.keys}
        return None if None in values.values() else cls.Params(**values)

    @classmethod
    def key(cls, name):
        """Its Key named `name`."""
        return next(k for k in cls.keys if k.name == name)

    @classmethod
    def in_file_unit(cls, params):
        """{key: value in the file's unit} of `params`, in the order of `keys` (what a fitted
        material file writes)."""
        return {k.name: getattr(params, k.name) / k.factor for k in cls.keys}

    def with_settings(self, kappa_successive=None, t10_energy="particle", batch_kappa=False):
        """This criterion with Eq. 8's kappa of fragments, the energy of a breakage's t10' and
        the batch kappa (attach()'s kappa_successive, t10_energy, kappa='batch') set; criteria
        without Eq. 8: itself."""
        return self

    # -- the fracture-energy distribution ---------------------------------------------------
    def cdf(self, energy, size):
        """P(fracture energy < `energy` (J/kg)) of particles of size `size` (m)."""
        return self._cdf(energy, size)

    def ppf(self, u, size):
        """The fracture energy (J/kg) at probability u, size `size` (m): cdf inverted."""
        return self._ppf(u, size)

    def rvs(self, rng, size):
        """One fracture energy (J/kg) per size in `size` (m), drawn with numpy Generator `rng`."""
        return self._rvs(rng, np.asarray(size, dtype=float))

    def median_fracture_energy(self, size):
        """The fracture energy (J/kg) half the particles of size `size` (m) stay below."""
        return self.ppf(0.5, size)

    @property
    def device_stiffness(self):
        """The stiffness (Pa) of the device the fracture energies are measured with (Eq. 3's
        correction): steel's, unless the criterion's parameters name another."""
        return DEVICE_STIFFNESS_STEEL

    # -- engine side --------------------------------------------------------------------------
    def overridden(self, kappa=None, emax_ratio=None):
        """The material with attach()'s overrides applied (criteria without them: unchanged)."""
        return self.material

    def sample(self, rng, sizes):
        """Fracture energies (J/kg) of new bodies of `sizes` (m), and no further columns."""
        return self.rvs(rng, sizes), {}

    def judge(self, table, ids, ek, specific):
        """judge_one on the bodies `ids` (arrays), as a Judgement."""
        return Judgement(*self.judge_one(table.columns, ids, ek, specific))

    def unload_all(self, table, ids):
        """unload() of each body in `ids` (a list; each body's own columns only, so the order
        does not matter): a criterion may do it at once (a collisional cloud closes hundreds of
        events a read)."""
        return [self.unload(table, i) for i in ids]

    def t10_at_threshold(self, table, i, threshold):
        """The t10' (%) body i would have had, broken at its threshold `threshold` (J/kg, its
        fracture energy): what a read at the crossing gives (the warning of a late read)."""
        raise NotImplementedError


def registry(*classes):
    """{name: class} of criterion classes, refusing a name given twice."""
    found = {}
    for cls in classes:
        if cls.name in found:
            raise ValueError(f"criterion name {cls.name!r} registered twice "
                             f"({found[cls.name].__name__} and {cls.__name__})")
        found[cls.name] = cls
    return found
