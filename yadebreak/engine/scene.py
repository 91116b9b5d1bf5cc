"""Attaching the engine to a scene, finding it again after O.load, and saving it with the scene.

The engine is two parts of YADE's loop (engine/parts/protocol.py): BreakageEngine, after the
InteractionLoop when the read schedule says, holds the controller and its state; Zeroing, before
the InteractionLoop, zeroes the fragments' artificial overlaps (asleep while there are none)."""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path

from yadebreak.model.materials import MATERIALS_DIR
from yadebreak.engine.parts import protocol
from yadebreak.adapter.yade_api import (O, close_remote_access, find_engine, scene_folder,
                                        wrapper)
from yadebreak.options.table import AttachError, Config
from yadebreak.engine.contacts.laws import laws_in
from yadebreak.engine.controller import Controller
from yadebreak.engine.materials import breakable_bodies, check_mapping, dummy_materials, resolve
from yadebreak.engine.state import EventLog
from yadebreak.engine.stepping import smallest_rayleigh_time

_TAG = "yadebreak:"
_SCRIPT_TAG = "yadebreak_script"
_RELOAD = "yadebreak_reload"              # reload()'s in-memory save
#: YADE's O.dt before anyone sets it: any other value before attach() is the user's
YADE_DEFAULT_DT = 1e-8


class BreakageEngine(protocol.Part):
    """The engine's read, after the InteractionLoop when its trigger, the read schedule
    (engine/reads.py), says; its state is the controller's (_state)."""

    kind = "breakage"
    hook = protocol.AFTER_INTERACTIONS

    def __init__(self, label, controller):
        self.controller = controller
        super().__init__(label, controller.schedule)

    @classmethod
    def tag_for(cls, label):
        return _TAG + label                  # the key every saved scene holds

    def act(self):
        self.controller.step()

    def current(self):
        """It read at the last read this scene made (else the scene was loaded or went back)."""
        ctl = self.controller
        return ctl.last_iter < O.iter <= ctl.last_iter + ctl.period

    def to_state(self, folder=None):
        return _state(self.controller, folder)

    @classmethod
    def from_state(cls, label, period, state):
        return cls(label, _restore(label, state, period))

    @classmethod
    def legacy_state(cls, label):
        raise AttachError(f"yadebreak engine '{label}' has no state in this scene")

    def close(self):
        self.controller.close()


class Zeroing(protocol.Part):
    """The engine's zeroing of artificial overlaps, before the InteractionLoop; asleep while
    there are none (engine/zeroing.py wakes it). Its state is the controller's."""

    kind = "breakage_zero"
    hook = protocol.BEFORE_INTERACTIONS

    zeroing = None                           # the controller's, as found at the last act

    def act(self):
        ctl = controller_of(self.label.removesuffix("_zero"))
        self.zeroing = ctl.zeroing
        ctl.zero_overlaps()

    def next_step(self, now):
        """Its trigger is the zeroing's own (zeroing.OverlapZeroing.next_step)."""
        zeroing = self.zeroing or controller_of(self.label.removesuffix("_zero")).zeroing
        return zeroing.next_step(now)

    @classmethod
    def legacy_state(cls, label):
        return {}                            # nothing of its own to restore


def attach(materials, seed=0, *, label="yadebreak", **options):
    """Register yadebreak in the current YADE scene and return its controller.

    materials: {YADE material label: material name, path or Material}; bodies of other materials
    are non-breakable partners. Call after O.engines is set (an InteractionLoop with
    Law2_ScGeom_MindlinPhys_Mindlin) and the breakable spheres (or convex Polyhedra: see
    docs/polyhedra.md) exist. Options: see
    config.OPTIONS (docs/options.md), checked before anything changes. Each material file
    chooses its criterion (breakage.model = "tavares" or "ab_t10"); one scene may mix both.
    """
    config = Config.from_options(seed=seed, **options)
    found = check_mapping(materials)
    _check_event_log(config.output.event_log)
    if label in protocol.live(BreakageEngine.kind) and protocol.installed(label):
        raise AttachError(f"yadebreak is already attached to this scene as '{label}': call attach "
                          "once per scene (or give another label)")
    engines = list(O.engines)
    if not config.output.remote_access:
        _close_remote_access()
    loop_idx, law = contact_law(engines)
    problem = law.problems(config.reading)
    if problem:
        raise AttachError(problem)
    label_ids = {m.id: m.label for m in O.materials if m.label in materials}
    breakable = breakable_bodies(label_ids)
    _check_not_tracked_elsewhere(label, [s[0] for s in breakable])
    # every check is done: from here on the scene changes
    dummy_materials(materials, config.replacement.dummy_stiffness, engines[loop_idx])
    scene_materials = resolve(found, law, config.criteria.kappa, config.criteria.emax_ratio)
    ctl = Controller(label, config, scene_materials, materials)
    ctl.register(breakable)
    if not len(ctl.bodies):
        ctl.warn_once("empty", "the scene has no breakable body: nothing will break (materials "
                      f"mapped: {sorted(materials)})")
    ctl.state.log.start()
    ctl.damping.apply_at_attach()
    user_dt = None if O.dt == YADE_DEFAULT_DT else O.dt
    if law.time_step_advice and user_dt is None:
        ctl.warn_once("dt", f"O.dt is YADE's default {O.dt:g} s: {law.time_step_advice}")
    ctl.time_step.at_attach(smallest_rayleigh_time(), user_dt)
    ctl.last_iter = O.iter - 1
    protocol.install(BreakageEngine(label, ctl), engines)
    protocol.install(Zeroing(label + "_zero"), engines, awake=False)
    O.engines = engines
    return ctl


