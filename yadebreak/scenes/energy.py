"""The energy a running scene holds and has lost, as YADE and the engine count it: what the energy
audit of a cascade reads (studies/verify/energy_audit.py). Outside the default path: YADE's
energy tracking is switched on only by track_energy()."""
from __future__ import annotations

from typing import NamedTuple

from yadebreak.adapter.yade_api import O, wrapper
from yadebreak.engine.replacement import _elastic_energy


class EnergyNow(NamedTuple):
    """The scene's energy (J) now: kinetic (translation and spin) of the dynamic bodies by the
    engine's kind of body (BodyTable.kind_of: "breakable", "unbreakable", "dummy"; "none" for a
    body the engine does not track), the elastic energy its contacts hold (the engine's count,
    zeroed overlaps as the zero of their contacts), and what YADE has accumulated since
    track_energy(): the Hertz-Mindlin law's normal and shear dashpots and friction slip
    (Law2_ScGeom_MindlinPhys_Mindlin.normDampDissip, shearDampDissip, frictionDissipation),
    Newton's damping (O.energy 'nonviscDamp': the engine's global damping of fragments) and
    gravity's (O.energy 'gravWork', counted as YADE does: the energy total stays constant); the
    kinetic energy the fines ledger carries (dummies="ledger")."""

    kinetic: dict
    elastic: float
    normal_dashpot: float
    shear_dashpot: float
    friction: float
    global_damping: float
    gravity: float
    ledger_kinetic: float


def _laws():
    for engine in O.engines:
        if isinstance(engine, wrapper.InteractionLoop):
            for law in engine.lawDispatcher.functors:
                if isinstance(law, wrapper.Law2_ScGeom_MindlinPhys_Mindlin):
                    yield law


def track_energy():
    """YADE's energy tracking on (O.trackEnergy, the law's calcEnergy), its totals from zero.
    Neither changes a force: they add up what the integrator and the law do."""
    O.trackEnergy = True
    O.energy.clear()
    laws = list(_laws())
    if not laws:
        raise ValueError("the scene has no Law2_ScGeom_MindlinPhys_Mindlin to track")
    for law in laws:
        law.calcEnergy = True
        law.normDampDissip = law.shearDampDissip = law.frictionDissipation = 0.0


def energy_now(brk):
    """EnergyNow of the scene of controller `brk`."""
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
    elastic = sum(_elastic_energy(i, zeroed.get((min(i.id1, i.id2), max(i.id1, i.id2))))
                  for i in O.interactions if i.isReal)
    laws = list(_laws())
    totals = dict(O.energy.items())
    return EnergyNow(kinetic, float(elastic), sum(law.normDampDissip for law in laws),
                     sum(law.shearDampDissip for law in laws),
                     sum(law.frictionDissipation for law in laws),
                     float(totals.get("nonviscDamp", 0.0)), float(totals.get("gravWork", 0.0)),
                     float(brk.ledger.kinetic_energy()))
