"""How a script's run goes, whatever the job: the one place where its end becomes an exit code
(run_script), SIGINT and SIGTERM turned into an 'interrupted' end at the job's next stop point,
one run per output folder (lock_out), checkpoints read and written whole, results kept as they
finish (PartialResults), finish markers for --resume, and progress lines with the time left.
The job's loop itself is yadebreak.jobs.skeleton's; the options, yadebreak.options.flags'.

Imports no yade (the controller's warning class only once a run starts): tests use it in-process.
"""
import errno
import hashlib
import json
import math
import os
import signal
import sys
import threading
import time
import traceback
import warnings
from contextlib import contextmanager, nullcontext
from pathlib import Path

from yadebreak.model.intervals import InputError

from yadebreak.options.flags import debugging, fail, quiet, script_option_names
from yadebreak.process.errors import disk_full, error_line, first_line
from yadebreak.process.files import (append_whole, save_figure, write_atomic,  # noqa: F401
                                     write_whole)
from yadebreak.process.signals import (Interrupted, catch_signals, restore_signals, signal_name,
                                       stop_requested, stop_signal)
from yadebreak.process.signals import stop_point, stop_points  # noqa: F401 (skeleton's)

class ScriptError(InputError):
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
    from yadebreak.model.materials import MaterialError
    close_remote_access()
    out = getattr(args[0], "out", None) if args else None
    began = time.time()
    handlers = catch_signals()
    try:
        with (nullcontext() if out is None else own_out(out, args[0])), warnings_shown_once():
            return main(*args)
    except StopRequested:
        raise SystemExit(0) from None
    except RunFinished as exc:
        progress(str(exc))
        return None
    except MaterialError as exc:
        if debugging():
            raise
        message = f"{exc.source}: " + "; ".join(exc.problems)
    except (InputError, FileNotFoundError) as exc:     # attach()'s, the scripts', ...
        if debugging():
            raise
        message = str(exc)
    except KeyboardInterrupt as exc:
        _end_interrupted(exc, out, began)
    except Exception as exc:             # a failure midway
        if stop_requested():             # a signal that struck inside a PyRunner: YADE wraps it
            _end_interrupted(Interrupted(stop_signal()), out, began)
        if disk_full(exc) and not debugging():
            print(f"[yadebreak] error: the disk is full ({error_line(exc)}): the run stopped; "
                  f"{kept_outputs(out, began)}", file=sys.stderr, flush=True)
            raise SystemExit(1) from None
        traceback.print_exc()            # for a bug report
        print(f"[yadebreak] error: the run failed ({type(exc).__name__}: {first_line(exc)}); "
              f"{kept_outputs(out, began)}", file=sys.stderr, flush=True)
        raise SystemExit(1) from None
    finally:
        restore_signals(handlers)
    fail(message)


def close_remote_access():
    """Under the `yade` launcher (which imports yade.remote to start them): close its Python
    prompt and XMLRPC servers, which listen on every interface (scenes.view's
    close_remote_access). Nothing to do under /usr/bin/python3."""
    if "yade.remote" in sys.modules:
        from yadebreak.scenes.view import close_remote_access as close
        close()


def _end_interrupted(exc, out, began):
    progress(f"interrupted ({signal_name(getattr(exc, 'signum', signal.SIGINT))}): "
             f"{kept_outputs(out, began)}")
    raise SystemExit(getattr(exc, "exit_code", 128 + signal.SIGINT)) from None


# -- one run per output folder ---------------------------------------------------------------------
LOCK = ".yadebreak.lock"
_LOCKS = {}          # folder -> its open lock file, held while this process lives


