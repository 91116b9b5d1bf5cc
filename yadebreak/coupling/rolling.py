"""Saved scenes' entry point of rolling friction (see yadebreak/coupling/__init__.py)."""
from yadebreak.engine.parts.rolling import on_step  # noqa: F401
