"""Saved scenes' entry points of the breakage engine (see yadebreak/coupling/__init__.py)."""
from yadebreak.engine.scene import on_read, on_zero  # noqa: F401
