"""The per-step engine: read -> judge -> log -> replace (and zero) -> time step -> reschedule.

One Controller per attached engine; `attach()` (scene.py) makes it and its PyRunners call
`step()` after the InteractionLoop and the zeroing before it. Each part lives in its own module:
contacts (reading), criteria (judging), state (bodies, events, ledger), replacement, zeroing,
reads (the read schedule: the trigger of the engine's part), stepping (time step, fragment
damping).
"""
from __future__ import annotations

import time
import warnings

import numpy as np

from yadebreak.model import families
from yadebreak.analysis import reports
from yadebreak.adapter.yade_api import O, interaction_counts, silence_polyhedra_pair_checks
from yadebreak.engine.contacts import ContactReader, Strongest
from yadebreak.engine.safeguards import LargeOverlaps
from yadebreak.criteria import criterion_for
from yadebreak.engine.breaks_past import BreaksPast
from yadebreak.engine.judging import Judge, Rules
from yadebreak.engine.replacement import Recipe, Replacer
from yadebreak.engine.state import BREAKABLE, BROKEN, UNBREAKABLE, EngineState, assembled_columns
from yadebreak.engine.reads import read_schedule
from yadebreak.engine.stepping import FragmentDamping, TimeStep
from yadebreak.engine.tracking import Tracking
from yadebreak.engine.zeroing import OverlapZeroing


class YadebreakWarning(RuntimeWarning):
    """A warning of yadebreak: its `cause` (one kind of trouble, e.g. "jump"), the message and the
    remedies, attach() options that address it, best first, as (option, advice with {} where the
    option's name goes). The text names the first; a script names the first it exposes
    (for_script)."""

    def __init__(self, cause, message, remedies=(), purpose=""):
        self.cause, self.message, self.remedies, self.purpose = cause, message, list(remedies), purpose
        first = self.remedies[0] if self.remedies else None
        super().__init__(f"yadebreak: {self._text(first, str)}")

    def _text(self, remedy, spell):
        """The message with `remedy` (option, advice) advised, its option named by spell()."""
        if remedy is None:
            return self.message
        option, advice = remedy
        return f"{self.message}: {advice.format(spell(option))} {self.purpose}".rstrip()

    def for_script(self, exposed):
        """The message naming the first remedy among `exposed` (a script's option names), as its
        command line spells it (--read-period); attach()'s name if it exposes none."""
        mine = next((r for r in self.remedies if r[0] in exposed), None)
        if mine is not None:
            return self._text(mine, lambda o: "--" + o.replace("_", "-"))
        return self._text(self.remedies[0] if self.remedies else None,
                          lambda o: f"{o} (an attach() option)")


#: said once where the scene's law counts YADE's do_intersect warnings (contacts/volumetric.py)
PAIR_CHECKS_SILENCED = ("YADE's warning \"Unhandled switch case:0, function do_intersect\" is "
                        "silenced: it comes at every step for every pair of polyhedra whose "
                        "bounding boxes overlap without touching, harmless (docs/polyhedra.md); "
                        "polyhedra_pair_checks counts them")