def lock_out(out, claim=None):
    """Hold <out>/.yadebreak.lock (until run_script releases it, or this process ends): a second
    run into the same folder is refused (ScriptError, one line naming the first). An flock: the
    kernel releases it when the process ends however it ends (kill -9 included), so a killed run
    leaves nothing stuck. Creates the folder. claim(): the run's own check of the folder, made
    once the lock is held and before the lock file is written (a refusal leaves it as it was).
    True if taken now, False if this process held it already or the file system has no
    locks."""
    import fcntl
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, "a file, not a folder", str(out))
    key = str(out.resolve())
    f, made = None, False
    if key not in _LOCKS:                 # (else this process holds it already)
        out.mkdir(parents=True, exist_ok=True)
        made = not (out / LOCK).exists()
        f = open(out / LOCK, "a+")
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            f.seek(0)
            holder = f.read().strip()
            f.close()
            f = None
            if exc.errno in (errno.EAGAIN, errno.EACCES):    # else a file system without locks
                raise ScriptError(f"--out = {out}: another run is writing there "
                                  f"({holder or 'a process'}); wait for it to end or choose "
                                  "another --out") from None
    try:
        if claim is not None:
            claim()
    except BaseException:
        if f is not None:
            if made:                      # a refusal leaves the folder as it was
                (out / LOCK).unlink(missing_ok=True)
            f.close()
        raise
    if f is None:
        return False
    f.seek(0)
    f.truncate()
    f.write(f"process {os.getpid()}, started {time.strftime('%Y-%m-%d %H:%M:%S')}\n")
    f.flush()
    _LOCKS[key] = f
    return True


def run_left_in(out):
    """What an earlier run left in `out`, in words, or None if it holds none: a finished run
    (finished.json), an interrupted one that --resume 1 continues (a checkpoint or partial
    results), or one that ended early without them (a summary.json, or outputs beside the lock
    that every run leaves; a lock alone is a run killed before it wrote anything)."""
    out = Path(out)
    if (out / FINISHED).is_file():
        return "a finished run (finished.json)"
    kept = [name for name in (CHECKPOINT, PARTIAL) if (out / name).is_file()]
    if kept:
        stamp = time.strftime("%Y-%m-%d %H:%M", time.localtime((out / kept[0]).stat().st_mtime))
        return f"an interrupted run ({kept[0]} of {stamp})"
    if (out / "summary.json").is_file():
        return "a run that ended early and cannot be resumed (summary.json)"
    if (out / LOCK).is_file() and any(p.name != LOCK for p in out.iterdir()):
        return "a run that ended early and cannot be resumed (its lock and outputs)"
    return None


@contextmanager
def own_out(out, args):
    """Hold the folder `out` for one run (of a script or a tool): locked against a second run
    (lock_out), a new run over an earlier one refused (claim_out; ScriptError), an --out that
    cannot be written (a file, a read-only or full disk) ended in one line and exit code 1
    before anything runs; on leaving, the lock is released, and a folder the run left holding
    only its lock is left as it was found (removed if this run made it). A finished run
    (finished.json) leaves no lock; one that ended otherwise keeps it, the mark of a run that
    wrote there (run_left_in)."""
    fresh = not Path(out).exists()
    left = None if fresh else run_left_in(out)            # read before our own lock
    try:
        locked = lock_out(out, lambda: claim_out(out, args, left))
    except OSError as exc:
        print(f"[yadebreak] error: --out = {out}: cannot be written ({error_line(exc)}); "
              "nothing was run", file=sys.stderr, flush=True)
        raise SystemExit(1) from None
    try:
        yield
    finally:
        if locked:                       # the run is over (a YADE prompt may follow)
            held = _LOCKS.pop(str(Path(out).resolve()))
            if (Path(out) / FINISHED).is_file():
                (Path(out) / LOCK).unlink()        # while held: no other run took this file
            held.close()
            if [p.name for p in Path(out).iterdir()] == [LOCK]:
                (Path(out) / LOCK).unlink()        # refused before writing: leave nothing
                if fresh:
                    Path(out).rmdir()


@contextmanager
def tool_run(out, args):
    """A `python3 -m yadebreak` command's run in the folder `out` (own_out; a refusal is one
    line and exit code 2), marked finished (finished.json) once the block ends without error:
    the command run again into it is refused without --overwrite 1."""
    try:
        with own_out(out, args):
            yield
            mark_finished(out, args)
    except ScriptError as exc:
        if debugging():
            raise
        fail(str(exc))


