"""The protocol of a part that runs in YADE's loop (in the spirit of HOOMD-blue's custom actions
and LAMMPS fixes): a part says when it acts (its hook in YADE's loop and its trigger: after each
act, the step it is due next; triggers.py), acts, and gives and takes its state, so that one
store saves every part with the scene and restores it after O.load, in this process or another.

    class Mine(Part):
        kind = "mine"                          # its name in the registry and in O.tags
        hook = AFTER_INTERACTIONS
        def act(self): ...
        def to_state(self, folder=None): return {...}   # JSON-able
        @classmethod
        def from_state(cls, label, period, state): return cls(...)

    install(Mine("mine", 5))                   # after O.engines is set (or into a list of engines);
                                               # 5: every 5 steps (or a triggers.Trigger)

Adding a part is one file with its class. One PyRunner per hook point (`yadebreak_<hook>`: just
before or after the InteractionLoop, or after NewtonIntegrator) calls the parts due there, in the
order they were installed; its members are listed in O.tags (`yadebreak_hook:<hook>`), each
part's state under its own key (`yadebreak_<kind>:<label>`), so that a loaded scene finds them
again. YADE's iterPeriod still does the waiting: while one part is awake at a hook, the runner's
period and last step are that part's (Python in YADE's loop costs a few microseconds a call, so
a part due every k steps costs nothing on the other k - 1); parts due at different steps make it
run every step. A part asleep (`sleep`) costs nothing; with none awake the runner is dead.
Scenes saved by earlier versions have a PyRunner per part, labelled as the part, whose command
calls `run(kind, label)`: they keep running as they were saved.
"""
from __future__ import annotations

import json
from importlib import import_module

from yadebreak.adapter.yade_api import O, current_scene, find_engine, wrapper
from yadebreak.engine.parts.triggers import as_trigger

#: where in YADE's loop a part's runner stands
BEFORE_INTERACTIONS = "before_interactions"
AFTER_INTERACTIONS = "after_interactions"
AFTER_NEWTON = "after_newton"
HOOKS = (BEFORE_INTERACTIONS, AFTER_INTERACTIONS, AFTER_NEWTON)

_KINDS: dict[str, type] = {}              # kind -> Part subclass (those defined so far)
#: the package's parts: kind -> the module that defines it, imported when a loaded scene names
#: the kind (no import is needed first for its side effect); a part defined elsewhere is found
#: by the module saved with its state (`part_module`)
PART_MODULES = {"breakage": "yadebreak.engine.scene", "breakage_zero": "yadebreak.engine.scene",
                "rolling": "yadebreak.engine.parts.rolling",
                "bonds": "yadebreak.engine.parts.bonds"}
_LIVE: dict[str, "Part"] = {}             # label -> this process's part
_SCENE_OF: dict[str, object] = {}         # label -> the scene its part belongs to
_MEMBERS: dict[str, tuple] = {}           # hook -> (scene, [(kind, label), ...]) read from O.tags


class Part:
    """One piece of work in YADE's loop; `label` names it, `trigger` says when it acts (a
    triggers.Trigger, or an integer k: every k steps); `period`: the steps from its last act to
    its next, as its trigger last said; `awake` False: it waits for wake(); `last`: the step it
    last acted at (None: never)."""

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

    def __init__(self, label, trigger=1):
        self.label = label
        self.trigger = as_trigger(trigger)
        self.period = self.trigger.next_step(0)
        self.awake = True
        self.last = None

    def act(self):
        raise NotImplementedError

    def next_step(self, now):
        """The step the part is due next, asked after it acted at `now` (its trigger's)."""
        return self.trigger.next_step(now)

    def to_state(self, folder=None):
        """The part's state as a JSON-able dict (its period, last step and whether it is awake
        are kept beside it); `folder`: the saved scene file's, for names of files relative to
        it (None: the working folder)."""
        return {}

    @classmethod
    def from_state(cls, label, period, state):
        """The part restored from its `state` (to_state's), due every `period` steps until its
        first act."""
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


def runner_label(hook):
    """The label of the PyRunner that calls the parts of `hook`."""
    return f"yadebreak_{hook}"


