"""Make `import yade` work from Debian's /usr/bin/python3.

Debian 12's python3-yade links dist-packages/yade to /usr/lib/<triplet>/yade/py/yade, but libyade
installs its modules under yade-double/ (the `yade` launcher adds that folder to sys.path itself).
This adds the same folder when a plain import fails. No yade import happens here.
"""
import glob
import importlib.util
import os
import sys


def one_openmp_thread():
    """One OpenMP thread for this thread's parallel regions, where libgomp was loaded before
    OMP_NUM_THREADS could be set (matplotlib.pyplot loads it; the variable is read once, at
    load): O.step() in this thread then runs YADE's loops in one thread. Measured on a 2-core
    machine with the other core busy: 4,000 steps of a copper ore cascade took 148 s with
    pyplot imported first, 1.3 s without."""
    import ctypes
    try:
        ctypes.CDLL("libgomp.so.1", mode=os.RTLD_NOLOAD).omp_set_num_threads(1)
    except OSError:                      # not loaded yet: it will read OMP_NUM_THREADS
        pass


def builtins_in_main():
    """YADE sets an engine's label by running `__builtins__.<label> = ...` in __main__; where
    __main__ holds the builtins as a dict (a process started by multiprocessing's spawn), that
    fails: give it the module, as a script's __main__ has."""
    import builtins
    main = sys.modules.get("__main__")
    if main is not None and getattr(main, "__builtins__", builtins) is not builtins:
        main.__builtins__ = builtins


def ensure_yade_importable():
    """Return True if yade can be imported, adding Debian's yade-double/py to sys.path if needed.

    With OMP_NUM_THREADS=1 (`import yadebreak` sets it unless the user chose otherwise, as the
    `yade` launcher does by default) it also holds libgomp to one thread where libgomp was
    loaded first (one_openmp_thread): imported into plain Python, YADE would start one OpenMP
    thread per core, and with the other core busy every parallel region waits for a descheduled
    thread (measured: a 13-body scene at 30 ms per step instead of 0.25 ms while another job
    ran).
    """
    if os.environ.get("OMP_NUM_THREADS") == "1":
        one_openmp_thread()
    builtins_in_main()
    if importlib.util.find_spec("yade") is not None:
        try:
            spec = importlib.util.find_spec("yade.wrapper")
            if spec is not None:
                return True
        except ImportError:
            pass
    for folder in sorted(glob.glob("/usr/lib/*/yade-double/py")) + sorted(glob.glob("/usr/lib/*/yade*/py")):
        if folder not in sys.path:
            sys.path.insert(1, folder)
        sys.modules.pop("yade", None)
        importlib.invalidate_caches()
        if importlib.util.find_spec("yade") is not None:
            return True
    return False
