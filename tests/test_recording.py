"""attach(breakage=False): the collision spectra of a scene. Nothing breaks or weakens; every
stressing event is logged as 'stressing' with the energy the breakage run would judge."""
import numpy as np
import pytest

from yadebreak import load_material

pytestmark = pytest.mark.yade


def _impacts(breakage, speeds):
    from yadebreak import engine, scenes
    from yadebreak.adapter.yade_api import O
    brk, ids = scenes.impact_scene("copper_ore", 5.5e-3, speeds=speeds, emin=0.0, seed=4,
                                   breakage=breakage)
    before = {i: brk.bodies[i].fracture_energy for i in ids}
    bodies = len(O.bodies)
    engine.run_steps(2000)
    return brk, ids, before, bodies, len(O.bodies)


def test_a_recording_run_logs_each_impact_at_e_v2_over_2_and_breaks_nothing(scene):
    """Copper ore on steel at 1-100 m/s (0.2 to 2,400 J/kg absorbed, most of these particles
    break in a breakage run): one 'stressing' event per particle at the absorbed energy of
    Eq. 4, e v^2 / 2, within 3 % (the same bound as the breakage run's damage events,
    tests/test_fast.py), and every body as it was."""
    speeds = [1.0, 5.0, 20.0, 50.0, 100.0]
    brk, ids, before, bodies, after = _impacts(False, speeds)
    e = load_material("copper_ore").energy_partition(load_material("steel"))
    events = {ev["id"]: ev for ev in brk.events}
    assert {ev["kind"] for ev in brk.events} == {"stressing"} and len(brk.events) == len(ids)
    for i, v in zip(ids, speeds):
        assert events[i]["specific_energy"] == pytest.approx(e * v * v / 2, rel=0.03)
        assert brk.bodies[i].fracture_energy == before[i] and brk.bodies[i].damage == 0.0
    assert after == bodies and not brk.breakage_events
    # the same particles in a breakage run: those whose fracture energy is below e v^2 / 2 break
    ratio = np.array([events[i]["specific_energy"] / before[i] for i in ids])
    assert ratio.max() > 1.0 > ratio.min()             # the case does span the threshold
    brk2, ids2, before2, _, _ = _impacts(True, speeds)
    assert before2 == {j: before[i] for i, j in zip(ids, ids2)}      # the same draws
    broke = {e2["id"] for e2 in brk2.breakage_events if e2["id"] in ids2}   # not fragments
    assert broke == {j for i, j in zip(ids, ids2) if events[i]["ratio"] > 1.0}
