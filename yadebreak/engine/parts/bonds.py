"""The bonds of a bonded agglomerate in YADE's loop: their beams on YADE's cohesive law, and the
failure criterion of Eqs. B7-B8 (docs/bonded.md) evaluated here by the BondWatch, since YADE's law
breaks bonds on force alone. The agglomerate's scene is scenes/agglomerate.py.

Each bond is a YADE interaction whose physics is a CohFrictPhys given the beam's stiffnesses of
Eq. B6 (axial, shear, bending, twist), made stress-free where it is built (`unp`: the sphere gap),
with adhesions YADE can never reach: YADE integrates the beam, BondWatch breaks it. A broken bond's
interaction is erased; if the spheres touch again YADE makes a Hertz-Mindlin contact (the only
physics functor of the scene), with damping and rolling friction. A contact is bonded or not,
never both.

The BondWatch's state (the bonds as built, their strengths, which broke when and how) lives in
Python, which O.save does not store: scenes.agglomerate.save_checkpoint keeps it in O.tags as
JSON (floats written exactly), and the scene's interactions keep the intact beams; the first step
after an O.load of such a file restores the watch from both (restore_watch).
"""
from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass

import numpy as np

from yadebreak.model import bonds
from yadebreak.model.intervals import Interval
from yadebreak.adapter.yade_api import O, utils, wrapper as _w
from yadebreak.engine.parts import protocol

#: stresses at or above this fraction of a bond's strength are counted (the document's Fig. 18)
WATCH_LEVEL = 0.8
#: the PyRunner's label, and the key of its BondWatch
LABEL = "bond_watch"
#: O.tags key of the agglomerate's record (its ids; with the watch's state in earlier versions)
TAG = "yadebreak_bonds"
#: an adhesion YADE's cohesive law never reaches (N, N m): bonds break here, not there
NEVER = 1e30
#: the accepted time steps (s): the rolling stiffness divides by dt^2, which must stay a float
TIME_STEP = Interval(1e-150, math.inf)
#: YADE counts steps in a signed 64-bit integer
MAX_STEPS = 2**63 - 1


def attach_bonds(ids, pairs, lengths, radii, binder, rng, target_id=None, check_period=1):
    """Bond spheres `ids` (YADE ids; radii in m) at `pairs` (indices into ids, lengths L_B in
    m) with beams of `binder` (strengths drawn from rng), after O.engines is set, and register
    the BondWatch (watching from the first touch of target_id; None: from the first step).
    Returns (watch, the bonds' time scale of Eq. B11 in s)."""
    network = BondNetwork.build(ids, pairs, lengths, radii, binder, rng)
    masses = np.array([O.bodies[int(i)].state.mass for i in ids])
    time_scale = bonds.bond_time_scale(masses, 0.4 * masses * radii**2, pairs,
                                       network.stiffness, network.lever_a, network.lever_b)
    watch = BondWatch(network, target_id, check_period=check_period)
    protocol.install(BondPart(LABEL, watch))
    return watch, time_scale


class BondPart(protocol.Part):
    """The BondWatch in YADE's loop: after Newton's step, every step; its state (the bonds as
    built, which broke when and how) goes with the scene (protocol)."""

    kind = "bonds"
    hook = protocol.AFTER_NEWTON
    saved_at_install = False          # the network's dump is stale a step later: saved with
    #                                   the scene (yadebreak.save, save_checkpoint) only

    def __init__(self, label, watch):
        super().__init__(label, 1)
        self.watch = watch

    def act(self):
        self.watch()

    def to_state(self, folder=None):
        return {"iter": O.iter, "label": self.label, "watch": self.watch.to_dict()}

    @classmethod
    def from_state(cls, label, period, state):
        """The watch restored (reading the intact bonds' interactions); RuntimeError if the
        scene ran on after it was stored (an O.save does not store it)."""
        if state["iter"] != O.iter:
            raise RuntimeError(f"the BondWatch's state in this scene was stored at step "
                               f"{state['iter']} and the scene is at step {O.iter}: O.save does "
                               "not store it; save bonded scenes with yadebreak.save or "
                               "scenes.agglomerate.save_checkpoint")
        return cls(label, BondWatch.from_dict(state["watch"]))

    @classmethod
    def legacy_state(cls, label):
        """Checkpoints of earlier versions keep the watch in the scene's record (TAG)."""
        return json.loads(O.tags[TAG]) if TAG in O.tags.keys() and O.tags[TAG] else None