def contact_law(engines):
    """(index of the InteractionLoop in `engines`, the law the engine reads there, a
    contacts.laws instance): Hertz-Mindlin (spheres, and polyhedra through ScGeom) or the
    volumetric law of polyhedra, one per scene (docs/polyhedra.md: the two cannot meet in one
    scene)."""
    loop_idx = next((k for k, e in enumerate(engines) if isinstance(e, wrapper.InteractionLoop)),
                    None)
    if loop_idx is None:
        raise AttachError("O.engines has no InteractionLoop: set O.engines (with "
                          "Law2_ScGeom_MindlinPhys_Mindlin) before calling yadebreak.attach")
    names = {type(f).__name__ for f in engines[loop_idx].lawDispatcher.functors}
    found = laws_in(names)
    if not found:
        raise AttachError("the InteractionLoop has no Law2_ScGeom_MindlinPhys_Mindlin: yadebreak "
                          "reads YADE's Hertz-Mindlin forces (use add_materials() for the Ip2), or "
                          "for polyhedra Law2_PolyhedraGeom_PolyhedraPhys_Volumetric")
    if len(found) > 1:
        raise AttachError(f"the InteractionLoop has {' and '.join(law.yade_law for law in found)}"
                          ": yadebreak reads one contact law per scene")
    return loop_idx, found[0]


def _check_event_log(path):
    """attach(event_log=...): a file that can be written, checked before the scene changes."""
    if path is None:
        return
    target = Path(path).absolute()
    if target.is_dir():
        raise AttachError(f"event_log = {path!r}: a folder; accepted: a file path (e.g. "
                          f"{os.path.join(path, 'events.jsonl')!r}) or None")
    folder = target.parent
    while not folder.exists():                 # attach makes the missing folders
        folder = folder.parent
    if not folder.is_dir() or not os.access(folder, os.W_OK | os.X_OK) or (
            target.exists() and not os.access(target, os.W_OK)):
        raise AttachError(f"event_log = {path!r}: cannot be written here ({folder} is not a "
                          "writable folder); accepted: a writable file path or None")
    if folder == target.parent:                # opened as the log will be (root passes access()
        existed = target.exists()              # where a file system refuses: /proc, read-only)
        try:
            with open(target, "a"):
                pass
        except OSError as exc:
            raise AttachError(f"event_log = {path!r}: cannot be written ({exc.strerror}); "
                              "accepted: a writable file path or None") from None
        if not existed:
            target.unlink()


def _check_not_tracked_elsewhere(label, ids):
    """One engine per body: a second label over bodies another one tracks would judge and break
    them twice."""
    for other, part in protocol.live(BreakageEngine.kind).items():
        if other == label or not protocol.installed(other):
            continue
        shared = sorted(set(ids) & set(part.controller.bodies))
        if shared:
            raise AttachError(f"bodies {shared[:5]}{' ...' if len(shared) > 5 else ''} are "
                              f"tracked by the yadebreak engine '{other}' already: map each "
                              "breakable material in one attach() only")


def detach(label="yadebreak"):
    """Remove the engine `label` from the scene (its PyRunners, its saved state); returns its
    controller, whose events and results stay readable."""
    part = protocol.uninstall(label)          # its controller closed
    protocol.uninstall(label + "_zero")
    for tag in (BreakageEngine.tag_for(label), Zeroing.tag_for(label + "_zero")):
        if tag in O.tags.keys():
            O.tags[tag] = ""                   # O.tags cannot delete a key
    return part.controller if part is not None else None


