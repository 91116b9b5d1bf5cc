"""Material library: TOML files, read with tomllib, validated and converted to SI once.

A material name ('copper_ore') is looked for in the folders of material_search_path(): those
in $YADEBREAK_MATERIALS, then the working folder's materials/, then the files shipped with the
package (yadebreak/data/materials, also reached as materials/ at the top of the repository).

This module reads what every material shares: [elastic], [contact.*], and of [breakage] the
criterion's name (`model`), the fragments' global damping and Eq. 10's table. The rest of
[breakage] belongs to the criterion it names, which parses it into its parameter object
(`Material.params`): parse() takes the registry of criteria from its caller
(yadebreak.criteria.load_material), since this room may not import them.

A file states its units as the paper prints them (mm, GPa, %); the Material object holds SI values
(m, Pa) except t10-related percentages (A), which stay in percent like t10 itself.
Never imports yade.
"""
from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from types import MappingProxyType
from typing import Mapping, NamedTuple

import numpy as np

from yadebreak import model
from yadebreak.model.intervals import DENSITY, POISSON_RATIO, YOUNG_MODULUS, InputError

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
    """An immutable material: what every material has (SI units: density kg/m3, young_modulus Pa)
    and, for a breakable one, its criterion's parameters as one object (`params`, the class its
    criterion declares; None for a material that does not break)."""

    name: str
    source: str
    description: str
    breakable: bool
    density: float
    young_modulus: float
    poisson_ratio: float
    contacts: Mapping[str, ContactParams]
    contact_like: str | None = None
    #: the file's breakage.model, the name of the criterion (None for a material that does not
    #: break)
    breakage_model: str | None = None
    #: the criterion's parameters (yadebreak.criteria: Tavares's, Ab-T10's), SI
    params: object = None
    #: the paper's global damping of fresh fragments (0.3 for copper ore, 0 otherwise); attach's
    #: global_damping overrides it (docs/high_energy.md, "Global damping")
    global_damping: float = 0.0
    beta_params: Mapping[float, tuple] | None = None
    beta_source: str | None = None

    def __getattr__(self, name):
        params = self.__dict__.get("params")
        if params is not None and hasattr(params, name):
            raise AttributeError(f"Material has no attribute {name!r}: it is a parameter of its "
                                 f"criterion, material.params.{name}")
        raise AttributeError(f"'Material' object has no attribute {name!r}")

    def with_params(self, **changes):
        """The same material with some of its criterion's parameters changed (SI)."""
        return dataclasses.replace(self, params=dataclasses.replace(self.params, **changes))

    @cached_property
    def criterion(self):
        """This material's breakage criterion, made by its parameters' class (the criterion the
        file names): the one place where the criterion is chosen, made once per material, so the
        model and the engine ask the same object."""
        self._need_breakable("breakage criterion")
        return self.params.criterion(self)

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
        return self.criterion.min_energy(size)

    def fracture_energy_cdf(self, energy, size):
        """Probability that a particle of size `size` (m) has its fracture energy below `energy`:
        Eqs. 1-3 (Tavares); Eq. 9.3 (Ab-T10, where the fracture energy is the e_cum at which the
        particle breaks)."""
        return self.criterion.cdf(energy, size)

    def fracture_energy_ppf(self, u, size):
        """The fracture energy (J/kg) at probability u for size `size` (m): Eqs. 1-3 inverted
        (Tavares); the e_cum threshold of strength u (Ab-T10, Eq. 9.3 inverted)."""
        return self.criterion.ppf(u, size)

    def sample_fracture_energy(self, rng, size):
        """One fracture energy (J/kg) per size in `size` (m), from Generator `rng`: Eqs. 1-3
        (Tavares); for Ab-T10 the e_cum threshold of a strength drawn uniform in [0, 1)."""
        return self.criterion.rvs(rng, size)

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
        return self.criterion.t10_of_cumulative_energy(e_cum, size)

    @property
    def t10_min(self):
        """The smallest t10' (%) a breakage gives: Eq. 9 (Tavares). Ab-T10's t10 = M P(e_cum)
        has no floor; below criteria.ab_t10.AB_T10_T10_FLOOR % events take the family set of
        that floor."""
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
class Key(NamedTuple):
    """One number of a material file: its name, the accepted range in the file's unit (bounds
    and whether each is accepted), that unit, the factor to SI, and its default (None:
    required)."""

    name: str
    lo: float
    lo_inclusive: bool
    hi: float
    hi_inclusive: bool
    unit: str
    factor: float = 1.0
    default: float | None = None

    @classmethod
    def of(cls, name, interval, unit, factor=1.0, default=None):
        """The key of a physical range (intervals.py, SI) read in a file unit worth `factor` SI
        units (GPa: 1e9)."""
        scaled = interval.scaled(factor)
        return cls(name, scaled.lo, not scaled.lo_open, scaled.hi, not scaled.hi_open, unit,
                   factor, default)

    def read(self, table, where, problems):
        """The key's value in `table` in SI (its default, or None and a problem, if absent or
        wrong)."""
        value = read_number(table, self.name, where, problems, self.lo, self.lo_inclusive,
                            self.hi, self.hi_inclusive, self.unit, default=self.default)
        return None if value is None else value * self.factor


