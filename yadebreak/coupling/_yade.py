"""The one place the coupling imports yade (from Debian's python3 too: see yadebreak.yadepath)."""
from ..yadepath import ensure_yade_importable

ensure_yade_importable()

import yade.wrapper as wrapper  # noqa: E402
from yade import O, utils  # noqa: E402

__all__ = ["O", "utils", "wrapper"]