def claim_out(out, args, found):
    """A run about to write into `out`, which held `found` (run_left_in, read before this run
    took its lock): a new run (no --resume) over an earlier run is refused (ScriptError, one line
    naming what is there and the two ways on), unless --overwrite 1, which clears the earlier
    run's markers (its finish marker, checkpoint and partial results: --resume 1 will not find
    them)."""
    resume, overwrite = getattr(args, "resume", False), getattr(args, "overwrite", False)
    if resume and overwrite:
        raise ScriptError("--resume 1 and --overwrite 1: choose one (continue the run in --out, "
                          "or start it over)")
    if resume or found is None:
        return
    if not overwrite:               # each way named works (a finished run does not resume)
        ways = ("continue it with --resume 1, start" if hasattr(args, "resume")
                and found.startswith("an interrupted run") else "start")
        raise ScriptError(f"--out = {out} holds {found}: {ways} it over with --overwrite 1, or "
                          "choose another --out")
    for name in (FINISHED, CHECKPOINT, PARTIAL):
        (Path(out) / name).unlink(missing_ok=True)


# -- what a run leaves -----------------------------------------------------------------------------
CHECKPOINT = "checkpoint.yade.gz"
PARTIAL = "partial.json"
#: the way on from what --resume 1 cannot continue (a plain run would be refused: the folder
#: holds a run)
AGAIN = "it cannot be resumed; start the run over with --overwrite 1, or choose another --out"


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
    parts, resumable = [], [n for n in (CHECKPOINT, PARTIAL) if (out / n).is_file()]
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
    again = AGAIN
    try:
        if path.stat().st_size == 0:
            raise ValueError("the file is empty")
        if path.name.endswith(".gz"):
            with gzip.open(path, "rb") as f:
                while f.read(1 << 20):
                    pass
    except (OSError, EOFError, ValueError, zlib.error) as exc:
        raise ScriptError(f"--resume: {path} is damaged ({first_line(exc)}): {again}") from exc
    try:
        return load(path)
    except (ScriptError, RunFinished):
        raise
    except OSError as exc:
        raise ScriptError(f"--resume: {path} cannot be resumed here ({exc})") from exc
    except Exception as exc:
        raise ScriptError(f"--resume: {path} is damaged ({first_line(exc) or type(exc).__name__}"
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
            _write_partial(write, "interrupted", Interrupted(stop_signal()).end_message)
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


@contextmanager
def warnings_shown_once():
    """Within the block (a script's run), each of yadebreak's warnings is shown once (one line; a
    run of several scenes would repeat it per scene), naming the script's own option where the
    warning names an attach() option that the script exposes (--read-period for read_period).
    Python's display, and its filters, are back after the block: library use keeps them."""
    shown = set()
    with warnings.catch_warnings():         # restores showwarning and the filters on leaving
        python_show = warnings.showwarning

        def show(message, category, filename, lineno, file=None, line=None):
            if not hasattr(message, "for_script"):      # not a coupling.YadebreakWarning
                return python_show(message, category, filename, lineno, file, line)
            if message.cause in shown:
                return None
            shown.add(message.cause)
            print(f"[yadebreak] WARNING: {message.for_script(script_option_names())} "
                  "(shown once)", file=sys.stderr, flush=True)
            return None

        warnings.showwarning = show          # the documented hook of the warnings module
        yield


def progress(message):
    """One line of what a run did (results, outputs written) on stdout, flushed at once."""
    print(f"[yadebreak] {message}", flush=True)


def status(message):
    """One progress line of a long run on stderr, flushed at once; none with --quiet 1."""
    if not quiet():
        print(f"[yadebreak] {message}", file=sys.stderr, flush=True)


#: a long run says how it goes at least this often (s of wall time), on stderr
STATUS_EVERY = 10.0


class Remaining:
    """The time a run has left, as a steady estimate: elapsed (1 - done) / done at each call,
    smoothed (an exponential average with weight 0.3 on the newest, the older counted down by the
    wall time since), so that a scene that ends early or late moves it by a third of the
    change, not all of it."""

    def __init__(self):
        self.left, self.at = None, None

    def __call__(self, elapsed_s, done):
        """'about N s left' (time_left's words) for `done` (0-1) of the work after `elapsed_s`."""
        estimate = seconds_left(elapsed_s, done)
        if estimate is None:
            return UNKNOWN_LEFT
        if self.left is not None:
            estimate = 0.7 * max(self.left - (elapsed_s - self.at), 0.0) + 0.3 * estimate
        self.left, self.at = estimate, elapsed_s
        return f"about {estimate:.0f} s left"


class Heartbeat:
    """While a block runs, `describe(elapsed_s)`'s line on stderr every STATUS_EVERY s (status):
    a thread, which runs while YADE's O.run waits in C++; none with --quiet 1. For a block whose
    own steps are too long to report between (one long scene)."""

    def __init__(self, describe, every=None):
        self.describe, self.every = describe, every
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._beat, daemon=True)

    def _beat(self):
        began = time.time()
        every = self.every if self.every is not None else STATUS_EVERY
        while not self._stop.wait(every):
            try:
                status(self.describe(time.time() - began))
            except Exception:            # a line missed, never the run
                pass

    def __enter__(self):
        if not quiet():
            self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
        return False


