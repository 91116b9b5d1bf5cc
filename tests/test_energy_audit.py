"""Replacement never creates energy, in every read mode.

Each breakage event carries its energy audit (J): the parent's kinetic energy and the elastic
energy of its contacts just before, the progeny's kinetic energy and the elastic energy of its
contacts just after. The scene's mechanical energy (kinetic plus elastic in every contact,
zeroed overlaps taken as the zero of their contacts) can only fall in an impact on a fixed wall
with damped contacts: it is checked every few steps through whole runs of the scene that threw
fragments at 16 times the impact speed when a child kept its parent's real overlap (copper ore,
10 mm, 45 m/s: 1,012 J/kg)."""
import numpy as np
import pytest

from yadebreak.model import placement

SPEED = 45.0


def _mechanical_energy(brk):
    from yadebreak.scenes.energy import energy_now
    now = energy_now(brk)
    return sum(now.kinetic.values()) + now.elastic


def _run(duration, every=10, **options):
    """Two particles at SPEED on a steel wall: the largest rise of the scene's mechanical energy
    between checks and its largest value (both relative to the start), the largest fragment
    speed at the end (m/s), the events."""
    from yadebreak import engine, scenes
    from yadebreak.adapter.yade_api import O
    brk, _ = scenes.impact_scene("copper_ore", 10e-3, speeds=[SPEED] * 2, seed=5, **options)
    start = previous = top = _mechanical_energy(brk)
    rise = 0.0
    while O.time < duration:
        engine.run_steps(every)
        now = _mechanical_energy(brk)
        rise = max(rise, (now - previous) / start)
        previous, top = now, max(top, now)
    fastest = max(b.state.vel.norm() for b in O.bodies if b is not None and b.dynamic)
    return rise, top / start, fastest, brk.breakage_events


@pytest.mark.yade
@pytest.mark.parametrize("options", [{}, {"read_period": "every_step"}, {"read_period": 4},
                                     {"read_period": "auto"}, {"zeroing_tolerance": 0.0},
                                     {"dummies": "ledger"}],
                         ids=["fast", "every_step", "every_4", "auto", "no_sleep", "ledger"])
def test_no_breakage_creates_energy(scene, options):
    rise, top, fastest, events = _run(1.5e-4, **options)
    assert len(events) >= 4                    # both particles broke, some fragments too
    for e in events:
        before = e["kinetic_energy_before"] + e["elastic_energy_before"]
        after = e["kinetic_energy_after"] + e["elastic_energy_after"]
        assert after <= before * (1 + 1e-12), e
        assert e["elastic_energy_after"] == 0.0          # every artificial overlap zeroed
        assert e["fragment_speed_excess"] <= 1e-9, e     # none outside the parent's field
    # the scene's energy never rose above its start (it fell by about 80 % over the run: the
    # dashpots and the energy zeroed at each breakage), and no 10-step window added more than
    # 1 % of it. Measured: at most 2e-10 of the start in most runs, 1e-7 reading every 4 steps
    # (the leapfrog's half-step velocities when the time step falls at a breakage), and up to
    # 0.6 % where a dummy fine lies wholly inside a larger sibling and is squeezed by it and two
    # others (docs/model.md, known limits). A child keeping its parent's real overlap put in
    # 1e-3 of the start over 10 steps, and threw a fragment at 16 v0.
    assert rise <= 0.01
    assert top <= 1.0 + 1e-12
    # a fine fragment squeezed out between converging heavier ones may leave faster than the
    # impact with the energy conserved (measured up to 2.8 v0); a child keeping its parent's
    # real overlap threw one at 16 v0
    assert fastest <= 3.0 * SPEED


@pytest.mark.yade
def test_the_audit_sees_energy_put_in(scene):
    """local_damping releases a share of each artificial overlap as force (the EDEM manual's
    option): the audit records that elastic energy after the breakage, and the fragments that
    it can push beyond the parent's field; without zeroing, far more."""
    *_, events = _run(6e-5, read_period="every_step", local_damping=0.3)
    assert max(e["elastic_energy_after"] for e in events) > 0.0
    assert max(e["fragment_speed_excess"] for e in events) > 0.0
    *_, events = _run(3e-5, read_period="every_step", zero_overlaps=False)
    created = [e["elastic_energy_after"] / (e["kinetic_energy_before"]
                                            + e["elastic_energy_before"]) for e in events]
    assert max(created) > 1.0                  # more energy than the parent had, in one event


