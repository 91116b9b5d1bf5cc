"""The engine's options: one table (name, default, accepted values, unit, help) that validates them
and renders their documentation, and the frozen groups the parts of the engine read. No yade import.

    config = Config.from_options(seed=1, read_period="fast", dummies="ledger")
    config.reading.read_period, config.replacement.dummies, config.time_step.fraction
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

from yadebreak.model.intervals import InputError, Interval


class AttachError(InputError, RuntimeError):
    """A scene or an option that yadebreak cannot work with; the message says what to change
    (a RuntimeError too, as it was first)."""


@dataclass(frozen=True)
class Option:
    """One row of the table: its group, default, accepted values (a check and its text), unit."""

    name: str
    group: str
    default: object
    check: object            # callable(value) -> bool
    accepted: str
    unit: str
    help: str


def _number(lo=-math.inf, hi=math.inf, lo_open=False, hi_open=False, none=False):
    accepted = Interval(lo, hi, lo_open, hi_open)

    def check(v):
        if v is None:
            return none
        return not isinstance(v, bool) and isinstance(v, (int, float)) and v in accepted
    return check


def _count(smallest, none=False):
    def check(v):
        if v is None:
            return none
        return isinstance(v, int) and not isinstance(v, bool) and v >= smallest
    return check


def _one_of(*values):
    return lambda v: isinstance(v, str) and v in values


def _boolean(v):
    return isinstance(v, bool)


def _read_period(v):
    return v in ("auto", "fast", "every_step") or _count(1)(v)


def _path_or_none(v):
    return v is None or isinstance(v, str)


OPTIONS = (
    # reading: the stressing energy taken from the contacts (Eqs. 14-16)
    Option("cs", "reading", 0.0, _number(0, 1), "[0, 1]", "-",
           "share of the tangential (shear) work counted in the stressing energy (Eq. 14)"),
    Option("emin", "reading", 1e-4, _number(0), ">= 0", "J",
           "a contact's energy counts once it holds at least this much (the paper's Emin)"),
    Option("read_period", "reading", "fast", _read_period,
           "'fast', 'every_step', an integer >= 1 or 'auto'", "steps",
           "how often contacts are read: 'fast' as often as the loading requires; 'every_step' "
           "every contact every step (the exact reference, the same as 1); every k steps; "
           "'auto' at read_fraction of the smallest breakable body's Rayleigh time"),
    Option("read_fraction", "reading", 0.05, _number(0, 1, lo_open=True), "(0, 1]", "-",
           "'auto': read at this fraction of the Rayleigh time of the smallest breakable body"),
    Option("fast_fraction", "reading", 0.25, _number(0, 1, lo_open=True), "(0, 1]", "-",
           "'fast': at least 1/this reads per Hertz loading time of the smallest tracked body "
           "(breakable, or an unbreakable fragment not yet stressed)"),
    Option("fast_tolerance", "reading", 0.02, _number(0, 1, lo_open=True), "(0, 1]", "-",
           "'fast': largest rise of a body's energy between reads, as a fraction of its "
           "fracture energy (a fresh contact's, at twice the top speed, included)"),
    # criteria: overrides of the material files and Rocky's safeguards
    Option("kappa", "criteria", None, _number(0, lo_open=True, none=True), "> 0 or None", "-",
           "overrides the material's kappa (Eq. 8); None keeps the file's"),
    Option("kappa_successive", "criteria", None, _number(0, lo_open=True, none=True),
           "> 0 or None", "-",
           "kappa of Eq. 8 for the breakage of fragments (generation >= 1; Tavares materials); "
           "None: the same as the first breakage's (the paper's)"),
    Option("break_at", "criteria", "threshold", _one_of("threshold", "peak"),
           "'threshold' or 'peak'", "-",
           "when a body breaks and which energy gives its t10' (Eq. 8): 'threshold' at the read "
           "where its energy first passes its fracture energy (the paper); 'peak' once the "
           "stressing event stops rising, t10' from the event's largest energy (unbreakable "
           "fragments likewise record the t10' of the event's peak)"),
    Option("emax_ratio", "criteria", None, _number(1, lo_open=True, none=True), "> 1 or None", "-",
           "overrides the material's Emax/E50 (Eq. 2); None keeps the file's"),
    Option("pause_steps", "criteria", None, _count(0, none=True), "an integer >= 0 or None",
           "steps", "steps after its creation during which a fragment counts no energy (Rocky's "
           "safeguard); None: 25 for Ab-T10 materials, 0 for Tavares ones"),
    Option("breakage", "criteria", True, _boolean, "True or False", "-",
           "False: nothing breaks or is damaged; every stressing event is recorded (kind "
           "'stressing', its largest specific energy and partner): a scene's collision spectra"),
    Option("fragments_energy_factor", "criteria", 1.0, _number(0, 1, lo_open=True), "(0, 1]", "-",
           "multiplies the specific energy that fragments see (Rocky's safeguard)"),
    # replacement: what a broken sphere becomes
    Option("replace", "replacement", True, _boolean, "True or False", "-",
           "replace broken spheres by their progeny (False: record the event only)"),
    Option("dmin", "replacement", None, _number(0, lo_open=True, none=True), "> 0 or None", "m",
           "fragments whose own progeny would be finer than this never break; None: top size / 20"),
    Option("dummies", "replacement", "spheres", _one_of("spheres", "ledger"),
           "'spheres' or 'ledger'", "-",
           "the unresolved fines: dummy spheres in the scene (the paper) or a mass ledger"),
    Option("dummy_stiffness", "replacement", 1.0, _number(0, 1, lo_open=True), "(0, 1]", "-",
           "Young's modulus of the dummy spheres as a share of their parent material's (the "
           "paper: the fines' class may be softer; dummies='spheres'); 1: the parent's"),
    Option("local_damping", "replacement", 0.0, _number(0, 1), "[0, 1]", "-",
           "share of a fragment's artificial overlap released as real force"),
    Option("zero_overlaps", "replacement", True, _boolean, "True or False", "-",
           "zero the artificial overlaps of fresh fragments (False only to show what it prevents)"),
    Option("zeroing_tolerance", "replacement", 0.05, _number(0, 1, hi_open=True), "[0, 1)", "-",
           "a zeroed pair that opens with no force is revisited only when its overlap may have "
           "shrunk by this share of itself (0: every step)"),
    Option("family_seed", "replacement", 0, _count(0), "an integer >= 0", "-",
           "seed of the family tables (not of the run: that is `seed`)"),
    # time step and fragment damping
    Option("time_step_fraction", "time_step", 0.05, _number(0, 1, lo_open=True, none=True),
           "(0, 1] or None", "-",
           "O.dt at most this fraction of the smallest sphere's Rayleigh time (a smaller O.dt set "
           "before attach is kept); None leaves O.dt to the user"),
    Option("global_damping", "time_step", None, _number(0, 1, hi_open=True, none=True),
           "[0, 1) or None", "-",
           "the paper's global damping of fragments: a force against each fragment's motion of "
           "this share of the force on it (YADE's Newton damping on fragments only; the parent "
           "never); None: each material file's global_damping (0.3 copper ore, else 0)"),
    Option("global_damping_time", "time_step", None, _number(0, none=True), ">= 0 or None", "s",
           "how long fresh fragments stay damped; None: for as long as they exist"),
    # output
    Option("event_log", "output", None, _path_or_none, "a path or None", "-",
           "JSON-lines file that receives every event as it happens"),
)

_BY_NAME = {o.name: o for o in OPTIONS}


@dataclass(frozen=True)
class Reading:
    cs: float
    emin: float
    read_period: int | str
    read_fraction: float
    fast_fraction: float
    fast_tolerance: float


@dataclass(frozen=True)
class Criteria:
    kappa: float | None
    kappa_successive: float | None
    break_at: str
    emax_ratio: float | None
    pause_steps: int | None
    breakage: bool
    fragments_energy_factor: float


@dataclass(frozen=True)
class Replacement:
    replace: bool
    dmin: float | None
    dummies: str
    dummy_stiffness: float
    local_damping: float
    zero_overlaps: bool
    zeroing_tolerance: float
    family_seed: int


@dataclass(frozen=True)
class TimeStep:
    time_step_fraction: float | None
    global_damping: float | None
    global_damping_time: float | None


@dataclass(frozen=True)
class Output:
    event_log: str | None


_GROUPS = {"reading": Reading, "criteria": Criteria, "replacement": Replacement,
           "time_step": TimeStep, "output": Output}


@dataclass(frozen=True)
class Config:
    """Every option of one attached engine, validated, in its groups."""

    seed: int
    reading: Reading
    criteria: Criteria
    replacement: Replacement
    time_step: TimeStep
    output: Output

    @classmethod
    def from_options(cls, seed=0, **options):
        """Check every option against the table (all problems at once, in one AttachError) and
        group them; unknown names are errors."""
        unknown = sorted(set(options) - set(_BY_NAME))
        if unknown:
            raise AttachError(f"unknown option(s) {unknown}; accepted: "
                              f"{sorted(n for n in _BY_NAME if n != 'family_seed')}")
        problems = []
        if not _count(0)(seed):
            problems.append(f"seed = {seed!r}: accepted an integer >= 0")
        values = {o.name: options.get(o.name, o.default) for o in OPTIONS}
        for o in OPTIONS:
            if not o.check(values[o.name]):
                unit = "" if o.unit == "-" else f" {o.unit}"
                problems.append(f"{o.name} = {values[o.name]!r}{unit}: accepted {o.accepted}")
        if values["dummies"] == "ledger" and values["dummy_stiffness"] != 1.0:
            problems.append(f"dummy_stiffness = {values['dummy_stiffness']!r}: needs "
                            "dummies='spheres' (a ledger keeps no dummy spheres)")
        if problems:
            raise AttachError("bad option(s): " + "; ".join(problems))
        groups = {g: kind(**{f.name: values[f.name] for f in fields(kind)})
                  for g, kind in _GROUPS.items()}
        return cls(seed=seed, **groups)

    def as_options(self):
        """The flat {name: value} this config was made from (saved with the scene)."""
        flat = {"seed": self.seed}
        for g in _GROUPS:
            group = getattr(self, g)
            flat.update({f.name: getattr(group, f.name) for f in fields(group)})
        return flat


def options_markdown():
    """The options as a Markdown table (README and docs render it from here)."""
    rows = ["| option | default | accepted | unit | what it does |", "|---|---|---|---|---|"]
    for o in OPTIONS:
        rows.append(f"| `{o.name}` | `{o.default!r}` | {o.accepted} | {o.unit} | {o.help} |")
    return "\n".join(rows)
