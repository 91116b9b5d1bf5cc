"""The YADE coupling: the only module that imports yade.

`attach()` registers a PyRunner after the InteractionLoop. Each step it reads, for every real
interaction that involves a tracked breakable body, the overlap and the total normal force
(elastic plus dashpot, YADE's `normalForce` after Law2_ScGeom_MindlinPhys_Mindlin) and integrates
Eqs. 15-16 by the trapezoidal rule while the overlap grows. A body's energy is Eq. 14,
Ek' = sum e_c (En_c + cs Es_c) over its current contacts with energy >= emin, e_c from Eq. 4.
It breaks when Ek'/m > E; otherwise, when its stressing event ends, it is weakened (Eqs. 5-6).

A stressing event of a body opens when its Ek' reaches emin. It ends, without breakage, when the
body has unloaded: its Ek' did not grow this step and the elastic energy now stored in its
counted contacts (its share, 0.4 kno delta^2.5 for Hertz) is below emin; a contact that ceases
drops out at once. A body in lasting contact (a bed under gravity) therefore closes its event when
the load is removed, and starts the next from the contact state it is left in.

On breakage (replace=True) the sphere is erased and a family of spheres (families.py) inserted
inside it, with exact mass and momentum; the sibling overlaps are zeroed through a second PyRunner
before the InteractionLoop that scales kno and kso so that only overlap beyond the artificial one
produces Hertz-Mindlin force (see ../shared/YADE.md).
"""
from __future__ import annotations

import dataclasses
import heapq
import json
import math
import os
import sys
import time
import warnings
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from .yadepath import ensure_yade_importable

ensure_yade_importable()

import yade.wrapper as _wrapper  # noqa: E402
from yade import O, utils  # noqa: E402

from . import families, model, placement
from .materials import Material, MaterialError, load_material

_REGISTRY: dict[str, "Breakage"] = {}
_TAG = "yadebreak:"


class AttachError(RuntimeError):
    """A scene that yadebreak cannot work with; the message says what to change."""


# ------------------------------------------------------------------------------- scene materials
def _frict_material(mat: Material, label: str, stiffness_scale: float = 1.0):
    contact = mat.contacts.get("self") or next(iter(mat.contacts.values()), None)
    friction = contact.friction if contact else 0.5
    return _wrapper.FrictMat(young=mat.young_modulus * stiffness_scale, poisson=mat.poisson_ratio,
                             density=mat.density, frictionAngle=math.atan(friction), label=label)


def add_materials(labels, stiffness_scale=1.0):
    """Create one YADE FrictMat per label from material files and return the Hertz-Mindlin
    Ip2 functor with restitution and friction per pair (paper Table 6) through MatchMaker.

    labels: {"ore": "copper_ore", "steel": "steel"}. stiffness_scale multiplies every Young's
    modulus, which keeps the ratios of Eq. 4. Returns (ip2, {label: Material}).
    """
    mats = {}
    ids = {}
    for label, name in labels.items():
        mat = name if isinstance(name, Material) else load_material(name)
        mats[label] = mat
        ids[label] = O.materials.append(_frict_material(mat, label, stiffness_scale))
    en, es, fr = [], [], []
    for la in labels:
        for lb in labels:
            if ids[la] > ids[lb]:
                continue
            try:
                c = mats[la].contact_with(mats[lb])
            except KeyError as exc:
                raise AttachError(str(exc.args[0])) from None
            en.append((ids[la], ids[lb], c.restitution))
            es.append((ids[la], ids[lb], c.restitution))
            fr.append((ids[la], ids[lb], math.atan(c.friction)))
    ip2 = _wrapper.Ip2_FrictMat_FrictMat_MindlinPhys(
        en=_wrapper.MatchMaker(matches=en), es=_wrapper.MatchMaker(matches=es),
        frictAngle=_wrapper.MatchMaker(matches=fr))
    return ip2, mats


#: Slots of a contact record saved in O.tags (the geom and phys wrappers after them are not).
_SAVED_SLOTS = 13

#: read_period="fast" never waits longer than this many steps between reads.
FAST_MAX_PERIOD = 200

#: Rocky's pause after a breakage event, in steps (seed 002, Section 2.4.2).
AB_T10_PAUSE_STEPS = 25


# ------------------------------------------------------------------------------- per-body state
@dataclass
class BodyState:
    """What yadebreak keeps for one sphere it tracks (breakable, unbreakable or dummy)."""

    kind: str                      # "breakable", "unbreakable", "dummy" or "broken"
    material: str                  # YADE material label
    mass: float                    # kg
    radius: float                  # m
    fracture_energy: float = math.inf   # J/kg, current (after damage)
    fracture_energy_initial: float = math.inf
    damage: float = 0.0            # accumulated: 1 - E / E_initial
    specific_energy: float = 0.0   # Ek'/m now, J/kg
    event_max: float = 0.0         # largest Ek' (J) of the open stressing event
    t10: float = math.nan          # unbreakable: t10' of the first event that would have broken it;
                                   # dummy: t10' of the event that made it
    parent_size: float = math.nan  # dummy: the parent's diameter (m)
    generation: int = 0
    pause_until: int = -1          # no energy is counted before this iteration (fresh fragments)
    # Ab-T10 (MODEL.md Section 9); fracture_energy is then the e_cum at which the body breaks
    e_min: float = 0.0             # J/kg, Eq. 9.1 at its size
    e_cum: float = 0.0             # J/kg, Eq. 9.2
    e_max: float = 0.0             # J/kg, Eq. 9.2
    e_prev: float = 0.0            # J/kg, specific energy at the previous read

    def as_dict(self):
        return asdict(self)


@dataclass
class Options:
    cs: float = 0.0
    emin: float = 1e-4
    kappa: float | None = None
    emax_ratio: float | None = None
    replace: bool = True
    dmin: float | None = None
    local_damping: float = 0.0
    global_damping: float = 0.0
    global_damping_time: float = 0.0
    time_step_fraction: float | None = 0.05
    event_log: str | None = None
    seed: int = 0
    read_period: int | str = 1      # 1: every step (exact); k; "auto" (see _auto_period) or
                                    # "fast" (see _fast_period)
    read_fraction: float = 0.05     # "auto": read at this fraction of the Rayleigh time of the
                                    # smallest breakable body
    fast_fraction: float = 0.25     # "fast": reads per Hertz loading time, at least 1 / this
    fast_tolerance: float = 0.02    # "fast": largest rise between reads, as a fraction of E
    family_seed: int = 0
    zero_overlaps: bool = True      # False only to show what the zeroing prevents
    dummies: str = "spheres"        # "spheres" (the paper) or "ledger" (fines kept outside the DEM)
    pause_steps: int | None = None  # steps after its creation during which a fragment counts no
                                    # energy (Rocky's safeguard); None: 25 for Ab-T10, 0 for Tavares
    fragments_energy_factor: float = 1.0   # multiplies the specific energy seen by fragments


