"""One skeleton for every job: a job supplies its scene, its measurements and its outputs; the
skeleton does the rest, the same way for all.

A scene that runs in chunks of steps (bed, mill, agglomerate) is a `Job`; `run(job)` then:
starts it (a fresh run: finish marker removed, then job.build(); --resume 1: a finished run says
so and stops, otherwise the checkpoint is read, damaged ones refused in one line, and its
arguments checked against this run's, then job.resume(); a run that left no checkpoint starts
again); calls job.advance() until it says how the run ended, writing a checkpoint at the first
safe point and then every --checkpoint-every s of wall time and stopping at
SIGINT or SIGTERM (checkpointed) at the job's safe points; ends as if killed at --stop-after
(tests); prints a progress line with the time left every job.report_every s, from a thread, so
also within a long chunk; on a failure writes the outputs so far with their end reason; at the
end writes the outputs, the finish marker, and removes the checkpoint.

    class Drop(Job):
        def build(self): ...                    # the scene, new
        def resume(self, path): ...             # the scene from its checkpoint; earlier wall s
        def advance(self): ...                  # a chunk of steps; None, "finished", "time_limit"
        def save(self, path, wall_s): ...       # the checkpoint
        def outputs(self, end_reason, end_message, runtime_s): ...     # summary.json etc.

    summary = skeleton.run(Drop(args))

A job of independent units (the energies of single impacts and drop-weight tests, the stability
matrix's cases) is a `Units` job, run by the same run(): one unit per advance(), each finished
unit kept in <out>/partial.json (PartialResults) where --resume 1 skips it (`run_units`).
"""
import math
import time
from contextlib import nullcontext
from pathlib import Path

from yadebreak.jobs.lifecycle import (CHECKPOINT, Heartbeat, PartialResults, Remaining,
                                       check_not_finished, check_resume_arguments, mark_finished,
                                       mark_started, partial_outputs_on_failure, progress,
                                       read_checkpoint, stop_point, stop_points)


class Job:
    """A job run in chunks of steps. `args`: its options (an argparse.Namespace with at least
    `out`); quiet: no progress lines."""

    #: s of wall time between two progress lines
    report_every = 10.0
    #: --checkpoint-every when `args` has none (s of wall time; < 0: no checkpoints)
    checkpoint_every = 60.0

    def __init__(self, args, quiet=False):
        self.args = args
        self.out = Path(args.out)
        self.say = (lambda message: None) if quiet else progress
        self.quiet = quiet

    # -- start ----------------------------------------------------------------------------------
    def start(self):
        """A fresh run (build), or --resume 1 from the checkpoint (resume); returns the run's
        wall time (s) before this invocation."""
        return _start(self)

    def check(self):
        """Cross-checks of the options, before anything is written (raise ScriptError)."""

    def build(self):
        """A fresh run: build the scene."""
        raise NotImplementedError

    def resume(self, path):
        """--resume 1: the scene from the checkpoint at `path` (see load_checked). Returns the
        run's wall time (s) before this invocation, up to that checkpoint."""
        raise NotImplementedError

    def open(self):
        """After build or resume: what the run writes as it goes (ParaView frames, logs)."""

    # -- the loop -------------------------------------------------------------------------------
    def advance(self):
        """One chunk of steps with its measurements: None to go on, or how the run ended
        ("finished", or "time_limit" at a limit of simulated time)."""
        raise NotImplementedError

    def at_safe_point(self):
        """True where a checkpoint may be written and a signal may stop the run (the state is
        whole and a resumed run goes on exactly from it)."""
        return True

    def elapsed(self):
        """How far the run is, in --stop-after's unit: s of simulated time (or impacts done)."""
        raise NotImplementedError

    def status(self):
        """The progress line's head (the skeleton adds the wall time and the time left)."""
        return ""

    def done(self):
        """Fraction of the run done, for the time left."""
        return 0.0

    def save(self, path, wall_s):
        """The checkpoint at `path`, with the run's wall time so far (s, all invocations)."""
        raise NotImplementedError

    # -- the end --------------------------------------------------------------------------------
    def close(self):
        """The loop has ended (finished or at a limit): close open events, the last frame."""

    def stopped(self):
        """The run stopped at --stop-after (as if killed): release what it holds."""

    def end_message(self, ended):
        """summary.json's end_message for the way the run ended."""
        return ""

    def outputs(self, end_reason, end_message, runtime_s):
        """summary.json and the other outputs; also the partial outputs of a failed run. Returns
        the summary (a dict)."""
        raise NotImplementedError

    def finished(self, summary):
        """The run wrote all its outputs: its last progress lines."""

    def result(self, summary):
        """What run() returns: the summary (None if stopped at --stop-after)."""
        return summary


def load_checked(path, load, args):
    """load(path) of a checkpoint for --resume (a damaged one refused in one line, see
    read_checkpoint): (scene, state), refused (naming them) if it was written with other
    arguments. Checkpoints of versions that did not record their arguments are taken as they
    are."""
    scene, state = read_checkpoint(path, load)
    if "arguments" in state:
        check_resume_arguments(state["arguments"], args, path)
    return scene, state