def watch_of(label=LABEL):
    """The BondWatch of the current scene (restored from it after O.load)."""
    return protocol.part_of(BondPart.kind, label).watch


def on_step(label):
    """The entry point that scenes saved by earlier versions name in their PyRunner commands."""
    protocol.run(BondPart.kind, label)


@dataclass
class BondNetwork:
    """The bonds as built, one row per bond (arrays), and their YADE interactions."""

    n_spheres: int             # spheres of the packing (some may have no bond)
    a: np.ndarray              # (m,) YADE id of the first sphere
    b: np.ndarray              # (m,) YADE id of the second
    pairs: np.ndarray          # (m, 2) packing indices
    radius: np.ndarray         # R_B, m (Eq. B2)
    length: np.ndarray         # L_B, m (Eq. B1)
    lever_a: np.ndarray        # sphere a's centre to the contact point, m
    lever_b: np.ndarray
    stiffness: bonds.BeamStiffness
    unp: np.ndarray            # YADE's overlap at bonding, m: the beam is stress-free there
    strengths: tuple           # (tensile, shear, compressive), (m,) each, Pa
    geoms: list                # YADE ScGeom6D of each bond (valid while intact)
    physs: list                # YADE CohFrictPhys of each bond

    @classmethod
    def build(cls, ids, pairs, lengths, radii, binder, rng):
        """Create the bond interactions in YADE (after O.engines is set) and their beams."""
        radius = bonds.bond_radius(radii[pairs[:, 0]], radii[pairs[:, 1]],
                                   binder.radius_multiplier)
        stiffness = bonds.beam_stiffness(binder.young_modulus, binder.poisson_ratio, radius,
                                         lengths)
        m = len(pairs)
        strengths = tuple(bonds.draw_strengths(mean, binder.strength_cv, m, rng) for mean in
                          (binder.tensile_strength, binder.shear_strength,
                           binder.compressive_strength))
        a, b = ids[pairs[:, 0]], ids[pairs[:, 1]]
        geoms, physs, unp = [], [], np.empty(m)
        for k in range(m):
            inter = utils.createInteraction(int(a[k]), int(b[k]))
            g = inter.geom
            unp[k] = g.penetrationDepth
            phys = _w.CohFrictPhys(
                kn=float(stiffness.axial[k]), ks=float(stiffness.shear[k]),
                kr=float(stiffness.bending[k]), ktw=float(stiffness.twist[k]),
                unp=float(unp[k]), normalAdhesion=NEVER, shearAdhesion=NEVER,
                momentRotationLaw=True, maxRollPl=-1.0, maxTwistPl=-1.0, fragile=False,
                cohesionBroken=False, initCohesion=False,
                tangensOfFrictionAngle=0.0)
            inter.phys = phys
            geoms.append(g)
            physs.append(phys)
        # ScGeom's contact point sits in the middle of the gap (or overlap)
        lever_a = radii[pairs[:, 0]] - 0.5 * unp
        lever_b = radii[pairs[:, 1]] - 0.5 * unp
        return cls(len(ids), a, b, pairs, radius, lengths, lever_a, lever_b, stiffness, unp,
                   strengths, geoms, physs)

    _ARRAYS = ("a", "b", "pairs", "radius", "length", "lever_a", "lever_b", "unp")

    def to_dict(self):
        """The bonds as built, JSON-able (floats exact: JSON writes their shortest repr)."""
        data = {k: getattr(self, k).tolist() for k in self._ARRAYS}
        data["stiffness"] = {k: v.tolist() for k, v in vars(self.stiffness).items()}
        data["strengths"] = [s.tolist() for s in self.strengths]
        data["n_spheres"] = self.n_spheres
        return data

    @classmethod
    def from_dict(cls, data, intact):
        """The network of to_dict, its intact bonds (a boolean mask) read again from YADE's
        interactions (broken bonds have none: None)."""
        arrays = {k: np.array(data[k]) for k in cls._ARRAYS}
        geoms, physs = [None] * len(arrays["a"]), [None] * len(arrays["a"])
        for k in np.flatnonzero(intact):
            a, b = int(arrays["a"][k]), int(arrays["b"][k])
            inter = O.interactions[a, b] if O.interactions.has(a, b) else None
            if inter is None or not isinstance(inter.phys, _w.CohFrictPhys):
                raise RuntimeError(f"bond {k} (bodies {a}-{b}) is intact in the BondWatch's "
                                   "state but has no bond in the scene: the state and the scene "
                                   "do not match")
            geoms[k], physs[k] = inter.geom, inter.phys
        stiffness = bonds.BeamStiffness(**{k: np.array(v) for k, v in data["stiffness"].items()})
        return cls(int(data["n_spheres"]), stiffness=stiffness,
                   strengths=tuple(np.array(s) for s in data["strengths"]), geoms=geoms,
                   physs=physs, **arrays)


