"""Coupling part 1: stressing energy, partition, damage, reproducibility, save/load (YADE)."""
import math

import numpy as np
import pytest

from yadebreak import load_material, model

pytestmark = pytest.mark.yade


def _unbreakable(brk, ids):
    for i in ids:
        brk.bodies[i].fracture_energy = 1e12


@pytest.mark.parametrize("target_restitution", [0.39, 0.9])
def test_wall_impact_receives_e_m_v2_over_2(scene, tmp_path, target_restitution):
    from yadebreak import scenes
    text = (load_material("copper_ore").source and
            open(load_material("copper_ore").source).read())
    path = tmp_path / "ore.toml"
    path.write_text(text.replace("restitution = 0.39", f"restitution = {target_restitution}"))
    speeds = [1.0, 5.0, 20.0]
    brk, ids = scenes.impact_scene(str(path), 5.5e-3, speeds=speeds, target="steel",
                                   time_step_fraction=0.05, emin=0.0, read_period="every_step")
    _unbreakable(brk, ids)
    scenes.run_until_rebound(ids)
    e = load_material(str(path)).energy_partition(load_material("steel"))
    got = {ev["id"]: ev["specific_energy"] for ev in brk.events if ev["kind"] == "damage"}
    assert sorted(got) == sorted(ids)
    for i, v in zip(ids, speeds):
        assert got[i] == pytest.approx(e * v * v / 2, rel=0.015)


def test_two_equal_spheres_receive_half_each(scene):
    from yade import O, utils
    from yadebreak import engine, scenes
    ip2, _ = engine.add_materials({"ore": "copper_ore"})
    r, v = 2.75e-3, 3.0
    a = O.bodies.append(utils.sphere((0, 0, 0), r, material="ore"))
    b = O.bodies.append(utils.sphere((2 * r * 1.01, 0, 0), r, material="ore"))
    O.bodies[a].state.vel = (v, 0, 0)
    O.bodies[b].state.vel = (-v, 0, 0)
    O.engines = scenes.hertz_engines(ip2)
    brk = engine.attach({"ore": "copper_ore"}, seed=1, emin=0.0, read_period="every_step")
    _unbreakable(brk, [a, b])
    O.run(3000, True)
    m = O.bodies[a].state.mass
    kinetic_loss = 2 * 0.5 * m * v * v        # both stop in the centre-of-mass frame
    ev = {e["id"]: e for e in brk.events if e["kind"] == "damage"}
    for i in (a, b):
        assert ev[i]["specific_energy"] * m == pytest.approx(0.5 * kinetic_loss, rel=0.015)


def test_subcritical_impact_weakens_by_eqs_5_6(scene):
    from yadebreak import scenes
    brk, ids = scenes.impact_scene("copper_ore", 5.5e-3, speeds=[4.0], seed=3)
    st = brk.bodies[ids[0]]
    st.fracture_energy = st.fracture_energy_initial = 50.0       # well above e v^2/2 = 6.4 J/kg
    scenes.run_until_rebound(ids)
    (ev,) = [e for e in brk.events if e["kind"] == "damage"]
    ratio = ev["specific_energy"] / 50.0
    expected = model.weakened_fracture_energy(50.0, ratio, load_material("copper_ore").params.gamma)
    assert ev["fracture_energy_after"] == pytest.approx(float(expected), rel=1e-12)
    assert st.fracture_energy == pytest.approx(float(expected), rel=1e-12)
    assert st.damage == pytest.approx(1 - expected / 50.0, rel=1e-12)
    assert brk.body_state(ids[0])["fracture_energy"] == st.fracture_energy


def _events_for(seed, steps_before=None, tmp_path=None, material="limestone", read_period=1):
    from yade import O
    from yadebreak import engine, scenes
    speeds = list(np.linspace(3, 30, 24))
    brk, ids = scenes.impact_scene(material, 5.5e-3, speeds=speeds, seed=seed, replace=False,
                                   read_period=read_period)
    if steps_before is not None:
        O.run(steps_before, True)
        path = str(tmp_path / "mid.yade.gz")
        engine.save(path)                # O.save with yadebreak's state
        O.run(137, True)                   # wander on, then come back to the saved state
        engine.forget()                  # as in a new process
        O.load(path)
    O.run(1500 - (steps_before or 0), True)
    brk = engine.controller_of()
    return [(e["kind"], e["id"], e["iter"], round(e["specific_energy"], 9),
             round(e["fracture_energy"], 9)) for e in brk.events]


