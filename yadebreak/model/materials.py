"""Material library: TOML files, read with tomllib, validated and converted to SI once.

A material name ('copper_ore') is looked for in the folders of material_search_path(): those
in $YADEBREAK_MATERIALS, then the working folder's materials/, then the files shipped with the
package (yadebreak/data/materials, also reached as materials/ at the top of the repository).

A file states its units as the paper prints them (mm, GPa, %); the Material object holds SI values
(m, Pa) except t10-related percentages (A), which stay in percent like t10 itself.
Never imports yade.
"""
from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Mapping

import numpy as np

from yadebreak import model
from yadebreak.model.intervals import DENSITY, PARTICLE_SIZE, POISSON_RATIO, YOUNG_MODULUS, InputError

#: the materials shipped with the package
MATERIALS_DIR = Path(__file__).resolve().parent.parent / "data" / "materials"

_N_KEYS = {"1.2": 1.2, "1.5": 1.5, "2": 2.0, "4": 4.0, "25": 25.0, "50": 50.0, "75": 75.0}


class MaterialError(InputError):
    """A material file that cannot be used. `problems` lists every problem found, one per line."""

    def __init__(self, source, problems):
        self.source = str(source)
        self.problems = list(problems)
        lines = "\n".join(f"  - {p}" for p in self.problems)
        super().__init__(f"material file {self.source} has {len(self.problems)} problem(s):\n{lines}")


@dataclass(frozen=True)
class ContactParams:
    """Contact parameters of a material pair (paper Table 6)."""

    friction: float
    rolling_friction: float
    restitution: float


