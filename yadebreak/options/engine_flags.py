"""attach()'s options as the flags of a job, made from the option table (table.py): their type,
range, unit, help and default come from the table's row; a job states only the defaults it
changes, each with its reason (Override), and one function turns the parsed flags back into
attach() options. No yade import.

    OVERRIDES = {"read_period": Override("every_step", "laboratory tests are the exact reference")}
    params = [engine_flag("read_period", OVERRIDES), engine_flag("dmin", OVERRIDES)]
    options = options_from_flags(args, ("read_period", "dmin"), OVERRIDES, event_log="...")

On a command line None is written as the row's token ("material", "forever", or 0 where 0 lies
outside the range): `--global-damping material` is the files' damping, `--global-damping 0` none.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Callable

from yadebreak.options.flags import choice, flag, integer, number, text
from yadebreak.options.table import OPTIONS

OPTION = {o.name: o for o in OPTIONS}


@dataclass(frozen=True)
class Derived:
    """A job's default computed from its other arguments: `shown` in --help, of(args) the value
    (None: the job computes it where it runs, e.g. one per figure); `token` writes it on the
    command line (None: the row's token)."""

    shown: str
    of: Callable | None = None
    token: object = None


@dataclass(frozen=True)
class Override:
    """A job's default of one attach() option that differs from the table's, and why."""

    value: object                 # the attach() value, or a Derived
    why: str


def engine_flag(name, overrides=None, where=""):
    """The flag of attach()'s option `name`, its default the job's override (in `overrides`, a
    {name: Override}) or else the table's; `where` begins its help (the runs it acts on)."""
    o = OPTION[name]
    override = (overrides or {}).get(name)
    default = o.default if override is None else override.value
    why = "" if override is None else override.why
    means, token = o.none, _token(o, override)
    if isinstance(default, Derived):
        means, why = default.shown, f"{default.shown}: {why}"
        default = None
    if default is None:
        if token == "":
            raise ValueError(f"{name}: None has no command-line token in the option table")
        default, why = token, why or means
    shown = f"{token:g}" if isinstance(token, float) else token
    helps = where + o.help + (f"; {shown}: {means}" if token != "" else "")
    lo, hi = o.interval.lo, o.interval.hi
    lo_open = o.interval.lo_open and token != lo          # a token 0 closes "> 0" to ">= 0"
    if o.kind == "number":
        words = o.words + ((token,) if isinstance(token, str) and token else ())
        param = number(name, default, o.unit, helps, lo, hi, lo_open, o.interval.hi_open, words)
    elif o.kind in ("count", "read_period"):
        param = integer(name, default, helps, lo=lo, hi=hi, words=o.words, unit=o.unit)
    elif o.kind == "choice":
        param = choice(name, default, o.words + ((token,) if token else ()), helps)
    elif o.kind == "boolean":
        param = flag(name, default, helps)
    else:
        param = text(name, default, helps)
    return dataclasses.replace(param, why=why)


def _token(option, override):
    """How a command line writes the job's None or derived default of `option`."""
    if override is not None and isinstance(override.value, Derived) \
            and override.value.token is not None:
        return override.value.token
    return option.token


def engine_value(name, value, overrides, args):
    """attach()'s value of option `name` from its flag's `value` (the token: the job's derived
    default, or None)."""
    o = OPTION[name]
    override = (overrides or {}).get(name)
    token = _token(o, override)
    if token != "" and value == token and not isinstance(value, bool):
        if override is not None and isinstance(override.value, Derived):
            return override.value.of(args)
        return None
    if o.kind == "boolean":
        return bool(value)
    if o.kind == "read_period" and value not in o.words:
        return int(value)
    return value


def options_from_flags(args, flags, overrides, **more):
    """The attach() options of a job: those it exposes as `flags` (names) from `args` (a flag
    absent from `args` takes its default), its `overrides` without a flag, then `more` (the
    run's own: event_log, ...)."""
    options = {}
    for name in flags:
        value = getattr(args, name, engine_flag(name, overrides).default)
        options[name] = engine_value(name, value, overrides, args)
    for name, override in (overrides or {}).items():
        if name not in flags:
            value = override.value
            options[name] = value.of(args) if isinstance(value, Derived) else value
    return {**options, **more}


def overrides_markdown(jobs):
    """Each job's overrides of the table's defaults, with their reasons, as Markdown rows (jobs:
    {job name: {option: Override}})."""
    rows = ["| job | option | its default | the table's | why |", "|---|---|---|---|---|"]
    for job, overrides in jobs.items():
        for name, o in overrides.items():
            value = o.value.shown if isinstance(o.value, Derived) else repr(o.value)
            rows.append(f"| {job} | `{name}` | {value} | `{OPTION[name].default!r}` | {o.why} |")
    return "\n".join(rows)
