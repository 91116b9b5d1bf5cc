"""The engine's options: one table (name, default, accepted values, unit, help, what None means)
that validates them, renders their documentation and makes the scripts' flags of them
(engine_flags.py), and the frozen groups the parts of the engine read. No yade import.

    config = Config.from_options(seed=1, read_period="fast", dummies="ledger")
    config.reading.read_period, config.replacement.dummies, config.time_step.fraction
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

from yadebreak.model.intervals import PARTICLE_SIZE, InputError, Interval


class AttachError(InputError, RuntimeError):
    """A scene or an option that yadebreak cannot work with; the message says what to change
    (a RuntimeError too, as it was first)."""


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


@dataclass(frozen=True)
class Option:
    """One row of the table: its group, default, kind and accepted values, unit and help.

    kind: "number" (within `interval`), "count" (an integer within `interval`), "choice" (one of
    `words`), "boolean", "path" or "read_period" (one of `words` or a count within `interval`).
    `none`: what None means ('' if None is not accepted); `token`: how a command line writes
    None (a word, or a number outside the range), '' if scripts never pass None."""

    name: str
    group: str
    default: object
    kind: str
    unit: str
    help: str
    interval: Interval = Interval()
    words: tuple = ()
    none: str = ""
    token: object = ""

    def check(self, v):
        """True if attach() accepts `v` for this option."""
        if v is None:
            return bool(self.none)
        if self.kind == "number":
            return v in self.words or _number(self.interval.lo, self.interval.hi,
                                              self.interval.lo_open, self.interval.hi_open)(v)
        if self.kind == "count":
            return _count(self.interval.lo)(v)
        if self.kind == "choice":
            return _one_of(*self.words)(v)
        if self.kind == "boolean":
            return _boolean(v)
        if self.kind == "read_period":
            return v in self.words or _count(self.interval.lo)(v)
        return isinstance(v, str)                                   # path

    @property
    def accepted(self):
        """The accepted values as attach()'s error and docs/options.md write them."""
        interval = str(self.interval).removeprefix("in ")
        text = {"number": interval, "count": f"an integer {interval}",
                "choice": " or ".join(repr(w) for w in self.words), "boolean": "True or False",
                "path": "a path"}.get(self.kind)
        if self.kind == "read_period":
            first, *more, last = [repr(w) for w in self.words]
            text = ", ".join([first, *more, f"an integer {interval}"]) + f" or {last}"
        elif self.kind == "number" and self.words:
            text = " or ".join([text, *(repr(w) for w in self.words)])
        return text + (" or None" if self.none else "")

    @property
    def described(self):
        """The help with what None means (docs/options.md)."""
        return self.help + (f"; None: {self.none}" if self.none else "")


@dataclass(frozen=True)
class Outcome:
    """What a value of the `outcome` option fixes: when a body breaks (break_at) and how the
    dummies' unresolved fines are spread (model.dummy_fines_passing's `fines`)."""

    break_at: str
    fines: str


#: the values of `outcome`: the paper's reading, and the one whose product is the model's
OUTCOMES = {"paper": Outcome(break_at="threshold", fines="gaudin_schuhmann"),
            "model": Outcome(break_at="peak", fines="eq10")}


def _row(name, group, default, kind, unit, help, lo=-math.inf, hi=math.inf, lo_open=False,
         hi_open=False, **more):
    return Option(name, group, default, kind, unit, help, Interval(lo, hi, lo_open, hi_open),
                  **more)