@dataclass(frozen=True)
class Material:
    """An immutable material. SI units: density kg/m3, young_modulus Pa, d0 m, energies J/kg."""

    name: str
    source: str
    description: str
    breakable: bool
    density: float
    young_modulus: float
    poisson_ratio: float
    contacts: Mapping[str, ContactParams]
    contact_like: str | None = None
    breakage_model: str | None = None
    # Tavares breakage parameters (None for non-breakable materials)
    e_inf: float | None = None
    d0: float | None = None
    phi: float | None = None
    sigma: float | None = None
    emax_ratio: float | None = None
    gamma: float | None = None
    A: float | None = None
    b_prime: float | None = None
    kappa: float | None = None
    #: the paper's global damping of fresh fragments (0.3 for copper ore, 0 otherwise); attach's
    #: global_damping overrides it (docs/high_energy.md, "Global damping")
    global_damping: float = 0.0
    device_stiffness: float = model.DEVICE_STIFFNESS_STEEL
    beta_params: Mapping[float, tuple] | None = None
    beta_source: str | None = None
    # Ab-T10 parameters (docs/model.md Section 9; None unless breakage_model == "ab_t10")
    e_min_ref: float | None = None       # J/kg, at size_ref
    size_ref: float | None = None        # m
    selection: float | None = None       # S, kg/J
    t10_max: float | None = None         # M, %

    @property
    def criterion(self):
        """This material's breakage criterion (an object of CRITERIA, named by its file's
        breakage.model; Tavares when none): the one place where the criterion is chosen."""
        return CRITERIA[self.breakage_model or "tavares"](self)

    @property
    def is_ab_t10(self):
        """The criterion is Ab-T10 (for outputs and callers; this module asks `criterion`)."""
        return self.breakage_model == "ab_t10"

    # -- stiffness ---------------------------------------------------------------------------
    @property
    def hertz_stiffness(self):
        """k = Y / (1 - nu^2) in Pa."""
        return float(model.hertz_stiffness(self.young_modulus, self.poisson_ratio))

    def energy_partition(self, other):
        """Eq. 4: share of a contact's energy this material absorbs against `other` (a Material)."""
        return float(model.energy_partition(self.hertz_stiffness, other.hertz_stiffness))

    # -- breakage: the criterion's, asked of `criterion` ---------------------------------------
    def _need_breakable(self, what):
        if not self.breakable:
            raise ValueError(f"material '{self.name}' is not breakable: it has no {what}")

    def median_fracture_energy(self, size):
        """Eq. 3: E50 (J/kg) at particle size `size` (m), against this material's device stiffness.
        Ab-T10: the e_cum at which half the particles of that size break (Eq. 9.3 at u = 0.5)."""
        self._need_breakable("fracture energy")
        return self.criterion.median_fracture_energy(size)

    def min_energy(self, size):
        """Ab-T10, Eq. 9.1: e_min (J/kg) at size `size` (m)."""
        self._need_breakable("e_min")
        return model.ab_t10_min_energy(size, self.e_min_ref, self.size_ref)

    def fracture_energy_cdf(self, energy, size):
        """Probability that a particle of size `size` (m) has its fracture energy below `energy`:
        Eqs. 1-3 (Tavares); Eq. 9.3 (Ab-T10, where the fracture energy is the e_cum at which the
        particle breaks)."""
        return self.criterion.fracture_energy_cdf(energy, size)

    def fracture_energy_ppf(self, u, size):
        """The fracture energy (J/kg) at probability u for size `size` (m): Eqs. 1-3 inverted
        (Tavares); the e_cum threshold of strength u (Ab-T10, Eq. 9.3 inverted)."""
        return self.criterion.fracture_energy_ppf(u, size)

    def sample_fracture_energy(self, rng, size):
        """One fracture energy (J/kg) per size in `size` (m), from Generator `rng`: Eqs. 1-3
        (Tavares); for Ab-T10 the e_cum threshold of a strength drawn uniform in [0, 1)."""
        return self.criterion.sample_fracture_energy(rng, np.asarray(size, dtype=float))

    def absorbed(self, specific_energy, partner=None):
        """e Ek/mp (J/kg): the share (Eq. 4) of `specific_energy` = Ek/mp (J/kg) this material
        absorbs against `partner` (a Material; None: the energy given is already absorbed)."""
        share = 1.0 if partner is None else self.energy_partition(partner)
        return share * np.asarray(specific_energy, dtype=float)

    def breakage_probability(self, specific_energy, size, partner=None):
        """Probability that a fresh particle of size `size` (m) breaks when a contact brings it
        `specific_energy` = Ek/mp (J/kg), of which it absorbs e (Eq. 4) against `partner`
        (a Material; None means the energy given is already Ek'/mp).
        Ab-T10: P(e_cum) of the e_cum one such loading leaves (Eqs. 9.2-9.3, small steps)."""
        return self.criterion.probability_once(self.absorbed(specific_energy, partner), size)

    def t10(self, ratio):
        """Eq. 8 with this material's A, b' and kappa; ratio = Ek' / (mp E). Tavares only."""
        self._need_breakable("t10")
        return self.criterion.t10(ratio)

    def t10_model(self, specific_energy, size, partner=None):
        """The model's t10 (%) of particles of size `size` (m) each stressed once with
        `specific_energy` = Ek/mp (J/kg) against `partner` (a Material; None: the energy given is
        already absorbed). Tavares: Eq. 7 with the absorbed energy e Ek/mp and the median fracture
        energy of the particles that break at it (E50b). Ab-T10: the mean of Eq. 9.4 over the
        particles that break: each breaks when e_cum reaches its strength u (uniform), with
        t10 = M u, so the mean is M P / 2, P = P(e_cum) of one such loading. NaN where no particle
        breaks."""
        return self.criterion.t10_once(self.absorbed(specific_energy, partner), size)

    def t10_of_cumulative_energy(self, e_cum, size):
        """Ab-T10, Eq. 9.4: t10 (%) of a particle of size `size` (m) broken at e_cum (J/kg)."""
        return model.ab_t10_t10(e_cum, size, self.min_energy(size), self.selection,
                                self.size_ref, self.t10_max)

    @property
    def t10_min(self):
        """The smallest t10' (%) a breakage gives: Eq. 9 (Tavares). Ab-T10's t10 = M P(e_cum)
        has no floor; below AB_T10_T10_FLOOR % events take the family set of that floor."""
        self._need_breakable("t10")
        return self.criterion.t10_min

    @property
    def t10_ceiling(self):
        """The largest t10' (%): A (Tavares, Eq. 8) or M (Ab-T10, Eq. 9.4)."""
        return self.criterion.t10_ceiling

    def contact_with(self, other):
        """Contact parameters (Table 6) for the pair (self, other).

        Looked up, in order: either file's [contact.<other name>] table; the [contact.self] table
        when both are the same material; then, for a material that declares `contact_like = "X"`
        (rubber borrows steel's, as the paper did in Fig. 9), the partner's [contact.X] table.
        """
        candidates = [(self, other.name), (other, self.name)]
        if self.name == other.name:
            candidates.append((self, "self"))
        candidates += [(self, other.contact_like), (other, self.contact_like)]
        for mat, key in candidates:
            if key is not None and key in mat.contacts:
                return mat.contacts[key]
        raise KeyError(f"no contact parameters for the pair '{self.name}' / '{other.name}': add a "
                       f"[contact.{other.name}] table to {self.source} or a [contact.{self.name}] "
                       f"table to {other.source}")


