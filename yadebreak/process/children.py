"""Child processes that go with their parent."""
import signal


def die_with_parent():
    """In the child, before exec: be sent SIGTERM when the worker that started us goes (Linux's
    PR_SET_PDEATHSIG), so that a stopped sweep leaves no YADE running."""
    try:
        import ctypes
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGTERM)
    except OSError:
        pass
