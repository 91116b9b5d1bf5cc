"""Parameters of scripts: `--name value` on the command line, or a yade-batch table row.

Each option is declared once, with its type, accepted range, unit, default and help:

    args = script_params([
        number("size", 5.5e-3, "m", "particle size", lo=0, lo_open=True, hi=1),
        integer("rings", 3, "hexagonal rings around the central particle", lo=0),
        text("out", "out/x", "output folder"),
    ], __doc__)

Under yade-batch (YADE_BATCH set), yade.utils.readParamsFromTable supplies the values; otherwise
argparse reads sys.argv. Either way every value is checked against its declaration before anything
runs: a bad value stops with one line on stderr naming the option, the value, the accepted range
and the unit (`[yadebreak] error: --energy = -1: must be > 0 (J)`), exit code 2, as argparse does;
`--debug 1` shows the traceback instead. Units: plain numbers are SI (m, s, J, J/kg, m/s); the
option's own unit may follow the number (`--size 5.5mm`, `--energy 3.05J`, `--energies
100J/kg,200J/kg`), another one is refused. Never imports yade unless yade-batch runs it.
"""
import argparse
import errno
import hashlib
import json
import math
import os
import re
import signal
import sys
import time
import traceback
import warnings
from contextlib import contextmanager
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path

from yadebreak.model.intervals import PARTICLE_SIZE, Interval

#: unit of an option -> the units accepted after a number, with their factor to that unit
UNITS = {
    "m": {"m": "1", "cm": "1e-2", "mm": "1e-3", "um": "1e-6"},
    "s": {"s": "1", "ms": "1e-3"},
    "J": {"J": "1"},
    "J/kg": {"J/kg": "1"},
    "m/s": {"m/s": "1"},
    "%": {"%": "1"},
    "-": {},
}
_NUMBER_THEN_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S.*?)\s*$")
_TRUE, _FALSE = ("1", "true", "yes", "on"), ("0", "false", "no", "off")
_DEBUG = False                  # --debug 1: tracebacks instead of one-line errors
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
    words: tuple = ()          # choice: the accepted words; integer: words accepted besides numbers

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
            return "a text"
        interval = str(self.interval)
        if self.kind == "integer":
            interval = "an integer" + ("" if interval == "any number" else f" {interval}")
            if self.words:
                interval += ", " + " or ".join(repr(w) for w in self.words)
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
        parts.append(f"default {default}{unit}")
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
        if factors[unit] == "1":
            return float(number)
        return float(Decimal(number) * Decimal(factors[unit]))

    def convert(self, value):
        """The checked value of this option from a command-line text or a yade-batch table value;
        raises ParamError."""
        shown = value
        if value is None and self.default is None:     # a default of None: "not given"
            return None
        if self.kind == "text":
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


