"""Breakage criteria in YADE: one class per criterion, the counterpart of the criterion the
material's model names (Material.criterion, `criterion_for`), behind one small interface. They
read and write the body columns of state.BodyTable; no yade import.

    judge(table, ids, ek, specific) -> Judgement     which of the bodies read now break
    judge_one(columns, i, ek, specific) -> tuple     the same function on one body (scalars)
    unload(table, i) -> event fields or None          a stressing event ended without breakage
    breakage(table, i, ek) -> (ratio, t10, extra)     the t10' of a breakage (Eq. 8 or 9.4)
    force(table, i, ratio) -> ek                      a breakage imposed by break_body()
    sample(rng, sizes) -> (fracture energies, extra columns)   state of a new body
    energy_to_break(table, ids) -> J/kg               the least one event must bring to break them
    event_kind                                        what unload()'s events are logged as

Recording (attach(breakage=False)) wraps a material's criterion: nothing breaks or weakens, every
stressing event is logged as 'stressing'.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from yadebreak import model


@dataclass
class Judgement:
    """What a criterion decided for the bodies read now (arrays aligned with the ids given).

    breaks: breaks now. level, threshold: the criterion's variable and the value at which the body
    breaks (J/kg). rising: the body's loading grew since the last read, by `rise` (J/kg, what a
    read schedule extrapolates). jump: the rise of the criterion's variable since the last read,
    for the warning that a read came late."""

    breaks: np.ndarray
    level: np.ndarray
    threshold: np.ndarray
    rising: np.ndarray
    rise: np.ndarray
    jump: np.ndarray
    order: np.ndarray | None = None       # judge_all: each body's criterion.order


class Tavares:
    """The Tavares UFRJ criterion: breaks when Ek'/m > E (Eqs. 1-3); an event that ends without
    breakage weakens the body (Eqs. 5-6); t10' from Eq. 8."""

    #: bodies of this criterion are settled first in a read (see Controller._settle)
    order = 0
    #: steps after its creation during which a fragment counts no energy (the EDEM paper has none)
    default_pause_steps = 0
    #: reads of up to this many bodies are judged one by one (judging.Judge): measured, judge_one
    #: costs about 1 us per body, judge with the judge's numpy path 25 us per read plus 0.2 us
    #: per body
    judged_one_by_one = 24

    #: unload()'s events are damage events
    event_kind = "damage"

    def __init__(self, material, kappa_successive=None):
        self.material = material
        # Eq. 8's kappa for fragments (generation >= 1); None: the material's for every event
        self.kappa_successive = kappa_successive

    def overridden(self, kappa=None, emax_ratio=None):
        """The material with attach()'s overrides of kappa (Eq. 8) and Emax/E50 (Eq. 2)."""
        changes = {k: v for k, v in (("kappa", kappa), ("emax_ratio", emax_ratio)) if v is not None}
        return dataclasses.replace(self.material, **changes) if changes else self.material

    def sample(self, rng, sizes):
        return self.material.sample_fracture_energy(rng, sizes), {}

    def judge(self, table, ids, ek, specific):
        """judge_one on the bodies `ids` (arrays), as a Judgement."""
        return Judgement(*self.judge_one(table.columns, ids, ek, specific))

    @staticmethod
    def judge_one(c, i, ek, specific):
        """The criterion on body i (an id and scalars, or ids and arrays: the same operations),
        from the columns `c`: (breaks, level, threshold, rising, rise, jump) as in Judgement."""
        before = c["specific_energy"][i]
        threshold = c["fracture_energy"][i]
        rise = specific - before
        return specific > threshold, specific, threshold, specific > before, rise, rise

    @staticmethod
    def energy_to_break(table, ids):
        """Eq. 1's criterion: an event breaks the body if its Ek'/m passes E (after damage)."""
        return table.columns["fracture_energy"][ids]

    def unload(self, table, i):
        """Eqs. 5-6 with the event's largest Ek' (breakable bodies only)."""
        c = table.columns
        before = float(c["fracture_energy"][i])
        ratio = float(c["event_max"][i]) / (float(c["mass"][i]) * before)
        if c["kind"][i] != 1:
            return None
        after = float(model.weakened_fracture_energy(before, ratio, self.material.gamma))
        c["fracture_energy"][i] = after
        c["damage"][i] = 1.0 - after / float(c["fracture_energy_initial"][i])
        return {"fracture_energy": before, "fracture_energy_after": after, "ratio": ratio}

    def breakage(self, table, i, ek):
        mat, c = self.material, table.columns
        ratio = ek / (float(c["mass"][i]) * float(c["fracture_energy"][i]))
        kappa = (mat.kappa if self.kappa_successive is None or c["generation"][i] == 0
                 else self.kappa_successive)
        return ratio, float(model.t10(ratio, mat.A, mat.b_prime, kappa)), {}

    def force(self, table, i, ratio):
        return ratio * float(table.columns["mass"][i]) * float(table.columns["fracture_energy"][i])