# ------------------------------------------------------------------------------- validation
def in_file_unit(interval, factor):
    """(lower, lower inclusive, upper, upper inclusive) of a physical range (intervals.py, SI) in
    a file's unit worth `factor` SI units (GPa: 1e9)."""
    unit = interval.scaled(factor)
    return unit.lo, not unit.lo_open, unit.hi, not unit.hi_open


# (key, lower, lower inclusive, upper, upper inclusive, unit in file, SI factor)
_ELASTIC = [
    ("density", *in_file_unit(DENSITY, 1.0), "kg/m3", 1.0),
    ("young_modulus", *in_file_unit(YOUNG_MODULUS, 1e9), "GPa", 1e9),
    ("poisson_ratio", *in_file_unit(POISSON_RATIO, 1.0), "-", 1.0),
]
_TAVARES = [
    ("e_inf", 0.0, False, math.inf, False, "J/kg", 1.0),
    ("d0", *in_file_unit(PARTICLE_SIZE, 1e-3), "mm", 1e-3),
    ("phi", 0.0, True, 10.0, True, "-", 1.0),
    ("sigma", 0.0, False, 10.0, True, "-", 1.0),
    ("emax_ratio", 1.0, False, math.inf, False, "-", 1.0),
    ("gamma", 0.0, False, 1000.0, True, "-", 1.0),
    ("A", 0.0, False, 100.0, True, "%", 1.0),
    ("b_prime", 0.0, False, math.inf, False, "-", 1.0),
    ("kappa", 0.0, False, math.inf, False, "-", 1.0),
]
_AB_T10 = [
    ("e_min_ref", 0.0, True, math.inf, False, "J/kg", 1.0),
    ("size_ref", *in_file_unit(PARTICLE_SIZE, 1e-3), "mm", 1e-3),
    ("selection", 0.0, False, math.inf, False, "kg/J", 1.0),
    ("t10_max", 0.0, False, 100.0, True, "%", 1.0),
]
#: optional for every breakage model: the damping of fresh fragments (docs/high_energy.md)
_GLOBAL_DAMPING = ("global_damping", 0.0, True, 1.0, False, "-", 1.0)
#: Ab-T10 events with t10 below this (%) take the family set at this t10 (see Material.t10_min):
#: below it the 11 classes cannot follow Eq. 10 within 2 % (2.6 % at t10 = 1 %).
AB_T10_T10_FLOOR = 2.0
_CONTACT = [
    ("friction", 0.0, True, 10.0, True, "-", 1.0),
    ("rolling_friction", 0.0, True, 10.0, True, "-", 1.0),
    ("restitution", 0.0, False, 1.0, True, "-", 1.0),
]