def _is_float(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


def number(name, default, unit, help, lo=-math.inf, hi=math.inf, lo_open=False, hi_open=False):
    """A real number in `unit` (a key of UNITS), in [lo, hi] (open ends as asked)."""
    return Param(name, default, "number", unit, help, lo, hi, lo_open, hi_open)


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


def text(name, default, help):
    return Param(name, default, "text", help=help)


DEBUG = flag("debug", False, "show the traceback of an error instead of its one line")


# options that the impact scripts share, declared once
def material_option(of="the particles", default="copper_ore"):
    return text("material", default, f"material of {of}: a name of the library or a .toml file")


def size_option(default):
    """--size: within the physical range of particle sizes (intervals.PARTICLE_SIZE), so that the
    time step it sets neither vanishes nor overflows a step count."""
    return number("size", default, "m", "particle size", lo=PARTICLE_SIZE.lo, hi=PARTICLE_SIZE.hi)


def read_period_option(default):
    """--read-period: how often yadebreak reads the contacts (attach()'s read_period)."""
    return integer("read_period", default, "how often contacts are read: 'fast' (as often as "
                   "the loading requires), 'every_step' (exact), every k steps or 'auto'",
                   lo=1, words=("auto", "fast", "every_step"), unit="steps")


def read_period_value(value):
    """attach()'s read_period from --read-period's value (a word, or k as text or a number)."""
    return value if value in ("auto", "fast", "every_step") else int(value)


def time_step_option():
    return number("time_step_fraction", 0.05, "-", "time step as a fraction of the smallest "
                  "sphere's Rayleigh time", lo=0, lo_open=True, hi=1)


def checkpointed_run_options(vtk_interval, out):
    """The options of a scene run with checkpoints (bed, mill, agglomerate): the ParaView frame
    interval (s of simulated time), checkpoints, --resume, --stop-after (tests) and the output
    folder."""
    return [
        number("vtk_interval", vtk_interval, "s", "simulated time between frames of the ParaView "
               "series in <out>/paraview (0: no series)", lo=0),
        number("checkpoint_every", 60.0, "s", "wall time between checkpoints (< 0: none)"),
        flag("resume", False, "continue the run that died in --out from its checkpoint"),
        number("stop_after", 0.0, "s", "(tests) end as if killed at this simulated time "
               "(0: never)", lo=0),
        text("out", out, "output folder"),
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
    global _DEBUG
    try:
        _DEBUG = DEBUG.convert(getattr(namespace, "debug", False))
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


def script_params(params, description=None, argv=None):
    """The checked values of a script's options (an argparse.Namespace). `params`: a list of
    Param (or a {name: default} dict, types following the defaults). Adds --debug."""
    if isinstance(params, dict):
        params = _from_defaults(params)
    params = [p for p in params if p.name != "debug"] + [DEBUG]
    _SCRIPT_OPTIONS.clear()
    _SCRIPT_OPTIONS.update(p.name for p in params)
    if os.environ.get("YADE_BATCH"):
        from yadebreak.coupling.yade_api import table_row
        defaults = {p.name: p.default for p in params}
        row, description = table_row(defaults)
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


class ScriptError(ValueError):
    """A user's mistake that a script reports in one line (exit code 2), e.g. a resume with other
    arguments."""


class StopRequested(Exception):
    """--stop-after: the script ends here, as if killed (tests of --resume)."""


class RunFinished(Exception):
    """--resume of a run that had finished: nothing to do; the script says so and ends (exit 0)."""


def run_script(main, *args):
    """Run a script's main(*args) as one run of the job: its --out locked against a second run
    (lock_out), SIGINT (Ctrl-C) and SIGTERM (a batch scheduler's wall-time limit) ending it as
    'interrupted' (see stop_points), and each way it ends turned into an exit code and one line:
    a user's mistake (a bad material file, option or resume, a damaged checkpoint, an --out in
    use) on stderr with exit code 2, as argparse does (--debug 1: the traceback); --stop-after 0;
    resuming a finished run says so and returns None; a signal 128 + its number (130 for SIGINT,
    143 for SIGTERM); a full disk 1; any other error its traceback, then 1. The last line names
    only the outputs that exist (kept_outputs). The one place where scripts turn exceptions into
    exit codes."""
    from yadebreak.coupling.config import AttachError
    from yadebreak.model.materials import MaterialError
    _show_warnings_once()
    out = getattr(args[0], "out", None) if args else None
    began = time.time()
    handlers, locked = _catch_signals(), False
    fresh = out is not None and not Path(out).exists()     # made by the lock: gone if unused
    try:
        locked = out is not None and lock_out(out)
        return main(*args)
    except StopRequested:
        raise SystemExit(0) from None
    except RunFinished as exc:
        progress(str(exc))
        return None
    except MaterialError as exc:
        if _DEBUG:
            raise
        message = f"{exc.source}: " + "; ".join(exc.problems)
    except (ScriptError, AttachError, FileNotFoundError) as exc:
        if _DEBUG:
            raise
        message = str(exc)
    except KeyboardInterrupt as exc:
        _end_interrupted(exc, out, began)
    except Exception as exc:             # a failure midway
        if stop_requested():             # a signal that struck inside a PyRunner: YADE wraps it
            _end_interrupted(Interrupted(_STOP["signal"]), out, began)
        if disk_full(exc) and not _DEBUG:
            print(f"[yadebreak] error: the disk is full ({error_line(exc)}): the run stopped; "
                  f"{kept_outputs(out, began)}", file=sys.stderr, flush=True)
            raise SystemExit(1) from None
        traceback.print_exc()            # for a bug report
        print(f"[yadebreak] error: the run failed ({type(exc).__name__}: {_first_line(exc)}); "
              f"{kept_outputs(out, began)}", file=sys.stderr, flush=True)
        raise SystemExit(1) from None
    finally:
        _restore_signals(handlers)
        if locked:                       # the run is over (a YADE prompt may follow)
            _LOCKS.pop(str(Path(out).resolve())).close()
            if fresh and [p.name for p in Path(out).iterdir()] == [LOCK]:
                (Path(out) / LOCK).unlink()        # refused before writing: leave nothing
                Path(out).rmdir()
    fail(message)


def _end_interrupted(exc, out, began):
    progress(f"interrupted ({_signal_name(getattr(exc, 'signum', signal.SIGINT))}): "
             f"{kept_outputs(out, began)}")
    raise SystemExit(getattr(exc, "exit_code", 128 + signal.SIGINT)) from None


def _first_line(exc):
    lines = str(exc).strip().splitlines()
    return lines[0] if lines else ""


def error_line(exc):
    """An error in one line: a full disk as its OSError (YADE wraps an error raised in a PyRunner
    in a RuntimeError of several lines), anything else as 'Type: first line'."""
    if disk_full(exc):
        if isinstance(exc, OSError):
            return f"OSError: {exc}"
        found = re.search(r"\[Errno (?:28|122)\][^\n]*", str(exc))
        return f"OSError: {found.group(0).strip()}" if found else _first_line(exc)
    return f"{type(exc).__name__}: {_first_line(exc)}"


def disk_full(exc):
    """True if `exc` is a full disk or an exceeded quota (ENOSPC, EDQUOT), also when YADE has
    wrapped it in a PyRunner's RuntimeError."""
    if isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EDQUOT):
        return True
    return isinstance(exc, RuntimeError) and bool(re.search(r"\[Errno (?:28|122)\]", str(exc)))


# -- one run per output folder ---------------------------------------------------------------------
LOCK = ".yadebreak.lock"
_LOCKS = {}          # folder -> its open lock file, held while this process lives


def lock_out(out):
    """Hold <out>/.yadebreak.lock (until run_script releases it, or this process ends): a second
    run into the same folder is refused (ScriptError, one line naming the first). An flock: the
    kernel releases it when the process ends however it ends (kill -9 included), so a killed run
    leaves nothing stuck. Creates the folder. True if taken now, False if this process held it
    already or the file system has no locks."""
    import fcntl
    out = Path(out)
    key = str(out.resolve())
    if key in _LOCKS:                     # this process holds it already
        return False
    out.mkdir(parents=True, exist_ok=True)
    f = open(out / LOCK, "a+")
    try:
        fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as exc:
        f.seek(0)
        holder = f.read().strip()
        f.close()
        if exc.errno not in (errno.EAGAIN, errno.EACCES):   # a file system without locks: run
            return False
        raise ScriptError(f"--out = {out}: another run is writing there ({holder or 'a process'}"
                          "); wait for it to end or choose another --out") from None
    f.seek(0)
    f.truncate()
    f.write(f"process {os.getpid()}, started {time.strftime('%Y-%m-%d %H:%M:%S')}\n")
    f.flush()
    _LOCKS[key] = f
    return True


# -- signals: SIGINT and SIGTERM end a run as 'interrupted' ----------------------------------------
class Interrupted(KeyboardInterrupt):
    """SIGINT (Ctrl-C) or SIGTERM: the run ends as 'interrupted', exit code 128 + the signal's
    number; `note` adds to its end message (a checkpoint that could not be written)."""

    def __init__(self, signum=signal.SIGINT, note=""):
        super().__init__(int(signum))
        self.signum, self.note = int(signum), note

    @property
    def exit_code(self):
        return 128 + self.signum

    @property
    def end_message(self):
        return f"stopped by {_signal_name(self.signum)}{self.note}"


def _signal_name(signum):
    return "Ctrl-C, SIGINT" if signum == signal.SIGINT else signal.Signals(signum).name


_STOP = {"signal": None, "points": 0}    # the signal received; depth of stop_points blocks


def _on_signal(signum, frame):
    first = _STOP["signal"] is None
    _STOP["signal"] = signum
    if _STOP["points"] and first:
        return                           # the job's loop stops at its next stop_point
    raise Interrupted(signum)


def _catch_signals():
    """SIGINT and SIGTERM to _on_signal while a script runs; returns the handlers to restore
    (none outside the main thread, where Python cannot set them)."""
    import threading
    _STOP["signal"] = None
    if threading.current_thread() is not threading.main_thread():
        return {}
    handlers = {}
    for s in (signal.SIGINT, signal.SIGTERM):
        handlers[s] = signal.getsignal(s)
        signal.signal(s, _on_signal)
    return handlers


def _restore_signals(handlers):
    for s, handler in handlers.items():
        signal.signal(s, signal.SIG_DFL if handler is None else handler)
    _STOP["signal"] = None


@contextmanager
def stop_points():
    """Within the block, SIGINT or SIGTERM only asks the run to stop: the job's loop stops at its
    next stop_point(), between its chunks of steps, where its state is whole (a signal handled
    where it strikes could land in a PyRunner, halfway through a breakage, and come out as YADE's
    PyRunner error). A second signal stops at once."""
    _STOP["points"] += 1
    try:
        yield
    finally:
        _STOP["points"] -= 1


def stop_requested():
    """True once SIGINT or SIGTERM has been received by run_script's handlers."""
    return _STOP["signal"] is not None


def stop_point(save=None):
    """Where a job's loop may stop (see stop_points): after SIGINT or SIGTERM, save() (the
    checkpoint), then raise Interrupted. A save that fails (a full disk) is said in the end
    message; the run still ends as interrupted."""
    signum = _STOP["signal"]
    if signum is None:
        return
    note = ""
    if save is not None:
        try:
            save()
        except OSError as exc:
            note = f"; the checkpoint could not be written ({error_line(exc)})"
    raise Interrupted(signum, note=note)


# -- what a run leaves -----------------------------------------------------------------------------
CHECKPOINT = "checkpoint.yade.gz"


def kept_outputs(out, since):
    """What a run that ended early left in `out`, naming only files that exist: summary.json with
    its end_reason if this run (begun at `since`, time.time()) wrote it, the checkpoint or partial
    results that --resume 1 goes on from, and how many other files this run wrote."""
    if out is None:
        return "see its output folder"
    out = Path(out)
    if not out.is_dir():
        return f"nothing was written in {out}"
    since -= 1.0                         # file times lag the clock by up to a tick
    parts, resumable = [], [n for n in (CHECKPOINT, "partial.json") if (out / n).is_file()]
    summary = out / "summary.json"
    wrote_summary = summary.is_file() and summary.stat().st_mtime >= since
    if wrote_summary:
        try:
            reason = json.loads(summary.read_text())["end_reason"]
            parts.append(f"summary.json (end_reason {reason!r})")
        except (OSError, ValueError, KeyError, TypeError):
            parts.append("summary.json (unreadable)")
    for name in resumable:
        stamp = time.strftime("%H:%M:%S", time.localtime((out / name).stat().st_mtime))
        parts.append(f"{name} (of {stamp}; --resume 1 goes on from it)")
    others = sum(1 for p in out.rglob("*") if p.is_file() and p.stat().st_mtime >= since
                 and p.name not in ("summary.json", LOCK, *resumable))
    if others:
        parts.append(f"{others} other file(s) written by this run")
    text = f"kept in {out}: {', '.join(parts)}" if parts else f"nothing kept in {out}"
    return text + ("" if wrote_summary else "; no summary.json was written")


def run_wall_time(loop, start):
    """Wall time (s) of a checkpointed run over all its invocations: those before this one (up to
    their last checkpoint: the rest was simulated again), kept by --resume in
    loop["wall_before_s"], and this one since `start` (time.time())."""
    return loop.get("wall_before_s", 0.0) + time.time() - start


def write_atomic(path, text):
    """Write `text` to `path` through a temporary file and os.replace: `path` holds the old
    content or the new, never part of it (a full disk, a kill); the temporary file is removed if
    the write fails."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    try:
        tmp.write_text(text)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def read_checkpoint(path, load):
    """load(path) for --resume, a damaged checkpoint (truncated, emptied, overwritten) refused in
    one line (ScriptError) before YADE reads it: a gzip file is read through first (its length
    and checksum); then a failure of load is the file's (damaged), or the folder's (an OSError:
    the checkpoint cannot be resumed there, e.g. its event log's folder is gone)."""
    import gzip
    import zlib
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"--resume: no checkpoint at {path}; run without --resume first")
    again = "it cannot be resumed; run again without --resume"
    try:
        if path.stat().st_size == 0:
            raise ValueError("the file is empty")
        if path.name.endswith(".gz"):
            with gzip.open(path, "rb") as f:
                while f.read(1 << 20):
                    pass
    except (OSError, EOFError, ValueError, zlib.error) as exc:
        raise ScriptError(f"--resume: {path} is damaged ({_first_line(exc)}): {again}") from exc
    try:
        return load(path)
    except (ScriptError, RunFinished):
        raise
    except OSError as exc:
        raise ScriptError(f"--resume: {path} cannot be resumed here ({exc})") from exc
    except Exception as exc:
        raise ScriptError(f"--resume: {path} is damaged ({_first_line(exc) or type(exc).__name__}"
                          f"): {again}") from exc


#: summary.json's end_reason: how a run ended
END_REASONS = ("finished", "time_limit", "error", "interrupted")


@contextmanager
def partial_outputs_on_failure(write):
    """Run the block; if it fails (an error, a full disk, SIGINT or SIGTERM), `write(end_reason,
    end_message)` writes the outputs so far (summary.json with end_reason 'error' or
    'interrupted'), then the failure goes on. --stop-after is not a failure (it stands for a
    killed run, which writes nothing)."""
    try:
        yield
    except StopRequested:
        raise
    except KeyboardInterrupt as exc:
        _write_partial(write, "interrupted", getattr(exc, "end_message", "stopped by Ctrl-C"))
        raise
    except Exception as exc:
        if stop_requested():             # the signal struck inside a PyRunner: YADE wrapped it
            _write_partial(write, "interrupted", Interrupted(_STOP["signal"]).end_message)
        else:
            _write_partial(write, "error", error_line(exc) if disk_full(exc)
                           else f"{type(exc).__name__}: {exc}")
        raise


def _write_partial(write, reason, message):
    try:
        write(reason, message)
    except Exception as exc:             # the original failure matters more: say, go on
        if not disk_full(exc):           # (a full disk: the run's last line says what is kept)
            print(f"[yadebreak] could not write the partial outputs: {type(exc).__name__}: {exc}",
                  file=sys.stderr, flush=True)


def _show_warnings_once():
    """A script shows each of yadebreak's warnings once per run (one line; a run of several
    scenes would repeat them per scene), naming the script's own option where the warning names
    an attach() option that the script exposes (--read-period for read_period)."""
    from yadebreak.coupling.controller import YadebreakWarning
    shown = set()
    python_show = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if not issubclass(category, YadebreakWarning):
            return python_show(message, category, filename, lineno, file, line)
        if message.cause in shown:
            return None
        shown.add(message.cause)
        print(f"[yadebreak] WARNING: {message.for_script(_SCRIPT_OPTIONS)} (shown once)",
              file=sys.stderr, flush=True)
        return None

    warnings.showwarning = show       # the documented hook (warnings module); library use keeps
    #                                   Python's own display


def progress(message):
    """One line of progress, flushed at once (long runs print these)."""
    print(f"[yadebreak] {message}", flush=True)


def time_left(elapsed_s, done):
    """'about N s left' after `elapsed_s` (s) of wall time with the fraction `done` of the work
    done; 'time left unknown' until 5 % is done (too early to extrapolate). Never negative or nan:
    `done` is taken within [0, 1]."""
    done = min(max(float(done), 0.0), 1.0) if math.isfinite(done) else 0.0
    if done < 0.05 or not math.isfinite(elapsed_s):
        return "time left unknown"
    return f"about {max(elapsed_s, 0.0) * (1.0 - done) / done:.0f} s left"


def resume_arguments(args):
    """The arguments that decide a run's results (not --resume, --stop-after, --out,
    --checkpoint-every, --vtk-interval, --debug or --jobs): what a resumed run must share with the
    one it continues."""
    return {k: v for k, v in sorted(vars(args).items())
            if k not in ("resume", "out", "stop_after", "checkpoint_every", "vtk_interval",
                         "debug", "jobs")}


def check_resume_arguments(saved, args, path):
    """Refuse to resume, naming the arguments that differ, when `saved` (resume_arguments of the
    interrupted run, stored at `path`) are not this run's."""
    now = resume_arguments(args)
    if saved != now:
        changed = sorted(k for k in set(saved) | set(now) if saved.get(k) != now.get(k))
        raise ScriptError(f"--resume: {path} was written with other values of {changed}; run "
                          "again without --resume or with the same values")


FINISHED = "finished.json"


def mark_started(out):
    """A new run (not --resume) in `out`: it is no longer a finished one."""
    (Path(out) / FINISHED).unlink(missing_ok=True)


def mark_finished(out, args):
    """The run in `out` wrote all its outputs: <out>/finished.json keeps its arguments."""
    (Path(out) / FINISHED).write_text(json.dumps({"arguments": resume_arguments(args)}))


def check_not_finished(out, args):
    """--resume: if the run in `out` finished, refuse other arguments (naming them), then raise
    RunFinished: nothing is run again and no output is rewritten."""
    path = Path(out) / FINISHED
    if path.exists():
        check_resume_arguments(json.loads(path.read_text())["arguments"], args, path)
        raise RunFinished(f"the run in {out} had finished: nothing to resume, its outputs are "
                          "kept (run again without --resume to redo it)")


def stop_if_asked(args, units_done):
    """--stop-after N: end the script here, as if killed, once N units are done (tests)."""
    if getattr(args, "stop_after", 0) and units_done >= args.stop_after:
        raise StopRequested()


class PartialResults:
    """Results a script has finished, kept in <out>/partial.json as it goes, so that `--resume 1`
    skips what an interrupted run completed. Each unit of work (an energy) must depend only on the
    arguments and its own seed, so that resuming gives what an uninterrupted run gives.

        partial = PartialResults(out, args)          # args.resume decides
        for k, energy in partial.todo(energies):     # the units not done yet
            partial.add(energy, compute(k, energy))  # stops here with --stop-after
        results = partial.ordered(energies)
        ...                                          # the outputs
        partial.finish()                             # a later --resume 1 has nothing to do
    """

    def __init__(self, out, args, validate=None):
        """validate(key, result): raises ValueError (saying why) if a unit's result read back by
        --resume 1 is not one this run could have written (a tampered or foreign file)."""
        self.out = Path(out)
        self.path = self.out / "partial.json"
        self.args = args
        self.done = {}
        if not getattr(args, "resume", False):
            mark_started(out)
            return
        check_not_finished(out, args)
        if self.path.exists():
            self.done = self._read(validate)
            progress(f"resuming: {len(self.done)} finished unit(s) kept from {self.path}")

    def _read(self, validate):
        """The units of partial.json, refused in one line (ScriptError) if the file is damaged
        (not UTF-8 JSON of this form), changed since it was written (its digest) or holds a
        result that validate refuses."""
        refuse = f"--resume: {self.path}"
        try:
            data = json.loads(self.path.read_bytes().decode("utf-8"))
            arguments, done = data["arguments"], data["done"]
            if not (isinstance(arguments, dict) and isinstance(done, dict)):
                raise ValueError("'arguments' and 'done' must be objects")
        except (ValueError, KeyError, TypeError) as exc:     # UnicodeDecodeError is a ValueError
            raise ScriptError(f"{refuse} is damaged ({type(exc).__name__}: {_first_line(exc)}): "
                              "it cannot be resumed; run again without --resume") from None
        check_resume_arguments(arguments, self.args, self.path)
        if "digest" in data and data["digest"] != _digest(done):
            raise ScriptError(f"{refuse} was changed after it was written (its digest does not "
                              "match): it cannot be resumed; run again without --resume")
        for key, result in done.items():
            try:
                if validate is not None:
                    validate(key, result)
            except (ValueError, KeyError, TypeError) as exc:
                raise ScriptError(f"{refuse}: the result for {key} is not one this run could "
                                  f"have written ({_first_line(exc)}); run again without "
                                  "--resume") from None
        return done

    def todo(self, keys):
        """(index, key) of the units not done yet, in order."""
        return [(k, key) for k, key in enumerate(keys) if str(key) not in self.done]

    def ordered(self, keys):
        """Every unit's result, in the order of `keys`."""
        return [self.done[str(key)] for key in keys]

    def add(self, key, result):
        self.done[str(key)] = result
        write_atomic(self.path, json.dumps({"arguments": resume_arguments(self.args),
                                            "done": self.done, "digest": _digest(self.done)}))
        stop_if_asked(self.args, len(self.done))

    def finish(self):
        """Every output is written: a later --resume 1 says so and does nothing."""
        mark_finished(self.out, self.args)


def _digest(done):
    """SHA-256 of partial.json's results: --resume 1 refuses a file changed after it was written."""
    return hashlib.sha256(json.dumps(done, sort_keys=True).encode()).hexdigest()