def read_keys(table, keys, where, problems):
    """{key name: SI value or None} of `keys` in `table`, unknown keys reported."""
    check_keys(table, {k.name for k in keys}, where, problems)
    return {k.name: k.read(table, where, problems) for k in keys}


_ELASTIC = (Key.of("density", DENSITY, "kg/m3"), Key.of("young_modulus", YOUNG_MODULUS, "GPa", 1e9),
            Key.of("poisson_ratio", POISSON_RATIO, "-"))
_CONTACT = (Key("friction", 0.0, True, 10.0, True, "-"),
            Key("rolling_friction", 0.0, True, 10.0, True, "-"),
            Key("restitution", 0.0, False, 1.0, True, "-"))
#: the [breakage] keys every criterion shares: the criterion's name, Eq. 10's table and where it
#: comes from, and the damping of fresh fragments (docs/high_energy.md)
GLOBAL_DAMPING = Key("global_damping", 0.0, True, 1.0, False, "-", 1.0, 0.0)
SHARED_BREAKAGE_KEYS = frozenset({"model", "beta", "beta_source", GLOBAL_DAMPING.name})
#: the criterion a [breakage] table without `model` names
DEFAULT_CRITERION = "tavares"


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


def read_number(table, key, where, problems, lo, lo_inc, hi, hi_inc, unit, default=None):
    """Read one number, checking type and range; append any problem and return None on failure
    (absent: `default`, a problem if it is None)."""
    if key not in table:
        if default is None:
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


def check_keys(table, allowed, where, problems):
    """Report every key of `table` not in `allowed`."""
    for key in table:
        if key not in allowed:
            problems.append(f"{where}.{key}: unknown key (allowed: {', '.join(sorted(allowed))})")


def read_table(doc, key, where, problems, required=True):
    """The sub-table `key` of `doc` ({} and a problem if absent or not a table)."""
    value = doc.get(key)
    if value is None:
        if required:
            problems.append(f"{where}{key}: missing table [{where}{key}]")
        return {}
    if not isinstance(value, dict):
        problems.append(f"{where}{key}: must be a table, got {type(value).__name__}")
        return {}
    return value