# ------------------------------------------------------------------- the breakage criteria
class TavaresCriterion:
    """The Tavares UFRJ model of a material's breakage (Eqs. 1-3, 7-8): what the model layer
    (Material, reports) asks of a criterion. coupling.criteria holds its counterpart in YADE,
    picked by the same `name`."""

    name = "tavares"
    #: [breakage] keys of the file (see _parse_breakage) and the defaults of the optional ones
    keys, defaults = _TAVARES + [_GLOBAL_DAMPING], {"emax_ratio": 100.0, "kappa": 1.0,
                                                        "global_damping": 0.0}
    #: the plots' legends of the model's breakage probability and t10
    probability_label = "model (Eqs. 1-4)"
    t10_label = "model: Eq. 7, e Ek/mp over E50b of the broken particles"

    def __init__(self, material):
        self.material = material

    #: [breakage] keys beyond `keys`, read by parse_more
    more_keys = {"device_stiffness"}

    @staticmethod
    def parse_more(breakage, values, problems):
        """The keys more_keys of [breakage] into `values` (SI)."""
        dev = _number(breakage, "device_stiffness", "breakage", problems,
                      *in_file_unit(YOUNG_MODULUS, 1e9), "GPa", required=False,
                      default=model.DEVICE_STIFFNESS_STEEL / 1e9)
        values["device_stiffness"] = None if dev is None else dev * 1e9

    def median_fracture_energy(self, size):
        """Eq. 3: E50 (J/kg) at size `size` (m), against the material's device stiffness."""
        m = self.material
        return model.median_fracture_energy(size, m.e_inf, m.d0, m.phi, m.hertz_stiffness,
                                            m.device_stiffness)

    def fracture_energy_cdf(self, energy, size):
        """Eqs. 1-3: P(fracture energy < `energy` (J/kg)) at size `size` (m)."""
        m = self.material
        return model.fracture_energy_cdf(energy, m.median_fracture_energy(size), m.sigma,
                                         m.emax_ratio)

    def fracture_energy_ppf(self, u, size):
        """Eqs. 1-3 inverted: the fracture energy (J/kg) at probability u, size `size` (m)."""
        m = self.material
        return model.fracture_energy_ppf(u, m.median_fracture_energy(size), m.sigma, m.emax_ratio)

    def sample_fracture_energy(self, rng, size):
        """One fracture energy (J/kg) per size (m, an array) from Generator `rng`."""
        m = self.material
        return model.sample_fracture_energy(rng, m.median_fracture_energy(size), m.sigma,
                                            m.emax_ratio, size=size.shape)

    def probability_once(self, absorbed, size):
        """P that a fresh particle of size `size` (m) breaks when it absorbs `absorbed` (J/kg)."""
        return self.fracture_energy_cdf(absorbed, size)

    def t10(self, ratio):
        """Eq. 8 (%); ratio = Ek' / (mp E)."""
        m = self.material
        return model.t10(ratio, m.A, m.b_prime, m.kappa)

    def t10_once(self, absorbed, size):
        """Eq. 7 (%) at `absorbed` (J/kg) over E50b of the particles of size `size` (m) that
        break at it."""
        m = self.material
        e50b = model.median_fracture_energy_broken(absorbed, m.median_fracture_energy(size),
                                                   m.sigma, m.emax_ratio)
        return model.t10_batch(absorbed, e50b, m.A, m.b_prime)

    @property
    def t10_min(self):
        """Eq. 9 (%)."""
        m = self.material
        return float(model.t10_primary(m.A, m.b_prime, m.kappa))

    @property
    def t10_ceiling(self):
        """A (%), Eq. 8's largest t10'."""
        return self.material.A

    def intact_measures(self, e_cum_intact, size):
        """What the intact particles of an impact test carry for its result: nothing here."""
        return {}

    #: the repeated-impact plot's legend of the model (see repeated_broken_fraction)
    repeated_label = "model (Eqs. 1-6), gamma = {gamma:g}"

    def repeated_broken_fraction(self, absorbed, size, impacts):
        """Eqs. 1-6: the fraction of particles of size `size` (m) broken after each of
        `impacts` loadings, each absorbing `absorbed` (J/kg), damage weakening the survivors."""
        m = self.material
        e50 = float(m.median_fracture_energy(size))
        return model.repeated_impact_broken_fraction(absorbed, e50, m.sigma, m.emax_ratio,
                                                     m.gamma, impacts)


