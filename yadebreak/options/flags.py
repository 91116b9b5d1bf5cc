"""Parameters of scripts: `--name value` on the command line, or a yade-batch table row.

Each option is declared once, with its type, accepted range, unit, default and help:

    args = script_params([
        number("size", 5.5e-3, "m", "particle size", lo=0, lo_open=True, hi=1),
        integer("rings", 3, "hexagonal rings around the central particle", lo=0),
        text("out", "out/x", "output folder"),
    ], __doc__)

Under yade-batch (YADE_BATCH set), the table's row supplies the values (the caller's table_row:
readParamsFromTable through coupling.yade_api; this module never imports yade); otherwise argparse
reads sys.argv. Either way every value is checked against its declaration before anything
runs: a bad value stops with one line on stderr naming the option, the value, the accepted range
and the unit (`[yadebreak] error: --energy = -1: must be > 0 (J)`), exit code 2, as argparse does;
`--debug 1` shows the traceback instead. Units: plain numbers are SI (m, s, J, J/kg, m/s); the
option's own unit may follow the number, with or without a space (`--size 5.5mm`, `--size
"5.5e-3 m"`, `--energy 3.05J`, `--energies 100J/kg,200J/kg`), another one is refused. An option
whose plain numbers are not SI says so in its unit: "mm" (grind's sizes), "min" (minutes); a
length unit converts to it (`--feed 8mm`, `--feed "0.008 m"`).

How a run goes once its options are read (exit codes, signals, the lock on --out, checkpoints,
partial results, finish markers, progress lines) is yadebreak.jobs.lifecycle's; the options of
each job are declared in yadebreak.jobs.options.
"""
import argparse
import math
import os
import re
import sys
from dataclasses import dataclass
from decimal import Decimal

from yadebreak.model.intervals import PARTICLE_SIZE, Interval
from yadebreak.process.scheduler import FORMS, SchedulerError, chosen

#: unit of an option -> the units accepted after a number, with their factor to that unit
UNITS = {
    "m": {"m": "1", "cm": "1e-2", "mm": "1e-3", "um": "1e-6"},
    "mm": {"mm": "1", "m": "1e3", "cm": "10", "um": "1e-3"},      # plain numbers in millimetres
    "s": {"s": "1", "ms": "1e-3"},
    "min": {"min": "1", "s": "1/60", "h": "60"},   # plain numbers in minutes
    "kg": {"kg": "1", "g": "1e-3", "t": "1e3"},
    "J": {"J": "1"},
    "J/kg": {"J/kg": "1"},
    "m/s": {"m/s": "1"},
    "%": {"%": "1"},
    "-": {},
}
_NUMBER_THEN_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S.*?)\s*$")
_TRUE, _FALSE = ("1", "true", "yes", "on"), ("0", "false", "no", "off")
_DEBUG = False                  # --debug 1: tracebacks instead of one-line errors
_QUIET = False                  # --quiet 1: no progress lines
_SCRIPT_OPTIONS = set()         # the running script's option names (warnings name them)


class ParamError(ValueError):
    """A bad value of a script's option; the message names the option, the value, the accepted
    range and the unit."""