def forget():
    """Forget every engine attached in this process (after O.reset(), or in tests): the next
    call finds them again from the scene's O.tags."""
    protocol.forget((BreakageEngine.kind, Zeroing.kind))


def controller_of(label="yadebreak"):
    """The controller of engine `label`, restored from the scene when it was loaded (O.load
    after yadebreak.save, in this process or another) or went back in time."""
    return protocol.part_of(BreakageEngine.kind, label).controller


def _runs(label):
    """How many times the runners of the engine's two parts have run. The state stored with the
    scene is current only if neither has run since, but for the call that restores it (YADE
    counts a run before the runner's command)."""
    return [protocol.runs(BreakageEngine.kind, label), protocol.runs(Zeroing.kind, label + "_zero")]


def _state(ctl, folder=None):
    """Everything needed to go on after O.load (JSON-able). The event log is named relative to
    `folder`, the saved scene file's (else relative to the working folder): a run folder moved
    or copied with its log goes on writing its own."""
    options = ctl.config.as_options()
    log = options.pop("event_log")
    return {
        "label": ctl.label, "options": options,
        "event_log": None if log is None else {
            "path": os.path.relpath(os.path.abspath(log), folder or os.getcwd()),
            "relative_to": "working folder" if folder is None else "scene file"},
        "materials": {k: _material_reference(v) for k, v in ctl.material_names.items()},
        "iter": O.iter, "last_read": ctl.last_iter, "runs": _runs(ctl.label),
        "state": ctl.state.to_dict(),
        "contacts": ctl.reader.to_dict(), "zeroed": ctl.zeroing.to_list(),
        "damped_until": ctl.damping.until, "fast": ctl.schedule.to_list(),
        "time_step": ctl.time_step.to_list()}


def _close_remote_access():
    """Close the `yade` launcher's remote prompt and XMLRPC server (they listen on every
    interface), saying so once, when there are any (a script closed them already)."""
    ports = close_remote_access()
    if ports:
        print(f"[yadebreak] closed YADE's remote Python prompt and XMLRPC server (ports "
              f"{', '.join(map(str, ports))}), which listen on every interface: "
              "attach(remote_access=True) keeps them", file=sys.stderr, flush=True)


def _material_reference(material):
    """How a stored state names a material: as given (a name or a path), a file of the library
    by its name (its absolute path would tie the scene to this checkout)."""
    source = Path(str(getattr(material, "source", material)))
    if source.suffix == ".toml" and source.resolve().parent == MATERIALS_DIR:
        return source.stem
    return str(source)


def _restore(label, data, period):
    """The controller of a stored state (_state), in the scene loaded now."""
    if any(now > then + 1 for now, then in zip(_runs(label), data["runs"])):
        raise AttachError(
            f"yadebreak's state in this scene was stored at step {data['iter']} and the scene ran "
            f"on before it was saved: O.save does not store yadebreak's state; save scenes with "
            f"yadebreak.save(path)")
    config = Config.from_options(**{**data["options"], "event_log": _stored_event_log(data)})
    scene_materials = resolve(check_mapping(data["materials"]), contact_law(list(O.engines))[1],
                              config.criteria.kappa, config.criteria.emax_ratio)
    ctl = Controller(label, config, scene_materials, data["materials"], data["state"])
    own = find_engine(label)                  # a PyRunner of its own (older scenes)
    ctl.schedule.period = own.iterPeriod if own is not None else period
    ctl.schedule.restore(data["fast"])
    ctl.time_step.restore(data.get("time_step", (None, None)))
    ctl.reader.restore(data["contacts"])
    ctl.zeroing.restore(data["zeroed"])
    ctl.damping.until = [tuple(x) for x in data["damped_until"]]
    ctl.last_iter = data.get("last_read", data["iter"] - 1)   # the steps since it: the next read's
    ctl.state.log.rewrite()                # the log holds exactly the events of this state
    return ctl


def _stored_event_log(data):
    """The event log of a stored state, found from where the scene was loaded: relative to the
    scene file's folder (or the working folder, for a state stored at attach); a state of an
    earlier version names its log as given, often absolute: a log of that name in the scene
    file's folder is taken (a run folder carries its log wherever it was moved or copied)."""
    here = scene_folder()
    log = data.get("event_log", ())
    if log is None:
        return None
    if log != ():
        base = here if log["relative_to"] == "scene file" and here else os.getcwd()
        return os.path.normpath(os.path.join(base, log["path"]))
    old = data["options"].get("event_log")
    if old is not None and os.path.isabs(old) and here is not None:
        return os.path.join(here, os.path.basename(old))
    return old