UNKNOWN_LEFT = "time left unknown"


def seconds_left(elapsed_s, done):
    """The wall time (s) left after `elapsed_s` with the fraction `done` of the work done; None
    until 5 % is done (too early to extrapolate). Never negative or nan: `done` is taken within
    [0, 1]."""
    done = min(max(float(done), 0.0), 1.0) if math.isfinite(done) else 0.0
    if done < 0.05 or not math.isfinite(elapsed_s):
        return None
    return max(elapsed_s, 0.0) * (1.0 - done) / done


def time_left(elapsed_s, done):
    """'about N s left' (seconds_left), or 'time left unknown'."""
    left = seconds_left(elapsed_s, done)
    return UNKNOWN_LEFT if left is None else f"about {left:.0f} s left"


def resume_arguments(args):
    """The arguments that decide a run's results (not --resume, --overwrite, --stop-after, --out,
    --checkpoint-every, --vtk-interval, --debug or --jobs, nor the Materials loaded from the
    material options): what a resumed run must share with the one it continues."""
    return {k: v for k, v in sorted(vars(args).items())
            if k not in ("resume", "overwrite", "out", "stop_after", "checkpoint_every",
                         "vtk_interval", "debug", "quiet", "jobs", "materials")}


def check_resume_arguments(saved, args, path):
    """Refuse to resume, naming the arguments that differ, when `saved` (resume_arguments of the
    interrupted run, stored at `path`) are not this run's (an option added since, at the value
    that was the behaviour then, is not a difference)."""
    from yadebreak.jobs.options import arguments_of_today
    now = resume_arguments(args)
    saved = arguments_of_today(saved, now)
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
    (Path(out) / FINISHED).write_text(json.dumps({"arguments": resume_arguments(args)},
                                                 default=str))


def check_not_finished(out, args):
    """--resume: if the run in `out` finished, refuse other arguments (naming them), then raise
    RunFinished: nothing is run again and no output is rewritten."""
    path = Path(out) / FINISHED
    if path.exists():
        check_resume_arguments(json.loads(path.read_text())["arguments"], args, path)
        raise RunFinished(f"the run in {out} had finished: nothing to resume, its outputs are "
                          "kept (--overwrite 1 runs it again)")


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
        self.path = self.out / PARTIAL
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
            raise ScriptError(f"{refuse} is damaged ({type(exc).__name__}: {first_line(exc)}): "
                              f"{AGAIN}") from None
        check_resume_arguments(arguments, self.args, self.path)
        if "digest" in data and data["digest"] != _digest(done):
            raise ScriptError(f"{refuse} was changed after it was written (its digest does not "
                              f"match): {AGAIN}")
        for key, result in done.items():
            try:
                if validate is not None:
                    validate(key, result)
            except (ValueError, KeyError, TypeError) as exc:
                raise ScriptError(f"{refuse}: the result for {key} is not one this run could "
                                  f"have written ({first_line(exc)}): {AGAIN}") from None
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