class AbT10Criterion:
    """Rocky's Ab-T10 model of a material's breakage (docs/model.md Section 9, Eqs. 9.1-9.4);
    see TavaresCriterion."""

    name = "ab_t10"
    keys, defaults = _AB_T10 + [_GLOBAL_DAMPING], {"global_damping": 0.0}
    probability_label = "model P(e_cum), e_cum = e Ek/mp - e_min (Eqs. 4, 9.1-9.3)"
    t10_label = "model: Eq. 9.4"

    def __init__(self, material):
        self.material = material

    more_keys = set()

    @staticmethod
    def parse_more(breakage, values, problems):
        """No keys beyond `keys`."""

    def median_fracture_energy(self, size):
        """The e_cum (J/kg) at which half the particles of size `size` (m) break."""
        return self.fracture_energy_ppf(0.5, size)

    def fracture_energy_cdf(self, energy, size):
        """Eq. 9.3: P(e_cum threshold < `energy` (J/kg)) at size `size` (m)."""
        m = self.material
        return model.ab_t10_probability(energy, size, m.min_energy(size), m.selection, m.size_ref)

    def fracture_energy_ppf(self, u, size):
        """Eq. 9.3 inverted: the e_cum threshold (J/kg) of strength u, size `size` (m)."""
        m = self.material
        return model.ab_t10_threshold(u, size, m.min_energy(size), m.selection, m.size_ref)

    def sample_fracture_energy(self, rng, size):
        """The e_cum threshold (J/kg) of a strength drawn uniform in [0, 1), per size (m)."""
        return self.fracture_energy_ppf(rng.random(size.shape), size)

    def probability_once(self, absorbed, size):
        """P(e_cum) of the e_cum one loading absorbing `absorbed` (J/kg) leaves (Eqs. 9.2-9.3)."""
        m = self.material
        return self.fracture_energy_cdf(model.ab_t10_single_impact_cum(absorbed,
                                                                       m.min_energy(size)), size)

    def t10(self, ratio):
        raise ValueError(f"material '{self.material.name}' uses Ab-T10: its t10 comes from e_cum "
                         "(t10_of_cumulative_energy), not from Eq. 8")

    def t10_once(self, absorbed, size):
        """The mean of Eq. 9.4 (%) over the particles that break after one loading absorbing
        `absorbed` (J/kg): M P / 2; NaN where none breaks."""
        m = self.material
        e_cum = model.ab_t10_single_impact_cum(absorbed, m.min_energy(size))
        t10 = 0.5 * m.t10_of_cumulative_energy(e_cum, size)
        return np.where(t10 > 0.0, t10, np.nan)

    @property
    def t10_min(self):
        """No floor in Eq. 9.4: AB_T10_T10_FLOOR (%), or M / 2 when smaller."""
        return min(AB_T10_T10_FLOOR, 0.5 * self.material.t10_max)

    @property
    def t10_ceiling(self):
        """M (%), Eq. 9.4's largest t10."""
        return self.material.t10_max

    def intact_measures(self, e_cum_intact, size):
        """The mean e_cum (J/kg) the intact particles of an impact test carry (what the broken
        ones would have reached) and P of it."""
        if not e_cum_intact:
            return {}
        e_cum = float(np.mean(e_cum_intact))
        return {"e_cum_measured": e_cum,
                "p_of_e_cum_measured": float(self.fracture_energy_cdf(e_cum, size))}

    repeated_label = "model P(e_cum), e_cum = k (e Ek/mp - e_min) (Eqs. 9.1-9.3)"

    def repeated_broken_fraction(self, absorbed, size, impacts):
        """Eqs. 9.1-9.3: the fraction broken after each of `impacts` loadings, each absorbing
        `absorbed` (J/kg), e_cum adding up over the impacts."""
        m = self.material
        return model.ab_t10_repeated_broken_fraction(absorbed, size, float(m.min_energy(size)),
                                                     m.selection, m.size_ref, impacts)


#: breakage.model -> its criterion: the one registry (coupling.criteria picks its YADE-side
#: counterpart by the same name)
CRITERIA = {c.name: c for c in (TavaresCriterion, AbT10Criterion)}


_TOP_KEYS = {"name", "description", "kind", "breakable", "contact_like", "elastic", "breakage",
             "contact"}
#: the kinds of material file: "replacement" (this module's; the default when `kind` is absent)
#: and "bonded_agglomerate" (spheres and binder, read by yadebreak.model.bonds)
KINDS = ("replacement", "bonded_agglomerate")


def _range_text(lo, lo_inc, hi, hi_inc):
    left = "[" if lo_inc else "("
    right = "]" if hi_inc else ")"
    hi_txt = "inf" if math.isinf(hi) else f"{hi:g}"
    return f"{left}{lo:g}, {hi_txt}{right}"


def _number(table, key, where, problems, lo, lo_inc, hi, hi_inc, unit, required=True,
            default=None):
    """Read one number, checking type and range; append any problem and return None on failure."""
    if key not in table:
        if required and default is None:
            problems.append(f"{where}.{key}: missing (a number in {unit}, accepted range "
                            f"{_range_text(lo, lo_inc, hi, hi_inc)})")
            return None
        return default
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        problems.append(f"{where}.{key}: must be a number in {unit}, got {type(value).__name__} "
                        f"{value!r}")
        return None
    value = float(value)
    ok_lo = value >= lo if lo_inc else value > lo
    ok_hi = value <= hi if hi_inc else value < hi
    if not (math.isfinite(value) and ok_lo and ok_hi):
        problems.append(f"{where}.{key} = {value:g} {unit} is out of range: accepted "
                        f"{_range_text(lo, lo_inc, hi, hi_inc)}{'' if unit == '-' else ' ' + unit}")
        return None
    return value


