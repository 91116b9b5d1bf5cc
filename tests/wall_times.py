"""The output keys that measure the machine, not the model (docs/outputs.md): a test that compares
two runs' outputs compares them without these."""

WALL_KEYS = frozenset({"runtime_s", "wall_s", "wall_time_read_s", "wall_time_replace_s",
                       "steps_wall_s", "scenes_wall_s", "scene_walls_s", "yade_engines_s",
                       "wall_time"})


def timeless(x):
    """`x` (JSON-like: dicts, lists or tuples, values) without its WALL_KEYS, at any depth."""
    if isinstance(x, dict):
        return {k: timeless(v) for k, v in x.items() if k not in WALL_KEYS}
    if isinstance(x, (list, tuple)):
        return [timeless(v) for v in x]
    return x
