"""The energy a running scene holds and has lost, as YADE and the engine count it: what the energy
audit of a cascade reads (studies/verify/energy_audit.py). Outside the default path: YADE's
energy tracking is switched on only by track_energy()."""
from __future__ import annotations

from typing import NamedTuple

from yadebreak.adapter.yade_api import O
from yadebreak.engine.parts.protocol import Part, install
from yadebreak.engine.contacts.hertz import contact_elastic_energy


class EnergyNow(NamedTuple):
    """The scene's energy (J) now: kinetic (translation and spin) of the dynamic bodies by the
    engine's kind of body (BodyTable.kind_of: "breakable", "unbreakable", "dummy"; "none" for a
    body the engine does not track), the elastic energy its contacts hold (the engine's count,
    zeroed overlaps as the zero of their contacts), and what has been lost since
    track_energy(): the normal and shear dashpots and friction slip (ContactDissipation), and
    from YADE's O.energy: Newton's damping ('nonviscDamp': the engine's global damping of
    fragments) and gravity's (O.energy 'gravWork', counted as YADE does: the energy total stays
    constant); the kinetic energy the fines ledger carries (dummies="ledger")."""

    kinetic: dict
    elastic: float
    normal_dashpot: float
    shear_dashpot: float
    friction: float
    global_damping: float
    gravity: float
    ledger_kinetic: float


class ContactDissipation(Part):
    """Reads every real contact every step, after the law (and the engine's breakage) at this
    step: the normal dashpot's work |Fv . n| |dd| (Fv = MindlinPhys.normalViscous, this step's,
    which YADE computes from the velocity that made dd, the overlap's last increment: YADE's own
    normDampDissip), and the shear force's work over the step that follows, settled at the next
    read once Newton has moved the bodies: the force (the law's, elastic and viscous) times the
    displacement of the two bodies' material points at the contact point (velocities v + w x r,
    averaged over the step, as the leapfrog's kinetic energy changes). The viscous part
    (shearForce less shearElastic) is the shear dashpot; friction slip is the elastic part's
    work less the rise of its elastic energy |Fs|^2 / (2 ks), plus that energy where a pair
    separates (a pair lost to a breakage is in the breakage's elastic_energy_before). ScGeom's
    shearInc is not that displacement where the overlap is deep (a fragment's zeroed one):
    counted with it, friction ran 1.2 % of E0 over 400 steps of a granulite cloud above the work
    the forces did. A contact of a body replaced at this step is not read: its force never
    acted."""

    kind = "energy_audit"

    def __init__(self, label="energy_audit", period=1):
        super().__init__(label, period)
        self.normal = self.shear = self.friction = 0.0
        self._last = {}                 # (id1, id2) -> (overlap, elastic shear energy)
        self._pending = []              # the last read's shear forces, their work still to count
        self._moved = {}                # body id -> (position, velocity, spin) at the last read

    def _settle(self):
        """(dashpot, elastic) work (J) the last read's shear forces did over the step since."""
        bodies, moved, dt = O.bodies, self._moved, O.dt
        dashpot = elastic = 0.0
        now = {}
        for a, b, point, viscous, force in self._pending:
            rel = None
            for sign, j in ((-1.0, a), (1.0, b)):
                body = bodies[j]
                if body is None:              # replaced: its force never acted
                    rel = None
                    break
                if j not in now:
                    x, v, w = moved[j]
                    now[j] = (x, 0.5 * (v + body.state.vel), 0.5 * (w + body.state.angVel))
                x, v, w = now[j]
                step = sign * (v + w.cross(point - x)) * dt
                rel = step if rel is None else rel + step
            if rel is not None:
                dashpot -= viscous.dot(rel)
                elastic -= force.dot(rel)
        return dashpot, elastic

    def act(self):
        dashpot, work = self._settle()
        last, now, pending, moved = self._last, {}, [], {}
        bodies = O.bodies
        normal = 0.0
        energy_rise = 0.0
        for i in O.interactions:
            if not i.isReal:
                continue
            phys, geom = i.phys, i.geom
            key = (i.id1, i.id2)
            d = geom.penetrationDepth
            force = phys.shearElastic
            energy = 0.5 * force.squaredNorm() / phys.ks if phys.ks > 0.0 else 0.0
            before = last.get(key)
            d0, e0 = before if before is not None else (max(d, 0.0), 0.0)
            normal += abs(phys.normalViscous.dot(geom.normal)) * abs(d - d0)
            energy_rise += energy - e0
            now[key] = (d, energy)
            # the viscous force the law applied: shearForce less its elastic part (YADE keeps
            # shearViscous with the opposite sign)
            pending.append((i.id1, i.id2, geom.contactPoint, phys.shearForce - force, force))
            for j in key:
                if j not in moved:
                    s = bodies[j].state
                    moved[j] = (s.pos, s.vel, s.angVel)
        friction = work - energy_rise
        for key, (_, e0) in last.items():
            if key not in now and O.bodies[key[0]] is not None and O.bodies[key[1]] is not None:
                friction += e0              # separated holding shear energy
        self._last, self._pending, self._moved = now, pending, moved
        self.normal += normal
        self.shear += dashpot
        self.friction += friction


def track_energy():
    """YADE's energy tracking on (O.trackEnergy: Newton's damping and gravity's work in
    O.energy), and the audit's reading of every contact every step (ContactDissipation).
    Neither changes a force. The law's own counters (Law2_ScGeom_MindlinPhys_Mindlin
    calcEnergy) are not used: on this YADE they corrupted memory (malloc aborts, segmentation
    faults) in a breakage cascade, and counted the dashpot of a parent's last step."""
    O.trackEnergy = True
    O.energy.clear()
    part = ContactDissipation()
    install(part)
    return part


def energy_now(brk, part=None):
    """EnergyNow of the scene of controller `brk` (`part`: track_energy()'s; None: before it)."""
    table = brk.state.table
    kinetic = {}
    for b in O.bodies:
        if b is None or not b.dynamic:
            continue
        kind = table.kind_of(b.id)
        energy = 0.5 * (b.state.mass * b.state.vel.squaredNorm()
                        + b.state.inertia[0] * b.state.angVel.squaredNorm())
        kinetic[kind] = kinetic.get(kind, 0.0) + energy
    zeroed = brk.zeroed
    elastic = sum(contact_elastic_energy(i, zeroed.get((min(i.id1, i.id2),
                                                        max(i.id1, i.id2))))
                  for i in O.interactions if i.isReal)
    totals = dict(O.energy.items())
    normal, shear, friction = ((part.normal, part.shear, part.friction) if part is not None
                               else (0.0, 0.0, 0.0))
    return EnergyNow(kinetic, float(elastic), normal, shear, friction,
                     float(totals.get("nonviscDamp", 0.0)), float(totals.get("gravWork", 0.0)),
                     float(brk.ledger.kinetic_energy()))