class AbT10:
    """Rocky's Ab-T10 criterion: e_cum grows by Eq. 9.2 and the body breaks when it passes the
    threshold drawn at its creation (Eq. 9.3, kept as its fracture_energy); t10 from Eq. 9.4."""

    #: Eq. 9.2 is one call for all the Ab-T10 bodies read, settled after the Tavares ones
    order = 1
    #: Rocky's pause after a breakage event (Rocky manual, 2.4.2)
    default_pause_steps = 25
    #: see Tavares: Eq. 9.2 (model.ab_t10_update, numpy on any shape) costs about 20 us per body
    #: one by one, the numpy path about 40 us per read for up to 50 bodies: equal near 2 bodies
    judged_one_by_one = 2
    event_kind = "damage"

    def __init__(self, material):
        self.material = material

    def overridden(self, kappa=None, emax_ratio=None):
        """Ab-T10 has neither kappa nor Emax: attach()'s overrides leave it as it is."""
        return self.material

    def sample(self, rng, sizes):
        return (self.material.sample_fracture_energy(rng, sizes),
                {"e_min": self.material.min_energy(sizes)})

    def judge(self, table, ids, ek, specific):
        """judge_one on the bodies `ids` (arrays), as a Judgement."""
        return Judgement(*self.judge_one(table.columns, ids, ek, specific))

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
        if c["kind"][i] != 1:
            return None
        energy = float(c["fracture_energy"][i])
        c["damage"][i] = e_cum / energy
        return {"e_cum": e_cum, "fracture_energy": energy,
                "ratio": float(c["event_max"][i]) / (float(c["mass"][i]) * energy)}

    def breakage(self, table, i, ek):
        c = table.columns
        e_cum = float(c["e_cum"][i])
        t10 = float(self.material.t10_of_cumulative_energy(e_cum, 2.0 * float(c["radius"][i])))
        return e_cum / float(c["fracture_energy"][i]), t10, {"e_cum": e_cum}

    def force(self, table, i, ratio):
        c = table.columns
        c["e_cum"][i] = ratio * c["fracture_energy"][i]     # as if e_cum had reached it
        return ratio * float(c["mass"][i]) * float(c["fracture_energy"][i])


def judge_all(criterion_of, table, ids, active, ek, specific, every=False):
    """Every material's criterion on its active bodies among `ids` (vectorised per material);
    criterion_of[m] is the criterion of material index m; `every`: all bodies are active.
    Returns a Judgement over all `ids` (inactive rows: no breakage, not rising) with `order`,
    the criteria's settling order."""
    n = len(ids)
    if every and len(criterion_of) == 1:             # one material: no grouping
        crit = criterion_of[0]
        j = crit.judge(table, ids, ek, specific)
        j.order = np.full(n, crit.order, np.int8)
        return j
    out = Judgement(breaks=np.zeros(n, bool), level=np.zeros(n), threshold=np.ones(n),
                    rising=np.zeros(n, bool), rise=np.zeros(n), jump=np.zeros(n),
                    order=np.zeros(n, np.int8))
    materials = table.columns["material"][ids]
    for m in np.unique(materials[active]).tolist():
        rows = np.nonzero(active & (materials == m))[0]
        crit = criterion_of[m]
        j = crit.judge(table, ids[rows], ek[rows], specific[rows])
        for name in ("breaks", "level", "threshold", "rising", "rise", "jump"):
            getattr(out, name)[rows] = getattr(j, name)
        out.order[rows] = crit.order
    return out


class Recording:
    """No breakage and no damage (attach(breakage=False)): every stressing event is logged as
    'stressing' with its largest specific energy and partner, and the body stays as it was: the
    collision spectra of a scene. The material's own criterion draws the fracture energies (kept
    for the events' `ratio`); reads follow the loading only."""

    event_kind = "stressing"
    default_pause_steps = 0
    judged_one_by_one = Tavares.judged_one_by_one

    def __init__(self, inner):
        self.inner = inner
        self.material = inner.material
        self.order = inner.order

    def sample(self, rng, sizes):
        return self.inner.sample(rng, sizes)

    def judge(self, table, ids, ek, specific):
        return Judgement(*self.judge_one(table.columns, ids, ek, specific))

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
        if c["kind"][i] != 1:
            return None
        energy = float(c["fracture_energy"][i])
        return {"fracture_energy": energy,
                "ratio": float(c["event_max"][i]) / (float(c["mass"][i]) * energy)}

    def breakage(self, table, i, ek):             # break_body() still breaks
        return self.inner.breakage(table, i, ek)

    def force(self, table, i, ratio):
        return self.inner.force(table, i, ratio)


#: the YADE-side counterpart of each criterion of the model's registry (materials.CRITERIA),
#: by its name
_CRITERIA = {"tavares": Tavares, "ab_t10": AbT10}


def criterion_for(material, breakage=True, kappa_successive=None):
    """The criterion object of a breakable Material: the counterpart of the one its model
    names (Material.criterion); with breakage=False its Recording. kappa_successive: Eq. 8's
    kappa for fragments (Tavares materials; None: the material's)."""
    criterion = (Tavares(material, kappa_successive) if material.criterion.name == "tavares"
                 else _CRITERIA[material.criterion.name](material))
    return criterion if breakage else Recording(criterion)