def parse(doc, source, criteria):
    """The Material of a parsed TOML document `doc` read from `source`; `criteria`: {name:
    criterion class} of the criteria a file may name (the class parses its own [breakage] keys:
    criteria.base.Criterion.parse). Raises MaterialError listing every problem."""
    problems = []
    if doc.get("kind", "replacement") != "replacement":
        raise MaterialError(source, [f"kind = {doc.get('kind')!r}: a bonded-agglomerate material, "
                                     "read by yadebreak.model.bonds.load_agglomerate_material (this "
                                     "reader takes kind = \"replacement\")"])
    check_keys(doc, _TOP_KEYS, "(top level)", problems)
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
    breakage = {}
    if breakable:
        breakage = _parse_breakage(doc, criteria, problems)
    elif "breakage" in doc:
        problems.append("breakage: given for a material with breakable = false")
    if problems:
        raise MaterialError(source, problems)
    return Material(name=name, source=str(source), description=description, breakable=breakable,
                    contacts=MappingProxyType(contacts), contact_like=contact_like,
                    **values, **breakage)


def _parse_elastic(doc, problems):
    """[elastic]: {key: SI value or None}."""
    return read_keys(read_table(doc, "elastic", "", problems), _ELASTIC, "elastic", problems)


def _parse_contacts(doc, contact_like, problems):
    """[contact.<other>] tables: {other: ContactParams}."""
    contacts = {}
    contact_doc = read_table(doc, "contact", "", problems, required=contact_like is None)
    for other, table in contact_doc.items():
        where = f"contact.{other}"
        if not isinstance(table, dict):
            problems.append(f"{where}: must be a table")
            continue
        got = read_keys(table, _CONTACT, where, problems)
        if None not in got.values():
            contacts[other] = ContactParams(**got)
    return contacts


def _parse_breakage(doc, criteria, problems):
    """[breakage] of a breakable material: the Material fields it gives (the criterion's name
    and parameters, the global damping, Eq. 10's table and its source)."""
    breakage = read_table(doc, "breakage", "", problems)
    model_name = breakage.get("model", DEFAULT_CRITERION)
    if model_name not in criteria:
        accepted = " or ".join(f"{n!r}" + (" (the default)" if n == DEFAULT_CRITERION else "")
                               for n in criteria)
        problems.append(f"breakage.model = {model_name!r}: accepted {accepted}")
        model_name = DEFAULT_CRITERION
    criterion = criteria[model_name]
    check_keys(breakage, SHARED_BREAKAGE_KEYS | criterion.file_keys(), "breakage", problems)
    fields = {"breakage_model": model_name,
              "params": criterion.parse(breakage, "breakage", problems),
              "global_damping": GLOBAL_DAMPING.read(breakage, "breakage", problems)}
    beta_source = breakage.get("beta_source", "material")
    if beta_source not in ("material", "table1"):
        problems.append(f"breakage.beta_source = {beta_source!r}: accepted 'material' (the "
                        "[breakage.beta] table) or 'table1' (the paper's Table 1 average)")
    if beta_source == "table1":
        if "beta" in breakage:
            problems.append("breakage.beta: given although beta_source = 'table1'; remove one")
        return {**fields, "beta_params": model.TABLE1_BETA_PARAMS, "beta_source": beta_source}
    return {**fields, "beta_source": beta_source,
            "beta_params": _parse_beta(read_table(breakage, "beta", "breakage.", problems),
                                       problems)}


def _parse_beta(beta_table, problems):
    """[breakage.beta]: {n: (alpha, beta)} for the seven n of Eq. 10, or None if incomplete."""
    check_keys(beta_table, set(_N_KEYS), "breakage.beta", problems)
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


def find_material_file(name):
    """The file of material `name` along the search path, or None."""
    for folder in material_search_path():
        path = folder / f"{name}.toml"
        if path.is_file():
            return path
    return None


def load_material(name_or_path, criteria):
    """Load and validate a material: a name ('copper_ore', looked for along
    material_search_path()) or a path to a .toml file; `criteria`: {name: criterion class} (see
    parse). Users call yadebreak.load_material, which gives the package's criteria.

    Every problem is reported at once in a MaterialError naming the file, the field and the
    accepted range. Unknown names list the available materials.
    """
    text = str(name_or_path)
    path = Path(text)
    if not (text.endswith(".toml") or path.exists()):
        path = find_material_file(text)
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
    return parse(doc, path, criteria)
