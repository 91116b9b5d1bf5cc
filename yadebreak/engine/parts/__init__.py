"""Parts that run in YADE's loop beside the breakage engine: rolling friction, the bond watch."""