def _check_keys(table, allowed, where, problems):
    for key in table:
        if key not in allowed:
            problems.append(f"{where}.{key}: unknown key (allowed: {', '.join(sorted(allowed))})")


def _read_table(doc, key, where, problems, required=True):
    value = doc.get(key)
    if value is None:
        if required:
            problems.append(f"{where}{key}: missing table [{where}{key}]")
        return {}
    if not isinstance(value, dict):
        problems.append(f"{where}{key}: must be a table, got {type(value).__name__}")
        return {}
    return value


def _parse(doc, source):
    problems = []
    if doc.get("kind", "replacement") != "replacement":
        raise MaterialError(source, [f"kind = {doc.get('kind')!r}: a bonded-agglomerate material, "
                                     "read by yadebreak.model.bonds.load_agglomerate_material (this "
                                     "reader takes kind = \"replacement\")"])
    _check_keys(doc, _TOP_KEYS, "(top level)", problems)
    name = doc.get("name", Path(source).stem)
    if not isinstance(name, str) or not name:
        problems.append(f"name: must be a non-empty string, got {name!r}")
        name = Path(source).stem
    description = doc.get("description", "")
    if not isinstance(description, str):
        problems.append("description: must be a string")
    breakable = doc.get("breakable")
    if not isinstance(breakable, bool):
        problems.append(f"breakable: missing or not true/false (got {breakable!r})")
        breakable = False
    contact_like = doc.get("contact_like")
    if contact_like is not None and not isinstance(contact_like, str):
        problems.append("contact_like: must be the name of another material")
        contact_like = None
    values = _parse_elastic(doc, problems)
    contacts = _parse_contacts(doc, contact_like, problems)
    model_name, beta_params, beta_source = None, None, None
    if breakable:
        model_name, beta_params, beta_source = _parse_breakage(doc, values, problems)
    elif "breakage" in doc:
        problems.append("breakage: given for a material with breakable = false")
    if problems:
        raise MaterialError(source, problems)
    return Material(name=name, source=str(source), description=description, breakable=breakable,
                    contacts=MappingProxyType(contacts), contact_like=contact_like,
                    breakage_model=model_name, beta_params=beta_params, beta_source=beta_source,
                    **values)


def _parse_elastic(doc, problems):
    """[elastic]: {key: SI value or None}."""
    elastic = _read_table(doc, "elastic", "", problems)
    _check_keys(elastic, {k[0] for k in _ELASTIC}, "elastic", problems)
    values = {}
    for key, lo, lo_inc, hi, hi_inc, unit, factor in _ELASTIC:
        v = _number(elastic, key, "elastic", problems, lo, lo_inc, hi, hi_inc, unit)
        values[key] = None if v is None else v * factor
    return values


def _parse_contacts(doc, contact_like, problems):
    """[contact.<other>] tables: {other: ContactParams}."""
    contacts = {}
    contact_doc = _read_table(doc, "contact", "", problems, required=contact_like is None)
    for other, table in contact_doc.items():
        where = f"contact.{other}"
        if not isinstance(table, dict):
            problems.append(f"{where}: must be a table")
            continue
        _check_keys(table, {k[0] for k in _CONTACT}, where, problems)
        got = [_number(table, k, where, problems, lo, li, hi, hi_i, u)
               for k, lo, li, hi, hi_i, u, _ in _CONTACT]
        if None not in got:
            contacts[other] = ContactParams(*got)
    return contacts


