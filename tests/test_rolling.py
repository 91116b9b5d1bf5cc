"""Rolling friction per contact pair (issue 18, coupling/rolling.py): a sphere rolling on a plate
stops where its rolling coefficient says, each pair of a bed gets its own coefficient from the
material files, and a replaced value replaces only its pair."""
import math

import numpy as np
import pytest

pytestmark = pytest.mark.yade

G = 9.81


def _rolling_sphere(scene, plate, v0, radius=0.01, stiffness_scale=1e-3):
    """A copper ore sphere rolling without slip at v0 (m/s) along x on a wall of material
    `plate` ("steel": the particle-steel pair; "ore": particle-particle), resting at its
    equilibrium overlap under gravity. Returns (sphere, rolling friction of the pair)."""
    from yade import utils
    from yadebreak import engine, scenes
    from yadebreak.model import placement
    from yadebreak.engine.materials import rolling_friction
    labels = {"ore": "copper_ore", "steel": "steel"}
    ip2, mats = engine.add_materials(labels, stiffness_scale=stiffness_scale)
    table, named = rolling_friction(labels)
    scene.bodies.append(utils.wall(0.0, axis=2, sense=1, material=plate))
    ore = mats["ore"]
    young = ore.young_modulus * stiffness_scale
    e_star = 1.0 / ((1 - ore.poisson_ratio**2) / young
                    + (1 - mats[plate].poisson_ratio**2) / (mats[plate].young_modulus
                                                            * stiffness_scale))
    mass = ore.density * 4.0 / 3.0 * math.pi * radius**3
    overlap = (mass * G / (4.0 / 3.0 * e_star * math.sqrt(radius))) ** (2.0 / 3.0)
    b = utils.sphere((0.0, 0.0, radius - overlap), radius, material="ore")
    b.state.vel = (v0, 0.0, 0.0)
    b.state.angVel = (0.0, v0 / radius, 0.0)          # rolling without slip along +x
    sphere = scene.bodies[scene.bodies.append(b)]
    scene.engines = scenes.hertz_engines(ip2, gravity=(0.0, 0.0, -G), rolling=table)
    scene.dt = 0.1 * float(placement.rayleigh_time(radius, ore.density, young,
                                                   ore.poisson_ratio))
    pair = "ore-ore" if plate == "ore" else "ore-steel"
    return sphere, named[pair]


@pytest.mark.parametrize("plate, v0", [("steel", 0.05), ("ore", 0.2)])
def test_a_rolling_sphere_stops_where_its_rolling_coefficient_says(scene, plate, v0):
    """Rolling without slip under a constant moment mu_r m g R: (m + I / R^2) dv/dt = -mu_r m g,
    so it stops after d = 7 v0^2 / (10 mu_r g) (0.0178 m for the particle-steel 0.01 at
    0.05 m/s; 0.0106 m for the particle-particle 0.27 at 0.2 m/s)."""
    sphere, mu = _rolling_sphere(scene, plate, v0)
    expected = 7.0 * v0**2 / (10.0 * mu * G)
    limit = 3.0 * v0 / (5.0 / 7.0 * mu * G) / scene.dt          # three times the stopping time
    steps = 0
    while sphere.state.vel[0] > 0.0 and steps < limit:   # (it moves < 1e-6 m in a chunk's end)
        scene.run(200, True)
        steps += 200
    assert sphere.state.vel[0] <= 0.0, "still rolling after three times its stopping time"
    travelled = sphere.state.pos[0]
    assert travelled == pytest.approx(expected, rel=0.02)
    # it rolled: no slip at the contact while it slowed down
    assert abs(sphere.state.angVel[1] * sphere.shape.radius - sphere.state.vel[0]) < 0.02 * v0


def test_without_rolling_friction_it_rolls_on(scene):
    """The same sphere without the part (the engines before issue 18) keeps its speed: what the
    test above measures is the rolling friction."""
    from yadebreak import scenes
    sphere, mu = _rolling_sphere(scene, "steel", 0.05)
    loop = next(e for e in scene.engines if type(e).__name__ == "InteractionLoop")
    scene.engines = scenes.hertz_engines(loop.physDispatcher.functors[0],
                                         gravity=(0.0, 0.0, -G))
    stop_steps = 0.05 / (5.0 / 7.0 * mu * G) / scene.dt
    scene.run(int(stop_steps), True)
    assert sphere.state.vel[0] == pytest.approx(0.05, rel=1e-3)


def test_each_pair_of_a_bed_gets_its_own_coefficient(scene):
    """A monolayer bed hit by the ball: every real contact has its pair's mu_r (particle-particle
    0.27, particle-steel 0.01 from the files; 0.33 where --steel-rolling-friction replaces it),
    capped at mu_r F_n R with R the smaller sphere's radius, and a rolling stiffness."""
    from yade import O
    from yadebreak import engine, scenes
    for steel, expected_steel in ((None, 0.01), (0.33, 0.33)):
        engine.forget()
        brk, info = scenes.bed_impact_scene(rings=1, energy=1.0, steel_rolling_friction=steel,
                                            read_period=1)
        assert info["rolling_friction"] == {"particle_particle": 0.27,
                                            "particle_steel": expected_steel}
        engine.run_steps(3000)
        seen = {"ore-ore": [], "ore-steel": []}
        for i in O.interactions:
            if not i.isReal:
                continue
            steel_pair = O.bodies[i.id1].material.label == "steel" or \
                O.bodies[i.id2].material.label == "steel"
            radius = min(r for r in (i.geom.refR1, i.geom.refR2) if r > 0)
            seen["ore-steel" if steel_pair else "ore-ore"].append(
                (i.phys.maxBendPl / radius, i.phys.kr))
        assert seen["ore-ore"] and seen["ore-steel"]      # the ball and the anvil touch
        for pair, mu in (("ore-ore", 0.27), ("ore-steel", expected_steel)):
            values = np.array(seen[pair])
            assert values[:, 0] == pytest.approx(mu, rel=1e-12), pair
            assert (values[:, 1] > 0).all(), pair