@dataclass(frozen=True)
class Param:
    """One option of a script; build it with number, integer, numbers, choice, flag or text."""

    name: str
    default: object
    kind: str                  # "number", "integer", "numbers", "choice", "flag" or "text"
    unit: str = "-"            # a key of UNITS ("-": no unit)
    help: str = ""
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    hi_open: bool = False
    words: tuple = ()          # choice: the accepted words; integer, number: words besides numbers
    empty: bool = True         # text: '' accepted (False: an output folder, a list to run)
    why: str = ""              # why the default is this job's (shown after it in --help)

    @property
    def flag(self):
        return "--" + self.name.replace("_", "-")

    @property
    def numeric(self):
        return self.kind in ("number", "integer", "numbers")

    @property
    def accepted(self):
        """The accepted values, as the error line and --help write them."""
        if self.kind == "flag":
            return "0 or 1"
        if self.kind == "choice":
            return " or ".join(repr(w) for w in self.words)
        if self.kind == "text":
            return "a text" if self.empty else "a non-empty text"
        interval = str(self.interval)
        if self.kind == "integer":
            interval = "an integer" + ("" if interval == "any number" else f" {interval}")
            if self.words:
                interval += ", " + " or ".join(repr(w) for w in self.words)
        elif self.kind == "number" and self.words:
            interval += " or " + " or ".join(repr(w) for w in self.words)
        elif self.kind == "numbers":
            interval = f"distinct numbers separated by commas, each {interval}"
        return interval

    @property
    def unit_text(self):
        return "no unit" if self.unit == "-" else self.unit

    @property
    def help_line(self):
        """--help's line, one convention for every script: what it is; accepted values and unit
        (and the units that may follow a number); default."""
        parts = [self.help] if self.help else []
        if self.numeric:
            accepted = f"{self.accepted} ({self.unit_text})"
            if self.kind != "integer" and UNITS.get(self.unit):
                accepted += ", a unit may follow the number: " + ", ".join(UNITS[self.unit])
            parts.append(accepted)
        elif self.kind in ("flag", "choice"):
            parts.append(self.accepted)
        default = int(bool(self.default)) if self.kind == "flag" else self.default
        unit = f" {self.unit}" if self.numeric and self.unit != "-" else ""
        unit = "" if default in self.words else unit
        if default is None and self.why:
            parts.append(f"default: {self.why}")
        else:
            parts.append(f"default {default}{unit}" + (f" ({self.why})" if self.why else ""))
        return "; ".join(parts).replace("%", "%%")       # argparse %-formats help strings

    def _error(self, value, why=""):
        unit = f" ({self.unit_text})" if self.numeric else ""
        return ParamError(f"{self.flag} = {value}: must be {self.accepted}{unit}{why}")

    @property
    def interval(self):
        return Interval(self.lo, self.hi, self.lo_open, self.hi_open)

    def _in_range(self, v):
        return v in self.interval

    def _number(self, text, shown):
        """A float from `text`: a plain number (SI, parsed as float() always has), or a number
        followed by one of the option's units (scaled exactly: 5.5mm is 5.5e-3)."""
        try:
            return float(text)
        except ValueError:
            pass
        match = _NUMBER_THEN_UNIT.match(text)
        if not match:
            raise self._error(shown, f"; {text.strip()!r} is not a number")
        number, unit = match.groups()
        factors = UNITS[self.unit]
        if unit not in factors:
            known = any(unit in table for table in UNITS.values())
            own = ", ".join(factors) if factors else "none"
            raise self._error(shown, f"; {'the unit ' if known else ''}{unit!r} is not accepted "
                                     f"here (units accepted: {own})")
        return scaled(number, factors[unit])

    def convert(self, value):
        """The checked value of this option from a command-line text or a yade-batch table value;
        raises ParamError."""
        shown = value
        if value is None and self.default is None:     # a default of None: "not given"
            return None
        if self.kind == "text":
            if not self.empty and not str(value).strip():
                raise self._error(repr(str(value)))
            return str(value)
        if self.kind == "flag":
            if isinstance(value, bool):
                return value
            word = str(value).strip().lower()
            if word in _TRUE or word in _FALSE:
                return word in _TRUE
            raise self._error(shown)
        if self.kind == "choice":
            if value in self.words:
                return value
            raise self._error(shown)
        if self.kind == "numbers":
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                value = str(value)
            if not isinstance(value, str):
                raise self._error(shown)
            texts, numbers = [], []
            for token in value.split(","):
                x = self._number(token.strip(), shown)
                if not self._in_range(x):
                    raise self._error(shown)
                # kept as text (the scripts read float() of each, as always), without its unit
                match = _NUMBER_THEN_UNIT.match(token)
                if match is None or match.group(2) not in UNITS[self.unit]:
                    texts.append(token.strip())
                elif UNITS[self.unit][match.group(2)] == "1":
                    texts.append(match.group(1))
                else:
                    texts.append(repr(x))
                numbers.append(x)
            if len(set(numbers)) != len(numbers):
                raise self._error(shown)
            return ",".join(texts)
        if self.kind == "integer":
            if isinstance(value, str):
                word = value.strip()
                if word in self.words:
                    return word
                try:
                    value = int(word)
                except ValueError:
                    raise self._error(shown) from None
            if isinstance(value, bool) or not isinstance(value, int) or not self._in_range(value):
                raise self._error(shown)
            return value
        # number
        if isinstance(value, str) and value.strip() in self.words:
            return value.strip()
        plain = isinstance(value, str) and _is_float(value)
        if isinstance(value, str):
            value = self._number(value, shown)
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not self._in_range(value):
            hint = ""
            if plain and self.unit == "m" and value > self.hi:
                hint = f"; plain numbers are metres: {shown.strip()}mm for millimetres"
            raise self._error(shown, hint)
        return value


def scaled(number, factor):
    """float(number) times a factor of UNITS ("1e-3", or a ratio "1/60"), exactly in decimal."""
    if factor == "1":
        return float(number)
    top, _, bottom = factor.partition("/")
    return float(Decimal(number) * Decimal(top) / Decimal(bottom or "1"))


