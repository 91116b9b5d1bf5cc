"""Breakage criteria: when a body breaks and what it leaves (Tavares, Ab-T10, recording)."""