def save(path):
    """O.save the scene with the state of every attached engine and rolling friction part (kept
    in O.tags, the event log named relative to the file's folder). O.save alone does not store
    it: after O.load such a scene refuses to go on rather than go on wrongly."""
    _store_all(os.path.dirname(os.path.abspath(str(path))))
    O.save(str(path))


def _store_all(folder=None):
    """Every engine's and part's state into O.tags (before O.save)."""
    protocol.store(folder)


def reload(label="yadebreak"):
    """O.save the scene in memory and O.load it back, with the state of every engine and
    rolling friction part; returns engine `label`'s controller, restored (the objects of the
    scene before are gone: take bodies and controllers again). Called where a run may be saved
    (a script's checkpoints), at steps that do not depend on when it is saved, it makes the run
    go on the same, to the last bit, whether it was saved and loaded there or not: O.save keeps
    the real interactions but not the potential ones (bounds overlapping, no contact yet) nor the
    collider's sorted bounds, and a loaded scene's collider makes those anew, in another order
    and some with their two bodies the other way round; the place of an interaction in YADE's
    list is the order in which forces are summed. Measured: without it a one-ring bed cut at step
    56,100 differed in the last bit from step 56,597 on and ended with 81 damage events against
    88; a one-ulp nudge of one body does the same."""
    walls = {name: part.controller.wall_time
             for name, part in protocol.live(BreakageEngine.kind).items()}
    _store_all()
    O.saveTmp(_RELOAD)
    O.loadTmp(_RELOAD)
    protocol.forget()
    for name, wall_time in walls.items():
        controller_of(name).wall_time = wall_time          # (this process's measure)
    return controller_of(label) if label is not None else None


def save_checkpoint(path, script_state):
    """save() the scene to `path` with a script's loop state (a JSON-able dict), whole or not at
    all: to temporary files first, then os.replace, so that a kill or a full disk never leaves
    half a checkpoint (the last good one stays; the temporary files are removed). A .gz path is
    saved plain by YADE and compressed here: YADE's own gzip writer loops forever on a full disk
    (measured, YADE 2023.02a), its plain writer raises."""
    path = Path(path)
    O.tags[_SCRIPT_TAG] = json.dumps(script_state)
    packed = path.name.endswith(".gz")
    plain = path.with_name(path.name + (".tmp.yade" if packed else ".tmp" + path.suffix))
    tmp = path.with_name(path.name + ".tmp")
    try:
        save(plain)
        if packed:
            import gzip
            import shutil
            with open(plain, "rb") as source, gzip.open(tmp, "wb", compresslevel=1) as target:
                shutil.copyfileobj(source, target, 1 << 20)
            os.replace(tmp, path)
        else:
            os.replace(plain, path)
    finally:
        plain.unlink(missing_ok=True)
        tmp.unlink(missing_ok=True)


def load_checkpoint(path, label="yadebreak"):
    """O.load a checkpoint written by save_checkpoint; returns (controller, script state); label
    None: a scene without yadebreak's engine (the bonded agglomerate), controller None."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"--resume: no checkpoint at {path}; run without --resume first")
    O.load(str(path))
    protocol.forget()                     # this process's parts: rebuilt from the loaded O.tags
    return None if label is None else controller_of(label), json.loads(O.tags[_SCRIPT_TAG])


def run_steps(steps):
    """Advance the scene by `steps` steps now and return. O.run(n, True) waits for the run in 40 ms
    polls (measured: 40 ms for 1 to 500 steps of a small scene, 120 ms for 5000 that take 71 ms),
    so short runs in a loop (a run to rebound, a progress loop) step directly. An event log that
    cannot be written (a full disk) stops it after the step, with that OSError alone (from a
    PyRunner it would come with YADE's traceback printed)."""
    step = O.step
    failed = EventLog.deferred = []
    try:
        for _ in range(int(steps)):
            step()
            if failed:
                raise failed[0]
    finally:
        EventLog.deferred = None


def on_read(label):
    """The entry point that scenes saved by earlier versions name after the InteractionLoop."""
    protocol.run(BreakageEngine.kind, label)


def on_zero(label):
    """The entry point that scenes saved by earlier versions name before the InteractionLoop."""
    protocol.run(Zeroing.kind, label + "_zero")