# ------------------------------------------------------------------------------- the controller
class Breakage:
    """The controller returned by attach(): state, events, and results of one scene."""

    def __init__(self, label, materials, options: Options):
        self.label = label
        self.options = options
        self.material_names = dict(materials)
        self.rng = np.random.default_rng(options.seed)
        self.bodies: dict[int, BodyState] = {}
        self.tracked: dict[int, BodyState] = {}    # breakable + unbreakable awaiting their t10'
        self.open_events: set[int] = set()         # tracked bodies with an open stressing event
        self.contacts: dict[tuple, list] = {}
        self.zeroed: dict[tuple, list] = {}        # pair -> [artificial overlap (m), kno0, kso0]
        self._zero_cache: dict[tuple, tuple] = {}  # pair -> wrappers read every step
        self.zero_by_body: dict[int, set] = {}     # body -> its zeroed pairs
        self.damped_until: list[tuple] = []        # (time, [ids]) of fresh fragments
        self.events: list[dict] = []
        self.ledger: list[list] = []              # dummy fines outside the DEM: mass, parent size,
                                                  # t10', material label, momentum (3)
        self.last_iter = -1
        self.warned: set[str] = set()
        self.top_size = 0.0
        self.wall_time = {"read": 0.0, "replace": 0.0}
        self._resolve_materials()
        self._log = None
        self._breakable_radii = []                 # heap of (radius, id), lazily cleaned
        self._auto_key = None
        self._speed_max = None                     # "fast": largest body speed, last scan
        self._reads_since_scan = 0
        self._load_key = None
        self._load_time_1 = 0.0
        self.period = 1 if options.read_period in ("auto", "fast") else options.read_period

    # -- set-up -------------------------------------------------------------------------------
    def _resolve_materials(self):
        labels = {m.label: m for m in O.materials}
        unknown = [lab for lab in self.material_names if lab not in labels]
        if unknown:
            raise AttachError(
                f"unknown YADE material label(s) {unknown}: the scene has "
                f"{sorted(l for l in labels if l) or 'no labelled materials'}; give each breakable "
                f"material a label (FrictMat(..., label='ore')) and map it in attach(materials=...)")
        self.material = {}                          # label -> Material
        for lab, name in self.material_names.items():
            mat = name if isinstance(name, Material) else load_material(name)
            if not mat.breakable:
                raise AttachError(f"material '{mat.name}' (label '{lab}') is not breakable: map only "
                                  "breakable materials in attach(materials=...)")
            opts = self.options
            if (opts.kappa is not None or opts.emax_ratio is not None) and not mat.is_ab_t10:
                mat = dataclasses.replace(mat, **{k: v for k, v in (
                    ("kappa", opts.kappa), ("emax_ratio", opts.emax_ratio)) if v is not None})
            self.material[lab] = mat
        self.material_by_id = {}                    # YADE material id -> (label, Material)
        self.stiffness_by_id = {}                   # YADE material id -> Hertz stiffness (Pa)
        for m in O.materials:
            young = getattr(m, "young", None)
            poisson = getattr(m, "poisson", 0.0)
            self.stiffness_by_id[m.id] = (math.inf if young is None
                                          else float(model.hertz_stiffness(young, poisson)))
            if m.label in self.material:
                self.material_by_id[m.id] = (m.label, self.material[m.label])
        self.tables = {lab: families.table_for(mat, self.options.family_seed)
                       for lab, mat in self.material.items()}
        self.ab_t10_labels = {lab for lab, mat in self.material.items() if mat.is_ab_t10}
        pause = self.options.pause_steps
        self.pause_steps = {lab: (pause if pause is not None else
                                  (AB_T10_PAUSE_STEPS if mat.is_ab_t10 else 0))
                            for lab, mat in self.material.items()}

    def _register_bodies(self):
        """Give every breakable sphere of the scene its state and fracture energy."""
        found = []
        problems = []
        for b in O.bodies:
            if b is None or b.id in self.bodies:
                continue
            mid = b.material.id if b.material is not None else None
            if mid not in self.material_by_id:
                continue
            label = self.material_by_id[mid][0]
            if not isinstance(b.shape, _wrapper.Sphere):
                problems.append(f"body {b.id} ({type(b.shape).__name__}) has the breakable material "
                                f"'{label}' but only spheres can break: give it another material")
                continue
            if b.isClumpMember or b.isClump:
                problems.append(f"body {b.id} is part of a clump and has the breakable material "
                                f"'{label}': clumps cannot break; use loose spheres")
                continue
            found.append(b)
        if problems:
            raise AttachError("; ".join(problems))
        if not found:
            return []
        sizes = np.array([2.0 * b.shape.radius for b in found])
        order = np.argsort([b.id for b in found], kind="stable")   # draws in id order: reproducible
        energies = np.empty(len(found))
        by_label = {}
        for k in order:
            by_label.setdefault(self.material_by_id[found[k].material.id][0], []).append(k)
        for label, idx in by_label.items():
            energies[idx] = self.material[label].sample_fracture_energy(self.rng, sizes[idx])
        for k, b in enumerate(found):
            label = self.material_by_id[b.material.id][0]
            st = BodyState(kind="breakable", material=label, mass=b.state.mass,
                           radius=b.shape.radius, fracture_energy=float(energies[k]),
                           fracture_energy_initial=float(energies[k]))
            if label in self.ab_t10_labels:
                st.e_min = float(self.material[label].min_energy(sizes[k]))
            self._adopt(b, st)
        self.top_size = max(self.top_size, float(sizes.max()))
        return found

    def _adopt(self, body, st):
        self.bodies[body.id] = st
        if st.kind in ("breakable", "unbreakable"):
            self.tracked[body.id] = st
        if st.kind == "breakable":
            heapq.heappush(self._breakable_radii, (st.radius, body.id))
        body.breakage = st                      # readable on the body while the scene lives

    # -- public API ------------------------------------------------------------------------------
    def body_state(self, body_id):
        """State of a tracked body as a dict (fracture_energy, damage, kind, specific_energy...)."""
        return self.bodies[body_id].as_dict()

    def break_body(self, body_id, ratio=1.0, direction=(0.0, 0.0, 1.0)):
        """Break a breakable body now, as if stressed to ratio = Ek'/(m E) (t10' from Eq. 8) along
        `direction`. Returns the breakage event."""
        st = self.tracked.get(body_id)
        if st is None or st.kind != "breakable":
            raise ValueError(f"body {body_id} is not a breakable body yadebreak tracks")
        ek = ratio * st.mass * st.fracture_energy
        if st.material in self.ab_t10_labels:
            st.e_cum = ratio * st.fracture_energy       # as if e_cum had reached ratio x threshold
        self._break_all([(body_id, st, ek, (ek, direction, 1.0))], self.contacts)
        return self.events[-1]

    def finish(self):
        """Close every open stressing event as if its body had unloaded (damage with the event's
        largest energy), for runs stopped once the loading is over. Returns how many."""
        touching = {}                            # one pass over the contacts
        for (a, b), c in self.contacts.items():
            if a in self.open_events:
                touching.setdefault(a, []).append((c, 3))
            if b in self.open_events:
                touching.setdefault(b, []).append((c, 4))
        closed = 0
        for bid in list(self.open_events):
            st = self.tracked.get(bid)
            if st is not None and st.event_max > 0.0:
                self._close_event(bid, st, touching.get(bid, ()))
                closed += 1
        self.open_events.clear()
        return closed

    @property
    def breakage_events(self):
        return [e for e in self.events if e["kind"] == "breakage"]

    def size_distribution(self, sizes, fines=True, fines_model="gaudin_schuhmann"):
        """The product size distribution (model.SizeDistribution, MODEL.md Section 7).

        fines=True spreads dummy and unbreakable masses (Eqs. 11-13); fines=False counts every
        sphere at its own size, as in the paper's Fig. 13. fines_model: "gaudin_schuhmann" (the
        paper's Eqs. 11-12) or "eq10" (see model.dummy_fines_passing).
        """
        resolved_d, resolved_m = [], []
        groups = {}
        for bid, st in self.bodies.items():
            if st.kind == "broken":
                continue
            g = groups.setdefault(st.material, {"dummy": ([], [], []), "unb": ([], [], [])})
            if fines and st.kind == "dummy":
                for lst, v in zip(g["dummy"], (st.mass, st.parent_size, st.t10)):
                    lst.append(v)
            elif fines and st.kind == "unbreakable":
                for lst, v in zip(g["unb"], (2 * st.radius, st.mass, st.t10)):
                    lst.append(v)
            else:
                resolved_d.append(2 * st.radius)
                resolved_m.append(st.mass)
        if fines:
            for mass, parent, t10, label, *_ in self.ledger:
                g = groups.setdefault(label, {"dummy": ([], [], []), "unb": ([], [], [])})
                for lst, v in zip(g["dummy"], (mass, parent, t10)):
                    lst.append(v)
        else:                            # the ledger's fines counted at the dummy size
            for mass, parent, *_ in self.ledger:
                resolved_d.append(model.X_MIN * parent)
                resolved_m.append(mass)
        sizes = np.atleast_1d(np.asarray(sizes, dtype=float))
        passing = np.zeros(sizes.shape)
        total = 0.0
        sd = model.size_distribution(sizes, resolved=(resolved_d, resolved_m))
        passing += sd.passing_mass
        total += sd.total_mass
        for label, g in groups.items():
            sd = model.size_distribution(sizes, dummies=g["dummy"], unbreakable=g["unb"],
                                         beta_params=self.material[label].beta_params,
                                         fines=fines_model)
            passing += sd.passing_mass
            total += sd.total_mass
        return model.SizeDistribution(sizes, passing, total)

    def total_mass(self):
        """Mass (kg) of every body yadebreak knows, fragments and ledger fines included (the
        broken parents excluded)."""
        return float(sum(st.mass for st in self.bodies.values() if st.kind != "broken")
                     + sum(entry[0] for entry in self.ledger))

    # -- event log -------------------------------------------------------------------------------
    def _record(self, event):
        self.events.append(event)
        if self.options.event_log:
            if self._log is None:
                Path(self.options.event_log).parent.mkdir(parents=True, exist_ok=True)
                self._log = open(self.options.event_log, "a", buffering=1)
            self._log.write(json.dumps(event) + "\n")
            self._log.flush()

    def _warn_once(self, cause, message):
        if cause not in self.warned:
            self.warned.add(cause)
            warnings.warn(f"yadebreak: {message}", RuntimeWarning, stacklevel=3)
            print(f"[yadebreak] WARNING: {message}", file=sys.stderr, flush=True)

    # -- the per-step work -------------------------------------------------------------------------
    def step(self):
        if not self.tracked and not self.open_events:
            self._release_damping()
            self.last_iter = O.iter           # nothing can break: next to no cost
            return
        t0 = time.perf_counter()
        opts = self.options
        emin = opts.emin
        cs = opts.cs
        tracked = self.tracked
        contacts = self.contacts
        zeroed = self.zeroed
        now_time = O.time
        interval = max(1, O.iter - self.last_iter)      # steps since the last read
        first_touch = 0.8 - 0.3 / interval ** 2
        stiff = self.stiffness_by_id
        seen = {}
        energy = {}               # body -> Ek' (counted)
        strongest = {}            # body -> (share energy, normal, sign) of its most energetic contact
        touching = {}             # tracked body -> [(contact record, offset slot)]
        grew = set()
        bodies = O.bodies
        for i in O.interactions:
            a = i.id1
            b = i.id2
            ta = tracked.get(a)
            tb = tracked.get(b)
            if ta is None and tb is None:
                continue
            key = (a, b)
            c = contacts.get(key)
            if c is None:
                g = i.geom
                if g is None:
                    continue
                ka = stiff[bodies[a].material.id]
                kb = stiff[bodies[b].material.id]
                # [delta, force, En, offset_a, offset_b, e_a, e_b, us, Fs, Es,
                #  delta and time of the read before, time of the last read, geom, phys]
                # (the last two: wrappers kept while the contact lives, never saved)
                c = [0.0, 0.0, 0.0, 0.0, 0.0,
                     float(model.energy_partition(ka, kb)), float(model.energy_partition(kb, ka)),
                     0.0, 0.0, 0.0, 0.0, now_time, now_time, g, i.phys]
                contacts[key] = c
            elif len(c) == _SAVED_SLOTS:           # restored from O.tags: wrappers again
                c += [i.geom, i.phys]
            g = c[13]
            delta = g.penetrationDepth
            force = c[14].normalForce.norm()      # compressive while the overlap grows
            d0 = c[0]
            peaked = delta < d0 and c[10] < d0 and c[12] > c[11]
            if delta > d0 or peaked:
                # a zeroed pair's kno varies (zero_overlaps): the trapezoid on its total force
                hertz = not (zeroed and ((a, b) in zeroed or (b, a) in zeroed))
                worked = True
                if delta > d0 and not hertz:
                    c[2] += 0.5 * (c[1] + force) * (delta - d0)
                elif delta > d0:
                    # Hertz part exact (Eq. 14 with F = kno delta^1.5), whatever the read
                    # interval; only the dashpot part by the trapezoidal rule
                    kno = c[14].kno
                    el0 = kno * d0 * math.sqrt(d0)
                    el1 = kno * delta * math.sqrt(delta)
                    if d0 > 0.0:
                        c[2] += (0.4 * (el1 * delta - el0 * d0)
                                 + 0.5 * (c[1] - el0 + force - el1) * (delta - d0))
                    else:
                        # from first touch: Mindlin's dashpot force grows like delta^(1/4)
                        # (cn ~ kn^(1/2)) at a nearly constant rate, so over many steps its work
                        # tends to 0.8 F delta; over one step YADE's leapfrog makes it the
                        # trapezoid's 0.5 F delta (measured: exact to 0.02 % at 5 % of T_R)
                        c[2] += 0.4 * el1 * delta + first_touch * (force - el1) * delta
                else:
                    # the overlap peaked between the last two reads: add the Hertz energy from
                    # the last read up to the peak of the parabola through the last three
                    # overlaps (matters when reads are sparse: read_period > 1 or "fast")
                    peak = (model.parabolic_peak(c[11], c[10], c[12], d0, now_time, delta)
                            if hertz else d0)
                    worked = peak > d0
                    if worked:
                        kno = c[14].kno
                        el0 = kno * d0 * math.sqrt(d0)
                        c[2] += (0.4 * kno * (peak ** 2.5 - d0 ** 2.5)
                                 + 0.5 * (c[1] - el0) * (peak - d0))
                if worked:
                    if ta is not None:
                        grew.add(a)
                    if tb is not None:
                        grew.add(b)
            c[10] = c[0]
            c[11] = c[12]
            c[12] = now_time
            c[0] = delta
            c[1] = force
            if cs > 0.0:
                ph = c[14]
                us = ph.usTotal.norm()
                fs = ph.shearForce.norm()
                if us > c[7]:
                    c[9] += 0.5 * (c[8] + fs) * (us - c[7])
                c[7] = us
                c[8] = fs
            seen[key] = c
            total = c[2] + cs * c[9]
            # the two endpoints written out, not looped: this runs for every contact every read
            if ta is not None:
                touching.setdefault(a, []).append((c, 3))
                own = total - c[3]
                if own >= emin:
                    share = c[5] * own
                    energy[a] = energy.get(a, 0.0) + share
                    if share > strongest.get(a, (0.0,))[0]:
                        strongest[a] = (share, g.normal, 1.0)      # normal points a -> b
            if tb is not None:
                touching.setdefault(b, []).append((c, 4))
                own = total - c[4]
                if own >= emin:
                    share = c[6] * own
                    energy[b] = energy.get(b, 0.0) + share
                    if share > strongest.get(b, (0.0,))[0]:
                        strongest[b] = (share, g.normal, -1.0)
        self.contacts = seen                  # ceased contacts drop out
        self.wall_time["read"] += time.perf_counter() - t0

        broken = []
        open_events = self.open_events
        now = O.iter
        factor = opts.fragments_energy_factor
        ab_labels = self.ab_t10_labels
        ab_bodies = []
        fast = opts.read_period == "fast"
        limits = []               # "fast": steps each loaded body allows before the next read
        for bid in list(open_events.union(energy)):
            st = tracked.get(bid)
            if st is None:
                open_events.discard(bid)
                continue
            if st.pause_until > now:
                # Rocky's safeguard: a fresh fragment counts nothing yet, and what its contacts
                # did meanwhile is never counted later
                self._restart_offsets(touching.get(bid, ()))
                st.event_max = st.specific_energy = 0.0
                open_events.discard(bid)
                continue
            ek = energy.get(bid, 0.0)
            if st.generation and factor != 1.0:
                ek *= factor
            specific = ek / st.mass
            if st.material in ab_labels:
                ab_bodies.append((bid, st, ek, specific))
                continue
            if fast and specific > st.specific_energy:
                limits.append(self._steps_allowed(st.fracture_energy, specific,
                                                  specific - st.specific_energy, interval))
            if specific > st.fracture_energy:
                if specific - st.specific_energy > 0.8 * st.fracture_energy:
                    self._warn_jump(bid, specific - st.specific_energy, st.fracture_energy)
                st.specific_energy = specific
                broken.append((bid, st, ek, strongest.get(bid)))
                continue
            self._follow_event(bid, st, ek, specific, grew, touching)
        if ab_bodies:
            # Eq. 9.2 for every Ab-T10 body read now, in one call
            e_cum, e_max = model.ab_t10_update(
                [x[3] for x in ab_bodies], [x[1].e_prev for x in ab_bodies],
                [x[1].e_cum for x in ab_bodies], [x[1].e_max for x in ab_bodies],
                [x[1].e_min for x in ab_bodies])
            for (bid, st, ek, specific), cum, top in zip(ab_bodies, e_cum.tolist(), e_max.tolist()):
                if fast and specific > st.e_prev:
                    limits.append(self._steps_allowed(st.fracture_energy, cum,
                                                      specific - st.e_prev, interval))
                rise = cum - st.e_cum
                st.e_cum, st.e_max, st.e_prev = cum, top, specific
                if cum > st.fracture_energy:
                    if rise > 0.8 * st.fracture_energy:
                        self._warn_jump(bid, rise, st.fracture_energy)
                    st.specific_energy = specific
                    broken.append((bid, st, ek, strongest.get(bid)))
                else:
                    self._follow_event(bid, st, ek, specific, grew, touching)
        if broken:
            self._break_all(broken, seen)
        self._release_damping()
        self.last_iter = O.iter
        if self.options.read_period == "auto":
            self._auto_period()
        elif fast:
            self._fast_period(limits)

    def _steps_allowed(self, threshold, level, rise, interval):
        """"fast": steps until the next read for a body whose criterion variable is `level` below
        `threshold` (J/kg) and rose by `rise` over the last `interval` steps: half the way to
        the threshold, or fast_tolerance of it, at the present rate."""
        return (max(self.options.fast_tolerance * threshold, 0.5 * (threshold - level))
                * interval / rise)

    def _fast_period(self, limits):
        """read_period="fast": read again after k steps, k the smallest of
        - what every loaded body allows (_steps_allowed), so that no body's energy passes its
          fracture energy by more than fast_tolerance of it between reads;
        - fast_fraction of the Hertz loading time of the smallest breakable sphere at twice the
          largest speed in the scene (rescanned every 16 reads and after breakage), so that an
          impact that begins between reads is read several times while it loads;
        - FAST_MAX_PERIOD steps."""
        smallest = self._smallest_breakable()
        if smallest is None:
            k = FAST_MAX_PERIOD
        else:
            self._reads_since_scan += 1
            if self._reads_since_scan >= 16 or self._speed_max is None:
                self._reads_since_scan = 0
                self._speed_max = max((b.state.vel.norm() for b in O.bodies
                                       if b is not None and b.dynamic), default=0.0)
            radius, bid = smallest
            if self._load_key != smallest:
                mat = O.bodies[bid].material
                self._load_key = smallest
                self._load_time_1 = float(placement.hertz_loading_time(
                    radius, mat.density, mat.young, mat.poisson, 1.0))   # at 1 m/s; ~ v^-1/5
            load_time = self._load_time_1 * max(2.0 * self._speed_max, 1e-6) ** -0.2
            k = min(FAST_MAX_PERIOD, int(self.options.fast_fraction * load_time / O.dt))
        if limits:
            k = min(k, int(min(limits)))
        self._set_period(max(1, k))

    def _smallest_breakable(self):
        """(radius, id) of the smallest breakable body, or None (broken ones dropped lazily)."""
        heap = self._breakable_radii
        while heap and getattr(self.tracked.get(heap[0][1]), "kind", None) != "breakable":
            heapq.heappop(heap)
        return heap[0] if heap else None

    def _set_period(self, k):
        """Read every k steps from now on."""
        if k != self.period:
            self.period = k
            _find_engine(self.label).iterPeriod = k

    def _follow_event(self, bid, st, ek, specific, grew, touching):
        """Keep a stressing event open while its energy grows; close it once the body unloads."""
        st.specific_energy = specific
        if ek > st.event_max:
            st.event_max = ek
            self.open_events.add(bid)
        elif (st.event_max > 0.0 and bid not in grew
              and self._stored_share(touching.get(bid, ())) <= self.options.emin):
            self._close_event(bid, st, touching.get(bid, ()))

    def _warn_jump(self, bid, rise, scale):
        mode = self.options.read_period
        remedy = ("time_step_fraction" if self.period == 1 else
                  "fast_fraction" if mode == "fast" else
                  "read_fraction" if mode == "auto" else "read_period")
        self._warn_once("jump", (
            f"specific energy rose by {100 * rise / scale:.0f} % of the fracture energy between "
            f"two reads at body {bid} (read every {self.period} step(s) of {O.dt:.3g} s): reduce "
            f"{remedy} for an accurate t10'"))

    def _auto_period(self):
        """Read every k steps, k dt <= read_fraction T_R of the smallest breakable body."""
        smallest = self._smallest_breakable()
        key = (smallest, O.dt)
        if key == self._auto_key:              # nothing changed: keep k (no numpy per step)
            return
        self._auto_key = key
        k = 1
        if smallest is not None:
            radius, bid = smallest
            mat = O.bodies[bid].material
            tr = float(placement.rayleigh_time(radius, mat.density, mat.young, mat.poisson))
            k = max(1, int(self.options.read_fraction * tr / O.dt))
        self._set_period(k)

    def _stored_share(self, touching):
        """Elastic energy (J) a body holds now in its counted contacts: its share of
        0.4 kno delta^2.5 (Hertz), with kno as the law uses it (scaled for zeroed pairs)."""
        emin = self.options.emin
        cs = self.options.cs
        total = 0.0
        for c, slot in touching:
            if c[2] + cs * c[9] - c[slot] >= emin and c[0] > 0.0:
                total += c[5 if slot == 3 else 6] * 0.4 * c[14].kno * c[0] ** 2.5
        return total

    def _close_event(self, bid, st, touching):
        """End of a stressing event without breakage: Eqs. 5-6 with the event's largest Ek'."""
        ratio = st.event_max / (st.mass * st.fracture_energy)
        before = st.fracture_energy
        if st.material in self.ab_t10_labels:
            # Eq. 9.2 at the unloading: e_t = 0 < e_min resets e_max; e_cum keeps the damage
            st.e_cum, st.e_max = (float(v) for v in model.ab_t10_update(
                0.0, st.e_prev, st.e_cum, st.e_max, st.e_min))
            st.e_prev = 0.0
            if st.kind == "breakable":
                st.damage = st.e_cum / st.fracture_energy
                self._record({"kind": "damage", "iter": O.iter, "time": O.time, "id": bid,
                              "radius": st.radius, "mass": st.mass,
                              "specific_energy": st.event_max / st.mass, "e_cum": st.e_cum,
                              "fracture_energy": before, "ratio": ratio})
        elif st.kind == "breakable":
            after = float(model.weakened_fracture_energy(before, ratio, self.material[st.material].gamma))
            st.fracture_energy = after
            st.damage = 1.0 - after / st.fracture_energy_initial
            self._record({"kind": "damage", "iter": O.iter, "time": O.time, "id": bid,
                          "radius": st.radius, "mass": st.mass,
                          "specific_energy": st.event_max / st.mass, "fracture_energy": before,
                          "fracture_energy_after": after, "ratio": ratio})
        st.event_max = 0.0
        st.specific_energy = 0.0
        self.open_events.discard(bid)
        self._restart_offsets(touching)      # the next event starts from the present state

    def _restart_offsets(self, touching):
        """Count a body's energy from now on: its offsets in its contacts (slot 3 or 4) become
        the contacts' present work."""
        cs = self.options.cs
        for c, slot in touching:
            c[slot] = c[2] + cs * c[9]

    # -- breakage and replacement ----------------------------------------------------------------
    def _break_all(self, broken, contacts):
        t0 = time.perf_counter()
        self._pending_dt = math.inf
        self._speed_max = None                    # "fast": fragments may be the fastest now
        for bid, st, ek, strongest in broken:
            if bid not in self.tracked:
                continue
            mat = self.material[st.material]
            if mat.is_ab_t10:
                ratio = st.e_cum / st.fracture_energy
                t10 = float(mat.t10_of_cumulative_energy(st.e_cum, 2.0 * st.radius))
            else:
                ratio = ek / (st.mass * st.fracture_energy)
                t10 = float(model.t10(ratio, mat.A, mat.b_prime, mat.kappa))
            if st.kind == "unbreakable":
                st.t10 = t10                       # keeps the t10' of its first would-be breakage
                del self.tracked[bid]
                self._record({"kind": "unbreakable_stressed", "iter": O.iter, "time": O.time,
                              "id": bid, "radius": st.radius, "mass": st.mass,
                              "specific_energy": ek / st.mass,
                              "fracture_energy": st.fracture_energy, "t10": t10})
                continue
            event = {"kind": "breakage", "iter": O.iter, "time": O.time, "id": bid,
                     "radius": st.radius, "mass": st.mass, "specific_energy": ek / st.mass,
                     "fracture_energy": st.fracture_energy, "ratio": ratio, "t10": t10,
                     "generation": st.generation, "fragments": []}
            if mat.is_ab_t10:
                event["e_cum"] = st.e_cum
            del self.tracked[bid]
            st.kind = "broken"
            if self.options.replace:
                direction = (np.array([0.0, 0.0, 1.0]) if strongest is None
                             else strongest[2] * np.array(strongest[1]))
                (event["fragments"], event["family_t10"],
                 event["fragment_speed_excess"]) = self._replace(bid, st, t10, direction)
            self._record(event)
        self._lower_time_step(self._pending_dt)
        self.wall_time["replace"] += time.perf_counter() - t0

    def _replace(self, bid, st, t10, direction):
        body = O.bodies[bid]
        opts = self.options
        table = self.tables[st.material]
        fam = table.draw(self.rng, t10)
        center = np.array(body.state.pos)
        radius = st.radius
        radii = fam.relative_sizes * radius
        centers = placement.place_fragments(center, radius, radii, direction, self.rng)
        masses = placement.fragment_masses(st.mass, radii)
        vel = placement.fragment_velocities(centers, masses, center, np.array(body.state.vel),
                                            np.array(body.state.angVel))
        angvel = body.state.angVel
        # no fragment may leave faster than the parent's rigid field allows: |v| + 2 |w| r bounds
        # it (v + w x (c_i - c_cm) after the momentum shift); the event records the margin
        speed_excess = float(np.linalg.norm(vel, axis=1).max() - np.linalg.norm(body.state.vel)
                             - 2.0 * np.linalg.norm(angvel) * radius)
        material = body.material
        mat = self.material[st.material]
        dmin = opts.dmin if opts.dmin is not None else self.top_size / 20.0
        # the parent's neighbours and its real (force-producing) overlap with each
        neighbours = []
        for inter in O.interactions.withBody(bid):
            other = inter.id2 if inter.id1 == bid else inter.id1
            z = self.zeroed.get((min(bid, other), max(bid, other)))
            real = inter.geom.penetrationDepth - (z[0] if z else 0.0)
            neighbours.append((other, max(real, 0.0)))
        O.bodies.erase(bid)
        for key in list(self.zero_by_body.get(bid, ())):
            self._drop_zeroed(key)
        inserted = np.arange(len(radii))
        if opts.dummies == "ledger":
            # dummy fines leave the DEM: their mass, momentum and t10' go to the ledger
            for k in np.nonzero(fam.is_dummy)[0]:
                self.ledger.append([float(masses[k]), 2.0 * radius, t10, st.material,
                                    *(float(masses[k]) * vel[k])])
            inserted = inserted[~fam.is_dummy]
        radii, centers, masses, vel = radii[inserted], centers[inserted], masses[inserted], vel[inserted]
        is_dummy = fam.is_dummy[inserted]
        new_bodies = []
        damped = opts.global_damping > 0.0
        for center_k, radius_k, mass_k, vel_k in zip(centers.tolist(), radii.tolist(),
                                                      masses.tolist(), vel.tolist()):
            # built directly (11 us) rather than with utils.sphere (36 us), which would also
            # compute a mass and inertia we replace and pick a random colour
            b = _wrapper.Body()
            b.shape = _wrapper.Sphere(radius=radius_k)
            b.material = material
            b.bound = _wrapper.Aabb()
            state = b.state
            state.pos = state.refPos = center_k
            state.mass = mass_k
            inertia = 0.4 * mass_k * radius_k * radius_k
            state.inertia = (inertia, inertia, inertia)
            state.vel = vel_k
            state.angVel = angvel
            if damped:
                state.isDamped = True          # global damping acts on fresh fragments only
            new_bodies.append(b)
        ids = O.bodies.append(new_bodies)
        new_ids = list(ids)
        for k, nid in enumerate(ids):
            if is_dummy[k]:
                kind = "dummy"
            elif model.X_MIN * 2.0 * radii[k] < dmin:
                kind = "unbreakable"       # its own progeny would be finer than dmin
            else:
                kind = "breakable"
            fs = BodyState(kind=kind, material=st.material, mass=float(masses[k]),
                           radius=float(radii[k]), generation=st.generation + 1)
            if kind == "dummy":
                fs.t10, fs.parent_size = t10, 2.0 * radius
            self.bodies[nid] = fs
        # fracture energies at the fragments' own sizes (unbreakable ones too: their first
        # would-be breakage gives the t10' they keep)
        need = [k for k in range(len(ids)) if self.bodies[ids[k]].kind != "dummy"]
        if need:
            energies = mat.sample_fracture_energy(self.rng, 2.0 * radii[need])
            for k, e in zip(need, energies):
                fs = self.bodies[ids[k]]
                fs.fracture_energy = fs.fracture_energy_initial = float(e)
            if mat.is_ab_t10:
                for k, e_min in zip(need, mat.min_energy(2.0 * radii[need]).tolist()):
                    self.bodies[ids[k]].e_min = e_min
        pause = self.pause_steps[st.material]
        if pause:
            for nid in ids:
                self.bodies[nid].pause_until = O.iter + pause
        for nid in ids:
            self._adopt(O.bodies[nid], self.bodies[nid])
        # zero the artificial overlaps: between siblings entirely; with each neighbour of the
        # parent, the child overlapping it most keeps the parent's real overlap as real force and
        # everything beyond it is zeroed, while the other children's overlaps with that neighbour
        # are zeroed entirely (else k children would each press with the parent's overlap and
        # multiply the force the parent carried)
        if opts.zero_overlaps and len(ids):
            ii, jj, overlap = placement.overlapping_pairs(centers, radii)
            self._zero_new(ids, centers, radii, ii, jj, overlap, neighbours)
        if self.zeroed:
            self._zero_engine().dead = False
        if opts.global_damping > 0.0:
            self.damped_until.append((O.time + opts.global_damping_time, list(ids)))
        if len(ids):
            tr = float(placement.rayleigh_time(radii.min(), material.density, material.young,
                                               material.poisson))
            if opts.time_step_fraction:
                self._pending_dt = min(self._pending_dt, opts.time_step_fraction * tr)
            else:
                self._check_time_step(tr)
        return new_ids, fam.t10, speed_excess

    def _zero_new(self, ids, centers, radii, ii, jj, overlap, neighbours):
        """Zero the artificial overlaps of fresh fragments (see _replace)."""
        for a, b, ov in zip(ii, jj, overlap):
            self._zero_pair(ids[a], ids[b], float(ov), created=False)
        for other, real in neighbours:
            ob = O.bodies[other]
            if ob is None:
                continue
            if isinstance(ob.shape, _wrapper.Sphere):
                ov = radii + ob.shape.radius - np.linalg.norm(centers - np.array(ob.state.pos), axis=1)
                created = False
            else:                                # walls, facets: ask YADE's own geometry
                ov = np.full(len(ids), -1.0)
                for k in range(len(ids)):
                    try:
                        ov[k] = utils.createInteraction(ids[k], other).geom.penetrationDepth
                    except Exception:
                        continue
                created = True
            touching = np.nonzero(ov > 0.0)[0]
            if len(touching) == 0:
                continue
            keeper = touching[np.argmax(ov[touching])]
            for k in touching:
                artificial = ov[k] - real if k == keeper else ov[k]
                if artificial > 0.0:
                    self._zero_pair(ids[k], other, float(artificial), created=created)

    def _check_time_step(self, rayleigh_time):
        """With time_step_fraction=None the user owns O.dt: warn once when it exceeds 20 % of the
        Rayleigh time of the smallest sphere present (Hertz contacts go unstable near it)."""
        if O.dt > 0.2 * rayleigh_time:
            self._warn_once("dt", (
                f"O.dt = {O.dt:.3g} s is {100 * O.dt / rayleigh_time:.0f} % of the Rayleigh time of "
                f"the smallest sphere ({rayleigh_time:.3g} s): contacts may go unstable and energies "
                f"be wrong; use time_step_fraction (0.05 recommended) or lower O.dt"))

    def _lower_time_step(self, new_dt):
        """O.dt = new_dt, keeping the leapfrog exact across the change.

        YADE's Newton takes v(n+1/2) = v(n-1/2) + a dt with the new dt; across a change the right
        increment is a (dt_old + dt_new) / 2. Without the a (dt_old - dt_new) / 2 added here, a
        body in mid-contact when a breakage shrinks dt gains energy (1.9 % measured on impacts
        of 5.5 mm copper ore at 100 J/kg when dt fell 19-fold). Done for bodies in tracked
        contacts, the only ones with a large acceleration that yadebreak knows of.
        """
        old = O.dt
        if not new_dt < old:
            return
        newton = next((e for e in O.engines if isinstance(e, _wrapper.NewtonIntegrator)), None)
        gravity = newton.gravity if newton is not None else None
        half = 0.5 * (old - new_dt)
        for bid in {k for key in self.contacts for k in key}:
            b = O.bodies[bid]
            if b is None or not b.dynamic:
                continue
            accel = O.forces.f(bid) / b.state.mass
            if gravity is not None:
                accel = accel + gravity
            b.state.vel = b.state.vel + accel * half
        O.dt = new_dt

    def _zero_pair(self, id_a, id_b, artificial, created):
        """Register an artificial overlap (m) of a new pair; only (1 - local_damping) of it is
        zeroed, the rest is released as real force."""
        inter = O.interactions[id_a, id_b] if created else utils.createInteraction(id_a, id_b)
        ph = inter.phys
        key = (min(id_a, id_b), max(id_a, id_b))
        # the zero engine scales kno, kso before the next force evaluation
        self._register_zeroed(key, [(1.0 - self.options.local_damping) * artificial, ph.kno,
                                    ph.kso])

    def _register_zeroed(self, key, zero):
        """Track a zeroed pair: [artificial overlap (m), kno0, kso0], indexed by both bodies."""
        self.zeroed[key] = zero
        for i in key:
            self.zero_by_body.setdefault(i, set()).add(key)

    def _zero_engine(self):
        return _find_engine(self.label + "_zero")

    def zero_overlaps(self):
        """Before the InteractionLoop: kno, kso of zeroed pairs scaled so that the Hertz force is
        that of the overlap beyond the artificial one; the reference shrinks as the pair opens
        and is dropped when it separates. Sphere pairs use this step's positions (no lag)."""
        if not self.zeroed:
            self._zero_engine().dead = True
            return
        cache = self._zero_cache
        done = []
        for key, z in self.zeroed.items():
            c = cache.get(key)
            if c is None:
                c = self._zero_wrappers(key)
                if c is None:
                    done.append(key)
                    continue
            state_a, state_b, radius_sum, phys, geom = c
            if geom is None:
                d = radius_sum - (state_a.pos - state_b.pos).norm()
            else:
                d = geom.penetrationDepth          # walls, facets: the last step's overlap
            if d <= 0.0:
                done.append(key)
                continue
            if d <= z[0]:
                z[0] = d
                if z[1] != 0.0 and phys.kno != 0.0:
                    phys.kno = 0.0
                    phys.kso = 0.0
                continue
            ratio = (d - z[0]) / d
            phys.kno = z[1] * ratio ** 1.5
            phys.kso = z[2] * ratio ** 0.5
        for key in done:
            self._drop_zeroed(key)

    def _zero_wrappers(self, key):
        ba, bb = O.bodies[key[0]], O.bodies[key[1]]
        if ba is None or bb is None or not O.interactions.has(key[0], key[1]):
            return None
        inter = O.interactions[key[0], key[1]]
        if not inter.isReal:
            return None
        spheres = isinstance(ba.shape, _wrapper.Sphere) and isinstance(bb.shape, _wrapper.Sphere)
        c = (ba.state, bb.state, (ba.shape.radius + bb.shape.radius) if spheres else 0.0,
             inter.phys, None if spheres else inter.geom)
        self._zero_cache[key] = c
        return c

    def _drop_zeroed(self, key):
        self.zeroed.pop(key, None)
        self._zero_cache.pop(key, None)
        for i in key:
            pairs = self.zero_by_body.get(i)
            if pairs is not None:
                pairs.discard(key)
                if not pairs:
                    del self.zero_by_body[i]

    def _release_damping(self):
        if not self.damped_until:
            return
        now = O.time
        keep = []
        for until, ids in self.damped_until:
            if now >= until:
                for i in ids:
                    b = O.bodies[i]
                    if b is not None:
                        b.state.isDamped = False
            else:
                keep.append((until, ids))
        self.damped_until = keep

    # -- persistence -------------------------------------------------------------------------------
    def state_dict(self):
        return {"label": self.label, "options": asdict(self.options),
                "materials": {k: (v.source if isinstance(v, Material) else v)
                              for k, v in self.material_names.items()},
                "rng": self.rng.bit_generator.state, "iter": O.iter, "top_size": self.top_size,
                "bodies": {str(k): v.as_dict() for k, v in self.bodies.items()},
                "tracked": sorted(self.tracked),
                "contacts": [[k[0], k[1], c[:_SAVED_SLOTS]] for k, c in self.contacts.items()],
                "zeroed": [[k[0], k[1], z] for k, z in self.zeroed.items()],
                "damped_until": self.damped_until, "events": self.events, "ledger": self.ledger,
                "warned": sorted(self.warned),
                "fast": [self._speed_max, self._reads_since_scan]}

    def sync_tags(self):
        """Write the whole state into O.tags, so that O.save keeps it (done by O.save itself)."""
        O.tags[_TAG + self.label] = json.dumps(self.state_dict())

    @classmethod
    def from_tags(cls, label):
        data = json.loads(O.tags[_TAG + label])
        self = cls(label, data["materials"], Options(**data["options"]))
        self.rng.bit_generator.state = data["rng"]
        self.top_size = data["top_size"]
        self.bodies = {int(k): BodyState(**v) for k, v in data["bodies"].items()}
        self.tracked = {i: self.bodies[i] for i in data["tracked"]}
        self._breakable_radii = [(st.radius, i) for i, st in self.tracked.items()
                                 if st.kind == "breakable"]
        heapq.heapify(self._breakable_radii)
        engine = _find_engine(label)
        if engine is not None:
            self.period = engine.iterPeriod
        self.open_events = {i for i in data["tracked"] if self.bodies[i].event_max > 0.0}
        self.contacts = {(a, b): c for a, b, c in data["contacts"]}
        for a, b, z in data["zeroed"]:
            self._register_zeroed((a, b), z)
        self.damped_until = [tuple(x) for x in data["damped_until"]]
        self.events = data["events"]
        self.ledger = data["ledger"]
        self.warned = set(data["warned"])
        self._speed_max, self._reads_since_scan = data.get("fast", [None, 0])
        self.last_iter = data["iter"] - 1
        for bid, st in self.bodies.items():
            b = O.bodies[bid] if bid < len(O.bodies) else None
            if b is not None:
                b.breakage = st
        if self.options.event_log:             # the log holds exactly the events of this state
            path = Path(self.options.event_log)
            tmp = path.with_suffix(".tmp")
            tmp.write_text("".join(json.dumps(e) + "\n" for e in self.events))
            os.replace(tmp, path)
        return self

    def close(self):
        if self._log is not None:
            self._log.close()
            self._log = None


