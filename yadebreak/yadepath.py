"""Make `import yade` work from Debian's /usr/bin/python3.

Debian 12's python3-yade links dist-packages/yade to /usr/lib/<triplet>/yade/py/yade, but libyade
installs its modules under yade-double/ (the `yade` launcher adds that folder to sys.path itself).
This adds the same folder when a plain import fails. No yade import happens here.
"""
import glob
import importlib.util
import sys


def ensure_yade_importable():
    """Return True if yade can be imported, adding Debian's yade-double/py to sys.path if needed."""
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
