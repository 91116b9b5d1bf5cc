"""Child processes that go with their parent."""
import os
import signal
import subprocess
import sys
from pathlib import Path


def die_with_parent():
    """In the child, before exec: be sent SIGTERM when the worker that started us goes (Linux's
    PR_SET_PDEATHSIG), so that a stopped sweep leaves no YADE running."""
    try:
        import ctypes
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGTERM)
    except OSError:
        pass


def python_module(module, *args, **popen):
    """Popen of `python3 -m module args...` with this process's interpreter (Debian's under the
    yade launcher) and this yadebreak first on its path, wherever it lives; it dies with us."""
    package = str(Path(__file__).resolve().parents[2])
    path = [package] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(path)}
    return subprocess.Popen([sys.executable or "/usr/bin/python3", "-m", module, *args],
                            env=env, preexec_fn=die_with_parent, **popen)
