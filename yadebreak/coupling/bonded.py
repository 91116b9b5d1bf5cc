"""Saved scenes' entry point of the bond watch (see yadebreak/coupling/__init__.py)."""
from yadebreak.engine.parts.bonds import on_step  # noqa: F401
