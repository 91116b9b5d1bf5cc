"""The protocol of a part that runs in YADE's loop (in the spirit of HOOMD-blue's custom actions
and LAMMPS fixes): a part says when it acts (its hook in YADE's loop and its period in steps),
acts, and gives and takes its state, so that one store saves every part with the scene and
restores it after O.load, in this process or another.

    class Mine(Part):
        kind = "mine"                          # its name in the registry and in O.tags
        hook = AFTER_INTERACTIONS
        def act(self): ...
        def to_state(self, folder=None): return {...}   # JSON-able
        @classmethod
        def from_state(cls, label, period, state): return cls(...)

    O.engines = O.engines + [install(Mine(...))]   # the PyRunner that calls it

Adding a part is one file with its class. A PyRunner calls `run(label)`, which finds the part
in this process or restores it from the scene's O.tags (`yadebreak_<kind>:<label>`); `store()`
writes every part of the scene into O.tags before O.save, `forget()` drops this process's parts
(after O.load, the next run restores them). One PyRunner per part keeps YADE's iterPeriod doing
the waiting: Python in YADE's loop costs a few microseconds per call, so a part due every k
steps costs nothing on the other k - 1.
"""
from __future__ import annotations

import json

from yadebreak.adapter.yade_api import O, current_scene, wrapper

#: where in YADE's loop a part's PyRunner stands
BEFORE_INTERACTIONS = "before_interactions"
AFTER_INTERACTIONS = "after_interactions"
AFTER_NEWTON = "after_newton"
HOOKS = (BEFORE_INTERACTIONS, AFTER_INTERACTIONS, AFTER_NEWTON)

_KINDS: dict[str, type] = {}              # kind -> Part subclass
_LIVE: dict[str, "Part"] = {}             # label -> this process's part
_SCENE_OF: dict[str, object] = {}         # label -> the scene its part belongs to


class Part:
    """One piece of work in YADE's loop; `label` names its PyRunner, `period` its steps."""

    kind: str = ""
    hook: str = AFTER_INTERACTIONS
    #: its state goes into O.tags when it is installed (so that a scene O.saved without
    #: yadebreak.save still carries its settings); False for a state valid only at the step it
    #: was stored, which store() writes with the scene
    saved_at_install: bool = True

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.kind:
            if cls.kind in _KINDS and _KINDS[cls.kind] is not cls:
                raise ValueError(f"a part of kind {cls.kind!r} is registered already")
            if cls.hook not in HOOKS:
                raise ValueError(f"part {cls.kind!r}: hook {cls.hook!r}, accepted {HOOKS}")
            _KINDS[cls.kind] = cls

    def __init__(self, label, period=1):
        self.label = label
        self.period = int(period)

    def act(self):
        raise NotImplementedError

    def to_state(self, folder=None):
        """The part's state as a JSON-able dict (its period is kept beside it); `folder`: the
        saved scene file's, for names of files relative to it (None: the working folder)."""
        return {}

    @classmethod
    def from_state(cls, label, period, state):
        return cls(label, period)

    @classmethod
    def legacy_state(cls, label):
        """The state of a scene saved before this part had its own O.tags key (None: none)."""
        return None

    def current(self):
        """False if the part has not followed this scene's steps (it is restored from O.tags)."""
        return True

    def close(self):
        """The part is dropped from this process (files it holds open are closed)."""

    @classmethod
    def tag_for(cls, label):
        """The O.tags key of the part `label` of this kind."""
        return f"yadebreak_{cls.kind}:{label}"

    @property
    def tag(self):
        return self.tag_for(self.label)


def install(part, dead=False):
    """Register `part` in this process and the scene (its state in O.tags) and return its
    PyRunner, to be put in O.engines where its hook says (`dead`: asleep until woken)."""
    hold(part)
    if part.saved_at_install:
        save_state(part)
    # updateGlobals=False: YADE would otherwise copy the caller's locals into __main__ after each
    # call (a user's `steps` or `_` changed by O.step() in a function)
    return wrapper.PyRunner(
        command=f"__import__('yadebreak.engine.parts.protocol').engine.parts.protocol."
                f"run({part.kind!r}, {part.label!r})",
        iterPeriod=part.period, initRun=True, label=part.label, dead=dead, updateGlobals=False)


def hold(part):
    """`part` is this process's part `part.label` of the current scene."""
    _LIVE[part.label] = part
    _SCENE_OF[part.label] = current_scene()


def save_state(part, folder=None):
    O.tags[part.tag] = json.dumps({**part.to_state(folder), "period": part.period})


def live(kind):
    """This process's parts of `kind` of the current scene: {label: part}."""
    scene = current_scene()
    return {label: p for label, p in _LIVE.items()
            if p.kind == kind and _SCENE_OF[label] == scene}


def run(kind, label):
    """Called by a part's PyRunner: the part acts (see part_of)."""
    part_of(kind, label).act()


def part_of(kind, label):
    """The part `label` of the current scene, restored from O.tags first when this process
    holds none that followed this scene (after O.load, or a part of an earlier scene)."""
    part = _LIVE.get(label)
    if part is None or _SCENE_OF[label] != current_scene() or not part.current():
        cls = _KINDS[kind]
        tag = cls.tag_for(label)
        data = (json.loads(O.tags[tag]) if tag in O.tags.keys() and O.tags[tag]
                else cls.legacy_state(label))
        if data is None:
            raise RuntimeError(f"the scene has no state of yadebreak's {kind} part {label!r}: "
                               "save scenes with yadebreak.save or a job's checkpoint")
        if part is not None:
            part.close()
        part = cls.from_state(label, data.get("period", 1), data)
        hold(part)
    return part


def store(folder=None):
    """Every part of this scene into O.tags with its state now (before O.save; `folder`: the
    scene file's)."""
    scene = current_scene()
    for label, part in _LIVE.items():
        if _SCENE_OF[label] == scene:
            save_state(part, folder)


def drop(label):
    """Forget part `label` in this process (detached); returns it, or None."""
    _SCENE_OF.pop(label, None)
    part = _LIVE.pop(label, None)
    if part is not None:
        part.close()
    return part


def forget(kinds=None):
    """Drop this process's parts (of `kinds` only, if given): the next run of each rebuilds it
    from O.tags (after O.load)."""
    for label in [k for k, p in _LIVE.items() if kinds is None or p.kind in kinds]:
        drop(label)