def number_and_unit(text):
    """('8', 'mm') of '8mm' or '8 mm', ('5.5', '') of '5.5'; None if `text` is no number."""
    if _is_float(text):
        return text.strip(), ""
    match = _NUMBER_THEN_UNIT.match(text)
    return match.groups() if match else None


def _is_float(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


def number(name, default, unit, help, lo=-math.inf, hi=math.inf, lo_open=False, hi_open=False,
           words=()):
    """A real number in `unit` (a key of UNITS), in [lo, hi] (open ends as asked), or one of
    `words`."""
    return Param(name, default, "number", unit, help, lo, hi, lo_open, hi_open, tuple(words))


def integer(name, default, help, lo=-math.inf, hi=math.inf, words=(), unit="-"):
    """An integer in [lo, hi], or one of `words`; `unit` names what it counts (no suffix)."""
    return Param(name, default, "integer", unit, help, lo, hi, words=tuple(words))


def numbers(name, default, unit, help, lo=-math.inf, lo_open=False):
    """A comma-separated list of distinct numbers (kept as text: "100,200,400"), each > or >= lo."""
    return Param(name, default, "numbers", unit, help, lo, lo_open=lo_open)


def choice(name, default, words, help):
    return Param(name, default, "choice", help=help, words=tuple(words))


def flag(name, default, help):
    """0 or 1 (also true/false, yes/no, on/off); the option alone means 1."""
    return Param(name, default, "flag", help=help)


def text(name, default, help, empty=True):
    """A text; empty=False refuses '' (and blanks)."""
    return Param(name, default, "text", help=help, empty=empty)


def out_option(default, help="output folder"):
    """--out: a folder to write in ('' would be the current folder: refused)."""
    return text("out", default, help, empty=False)


def scheduler_options(what):
    """--jobs and --scheduler (process/scheduler.py) of a command whose `what` are Dask tasks:
    --jobs N is --scheduler local:N; neither given: a worker per core."""
    return [Param("jobs", None, "integer", "processes", f"processes on this machine running "
                  f"the {what} (--scheduler local:N)", lo=1,
                  why="the cores this process may use, unless --scheduler is given"),
            text("scheduler", "", f"where the {what} run: {FORMS} (default: local, a worker "
                 "per core); the results do not depend on it"),
            integer("retries", 1, f"further attempts of a {what[:-1]} whose worker failed",
                    lo=0)]


def scheduler_of(args):
    """The process.scheduler.Scheduler of a command's --scheduler and --jobs; both given, or a
    form not accepted, ends the program with its one line (fail)."""
    try:
        return chosen(args.scheduler, args.jobs)
    except SchedulerError as exc:
        fail(str(exc))


DEBUG = flag("debug", False, "show the traceback of an error instead of its one line")
QUIET = flag("quiet", False, "no progress lines on stderr (results, warnings and errors still "
             "show)")
#: the flags every script and command takes
COMMON = [DEBUG, QUIET]


# options that the impact scripts share, declared once
def material_option(of="the particles", default="copper_ore"):
    return text("material", default, f"material of {of}: a name of the library or a .toml file")


def size_option(default):
    """--size: within the physical range of particle sizes (intervals.PARTICLE_SIZE), so that the
    time step it sets neither vanishes nor overflows a step count."""
    return number("size", default, "m", "particle size", lo=PARTICLE_SIZE.lo, hi=PARTICLE_SIZE.hi)


def overwrite_option():
    """--overwrite: a new run into an --out that holds an earlier run (otherwise refused)."""
    return flag("overwrite", False, "start a new run in an --out that holds an earlier run, "
                "finished or interrupted (without it such an --out is refused)")


def checkpointed_run_options(vtk_interval, out):
    """The options of a scene run with checkpoints (bed, mill, agglomerate): the ParaView frame
    interval (s of simulated time), checkpoints, --resume, --stop-after (tests) and the output
    folder."""
    return [
        number("vtk_interval", vtk_interval, "s", "simulated time between frames of the ParaView "
               "series in <out>/paraview (0: no series)", lo=0),
        number("checkpoint_every", 60.0, "s", "wall time between checkpoints, the first a few "
               "seconds in (< 0: none)"),
        flag("resume", False, "continue the run that died in --out from its checkpoint (none: "
             "it starts again)"),
        overwrite_option(),
        number("stop_after", 0.0, "s", "(tests) end as if killed at this simulated time "
               "(0: never)", lo=0),
        out_option(out),
    ]


def _from_defaults(defaults):
    """Params from a {name: default} dict (types follow the defaults, no range)."""
    kinds = {bool: "flag", int: "integer", float: "number"}
    return [Param(k, v, kinds.get(type(v), "text")) for k, v in defaults.items()]


def fail(message):
    """One line on stderr and exit code 2, as argparse does for a user's mistake."""
    print(f"[yadebreak] error: {message}", file=sys.stderr, flush=True)
    raise SystemExit(2)


class ScriptParser(argparse.ArgumentParser):
    """argparse with one-line errors (`[yadebreak] error: ...`, exit 2) and help that keeps the
    description's lines."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", argparse.RawDescriptionHelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message):
        fail(f"{message} ({self.prog} --help lists the options)")


def add_params(parser, params):
    """Add `params` to an argparse parser (values read as text; check them with read_params)."""
    for p in params:
        if p.kind == "flag":            # `--resume` alone is `--resume 1`
            parser.add_argument(p.flag, dest=p.name, default=p.default, help=p.help_line,
                                metavar="0|1", nargs="?", const=True)
        else:
            parser.add_argument(p.flag, dest=p.name, default=p.default, help=p.help_line)


def read_params(namespace, params):
    """Check and convert every value of `namespace` declared in `params` (in place); a bad one
    ends the program with its one line (exit 2), or raises it with --debug 1."""
    global _DEBUG, _QUIET
    try:
        _DEBUG = DEBUG.convert(getattr(namespace, "debug", False))
        _QUIET = QUIET.convert(getattr(namespace, "quiet", False))
        for p in params:
            setattr(namespace, p.name, p.convert(getattr(namespace, p.name)))
    except ParamError as exc:
        if _DEBUG:
            raise
        fail(str(exc))
    return namespace


def join_negative_values(argv, params):
    """`--size -5e-3` as `--size=-5e-3`: argparse would take '-5e-3' for an option and say only
    "expected one argument", not what is wrong with the value."""
    flags = {p.flag for p in params}
    out, k = [], 0
    while k < len(argv):
        a = argv[k]
        if a in flags and k + 1 < len(argv) and re.match(r"^-[\d.]", argv[k + 1]):
            out.append(f"{a}={argv[k + 1]}")
            k += 2
        else:
            out.append(a)
            k += 1
    return out


def script_params(params, description=None, argv=None, table_row=None):
    """The checked values of a script's options (an argparse.Namespace). `params`: a list of
    Param (or a {name: default} dict, types following the defaults). Adds --debug. Under
    yade-batch, `table_row(defaults)` gives the row's values and description (the YADE layers
    pass coupling.yade_api.table_row: this module never imports YADE)."""
    if isinstance(params, dict):
        params = _from_defaults(params)
    params = [p for p in params if p.name not in ("debug", "quiet")] + COMMON
    _SCRIPT_OPTIONS.clear()
    _SCRIPT_OPTIONS.update(p.name for p in params)
    if os.environ.get("YADE_BATCH"):
        if table_row is None:         # reading argv would ignore the table's row
            fail("under yade-batch the options come from the table's row: pass "
                 "table_row=yadebreak.adapter.yade_api.table_row to script_params")
        defaults = {p.name: p.default for p in params}
        try:
            row, description = table_row(defaults)
        except NameError as exc:  # readParamsFromTable: a column without a default
            column = re.search(r"`(\w+)'", str(exc))
            fail(f"the table's column {column.group(1) if column else str(exc)!r} is not an option "
                 f"of this script (its options: {', '.join(sorted(defaults))})")
        values = argparse.Namespace(**row)
        read_params(values, params)
        if "out" in defaults and values.out == defaults["out"] and description:
            # `python3 -m yadebreak sweep` names the folder of its lines; yade-batch: out/sweep/
            root = os.environ.get("YADEBREAK_SWEEP_OUT") or os.path.join(
                os.path.dirname(defaults["out"]) or ".", "sweep")
            values.out = str(os.path.join(root, description))
        return values
    parser = ScriptParser(description=description)
    add_params(parser, params)
    args = sys.argv[1:] if argv is None else argv
    return read_params(parser.parse_args(join_negative_values(list(args), params)), params)


def debugging():
    """True if the running script was given --debug 1 (tracebacks instead of one-line errors)."""
    return _DEBUG


def quiet():
    """True if the running script or command was given --quiet 1 (no progress lines)."""
    return _QUIET


def script_option_names():
    """The option names of the script whose options were read last (warnings name them)."""
    return frozenset(_SCRIPT_OPTIONS)
