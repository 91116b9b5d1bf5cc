"""attach(contact_energy_at_break="carried"): the elastic energy a broken sphere's contacts hold is
counted as Ek' already absorbed by the fragments that take those contacts over (the paper's
Section 1: successive events "if there is still energy remaining in the contact after the
primary breakage event"). It moves no body: the scene is the same as under "dropped" (the
paper's zeroing) until a decision differs."""
import math

import numpy as np
import pytest

from yadebreak import load_material, model
from yadebreak.criteria import criterion_for
from yadebreak.engine import judging
from yadebreak.engine.contacts import ContactReader, Loading
from yadebreak.engine.state import BREAKABLE, EngineState

ENERGY = 1000.0                  # J/kg: a 29 mm copper ore particle breaks at its first impact


def _first_breakage(mode):
    from yadebreak.adapter.yade_api import O
    from yadebreak.scenes.impacts import impact_scene
    brk, ids = impact_scene("copper_ore", 0.029, [math.sqrt(2 * ENERGY)], seed=3,
                            read_period="every_step", time_step_fraction=0.02, emax_ratio=4.0,
                            contact_energy_at_break=mode)
    while not brk.breakage_events and O.iter < 20000:
        O.run(1, True)
    event = brk.breakage_events[0]
    frags = event["fragments"]
    state = [(tuple(O.bodies[i].state.pos), tuple(O.bodies[i].state.vel)) for i in frags]
    carried = brk.state.table.columns["carried"][frags].copy()
    young = {m.label: (m.young, m.poisson) for m in O.materials}
    return event, state, carried, young, frags, brk


def test_the_walls_share_of_the_elastic_energy_goes_to_the_nearest_fragment_and_nothing_moves():
    dropped, state_d, carried_d, _, _, _ = _first_breakage("dropped")
    event, state_c, carried, young, frags, brk = _first_breakage("carried")
    # the same breakage, the same fragments where they were, moving as they were
    assert event["iter"] == dropped["iter"] and event["t10"] == dropped["t10"]
    assert state_c == state_d
    assert not carried_d.any()
    # one contact (the plate): the particle's share (Eq. 4, from the scene's own moduli) of its
    # elastic energy, to the one fragment nearest the plate (none overlaps it)
    (yp, nup), (yt, nut) = young["particle"], young["target"]
    share = float(model.energy_partition(yp / (1 - nup ** 2), yt / (1 - nut ** 2)))
    assert share == pytest.approx(0.806, abs=1e-3)
    assert event["carried_energy"] == pytest.approx(share * event["elastic_energy_before"],
                                                    rel=1e-12)
    assert carried.sum() == pytest.approx(event["carried_energy"], rel=1e-12)
    taker = frags[int(np.argmax(carried))]
    assert np.count_nonzero(carried) == 1
    from yadebreak.adapter.yade_api import O
    lowest = min(frags, key=lambda i: O.bodies[i].state.pos[2] - O.bodies[i].shape.radius)
    assert taker == lowest
    assert brk.state.table.kind_of(taker) in ("dummy", "breakable", "unbreakable")


@pytest.mark.parametrize("path", ("plan_each", "plan_all"))
def test_carried_energy_counts_in_the_event_breaks_past_the_fracture_energy_and_ends_with_it(path):
    """Ek' = the contacts' work plus the carried energy: below m E the event opens and, once
    unloaded, damages the body with that Ek' (Eqs. 5-6) and forgets the carried energy; above,
    the body breaks with Ek' = both."""
    cu = load_material("copper_ore")
    mass, energy = 2e-3, 400.0                          # kg, J/kg
    for carried, loaded, breaks in ((0.3, 0.0, False), (0.7, 0.5, True)):
        st = EngineState(["ore"], 0)
        st.table.add([0], BREAKABLE, "ore", mass, 5e-3, fracture_energy=energy,
                     fracture_energy_initial=energy)
        st.tracked.add(0)
        st.open_events.add(0)
        st.table.columns["carried"][0] = carried * energy * mass
        judge = judging.Judge(st, [criterion_for(cu)], ContactReader({}, 0.0, 1e-4),
                              judging.Rules(1.0, 0.02, carried=True))
        judge.small = 24 if path == "plan_each" else 0
        loading = Loading({0: loaded * energy * mass} if loaded else {})
        broken, _ = judge.judge(loading, 1, 0, False)
        if breaks:
            assert broken and broken[0][1] == pytest.approx(1.2 * energy * mass)
            continue
        assert not broken and st.table.columns["event_max"][0] == pytest.approx(0.3 * energy * mass)
        judge.judge(Loading({}), 1, 1, False)          # unloaded: the event ends
        c = st.table.columns
        assert 0 not in st.open_events and c["carried"][0] == 0.0
        after = float(model.weakened_fracture_energy(energy, 0.3, cu.params.gamma))
        assert c["fracture_energy"][0] == pytest.approx(after, rel=1e-12)