def install(part, engines=None, awake=True):
    """Register `part` in this process and the scene (its state in O.tags) and add it to its
    hook's runner in `engines` (a list of engines about to be O.engines; None: O.engines, set
    again), which gets the runner where the hook says if it has none. Returns the engines."""
    target = list(O.engines) if engines is None else engines
    part.awake = bool(awake)
    hold(part)
    members = _members(part.hook) if _find(target, runner_label(part.hook)) else []
    if any(label == part.label for _, label in members):
        raise ValueError(f"a part labelled {part.label!r} is installed already")
    _set_members(part.hook, members + [(part.kind, part.label)])
    if part.saved_at_install:
        save_state(part)
    runner = _find(target, runner_label(part.hook)) or _add_runner(target, part.hook)
    _time(runner, part.hook)
    if engines is None:
        O.engines = target
    return target


def _add_runner(engines, hook):
    """The hook's runner, put in `engines` where the hook says."""
    # updateGlobals=False: YADE would otherwise copy the caller's locals into __main__ after each
    # call (a user's `steps` or `_` changed by O.step() in a function)
    runner = wrapper.PyRunner(
        command=f"__import__('yadebreak.engine.parts.protocol').engine.parts.protocol."
                f"run_hook({hook!r})",
        iterPeriod=1, initRun=True, label=runner_label(hook), updateGlobals=False)
    kind = wrapper.NewtonIntegrator if hook == AFTER_NEWTON else wrapper.InteractionLoop
    at = next((k for k, e in enumerate(engines) if isinstance(e, kind)), None)
    if at is None:
        raise ValueError(f"O.engines has no {kind.__name__}: a part {hook} is installed after "
                         "O.engines is set")
    engines.insert(at if hook == BEFORE_INTERACTIONS else at + 1, runner)
    return runner


def uninstall(label):
    """Take part `label` out of the scene's engines (its runner goes when it was the last one
    there) and out of this process; returns the part, or None."""
    for hook in HOOKS:
        members = _members(hook)
        if any(name == label for _, name in members):
            rest = [(kind, name) for kind, name in members if name != label]
            _set_members(hook, rest)
            runner = find_engine(runner_label(hook))
            if not rest:
                O.engines = [e for e in O.engines if e is not runner
                             and getattr(e, "label", "") != runner_label(hook)]
            elif runner is not None:
                _time(runner, hook)
    if find_engine(label) is not None:                 # a runner of its own (older scenes)
        O.engines = [e for e in O.engines if getattr(e, "label", "") != label]
    return drop(label)


def installed(label):
    """Whether part `label` is in this scene's engines."""
    return find_engine(label) is not None or any(
        find_engine(runner_label(hook)) is not None
        and any(name == label for _, name in _members(hook)) for hook in HOOKS)


def hold(part):
    """`part` is this process's part `part.label` of the current scene."""
    _LIVE[part.label] = part
    _SCENE_OF[part.label] = current_scene()


def save_state(part, folder=None):
    O.tags[part.tag] = json.dumps({**part.to_state(folder), "period": part.period,
                                   "last": part.last, "awake": part.awake,
                                   "part_module": type(part).__module__})


def part_class(kind, module=None):
    """The Part subclass of `kind`, its module imported if no class of that kind is defined in
    this process yet: `module` (the one saved with the part), else PART_MODULES'."""
    if kind not in _KINDS:
        where = module or PART_MODULES.get(kind)
        if where is None:
            raise RuntimeError(f"no yadebreak part of kind {kind!r} is defined: import the "
                               "module that defines it before loading the scene")
        import_module(where)
        if kind not in _KINDS:
            raise RuntimeError(f"module {where} defines no yadebreak part of kind {kind!r}")
    return _KINDS[kind]


def live(kind):
    """This process's parts of `kind` of the current scene: {label: part}."""
    scene = current_scene()
    return {label: p for label, p in _LIVE.items()
            if p.kind == kind and _SCENE_OF[label] == scene}


def run_hook(hook):
    """Called by a hook's runner: every awake part there whose period has passed acts, and its
    trigger says when it is due next."""
    now = O.iter
    for kind, label in _members(hook):
        part = part_of(kind, label)
        if part.awake and (part.last is None or now - part.last >= part.period):
            part.last = now
            part.act()
            period = part.next_step(now) - now
            if period != part.period:
                _change(label, period=max(1, period))


def run(kind, label):
    """Called by a part's own PyRunner (scenes saved by earlier versions): the part acts."""
    part = part_of(kind, label)
    part.last = O.iter
    part.act()
    _change(label, period=max(1, part.next_step(O.iter) - O.iter))


def set_trigger(label, trigger):
    """Part `label` acts when `trigger` says (a Trigger, or an integer: every k steps), counted
    from its last act (a step already past: the next step)."""
    part = _named(label)
    if part is None:
        raise ValueError(f"no yadebreak part labelled {label!r} in this scene")
    part.trigger = as_trigger(trigger)
    _change(label, period=_period_after_last(part))