OPTIONS = (
    # reading: the stressing energy taken from the contacts (Eqs. 14-16)
    _row("cs", "reading", 0.0, "number", "-",
         "share of the tangential (shear) work counted in the stressing energy (Eq. 14)", 0, 1),
    _row("emin", "reading", 1e-4, "number", "J",
         "a contact's energy counts once it holds at least this much (the paper's Emin)", 0),
    _row("read_period", "reading", "fast", "read_period", "steps",
         "how often contacts are read: 'fast' as often as the loading requires; 'every_step' "
         "every contact every step (the exact reference, the same as 1); every k steps; "
         "'auto' at read_fraction of the smallest breakable body's Rayleigh time", 1,
         words=("fast", "every_step", "auto")),
    _row("read_fraction", "reading", 0.05, "number", "-",
         "'auto': read at this fraction of the Rayleigh time of the smallest breakable body", 0, 1,
         lo_open=True),
    _row("fast_fraction", "reading", 0.25, "number", "-",
         "'fast': at least 1/this reads per Hertz loading time of the smallest tracked body "
         "(breakable, or an unbreakable fragment not yet stressed)", 0, 1, lo_open=True),
    _row("fast_tolerance", "reading", 0.02, "number", "-",
         "'fast': largest rise of a body's energy between reads, as a fraction of its "
         "fracture energy (a fresh contact's, at twice the top speed, included)", 0, 1,
         lo_open=True),
    # criteria: overrides of the material files and Rocky's safeguards
    _row("kappa", "criteria", None, "number", "-",
         "overrides the material's kappa (Eq. 8); 'batch': at each breakage the kappa at which "
         "Eq. 8's mean over the particles of the body's size that break at its specific energy "
         "is Eq. 7 (the paper's Section 2.2: 'Values of kappa were found to vary from about 0.95 "
         "to exp(sigma^2/2)'; Tavares materials; docs/model.md)", 0, lo_open=True,
         words=("batch",), none="keeps the file's", token=0.0),
    _row("kappa_successive", "criteria", None, "number", "-",
         "kappa of Eq. 8 for the breakage of fragments (generation >= 1; Tavares materials)", 0,
         lo_open=True, none="the same as the first breakage's (the paper's)", token=0.0),
    _row("outcome", "criteria", "paper", "choice", "-",
         "what a breakage makes (docs/model.md, 'The outcome of a breakage'): 'paper', t10' of "
         "Eq. 8 at the read where the energy first passes the fracture energy and the dummies' "
         "fines spread by Eqs. 11-12 (the paper's Fig. 17 text and Section 2.4); 'model', t10' "
         "of Eq. 8 at the whole stressing event's energy (break_at='peak') and the fines spread "
         "by Eq. 10, so that one breakage's product is Eq. 10 at its t10' (with kappa='batch' "
         "single impacts then follow Eq. 7; with kappa 1, Eq. 8's mean over the broken, up to "
         "exp(sigma^2/2) above it); 'model' refuses break_at='threshold' and "
         "t10_energy='e50b'",
         words=tuple(OUTCOMES)),
    _row("break_at", "criteria", None, "choice", "-",
         "when a body breaks and which energy gives its t10' (Eq. 8): 'threshold' at the read "
         "where its energy first passes its fracture energy (the paper); 'peak' once the "
         "stressing event stops rising, t10' from the event's largest energy (unbreakable "
         "fragments likewise record the t10' of the event's peak)",
         words=("threshold", "peak"), none="the outcome's ('threshold' for 'paper', 'peak' "
         "for 'model')", token="outcome"),
    _row("t10_energy", "criteria", "particle", "choice", "-",
         "the fracture energy in a breakage's t10' (Rocky's 'Energy for t10 Calculation'; "
         "Tavares materials): 'particle', the body's own (Eq. 8; Rocky's default, 'Current "
         "Particle Energy'); 'e50b', the median fracture energy of the particles of its size "
         "that break at the specific energy it absorbed (Eq. 7 with that E50b; Rocky's 'Median "
         "Specific Fracture Energy (e50b)')", words=("particle", "e50b")),
    _row("emax_ratio", "criteria", None, "number", "-", "overrides the material's Emax/E50 "
         "(Eq. 2)", 1, lo_open=True, none="keeps the file's", token=0.0),
    _row("pause_steps", "criteria", None, "count", "steps", "steps after its creation during "
         "which a fragment counts no energy (Rocky's safeguard)", 0,
         none="25 for Ab-T10 materials, 0 for Tavares ones", token="material"),
    _row("breakage", "criteria", True, "boolean", "-",
         "False: nothing breaks or is damaged; every stressing event is recorded (kind "
         "'stressing', its largest specific energy and partner): a scene's collision spectra"),
    _row("fragments_energy_factor", "criteria", 1.0, "number", "-",
         "multiplies the specific energy that fragments see (Rocky's safeguard)", 0, 1,
         lo_open=True),
    # replacement: what a broken sphere becomes
    _row("replace", "replacement", True, "boolean", "-",
         "replace broken spheres by their progeny (False: record the event only)"),
    _row("dmin", "replacement", None, "number", "m",
         "fragments whose own progeny would be finer than this never break", 0,
         PARTICLE_SIZE.hi, lo_open=True, none="top size / 20", token=0.0),
    _row("dummies", "replacement", "spheres", "choice", "-",
         "the unresolved fines: dummy spheres in the scene (the paper) or a mass ledger",
         words=("spheres", "ledger")),
    _row("dummy_stiffness", "replacement", 1.0, "number", "-",
         "Young's modulus of the dummy spheres as a share of their parent material's (the "
         "paper: the fines' class may be softer; dummies='spheres'); 1: the parent's", 0, 1,
         lo_open=True),
    _row("local_damping", "replacement", 0.0, "number", "-",
         "share of a fragment's artificial overlap released as real force", 0, 1),
    _row("contact_energy_at_break", "replacement", "dropped", "choice", "-",
         "the elastic energy a broken sphere's contacts hold at its breakage, which the zeroing "
         "of its fragments' overlaps takes out of the contacts: 'dropped' (the paper's "
         "zeroing); 'carried', counted as already absorbed by the fragments that take over each "
         "contact, shared by the Hertz energy of their overlaps, until their stressing event "
         "ends (the paper's Section 1: successive events 'if there is still energy remaining "
         "in the contact after the primary breakage event'; no force changes)",
         words=("dropped", "carried")),
    _row("zero_overlaps", "replacement", True, "boolean", "-",
         "zero the artificial overlaps of fresh fragments (False only to show what it prevents)"),
    _row("zeroing_tolerance", "replacement", 0.05, "number", "-",
         "a zeroed pair that opens with no force is revisited only when its overlap may have "
         "shrunk by this share of itself (0: every step)", 0, 1, hi_open=True),
    _row("overlap_factor", "replacement", None, "number", "-",
         "Rocky's breakage for large deformations: a tracked body whose contact overlap (on "
         "the volumetric law, the approach) passes this times dmin breaks at once at its "
         "present energy, or goes to the fines ledger if its volume is under 3 dmin^3", 0,
         lo_open=True, none="off", token=0.0),
    _row("min_volume_fraction", "replacement", 0.25, "number", "-",
         "Rocky's 'Minimum Volume Fraction for Fragment Disabling': a polyhedron's cell whose "
         "volume is under this times the cube of the event's smallest resolved size goes to "
         "the fines ledger (0: none)", 0, 1),
    _row("family_seed", "replacement", 0, "count", "-",
         "seed of the family tables (not of the run: that is `seed`)", 0),
    # time step and fragment damping
    _row("time_step_fraction", "time_step", 0.05, "number", "-",
         "O.dt at most this fraction of the smallest sphere's Rayleigh time (a smaller O.dt set "
         "before attach is kept)", 0, 1, lo_open=True, none="leaves O.dt to the user"),
    _row("global_damping", "time_step", None, "number", "-",
         "the paper's global damping of fragments: a force against each fragment's motion of "
         "this share of the force on it (YADE's Newton damping on fragments only; the parent "
         "never); 0: none", 0, 1, hi_open=True,
         none="each material file's global_damping (0.3 copper ore, else 0)", token="material"),
    _row("global_damping_time", "time_step", None, "number", "s",
         "how long fresh fragments stay damped", 0,
         none="for as long as they exist", token="forever"),
    # output
    _row("event_log", "output", None, "path", "-",
         "JSON-lines file that receives every event, written with the read that made it "
         "(missing folders are made)",
         none="no file"),
    _row("remote_access", "output", False, "boolean", "-",
         "keep the remote Python prompt and XMLRPC server that the `yade` launcher opens on "
         "every interface (ports 9000 and 21000 or up); False: attach() closes them and says so "
         "once"),
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
    outcome: str
    break_at: str
    t10_energy: str
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
    contact_energy_at_break: str
    zero_overlaps: bool
    zeroing_tolerance: float
    overlap_factor: float | None
    min_volume_fraction: float
    family_seed: int


@dataclass(frozen=True)
class TimeStep:
    time_step_fraction: float | None
    global_damping: float | None
    global_damping_time: float | None


@dataclass(frozen=True)
class Output:
    event_log: str | None
    remote_access: bool


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
        problems += _outcome_conflicts(values)
        if problems:
            raise AttachError("bad option(s): " + "; ".join(problems))
        if values["break_at"] is None:
            values["break_at"] = OUTCOMES[values["outcome"]].break_at
        groups = {g: kind(**{f.name: values[f.name] for f in fields(kind)})
                  for g, kind in _GROUPS.items()}
        return cls(seed=seed, **groups)

    @property
    def fines(self):
        """How the dummies' unresolved fines are spread (model.dummy_fines_passing's `fines`)."""
        return OUTCOMES[self.criteria.outcome].fines

    def as_options(self):
        """The flat {name: value} this config was made from (saved with the scene)."""
        flat = {"seed": self.seed}
        for g in _GROUPS:
            group = getattr(self, g)
            flat.update({f.name: getattr(group, f.name) for f in fields(group)})
        return flat


def _outcome_conflicts(values):
    """outcome='model' reads t10' of Eq. 8 at the event's whole energy: a threshold break or
    Rocky's e50b energy would be another reading, so each is refused in one line."""
    if values["outcome"] != "model":
        return []
    refused = {"break_at": ("threshold", "breaks at the stressing event's peak",
                            "'peak' or None"),
               "t10_energy": ("e50b", "takes the body's own fracture energy in Eq. 8",
                              "'particle'")}
    return [f"{name} = {value!r}: outcome='model' {why} (accepted with it: {accepted}); "
            "outcome='paper' takes the other readings"
            for name, (value, why, accepted) in refused.items() if values[name] == value]


def options_markdown():
    """The options as a Markdown table (README and docs render it from here)."""
    rows = ["| option | default | accepted | unit | what it does |", "|---|---|---|---|---|"]
    for o in OPTIONS:
        rows.append(f"| `{o.name}` | `{o.default!r}` | {o.accepted} | {o.unit} | {o.described} |")
    return "\n".join(rows)
