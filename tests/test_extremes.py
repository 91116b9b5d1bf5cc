"""Stability at the extremes, a fast subset (issue 7): no NaN or infinity, mass conserved to 1e-9,
no kinetic energy created (the contact law only dissipates and stores), and the run ends."""
import numpy as np
import pytest

pytestmark = pytest.mark.yade


def _kinetic(brk):
    from yade import O
    total = 0.0
    for b in O.bodies:
        if b is not None and b.dynamic:
            total += 0.5 * b.state.mass * b.state.vel.squaredNorm()
            total += 0.5 * b.state.inertia[0] * b.state.angVel.squaredNorm()
    for mass, *_rest in brk.ledger:              # ledger fines carry their momentum
        momentum = np.array(_rest[-3:])
        total += 0.5 * momentum @ momentum / mass
    return total


@pytest.mark.parametrize("label, size, speed, options", [
    ("150 m/s impact", 5.5e-3, 150.0, {}),
    ("0.1 mm particle", 1e-4, 30.0, {}),
    ("200 mm particle", 0.2, 10.0, {}),
    ("time step at 40 % of the Rayleigh time", 5.5e-3, 30.0, {"time_step_fraction": 0.4}),
    ("time step at 0.5 % of the Rayleigh time", 5.5e-3, 30.0, {"time_step_fraction": 0.005}),
])
def test_extreme_impacts_stay_finite_and_conservative(scene, label, size, speed, options):
    from yade import O
    from yadebreak import scenes
    brk, ids = scenes.impact_scene("limestone", size, [speed], dummies="ledger", **options)
    m0 = brk.total_mass()
    k0 = _kinetic(brk)
    O.run(3000, True)
    for b in O.bodies:
        if b is not None:
            assert np.all(np.isfinite(np.array(b.state.pos))) and np.all(np.isfinite(np.array(b.state.vel)))
    assert brk.total_mass() == pytest.approx(m0, rel=1e-9)
    assert _kinetic(brk) <= k0 * (1 + 1e-6), label
    for e in brk.events:
        assert np.isfinite(e["specific_energy"]) and np.isfinite(e["fracture_energy"])