def _find_engine(label):
    for e in O.engines:
        if getattr(e, "label", "") == label:
            return e
    return None


def _controller(label):
    """The controller of `label`, restored from O.tags when the scene was loaded or went back in
    time (its iteration is not the one that follows the controller's last read)."""
    ctl = _REGISTRY.get(label)
    stale = ctl is None or O.iter <= ctl.last_iter or O.iter > ctl.last_iter + ctl.period
    if stale:
        if _TAG + label not in O.tags.keys():
            raise AttachError(f"yadebreak engine '{label}' has no state in this scene")
        if ctl is not None:
            ctl.close()
        ctl = Breakage.from_tags(label)
        _REGISTRY[label] = ctl
    return ctl


_SCRIPT_TAG = "yadebreak_script"


def save_checkpoint(path, script_state):
    """O.save the scene to `path` (yadebreak's own state travels in O.tags) with a script's loop
    state (a JSON-able dict), written to a temporary file first so a crash never leaves half a
    checkpoint."""
    path = Path(path)
    O.tags[_SCRIPT_TAG] = json.dumps(script_state)
    tmp = path.with_name(path.name + ".tmp.yade.gz")
    O.save(str(tmp))
    os.replace(tmp, path)


def load_checkpoint(path, label="yadebreak"):
    """O.load a checkpoint written by save_checkpoint; returns (controller, script state)."""
    path = Path(path)
    if not path.exists():
        raise SystemExit(f"--resume: no checkpoint at {path}; run without --resume first")
    O.load(str(path))
    return _controller(label), json.loads(O.tags[_SCRIPT_TAG])


