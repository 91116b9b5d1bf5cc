"""SIGINT and SIGTERM end a run as 'interrupted', at the run loop's next stop point."""
import signal
from contextlib import contextmanager

from yadebreak.process.errors import error_line


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
        return f"stopped by {signal_name(self.signum)}{self.note}"


def signal_name(signum):
    """How end messages name a signal: 'Ctrl-C, SIGINT', 'SIGTERM'."""
    return "Ctrl-C, SIGINT" if signum == signal.SIGINT else signal.Signals(signum).name


_STOP = {"signal": None, "points": 0}    # the signal received; depth of stop_points blocks


def on_signal(signum, frame):
    """The handler of SIGINT and SIGTERM while a script runs: within stop_points the first signal
    only asks the run to stop; otherwise raise Interrupted where it strikes."""
    first = _STOP["signal"] is None
    _STOP["signal"] = signum
    if _STOP["points"] and first:
        return                           # the job's loop stops at its next stop_point
    raise Interrupted(signum)


def catch_signals():
    """SIGINT and SIGTERM to on_signal while a script runs; returns the handlers to restore
    (none outside the main thread, where Python cannot set them)."""
    import threading
    _STOP["signal"] = None
    if threading.current_thread() is not threading.main_thread():
        return {}
    handlers = {}
    for s in (signal.SIGINT, signal.SIGTERM):
        handlers[s] = signal.getsignal(s)
        signal.signal(s, on_signal)
    return handlers


def restore_signals(handlers):
    """Put back the handlers catch_signals replaced, and forget the signal received."""
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


def stop_signal():
    """The signal that asked the run to stop (None if none has): its end message names it."""
    return _STOP["signal"]


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