class Controller:
    """The engine of one scene: its state, its parts, and the results (`events`,
    `size_distribution`, `body_state`). `saved`: the state of a stored scene (EngineState's
    to_dict), None for a new one."""

    def __init__(self, label, config, scene_materials, material_names, saved=None):
        self.label = label
        self.config = config
        self.material_names = dict(material_names)      # as given to attach (saved)
        self.material = scene_materials.by_label         # YADE label -> Material
        self.label_by_id = scene_materials.label_by_id
        self.criteria = {lab: criterion_for(mat, config.criteria.breakage,
                                            config.criteria.kappa_successive,
                                            config.criteria.t10_energy,
                                            config.criteria.kappa == "batch")
                         for lab, mat in self.material.items()}
        columns, log = assembled_columns(self.criteria.values()), config.output.event_log
        self.state = (EngineState(list(self.material), config.seed, log, columns) if saved is None
                      else EngineState.from_dict(saved, log, columns))
        # criterion of each material index of the body table
        self._criterion_of = [self.criteria[lab] for lab in self.state.table.labels]
        self.pause_steps = {lab: (config.criteria.pause_steps if config.criteria.pause_steps
                                  is not None else crit.default_pause_steps)
                            for lab, crit in self.criteria.items()}
        self.reader = ContactReader(scene_materials.stiffness_by_id, config.reading.cs,
                                    config.reading.emin, scene_materials.law)
        self.zeroing = OverlapZeroing(config.replacement.local_damping, label + "_zero",
                                      config.replacement.zeroing_tolerance)
        law = scene_materials.law
        if law.pair_checks is not None:
            silence_polyhedra_pair_checks()
            self.warn_once("pair_checks", PAIR_CHECKS_SILENCED)
        fast = config.reading.read_period == "fast" and not law.reads_every_step
        self.tracking = Tracking(self.state, config.reading.fast_tolerance if fast else None)
        self.schedule = read_schedule(config.reading, self.tracking.smallest_breakable,
                                      self.tracking.reach_now if fast else None,
                                      every_step=law.reads_every_step)
        self.time_step = TimeStep(config.time_step.time_step_fraction, self.warn_once)
        #: O.dt follows the loading where reads cannot come closer (stepping.TimeStep)
        self.step_follows_loading = bool(law.reads_every_step
                                         and config.time_step.time_step_fraction)
        gd = config.time_step.global_damping        # None: each material file's
        self.damping = FragmentDamping(
            {lab: (gd if gd is not None else mat.global_damping)
             for lab, mat in self.material.items()}, config.time_step.global_damping_time)
        self.replacer = Replacer(config.replacement, self.state,
                                 self._recipes(scene_materials), self.zeroing, self.reader)
        rules = Rules(config.criteria.fragments_energy_factor, config.reading.fast_tolerance,
                      config.criteria.break_at == "peak", any(self.pause_steps.values()),
                      config.replacement.contact_energy_at_break == "carried")
        told = BreaksPast(self.state, self.criteria, self.schedule, self.reader, self.warn_once)
        self.judge = Judge(self.state, self._criterion_of, self.reader, rules,
                           record=self.record_event, warn_jump=told.jump, warn_emin=told.emin,
                           weakened=self.tracking.weakened)
        self.large_overlaps = (LargeOverlaps(config.replacement.overlap_factor)
                               if config.replacement.overlap_factor else None)
        self.last_iter = -1
        self.wall_time = {"read": 0.0, "replace": 0.0}

    def _recipes(self, scene_materials):
        """Replacement.Recipe of each breakable material."""
        config, damped = self.config, self.damping.damped_labels
        dummies = (scene_materials.dummy_by_label
                   if config.replacement.dummy_stiffness != 1.0 else {})
        return {lab: Recipe(self.criteria[lab],
                            families.family_table(mat.beta_params, self.criteria[lab].t10_min,
                                                  self.criteria[lab].t10_ceiling,
                                                  config.replacement.family_seed),
                            self.pause_steps[lab], (lab in damped) if damped else None,
                            dummies.get(lab))
                for lab, mat in self.material.items()}

    # -- what users read ---------------------------------------------------------------------
    @property
    def bodies(self):
        """The body table: bodies[i].fracture_energy etc. (state.BodyTable)."""
        return self.state.table

    @property
    def events(self):
        return self.state.log.events

    @property
    def breakage_events(self):
        return [e for e in self.events if e["kind"] == "breakage"]

    @property
    def polyhedra_pair_checks(self):
        """YADE's silenced do_intersect warnings in this process (contacts/volumetric.PairChecks;
        None where the scene's law counts none)."""
        checks = self.reader.pair_checks
        return None if checks is None else checks.count

    @property
    def ledger(self):
        return self.state.ledger

    @property
    def warned(self):
        return self.state.warned

    @property
    def period(self):
        """Steps between reads now."""
        return self.schedule.period

    @property
    def zeroed(self):
        """{(id_a, id_b): ZeroedOverlap} of the pairs whose artificial overlap is zeroed."""
        return self.zeroing.pairs

    def body_state(self, body_id):
        """State of a body as a dict (fracture_energy, damage, kind, specific_energy...)."""
        return self.state.table[body_id].as_dict()

    def could_break(self, ids, more):
        """Which of the bodies `ids` could break if their stressing event went on to count
        `more` (J/kg, one per body) than it has now (Ek'/m at the last read), or be stressed past
        their fracture energy for the first time if they are unbreakable fragments (that sets
        their t10', hence their fines): tracked bodies whose criterion needs no more
        (criteria: energy_to_break). Dummies never break. A scene's end rule asks it
        (scenes.run_until_rebound)."""
        table, tracked = self.state.table, self.state.tracked
        c = table.columns
        ids = np.asarray(ids, np.int64)
        rows = np.flatnonzero(np.fromiter((i in tracked for i in ids.tolist()), bool, len(ids)))
        need, now = np.full(len(ids), np.inf), np.zeros(len(ids))
        now[rows] = c["specific_energy"][ids[rows]]
        materials = c["material"][ids[rows]]
        for m in np.unique(materials).tolist():
            of_m = rows[materials == m]
            need[of_m] = self._criterion_of[m].energy_to_break(table, ids[of_m])
        return now + np.asarray(more, float) >= need

    def total_mass(self):
        """Mass (kg) of every body yadebreak knows, fragments and ledger fines included."""
        return self.state.total_mass()

    def size_distribution(self, sizes, fines=True, fines_model=None):
        """The product size distribution, fines included (reports.product_size_distribution);
        fines_model None: the attached outcome's ("gaudin_schuhmann" for 'paper', "eq10" for
        'model')."""
        return reports.product_size_distribution(self.state.table, self.state.ledger,
                                                 self.material, sizes, fines,
                                                 fines_model or self.config.fines)

    # -- set-up --------------------------------------------------------------------------------
    def register(self, spheres):
        """Give the breakable spheres found at attach (state.Breakable records, in id order)
        their state and fracture energy, drawn per material in id order."""
        if not spheres:
            return
        ids = np.array([f.id for f in spheres])
        labels = [f.label for f in spheres]
        sizes = np.array([2.0 * f.radius for f in spheres])
        table = self.state.table
        for label in dict.fromkeys(labels):
            idx = np.array([k for k, lab in enumerate(labels) if lab == label])
            energies, extra = self.criteria[label].sample(self.state.rng, sizes[idx])
            table.add(ids[idx], BREAKABLE, label, [spheres[k].mass for k in idx], sizes[idx] / 2.0,
                      fracture_energy=energies, fracture_energy_initial=energies, **extra)
        table.known = dict.fromkeys(ids.tolist())     # the scene's order (sums follow it)
        self.tracking.adopt(ids.tolist())
        self.state.top_size = max(self.state.top_size, float(sizes.max()))

    def warn_once(self, cause, message, remedies=(), purpose=""):
        """A YadebreakWarning, once per cause for this controller (scripts: once per run)."""
        if cause not in self.state.warned:
            self.state.warned.add(cause)
            warnings.warn(YadebreakWarning(cause, message, remedies, purpose), stacklevel=3)

    # -- the per-step work -----------------------------------------------------------------------
    def step(self):
        """After the InteractionLoop, when the read schedule says: read -> judge -> log ->
        replace -> time step -> reschedule."""
        state = self.state
        self.reader.contact_law.settle(O)         # the law's corrections of this step's forces
        if not state.tracked and not state.open_events:
            self.zeroing.forget_changes()         # the next read looks every row up
            if self.step_follows_loading:
                self.time_step.follow(None, self.reader.bodies_in_contact)
            self.damping.release()
            self.last_iter = O.iter               # nothing can break: next to no cost
            return
        t0 = time.perf_counter()
        interval = max(1, O.iter - self.last_iter)        # steps since the last read
        loading = self.reader.read(O.interactions, O.bodies, state.tracked, self.zeroing.pairs,
                                   O.time, interval, self.zeroing.asleep,
                                   interaction_counts, self.zeroing.take_changes())
        self.wall_time["read"] += time.perf_counter() - t0
        follow = self.step_follows_loading
        with state.log.held():                    # the read's events: one write
            broken, limits = self.judge.judge(loading, interval, O.iter,
                                              follow or self.schedule.mode == "fast")
            if self.large_overlaps is not None:
                broken = broken + self.large_overlaps.due(self, loading, broken)
            if broken:
                self._break_all(broken)
        if follow:
            self.time_step.follow(limits, self.reader.bodies_in_contact)
        self.damping.release()
        self.last_iter = O.iter
        self.schedule.after_read(limits)

    def record_event(self, kind, bid, **fields):
        """Log an event of body `bid` now (its radius and mass added)."""
        c = self.state.table.columns
        self.state.log.record({"kind": kind, "iter": O.iter, "time": O.time, "id": bid,
                               "radius": float(c["radius"][bid]), "mass": float(c["mass"][bid]),
                               **fields})

    # -- breakage ---------------------------------------------------------------------------------
    def _break_all(self, broken):
        """Log each breakage, replace the spheres, then lower the time step for the finest
        fragment (once for all the breakages of this read)."""
        t0 = time.perf_counter()
        state, table = self.state, self.state.table
        c = table.columns
        new_dt = np.inf
        dmin = self.dmin()
        for bid, ek, strongest in broken:
            if bid not in state.tracked:
                continue
            label = table.label_of(bid)
            ratio, t10, extra = self.criteria[label].breakage(table, bid, ek)
            state.tracked.discard(bid)
            energy = float(c["fracture_energy"][bid])
            specific = ek / float(c["mass"][bid])
            if c["kind"][bid] == UNBREAKABLE:
                c["t10"][bid] = t10                # keeps the t10' of its first would-be breakage
                self.record_event("unbreakable_stressed", bid, specific_energy=specific,
                                  fracture_energy=energy, t10=t10)
                continue
            c["kind"][bid] = BROKEN
            event = {"specific_energy": specific, "fracture_energy": energy, "ratio": ratio,
                     "t10": t10, "generation": int(c["generation"][bid]), "fragments": [],
                     "partner": -1 if strongest is None else int(strongest.other), **extra}
            if self.config.replacement.replace:
                direction = (np.array([0.0, 0.0, 1.0]) if strongest is None
                             else strongest.sign * np.array(strongest.normal))
                progeny = self.replacer.replace(bid, t10, direction, dmin)
                self.reader.erased(bid)
                event.update(fragments=progeny.ids, family_t10=progeny.family_t10,
                             fragment_speed_excess=progeny.speed_excess, **progeny.audit)
                self.tracking.adopt(progeny.ids)
                self.damping.add(progeny.ids)
                self.schedule.saw_speed(max((O.bodies[i].state.vel.norm() for i in progeny.ids),
                                            default=0.0))
                step = self.reader.contact_law.fragment_time_step
                for radius, material in progeny.smallest:
                    new_dt = min(new_dt, step(self.time_step, radius, material))
            self.record_event("breakage", bid, **event)
        self.time_step.lower(new_dt, self.reader.bodies_in_contact)
        self.wall_time["replace"] += time.perf_counter() - t0

    def dmin(self):
        """The smallest fragment size (m) replacement places now: the option, else top size / 20."""
        dmin = self.config.replacement.dmin
        return dmin if dmin is not None else self.state.top_size / 20.0

    def break_body(self, body_id, ratio=1.0, direction=(0.0, 0.0, 1.0)):
        """Break a breakable body now, as if stressed to ratio = Ek'/(m E) (its criterion's t10')
        along `direction`. Returns the breakage event."""
        if body_id not in self.state.tracked or self.state.table.kind_of(body_id) != "breakable":
            raise ValueError(f"body {body_id} is not a breakable body yadebreak tracks")
        label = self.state.table.label_of(body_id)
        ek = self.criteria[label].force(self.state.table, body_id, ratio)
        self._break_all([(body_id, ek, Strongest(ek, direction, 1.0, -1))])   # no partner: asked for
        return self.events[-1]

    def finish(self):
        """Close every open stressing event as if its body had unloaded (damage with the event's
        largest energy; break_at="peak": a body past its threshold breaks), for runs stopped once
        the loading is over. Returns how many."""
        state = self.state
        c = state.table.columns
        event_max = c["event_max"]
        cracked = sorted(i for i in state.open_events if i in state.tracked and c["cracked"][i])
        if cracked:
            self._break_all([(i, float(event_max[i]), None) for i in cracked])
        # in id order, as a read judges: not in the order the set keeps, which its history sets
        ending = sorted(bid for bid in state.open_events
                        if bid in state.tracked and event_max[bid] > 0.0)
        self.judge.close_events(ending)
        state.open_events.clear()
        return len(cracked) + len(ending)

    def zero_overlaps(self):
        """Before the InteractionLoop (see zeroing.py)."""
        self.zeroing.apply()

    def close(self):
        self.state.log.close()