def wake(label):
    """Part `label` acts again, when its trigger says counted from its last act (a step already
    past: the next step)."""
    part = _named(label)
    if part is None:                                   # not restored (older scenes' own runner)
        _change(label, awake=True)
        return
    _change(label, awake=True, period=_period_after_last(part))


def _period_after_last(part):
    """The steps from the part's last act (now, if it never acted) to the one its trigger
    says."""
    last = part.last if part.last is not None else O.iter
    return max(1, part.next_step(last) - last)


def sleep(label):
    """Part `label` does not act until woken; a runner with no part awake is dead."""
    _change(label, awake=False)


def _change(label, **values):
    """Part `label`'s period or wakefulness, and its runner's timing with it."""
    part = _named(label)
    if part is None:                                   # not restored (older scenes' own runner)
        own = find_engine(label)
        if own is not None and "awake" in values:
            own.dead = not values["awake"]
        elif own is not None:
            own.iterPeriod = values["period"]
        return
    for k, v in values.items():
        setattr(part, k, v)
    own = find_engine(part.label)                      # a runner of its own (older scenes)
    if own is not None:
        own.iterPeriod, own.dead = part.period, not part.awake
        return
    runner = find_engine(runner_label(part.hook))
    if runner is not None:
        _time(runner, part.hook)


def _named(label):
    """This scene's part `label` (restored if it must be), or None if the scene lists none."""
    part = _LIVE.get(label)
    if part is not None and _SCENE_OF[label] == current_scene():
        return part
    for hook in HOOKS:
        for kind, name in _members(hook):
            if name == label:
                return part_of(kind, label)
    return None


def runs(kind, label):
    """How many times the runner of part `label` has run (YADE's nDone; 0 if none)."""
    runner = find_engine(label) or find_engine(runner_label(part_class(kind).hook))
    return getattr(runner, "nDone", 0)


def _time(runner, hook):
    """The runner's period: its one awake part's (with that part's last step, so that YADE
    waits for it), 1 if the awake parts are due at different steps; dead if none is awake."""
    parts = [_LIVE.get(label) for _, label in _members(hook)]
    if any(p is None for p in parts):                  # not restored yet: every step
        runner.dead, runner.iterPeriod = False, 1
        return
    awake = [p for p in parts if p.awake]
    runner.dead = not awake
    steps = {(p.period, p.last) for p in awake}
    if len(steps) != 1:
        runner.iterPeriod = 1
        return
    period, last = steps.pop()
    runner.iterPeriod = period
    if last is not None and runner.nDone:
        runner.iterLast = last


def part_of(kind, label):
    """The part `label` of the current scene, restored from O.tags first when this process
    holds none that followed this scene (after O.load, or a part of an earlier scene)."""
    part = _LIVE.get(label)
    if part is None or _SCENE_OF[label] != current_scene() or not part.current():
        saved_module = (None if kind in _KINDS or kind in PART_MODULES     # a user's part not
                        else _saved(f"yadebreak_{kind}:{label}", {}).get("part_module"))  # imported
        cls = part_class(kind, saved_module)
        data = _saved(cls.tag_for(label), None)
        if data is None:
            data = cls.legacy_state(label)
        if data is None:
            raise RuntimeError(f"the scene has no state of yadebreak's {kind} part {label!r}: "
                               "save scenes with yadebreak.save or a job's checkpoint")
        if part is not None:
            part.close()
        part = cls.from_state(label, data.get("period", 1), data)
        part.last, part.awake = data.get("last"), data.get("awake", True)
        hold(part)
    return part


def _saved(tag, default):
    """The state stored under O.tags[tag], or `default`."""
    return json.loads(O.tags[tag]) if tag in O.tags.keys() and O.tags[tag] else default


def _members(hook):
    """The (kind, label) of the parts at `hook` in this scene, in calling order."""
    scene = current_scene()
    cached = _MEMBERS.get(hook)
    if cached is None or cached[0] != scene:
        key = f"yadebreak_hook:{hook}"
        text = O.tags[key] if key in O.tags.keys() else ""
        cached = _MEMBERS[hook] = (scene, [tuple(m) for m in json.loads(text or "[]")])
    return cached[1]


def _set_members(hook, members):
    O.tags[f"yadebreak_hook:{hook}"] = json.dumps([list(m) for m in members])
    _MEMBERS[hook] = (current_scene(), list(members))


def _find(engines, label):
    return next((e for e in engines if getattr(e, "label", "") == label), None)


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
    if kinds is None:
        _MEMBERS.clear()