def run_steps(steps):
    """Advance the scene by `steps` steps now and return. O.run(n, True) waits for the run in 40 ms
    polls (measured: 40 ms for 1 to 500 steps of a small scene, 120 ms for 5000 that take 71 ms),
    so short runs in a loop (a run to rebound, a progress loop) step directly."""
    step = O.step
    for _ in range(int(steps)):
        step()


def _run(label):
    """Called by the PyRunner after the InteractionLoop."""
    _controller(label).step()


def _run_zero(label):
    """Called by the PyRunner before the InteractionLoop."""
    _controller(label).zero_overlaps()


# keep the state in O.tags whenever the scene is saved
_original_save = _wrapper.Omega.save


def _save_with_state(self, *args, **kwargs):
    for ctl in _REGISTRY.values():
        try:
            ctl.sync_tags()
        except Exception as exc:     # never lose the save itself
            print(f"[yadebreak] could not store state in O.tags: {exc}", file=sys.stderr)
    return _original_save(self, *args, **kwargs)


if getattr(_wrapper.Omega.save, "__name__", "") != "_save_with_state":
    _wrapper.Omega.save = _save_with_state


# ------------------------------------------------------------------------------- attach
def attach(materials, seed=0, *, label="yadebreak", **options):
    """Register yadebreak in the current YADE scene and return its controller.

    materials: {YADE material label: material name, path or Material}. Bodies of other materials
    are non-breakable partners. Call after O.engines is set (an InteractionLoop with
    Law2_ScGeom_MindlinPhys_Mindlin) and the breakable spheres exist.
    Options: cs (0), emin (1e-4 J), kappa, emax_ratio (override the files), replace (True),
    dmin (top size / 20), local_damping (0), global_damping (0), global_damping_time (0 s),
    time_step_fraction (0.05 of the smallest sphere's Rayleigh time; None leaves O.dt),
    event_log (a JSON-lines path), read_period (1: contacts read every step; an integer k; or
    "auto": every k steps with k dt <= read_fraction (0.05) of the Rayleigh time of the smallest
    breakable body, so contacts of bodies that can break are sampled as finely as the paper's
    5 % time step while dt follows the finest fragment; or "fast": as often as the loading requires,
    see Breakage._fast_period, tuned by fast_fraction (0.25) and fast_tolerance (0.02)), pause_steps (steps after its creation
    during which a fragment counts no energy: Rocky's safeguard; default 25 for Ab-T10 materials,
    0 for Tavares ones), fragments_energy_factor (1; multiplies the specific energy fragments see).
    Each material file chooses its criterion (breakage.model = "tavares" or "ab_t10"); one scene
    may mix both.
    """
    unknown = set(options) - set(Options.__dataclass_fields__) - {"seed"}
    if unknown:
        raise AttachError(f"unknown option(s) {sorted(unknown)}; accepted: "
                          f"{sorted(set(Options.__dataclass_fields__) - {'seed', 'family_seed'})}")
    opts = Options(seed=seed, **options)
    _check_options(opts)
    if label in _REGISTRY and _find_engine(label) is not None:
        raise AttachError(f"yadebreak is already attached to this scene as '{label}': call attach "
                          "once per scene (or give another label)")
    engines = list(O.engines)
    loop_idx = next((k for k, e in enumerate(engines) if isinstance(e, _wrapper.InteractionLoop)), None)
    if loop_idx is None:
        raise AttachError("O.engines has no InteractionLoop: set O.engines (with "
                          "Law2_ScGeom_MindlinPhys_Mindlin) before calling yadebreak.attach")
    laws = engines[loop_idx].lawDispatcher.functors
    if not any(isinstance(f, _wrapper.Law2_ScGeom_MindlinPhys_Mindlin) for f in laws):
        raise AttachError("the InteractionLoop has no Law2_ScGeom_MindlinPhys_Mindlin: yadebreak "
                          "reads YADE's Hertz-Mindlin forces (use add_materials() for the Ip2)")
    try:
        ctl = Breakage(label, materials, opts)
    except MaterialError as exc:
        raise AttachError(str(exc)) from None
    ctl._register_bodies()
    if not ctl.bodies:
        ctl._warn_once("empty", "the scene has no breakable body: nothing will break (materials "
                       f"mapped: {sorted(materials)})")
    if opts.global_damping > 0.0:
        newton = next((e for e in engines if isinstance(e, _wrapper.NewtonIntegrator)), None)
        if newton is not None:
            newton.damping = opts.global_damping
            for b in O.bodies:                 # global damping acts on fresh fragments only
                if b is not None:
                    b.state.isDamped = False
    radii = [(b.shape.radius, b.material) for b in O.bodies
             if b is not None and isinstance(b.shape, _wrapper.Sphere)]
    if radii:
        tr = min(float(placement.rayleigh_time(r, m.density, m.young, m.poisson))
                 for r, m in radii)
        if opts.time_step_fraction:
            O.dt = opts.time_step_fraction * tr
        else:
            ctl._check_time_step(tr)
    if opts.event_log:
        Path(opts.event_log).parent.mkdir(parents=True, exist_ok=True)
        open(opts.event_log, "w").close()
    runner = _wrapper.PyRunner(command=f"__import__('yadebreak.coupling').coupling._run({label!r})",
                               iterPeriod=ctl.period,
                               initRun=True, label=label)
    zero = _wrapper.PyRunner(command=f"__import__('yadebreak.coupling').coupling._run_zero({label!r})",
                             iterPeriod=1, initRun=True, label=label + "_zero", dead=True)
    engines.insert(loop_idx + 1, runner)
    engines.insert(loop_idx, zero)
    O.engines = engines
    ctl.last_iter = O.iter - 1
    _REGISTRY[label] = ctl
    ctl.sync_tags()
    return ctl