@pytest.mark.parametrize("material, read_period", [("limestone", 1), ("ab_t10_ore", 1),
                                                   ("limestone", "fast")])
def test_same_seed_same_events_and_save_load_continues(scene, tmp_path, material, read_period):
    first = _events_for(7, material=material, read_period=read_period)
    again = _events_for(7, material=material, read_period=read_period)
    other = _events_for(8, material=material, read_period=read_period)
    assert first == again
    assert first != other
    assert any(k == "breakage" for k, *_ in first) and any(k == "damage" for k, *_ in first)
    resumed = _events_for(7, steps_before=310, tmp_path=tmp_path, material=material,
                          read_period=read_period)
    assert resumed == first


def test_event_log_written_as_it_goes(scene, tmp_path):
    import json
    from yade import O
    from yadebreak import scenes
    log = tmp_path / "events.jsonl"
    brk, ids = scenes.impact_scene("limestone", 5.5e-3, speeds=[30.0, 2.0], event_log=str(log))
    O.run(5000, True)
    lines = [json.loads(x) for x in log.read_text().splitlines()]
    assert len(lines) == len(brk.events) >= 2
    assert {e["kind"] for e in lines} >= {"breakage", "damage"}
    for key in ("kind", "iter", "time", "id", "radius", "mass", "specific_energy", "fracture_energy"):
        assert key in lines[0]


def test_body_state_and_tags(scene):
    from yade import O
    from yadebreak import scenes
    brk, ids = scenes.impact_scene("granulite", 5.5e-3, speeds=[1.0])
    st = brk.body_state(ids[0])
    assert st["kind"] == "breakable" and st["damage"] == 0.0 and st["specific_energy"] == 0.0
    assert brk.bodies[ids[0]].fracture_energy == st["fracture_energy"]
    assert not hasattr(O.bodies[ids[0]], "breakage")       # nothing set on YADE's own objects
    assert "yadebreak:yadebreak" in O.tags.keys()


@pytest.mark.parametrize("material, energy", [("copper_ore", 150.0), ("copper_ore", 400.0),
                                              ("limestone", 60.0)])
def test_single_impact_broken_fraction_within_3_binomial_sigma(scene, material, energy):
    from yadebreak import scenes
    n = 250
    speed = (2 * energy) ** 0.5
    brk, ids = scenes.impact_scene(material, 5.5e-3, speeds=[speed] * n, seed=11, replace=False)
    scenes.run_until_rebound(ids)
    broken = {e["id"] for e in brk.breakage_events}
    fraction = len(broken & set(ids)) / n
    mat = load_material(material)
    p = float(mat.breakage_probability(energy, 5.5e-3, partner=load_material("steel")))
    sigma = math.sqrt(p * (1 - p) / n)
    assert 0.05 < p < 0.95
    assert abs(fraction - p) <= 3 * sigma


def test_repeated_impacts_follow_the_damage_model(scene):
    """Paper Fig. 11: the broken fraction after each impact against the model's twin (Eqs. 1-6),
    within 3 binomial sigma at every impact (200 particles, fixed seed)."""
    from yade import O
    from yadebreak import scenes
    mat = load_material("copper_ore")
    n, impacts, energy, size = 200, 6, 94.7, 37.5e-3
    speed = math.sqrt(2 * energy)
    brk, ids = scenes.impact_scene(mat, size, [speed] * n, seed=21, replace=False)
    home = {i: tuple(O.bodies[i].state.pos) for i in ids}
    alive = list(ids)
    got = []
    for _ in range(impacts):
        alive = scenes.impact_again(brk, alive, home, speed)
        got.append(1 - len(alive) / n)
    share = mat.energy_partition(load_material("steel"))
    expected = model.repeated_impact_broken_fraction(
        share * energy, float(mat.median_fracture_energy(size)), mat.params.sigma, mat.params.emax_ratio,
        mat.params.gamma, impacts)
    sigma = np.sqrt(expected * (1 - expected) / n)
    assert np.all(np.abs(np.array(got) - expected) <= 3 * sigma)
    assert got[-1] > 2 * got[0]             # damage matters: later impacts break more
