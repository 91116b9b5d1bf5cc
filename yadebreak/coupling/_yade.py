"""The one place the coupling imports yade (from Debian's python3 too: see yadebreak.yadepath)."""
from ..yadepath import ensure_yade_importable

ensure_yade_importable()

import yade.wrapper as wrapper  # noqa: E402
from yade import O, Vector3, utils  # noqa: E402

__all__ = ["O", "Vector3", "find_engine", "utils", "wrapper"]


def find_engine(label):
    """The engine of O.engines with this label, or None."""
    return next((e for e in O.engines if getattr(e, "label", "") == label), None)
