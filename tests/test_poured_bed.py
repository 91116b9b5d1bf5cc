"""Poured multi-layer beds (issue 18, poured_bed.py): particles poured into the holder settle at
rest inside it, the settled bed is cached (the second run loads it, identical), and the run
reports how the bed was built, its motion at the ball's touch and the rolling friction used."""
import argparse

import numpy as np
import pytest

pytestmark = pytest.mark.yade

SIZE = 5.5e-3


def _bed(cache, **kw):
    from yadebreak import engine, scenes
    engine.forget()
    return scenes.bed_impact_scene(rings=1, layers=3, energy=1.0, bed_cache=str(cache), **kw)


def test_a_poured_bed_settles_at_rest_inside_its_holder_and_is_cached(scene, tmp_path):
    from yade import O
    from yadebreak.scenes import poured_bed
    from yadebreak import scenes
    brk, info = _bed(tmp_path)
    settled = info["settled"]
    n = len(info["particles"])
    assert info["packing"] == "poured" and not settled["cached"]
    assert n == len(scenes.hex_bed_positions(SIZE, 1, 3))          # the lattice's count
    mass = O.bodies[info["particles"][0]].state.mass
    assert settled["kinetic_energy"] < poured_bed.REST_FRACTION * n * mass * 9.81 * SIZE
    pos = np.array([tuple(O.bodies[i].state.pos) for i in info["particles"]])
    reach = np.max(np.linalg.norm(scenes.hex_bed_positions(SIZE, 1, 3)[:, :2], axis=1))
    holder_radius = reach + 0.52 * SIZE
    # inside the holder, resting on the anvil, pressed by gravity only (overlaps < 0.1 % of d)
    assert np.all(np.linalg.norm(pos[:, :2], axis=1) <= holder_radius - SIZE / 2 + 1e-5)
    assert pos[:, 2].min() == pytest.approx(SIZE / 2, rel=1e-3)
    gaps = np.linalg.norm(pos[:, None] - pos[None], axis=2)[np.triu_indices(n, 1)] - SIZE
    assert gaps.min() > -1e-3 * SIZE
    # a bed of three layers' worth: higher than two layers
    assert settled["height"] > 2 * SIZE
    again_brk, again = _bed(tmp_path)
    assert again["settled"] == {**settled, "cached": True}
    again_pos = np.array([tuple(O.bodies[i].state.pos) for i in again["particles"]])
    assert np.array_equal(again_pos, pos)
    assert O.time == 0.0 and O.iter == 0


def test_poured_only_for_several_layers(scene, tmp_path):
    from yadebreak import scenes
    with pytest.raises(ValueError, match="'poured' for beds of 2 layers or more"):
        scenes.bed_impact_scene(rings=1, layers=1, packing="poured", bed_cache=str(tmp_path))


def test_the_run_reports_its_bed_and_rolling_friction(scene, tmp_path):
    """summary.json: bed_packing, the bed's kinetic energy at the ball's touch (a settled bed is
    at rest: below 1e-6 of the impact energy) and the rolling friction of each pair. The run
    stops at 25 ms, after the ball's touch (23 ms) and its first breakages: the time step falls
    twentyfold with the fragments, and the rest of the run (1.2 million steps to its end, 82 s)
    would add nothing here; a poured bed's run to its end is the Fig. 22 test's."""
    from yadebreak.jobs import bed
    args = argparse.Namespace(material="copper_ore", size=SIZE, rings=1, layers=3, energy=1.0,
                              speed=0.0, seed=1, time_step_fraction=0.05, dmin=0.0,
                              global_damping="material", dummies="ledger", read_period="fast",
                              max_time=0.025, out=str(tmp_path / "run"), packing="auto",
                              rolling_friction=True, steel_rolling_friction=0.33,
                              bed_cache=str(tmp_path / "cache"))
    brk, summary = bed.run(args, quiet=True)
    assert summary["bed_packing"] == "poured"
    assert summary["rolling_friction"] == {"particle_particle": 0.27, "particle_steel": 0.33}
    assert 0.0 <= summary["bed_kinetic_energy_at_touch"] < 1e-6 * summary["energy"]
    assert summary["end_reason"] == "time_limit" and summary["breakage_events"] > 0
    assert summary["final_mass"] == pytest.approx(summary["initial_mass"], rel=1e-9)


def _run(tmp_path, name, **kw):
    from yade import O
    from yadebreak.jobs import bed
    from yadebreak import engine
    engine.forget()
    O.reset()
    values = dict(material="copper_ore", size=SIZE, rings=2, layers=1, energy=1.0, speed=0.0,
                  seed=1, time_step_fraction=0.05, dmin=0.0, global_damping="material",
                  dummies="ledger", read_period="fast", max_time=0.05, out=str(tmp_path / name),
                  packing="auto", rolling_friction=True, steel_rolling_friction=-1.0,
                  bed_cache=str(tmp_path / "cache"))
    values.update(kw)
    return bed.run(argparse.Namespace(**values), quiet=True)[1]


def _passing(summary_folder, size):
    table = np.loadtxt(summary_folder / "size_distribution.csv", delimiter=",", skiprows=1)
    return float(np.interp(np.log(size), np.log(table[:, 0]), table[:, 1]))


def test_more_energy_captures_more_particles_and_breaks_them_finer(scene, tmp_path):
    """Paper Figs. 20-21 on a monolayer of 2 rings of copper ore: from 1.39 J to 8.69 J (the
    ball at 1.0 and 2.5 m/s) the capture radius grows and the product gets finer, at the feed's
    lower sieve (4.75 mm) and at a tenth of the size."""
    # dmin = size / 5: fragments finer than that do not break again (4.8x faster; the trend
    # holds: the unbreakable fragments' Eq. 10 fines follow their t10')
    low = _run(tmp_path, "low", energy=1.39, dmin=SIZE / 5)
    high = _run(tmp_path, "high", energy=8.69, dmin=SIZE / 5)
    assert high["capture_radius"] > low["capture_radius"]
    for sieve in (4.75e-3, SIZE / 10):
        assert _passing(tmp_path / "high", sieve) > _passing(tmp_path / "low", sieve), sieve


def test_copper_ore_breaks_less_mass_on_a_multi_layer_bed(scene, tmp_path):
    """Paper Fig. 22 and its text: for copper ore, less broken mass on beds of several layers
    than on the monolayer (the ball loses momentum penetrating the layers). Small configuration:
    2 rings, one layer (19 particles) against a poured bed of 3 layers (47), 3.05 J, seed 1."""
    mono = _run(tmp_path, "mono", energy=3.05, dmin=SIZE / 5)    # as above: the same for both
    multi = _run(tmp_path, "multi", energy=3.05, layers=3, dmin=SIZE / 5)
    assert multi["bed_packing"] == "poured" and multi["end_reason"] == "finished"
    assert multi["broken_mass"] < mono["broken_mass"]
