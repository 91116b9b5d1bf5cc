"""Where yadebreak keeps what it builds once and reuses: one rule for every cache.

The root is $YADEBREAK_CACHE, else $XDG_CACHE_HOME/yadebreak, else ~/.cache/yadebreak; each kind
of thing has its folder under it (families/: progeny family tables, beds/: settled poured beds).
Deleting any of them is safe: what is missing is built again.
"""
from __future__ import annotations

import os
from pathlib import Path

KINDS = ("families", "beds")


def cache_root():
    """The cache's root folder (not created)."""
    if os.environ.get("YADEBREAK_CACHE"):
        return Path(os.environ["YADEBREAK_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "yadebreak"


def cache_folder(kind, given=""):
    """The folder of one kind of cached thing: `given` (a user's option) if any, else
    <root>/<kind> (not created)."""
    if kind not in KINDS:
        raise ValueError(f"cache kind {kind!r}: one of {', '.join(KINDS)}")
    return Path(given) if given else cache_root() / kind


def legacy_folders(kind):
    """Where version 0.2 kept this kind (read, never written): the root itself under
    $YADEBREAK_CACHE, and ~/.cache/yadebreak for family tables."""
    return [cache_root()] if kind == "families" or os.environ.get("YADEBREAK_CACHE") else []