def run(job):
    """Run `job` from start (or its checkpoint) to its outputs; returns job.result(summary)."""
    args, out = job.args, job.out
    job.check()                                   # before anything is written
    out.mkdir(parents=True, exist_ok=True)
    start = time.time()
    # SIGINT, SIGTERM from here on: the run ends at its loop's next safe point, checkpointed
    with stop_points():
        wall_before = job.start()

        def runtime():                            # s: the whole run's, over its invocations
            return wall_before + time.time() - start

        job.open()
        with partial_outputs_on_failure(lambda reason, message: job.outputs(reason, message,
                                                                            runtime())):
            ended = _loop(job, start, runtime)
            if ended is not None:
                job.close()
    if ended is None:
        job.stopped()
        return job.result(None)
    summary = job.outputs(ended, job.end_message(ended), runtime())
    mark_finished(out, args)                      # --resume 1 now says so and does nothing
    (out / CHECKPOINT).unlink(missing_ok=True)    # a mid-run state, of no more use
    job.finished(summary)
    return job.result(summary)


def _start(job):
    """Build the scene, or resume it (--resume 1); the wall time (s) of earlier invocations."""
    if getattr(job.args, "resume", False):
        check_not_finished(job.out, job.args)     # a finished run: says so, nothing is rewritten
        if (job.out / CHECKPOINT).exists():
            return job.resume(job.out / CHECKPOINT)
        progress(f"--resume: {job.out} holds no checkpoint (the run stopped before its first): "
                 "it starts again, with the same options and seed")
    mark_started(job.out)
    (job.out / CHECKPOINT).unlink(missing_ok=True)   # an earlier run's: --resume must not find it
    job.build()
    return 0.0


def _loop(job, start, runtime):
    """advance() until the run ends: how it ended, or None at --stop-after (tests: as if the run
    had died there)."""
    args, path = job.args, job.out / CHECKPOINT
    every = getattr(args, "checkpoint_every", job.checkpoint_every)
    stop_after = getattr(args, "stop_after", 0.0)
    remaining = Remaining()
    last_checkpoint = -math.inf           # the first at the first safe point: seconds in, a run
    #                                       killed early goes on from there

    def save():
        job.save(path, runtime())

    def line(_):
        wall = time.time() - start
        return f"{job.status()}, wall {wall:.0f} s, {remaining(wall, job.done())}"

    # the progress line from a thread, also while one chunk of a large scene runs
    beat = (Heartbeat(line, job.report_every)
            if math.isfinite(job.report_every) and not job.quiet else nullcontext())
    with beat:
        while True:
            ended = job.advance()
            if ended is not None:
                return ended
            if job.at_safe_point():
                if every >= 0 and time.time() - last_checkpoint >= every:
                    save()                            # --resume 1 goes on from here
                    last_checkpoint = time.time()
                stop_point(save)                      # SIGINT, SIGTERM: end here, checkpointed
            if stop_after and job.elapsed() >= stop_after:
                return None


class Units(Job):
    """A job of independent units, each one advance(): compute(k, key) gives (the scene's
    controller, the unit's result); write(results of the keys done, end_reason, end_message)
    the outputs (also those of a failed run, with the units done; returns the summary);
    limited(results) the end message if a unit stopped at a limit (end reason "time_limit"), else
    "". With `resumable`, each unit's result is kept in <out>/partial.json as it finishes
    (validate(key, result): see PartialResults), so that --resume 1 skips the units an
    interrupted run finished (each must depend only on the arguments and its own seed); a signal
    ends the run at the unit's next stop point. run() returns the last controller."""

    report_every = math.inf           # each unit says its own lines
    checkpoint_every = -1.0           # partial.json, written at each unit, is the checkpoint

    def __init__(self, args, keys, compute, write, limited=None, validate=None, resumable=True):
        super().__init__(args)
        self.keys, self.compute, self.write = list(keys), compute, write
        self.limited, self.validate, self.resumable = limited, validate, resumable
        self.brk, self.message = None, ""

    def start(self):
        if self.resumable:
            self.partial = PartialResults(self.out, self.args, self.validate)
        else:
            mark_started(self.out)
            self.partial = _InMemory()
        self.todo = iter(self.partial.todo(self.keys))
        return 0.0

    def advance(self):
        k, key = next(self.todo, (None, None))
        if key is None:
            results = self.partial.ordered(self.keys)
            self.message = self.limited(results) if self.limited is not None else ""
            return "time_limit" if self.message else "finished"
        self.brk, result = self.compute(k, key)
        self.partial.add(key, result)         # --stop-after: ends here, as if killed
        return None

    def elapsed(self):
        return len(self.partial.done)

    def save(self, path, wall_s):
        """partial.json holds every finished unit already."""

    def end_message(self, ended):
        return self.message

    def outputs(self, end_reason, end_message, runtime_s):
        return self.write(self.partial.ordered([key for key in self.keys
                                                if str(key) in self.partial.done]),
                          end_reason, end_message)

    def result(self, summary):
        return self.brk


class _InMemory:
    """The finished units of a run that is not resumed (PartialResults' interface)."""

    def __init__(self):
        self.done = {}

    def todo(self, keys):
        return list(enumerate(keys))

    def ordered(self, keys):
        return [self.done[str(key)] for key in keys]

    def add(self, key, result):
        self.done[str(key)] = result


def run_units(args, keys, compute, write, limited=None, validate=None):
    """run() of a Units job (its arguments): the last computed controller."""
    return run(Units(args, keys, compute, write, limited, validate))