def _parse_breakage(doc, values, problems):
    """[breakage] of a breakable material into `values` (SI); returns (model name, beta
    parameters, beta source)."""
    breakage = _read_table(doc, "breakage", "", problems)
    model_name = breakage.get("model", "tavares")
    if model_name not in CRITERIA:
        problems.append(f"breakage.model = {model_name!r}: accepted 'tavares' (the default) "
                        "or 'ab_t10'")
        model_name = "tavares"
    criterion = CRITERIA[model_name]
    allowed = {k[0] for k in criterion.keys} | {"model", "beta", "beta_source"}
    _check_keys(breakage, allowed | criterion.more_keys, "breakage", problems)
    for key, lo, lo_inc, hi, hi_inc, unit, factor in criterion.keys:
        v = _number(breakage, key, "breakage", problems, lo, lo_inc, hi, hi_inc, unit,
                    default=criterion.defaults.get(key))
        values[key] = None if v is None else v * factor
    criterion.parse_more(breakage, values, problems)
    beta_source = breakage.get("beta_source", "material")
    if beta_source not in ("material", "table1"):
        problems.append(f"breakage.beta_source = {beta_source!r}: accepted 'material' (the "
                        "[breakage.beta] table) or 'table1' (the paper's Table 1 average)")
    if beta_source == "table1":
        if "beta" in breakage:
            problems.append("breakage.beta: given although beta_source = 'table1'; remove one")
        return model_name, model.TABLE1_BETA_PARAMS, beta_source
    return model_name, _parse_beta(_read_table(breakage, "beta", "breakage.", problems),
                                   problems), beta_source


def _parse_beta(beta_table, problems):
    """[breakage.beta]: {n: (alpha, beta)} for the seven n of Eq. 10, or None if incomplete."""
    _check_keys(beta_table, set(_N_KEYS), "breakage.beta", problems)
    parsed = {}
    for key, n in _N_KEYS.items():
        pair = beta_table.get(key)
        where = f'breakage.beta."{key}"'
        if pair is None:
            if beta_table:
                problems.append(f"{where}: missing ([alpha, beta] for n = {key})")
            continue
        if (not isinstance(pair, list) or len(pair) != 2
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in pair)):
            problems.append(f"{where}: must be a pair of numbers [alpha, beta], got {pair!r}")
            continue
        if not all(math.isfinite(v) and v > 0 for v in pair):
            problems.append(f"{where} = {pair}: alpha and beta must be > 0, accepted range "
                            "(0, inf)")
            continue
        parsed[n] = (float(pair[0]), float(pair[1]))
    return MappingProxyType(parsed) if len(parsed) == 7 else None


def material_search_path():
    """The folders a material name is looked for in, in order: those listed in
    $YADEBREAK_MATERIALS (separated by os.pathsep), the working folder's materials/, and the
    materials shipped with the package."""
    listed = [Path(p) for p in os.environ.get("YADEBREAK_MATERIALS", "").split(os.pathsep) if p]
    return [*listed, Path.cwd() / "materials", MATERIALS_DIR]


def available_materials(directory=None, kind="replacement"):
    """Names of the material files of `kind` (one of KINDS; None: all) in `directory`, or in
    every folder of the search path."""
    if kind is not None and kind not in KINDS:
        raise ValueError(f"kind = {kind!r}: accepted {', '.join(KINDS)} or None")
    folders = [Path(directory)] if directory is not None else material_search_path()
    return sorted({p.stem for folder in folders for p in folder.glob("*.toml")
                   if kind is None or _kind_of(p) == kind})


def _kind_of(path):
    """The `kind` of a material file (files that do not parse count as "replacement", whose
    reader reports their problems)."""
    try:
        return tomllib.loads(path.read_text(encoding="utf-8")).get("kind", "replacement")
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return "replacement"


def _find(name):
    """The file of material `name` along the search path, or None."""
    for folder in material_search_path():
        path = folder / f"{name}.toml"
        if path.is_file():
            return path
    return None


def load_material(name_or_path):
    """Load and validate a material: a name ('copper_ore', looked for along
    material_search_path()) or a path to a .toml file.

    Every problem is reported at once in a MaterialError naming the file, the field and the
    accepted range. Unknown names list the available materials.
    """
    text = str(name_or_path)
    path = Path(text)
    if not (text.endswith(".toml") or path.exists()):
        path = _find(text)
        if path is None:
            raise MaterialError(text, [f"unknown material '{text}': available are "
                                       f"{', '.join(available_materials())} (or give a path to a "
                                       ".toml file, or list folders in $YADEBREAK_MATERIALS)"])
    if not path.is_file():
        raise MaterialError(path, ["file not found"])
    raw = path.read_bytes()
    if not raw.strip():
        raise MaterialError(path, ["the file is empty: see materials/copper_ore.toml for the format"])
    try:
        doc = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise MaterialError(path, [f"not valid TOML: {exc}"]) from None
    return _parse(doc, path)