def _is_count(value, smallest):
    """An integer (not a bool) of at least `smallest`."""
    return isinstance(value, int) and not isinstance(value, bool) and value >= smallest


def _check_options(opts):
    problems = []
    if not (0.0 <= opts.cs <= 1.0):
        problems.append(f"cs = {opts.cs}: accepted [0, 1]")
    if not (opts.emin >= 0.0):
        problems.append(f"emin = {opts.emin} J: accepted >= 0")
    if opts.kappa is not None and not opts.kappa > 0:
        problems.append(f"kappa = {opts.kappa}: accepted > 0")
    if opts.emax_ratio is not None and not opts.emax_ratio > 1:
        problems.append(f"emax_ratio = {opts.emax_ratio}: accepted > 1")
    if opts.dmin is not None and not opts.dmin > 0:
        problems.append(f"dmin = {opts.dmin} m: accepted > 0")
    if not (0.0 <= opts.local_damping <= 1.0):
        problems.append(f"local_damping = {opts.local_damping}: accepted [0, 1]")
    if not (0.0 <= opts.global_damping < 1.0):
        problems.append(f"global_damping = {opts.global_damping}: accepted [0, 1)")
    if not opts.global_damping_time >= 0:
        problems.append(f"global_damping_time = {opts.global_damping_time} s: accepted >= 0")
    if opts.time_step_fraction is not None and not (0.0 < opts.time_step_fraction <= 1.0):
        problems.append(f"time_step_fraction = {opts.time_step_fraction}: accepted (0, 1]")
    if opts.dummies not in ("spheres", "ledger"):
        problems.append(f"dummies = {opts.dummies!r}: accepted 'spheres' or 'ledger'")
    if not (opts.read_period in ("auto", "fast") or _is_count(opts.read_period, 1)):
        problems.append(f"read_period = {opts.read_period!r}: accepted an integer >= 1, 'auto' "
                        "or 'fast'")
    if not (0.0 < opts.fast_fraction <= 1.0):
        problems.append(f"fast_fraction = {opts.fast_fraction}: accepted (0, 1]")
    if not (0.0 < opts.fast_tolerance <= 1.0):
        problems.append(f"fast_tolerance = {opts.fast_tolerance}: accepted (0, 1]")
    if opts.pause_steps is not None and not _is_count(opts.pause_steps, 0):
        problems.append(f"pause_steps = {opts.pause_steps!r}: accepted an integer >= 0 or None")
    if not (0.0 < opts.fragments_energy_factor <= 1.0):
        problems.append(f"fragments_energy_factor = {opts.fragments_energy_factor}: accepted (0, 1]")
    if not (0.0 < opts.read_fraction <= 1.0):
        problems.append(f"read_fraction = {opts.read_fraction}: accepted (0, 1]")
    if problems:
        raise AttachError("bad option(s): " + "; ".join(problems))