class BondWatch:
    """Called by a PyRunner every step: from the first touch of the target on, every
    `check_period` steps, reads every intact bond from YADE, evaluates Eqs. B7-B8 and breaks the
    bonds that fail (records time and mode, erases the interaction). Before the first touch the
    agglomerate moves as a rigid body and no bond can change, so nothing is read.

    Cost: about 1 us per intact bond per check (four reads from YADE), plus ~3 us for each bond
    whose scalar bound reaches WATCH_LEVEL of a strength (its end moments computed exactly)."""

    def __init__(self, network, target_id, check_period=1):
        self.net = network
        self.target_id = target_id
        self.check_period = int(check_period)
        m = len(network.a)
        self.mode = np.zeros(m, np.int8)             # bonds.MODES index, 0: intact
        self.failed_at = np.full(m, np.nan)          # s of simulated time
        self.alive = np.arange(m)                    # rows of intact bonds
        self._geoms, self._physs = list(network.geoms), list(network.physs)
        self._intact = _IntactColumns(network, self.alive)
        self.touch_time = None                       # s, the first touch of the target
        self.above = np.zeros(3, int)                # bonds at >= WATCH_LEVEL: tension, shear,
        #                                              compression (at the last check)
        self.checks = 0
        self.bonds_read = 0
        self.seconds = 0.0                           # wall time spent in check() (cost report)
        self.on_failure = None                       # callable(rows, modes, time), if set

    _STATE = ("touch_time", "checks", "bonds_read", "seconds", "check_period", "target_id")

    def to_dict(self):
        """The watch's state, JSON-able: the network, each bond's mode and failure time."""
        data = {k: getattr(self, k) for k in self._STATE}
        data.update(network=self.net.to_dict(), mode=self.mode.tolist(),
                    failed_at=self.failed_at.tolist(), above=self.above.tolist())
        return data

    @classmethod
    def from_dict(cls, data):
        """The watch of to_dict, the intact bonds read from the scene's interactions."""
        mode = np.array(data["mode"], np.int8)
        watch = cls(BondNetwork.from_dict(data["network"], mode == bonds.INTACT),
                    data["target_id"], data["check_period"])
        watch.mode, watch.failed_at = mode, np.array(data["failed_at"], float)
        watch.alive = np.flatnonzero(mode == bonds.INTACT)     # as _break keeps it: ascending
        watch._geoms = [watch.net.geoms[r] for r in watch.alive]
        watch._physs = [watch.net.physs[r] for r in watch.alive]
        watch._intact = _IntactColumns(watch.net, watch.alive)
        watch.above = np.array(data["above"], int)
        for k in ("touch_time", "checks", "bonds_read", "seconds"):
            setattr(watch, k, data[k])
        return watch

    # -- the per-step path --------------------------------------------------------------------
    def __call__(self):
        if self.touch_time is None:
            if self.target_id is not None and O.forces.f(self.target_id).norm() == 0.0:
                return
            self.touch_time = O.time
        if (O.iter % self.check_period) == 0:
            began = time.perf_counter()
            self.check()
            self.seconds += time.perf_counter() - began

    def check(self):
        """Read the intact bonds, count those near their strengths, break those past them."""
        tensile, shear, compressive = self._stresses()
        alive, st, ss, sc = self.alive, *self._intact.strengths
        self.above = np.array([np.count_nonzero(tensile >= WATCH_LEVEL * st),
                               np.count_nonzero(shear >= WATCH_LEVEL * ss),
                               np.count_nonzero(compressive >= WATCH_LEVEL * sc)])
        modes = bonds.failure_modes(tensile, shear, compressive, (st, ss, sc))
        failing = np.flatnonzero(modes)
        self.checks += 1
        self.bonds_read += len(alive)
        if len(failing):
            self._break(failing, modes[failing])

    def _stresses(self):
        """Eq. B7 for every intact bond: scalar reads bound the end moments from above (|M| +
        max(d_a, d_b) |F_s|); bonds whose bound reaches WATCH_LEVEL of a strength get the exact
        end moments."""
        col, geoms, physs = self._intact, self._geoms, self._physs
        n = len(geoms)
        depth = np.fromiter((g.penetrationDepth for g in geoms), float, n)
        shear = np.fromiter((p.shearForce.norm() for p in physs), float, n)
        moment = np.fromiter((p.moment_bending.norm() for p in physs), float, n)
        twist = np.fromiter((p.moment_twist.norm() for p in physs), float, n)
        axial = -col.axial_stiffness * (depth - col.unp)     # tension > 0
        lever_a, lever_b, radius = col.lever_a, col.lever_b, col.radius
        bound = moment + np.maximum(lever_a, lever_b) * shear
        tensile, shear_stress, compressive = bonds.bond_stresses(axial, shear, bound, twist,
                                                                 radius)
        st, _, sc = col.strengths
        near = np.flatnonzero((tensile >= WATCH_LEVEL * st) | (compressive >= WATCH_LEVEL * sc))
        if len(near):
            exact = np.array([_end_moment(geoms[k], physs[k], lever_a[k], lever_b[k])
                              for k in near])
            t, _, c = bonds.bond_stresses(axial[near], shear[near], exact, twist[near],
                                          radius[near])
            tensile[near], compressive[near] = t, c
        return tensile, shear_stress, compressive

    def _break(self, failing, modes):
        rows = self.alive[failing]
        self.mode[rows] = modes
        self.failed_at[rows] = O.time
        for r in rows:
            O.interactions.erase(int(self.net.a[r]), int(self.net.b[r]))
        keep = np.ones(len(self.alive), bool)
        keep[failing] = False
        self.alive = self.alive[keep]
        self._geoms = [g for g, k in zip(self._geoms, keep) if k]
        self._physs = [p for p, k in zip(self._physs, keep) if k]
        self._intact = _IntactColumns(self.net, self.alive)
        if self.on_failure is not None:
            self.on_failure(rows, modes, O.time)

    # -- what the run reports -----------------------------------------------------------------
    def broken_count(self, mode=None):
        """Bonds broken (in `mode`, a bonds.MODES index, or in any)."""
        return int(np.count_nonzero(self.mode != bonds.INTACT if mode is None
                                    else self.mode == mode))

    def damage_ratios(self):
        """Per packing sphere: broken over initial bonds (Eq. B9; NaN for a sphere with none)."""
        return bonds.damage_ratios(self.net.n_spheres, self.net.pairs, self.mode != 0)

    def fragments(self):
        """(label per packing sphere, spheres per label) of the surviving bond graph."""
        return bonds.fragments(self.net.n_spheres, self.net.pairs, self.mode == 0)


class _IntactColumns:
    """The network's per-bond constants for the intact bonds, in the order BondWatch reads them:
    gathered once per breakage, not every step."""

    def __init__(self, net, alive):
        self.axial_stiffness = net.stiffness.axial[alive]
        self.unp = net.unp[alive]
        self.lever_a, self.lever_b = net.lever_a[alive], net.lever_b[alive]
        self.radius = net.radius[alive]
        self.strengths = tuple(s[alive] for s in net.strengths)    # tensile, shear, compressive


def _end_moment(geom, phys, lever_a, lever_b):
    """The larger of the beam's two end bending moments (N m): |M + d_a n x F_s| at sphere a and
    |M - d_b n x F_s| at sphere b, M the bending moment YADE integrates (Eqs. B12-B13)."""
    m = phys.moment_bending
    lever = geom.normal.cross(phys.shearForce)
    return max((m + lever * lever_a).norm(), (m - lever * lever_b).norm())