@pytest.mark.yade
def test_a_pair_that_closes_while_asleep_wakes_without_stored_energy(scene):
    """A zeroed pair that opens sleeps (zeroing_tolerance); if it is pushed back together while
    asleep, no force resisted the closing, so it must wake with no elastic energy: its zero is
    raised to the overlap it has then (the energy would otherwise come from nowhere)."""
    from yadebreak import engine, scenes
    from yadebreak.adapter.yade_api import O
    brk, (a,) = scenes.impact_scene("copper_ore", 5e-3, speeds=[0.0], zeroing_tolerance=0.5)
    brk.bodies[a].fracture_energy = 1e12       # the pair's contact, not breakage, is tested
    b = O.bodies.append(_sphere_like(O.bodies[a], offset=4.5e-3))     # 0.5 mm overlap
    brk.zeroing.zero_pair(a, b, 0.5e-3, created=False)
    brk.zeroing.wake()
    O.bodies[a].state.vel, O.bodies[b].state.vel = (0, 0, 0.5), (0, 0, 1.5)    # opening
    engine.run_steps(3)
    key = (min(a, b), max(a, b))
    assert key in brk.zeroing.asleep
    for body, v in ((a, 2.0), (b, 0.0)):                               # closing hard
        O.bodies[body].state.vel = (0, 0, v)
    while key in brk.zeroing.asleep:
        engine.run_steps(1)
    inter = O.interactions[a, b]
    zero = brk.zeroing.pairs[key]
    assert inter.geom.penetrationDepth > 0.5e-3 - 1e-12   # it did close past where it slept
    assert zero.artificial == pytest.approx(inter.geom.penetrationDepth, rel=1e-3)
    assert inter.phys.normalForce.norm() < 1e-3 * zero.kno0 * (0.1e-3) ** 1.5


def _sphere_like(body, offset):
    from yadebreak.adapter.yade_api import utils
    pos = body.state.pos
    return utils.sphere((pos[0], pos[1], pos[2] + offset), body.shape.radius,
                        material=body.material)


def test_fragments_never_spin_with_more_energy_than_their_parent():
    """spin_scale: the progeny's rotational energy (spin plus the rigid field about its centre of
    mass) is at most the parent's I w^2 / 2, equal to it when capped, and the field's linear
    momentum stays the parent's."""
    rng = np.random.default_rng(3)
    radius, mass = 5e-3, 1e-3
    inertia = 0.4 * mass * radius ** 2
    capped = 0
    for k in range(60):
        fine = k % 2 == 1                        # many fine fragments, or a few coarse ones
        radii = radius * (rng.uniform(0.05, 0.2, size=rng.integers(20, 40)) if fine
                          else rng.uniform(0.1, 0.6, size=rng.integers(2, 12)))
        if fine:                                 # all at the parent's surface, the extreme
            out = rng.normal(size=(len(radii), 3))
            centers = out / np.linalg.norm(out, axis=1)[:, None] * (radius - radii)[:, None]
        else:
            centers = placement.place_fragments(np.zeros(3), radius, radii, rng.normal(size=3),
                                                rng)
        masses = placement.fragment_masses(mass, radii)
        spin = rng.normal(size=3) * 100.0
        velocity = rng.normal(size=3)
        w = spin * placement.spin_scale(centers, masses, radii, np.zeros(3), inertia, spin)
        vel = placement.fragment_velocities(centers, masses, np.zeros(3), velocity, w)
        assert masses @ vel == pytest.approx(mass * velocity, rel=1e-12)
        rotational = 0.5 * (masses @ ((vel - velocity) ** 2).sum(axis=1)
                            + (0.4 * masses * radii ** 2).sum() * w @ w)
        parent = 0.5 * inertia * spin @ spin
        assert rotational <= parent * (1 + 1e-12)
        if not np.allclose(w, spin):
            capped += 1
            assert rotational == pytest.approx(parent, rel=1e-9)
    assert capped >= 25                         # fragments at the surface do carry more
