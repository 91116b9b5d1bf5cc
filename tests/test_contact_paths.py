"""The contact reader's two paths (contact by contact on Python scalars, over YADE's list of real
interactions, for a few contacts; numpy over the rows kept, with new contacts looked for only
around the bodies whose count of interactions changed, for many) read the same scene alike: the
same contacts with the same numbers bit for bit, the same energies (to round-off: the rows are
summed in another order), strongest contacts and growing bodies, through impacts, breakage,
zeroed and sleeping pairs and inherited contacts, with and without shear work. The numpy path
reads alike whether it looks every row up in the zeroed and sleeping pairs or follows the pairs
the zeroing changed, and tells what bodies' contacts hold as the scalar path does. The physics
both call (HertzMindlinWork, own_share) is tested on closed forms in test_engine_parts.py."""
import numpy as np
import pytest

pytestmark = pytest.mark.yade


def _same_loading(x, y):
    assert x.energy.keys() == y.energy.keys() and x.grew == y.grew
    for body, energy in x.energy.items():
        assert y.energy[body] == pytest.approx(energy, rel=1e-12, abs=1e-300)
        px, py = x.strongest.partner(body), y.strongest.partner(body)   # before get() makes it
        sx, sy = x.strongest.get(body), y.strongest.get(body)
        assert (sx is None) == (sy is None)
        assert px == py == (-1 if sx is None else sx.other)
        if sx is not None:
            assert sx[0] == sy[0] and sx[2:] == sy[2:] and tuple(sx[1]) == tuple(sy[1])


def _rows(reader):
    """{(id1, id2): the contact's numbers}"""
    return {(a, b): tuple(v) for a, b, v in zip(reader.table.a.tolist(), reader.table.b.tolist(),
                                                reader.table.data.T.tolist())}


@pytest.mark.parametrize("cs", [0.0, 0.5])
def test_both_paths_read_a_breaking_bed_alike(scene, cs):
    from yadebreak.adapter.yade_api import interaction_counts
    from yadebreak import engine, scenes
    from yadebreak.engine.contacts import ContactReader
    brk, info = scenes.bed_impact_scene("copper_ore", 5.5e-3, 3, 1, 6.0, seed=4, read_period=1,
                                        dummies="spheres", cs=cs)
    O = scene
    each, full, kept = (ContactReader(brk.reader.stiffness, cs, brk.reader.emin)
                        for _ in range(3))
    each.small, full.small, kept.small = 10 ** 9, -1, -1
    # `kept` is told the pairs the zeroing changed since its last read (ZeroedRows follows them),
    # `full` looks every row up in the zeroed and asleep pairs at every read
    zeroed_then, asleep_then, changes, held, knos_kept = set(), set(), 0, 0, 0
    while not any(O.interactions.withBody(info["ball"])):
        engine.run_steps(50)
    scenes.hold_release(info)
    reads = 0
    seen = {"zeroed": 0, "asleep": 0, "inherited": 0}
    for step in range(4000):
        O.step()
        for r in (each, full, kept):      # what the engine told its reader since the last step
            r.inherited |= brk.reader.inherited
            r.erased_bodies |= brk.reader.erased_bodies
        for what, pairs in (("zeroed", brk.zeroing.pairs), ("asleep", brk.zeroing.asleep),
                            ("inherited", brk.reader.inherited)):
            seen[what] = max(seen[what], len(pairs))
        if step % 3:                         # every third step: sparse reads and peaks too
            continue
        state = brk.state
        args = (O.interactions, O.bodies, state.tracked, brk.zeroing.pairs, O.time, 3,
                brk.zeroing.asleep, interaction_counts)
        zeroed_now, asleep_now = set(brk.zeroing.pairs), set(brk.zeroing.asleep)
        changed = (zeroed_now ^ zeroed_then) | (asleep_now ^ asleep_then)
        zeroed_then, asleep_then = zeroed_now, asleep_now
        by_full = full.read(*args)
        _same_loading(each.read(*args), by_full)
        assert _rows(each) == _rows(full)
        _same_loading(kept.read(*args, zeroing_changes=changed), by_full)
        assert _rows(kept) == _rows(full)
        changes += len(changed)
        for r in (full, kept):   # a row's kno kept from its first numpy read is YADE's still
            t = r.table
            assert t.kno_of(np.arange(len(t))).tolist() == [p.kno for p in t.physs]
            knos_kept += int(np.isfinite(t._kno).sum())
        # what a body's contacts hold, asked for many bodies at once or body by body
        asked = sorted(full.bodies_in_contact() & state.tracked)
        at_once = full.stored_shares(asked)
        assert at_once == pytest.approx([each.stored_share(i) for i in asked], rel=1e-12,
                                        abs=1e-300)
        held += sum(x > 0.0 for x in at_once)
        reads += 1
    assert brk.breakage_events, "the bed must break for the comparison to mean something"
    assert min(seen.values()) > 10, seen    # zeroed, sleeping and inherited pairs were read
    assert len(full) > 0 and reads > 1000 and changes > 100 and held > 1000 and knos_kept > 1000


def test_interaction_counts_are_yades_below_and_above_256(scene):
    """adapter.yade_api.interaction_counts gives YADE's numIntrsOfEachBody as an array: through
    bytes while every count is below 256 (spheres touching their neighbours), through fromiter
    once a body has more (a wall under 300 spheres)."""
    from yade import utils
    from yade.wrapper import (Bo1_Sphere_Aabb, Bo1_Wall_Aabb, ForceResetter,
                              Ig2_Sphere_Sphere_ScGeom, Ig2_Wall_Sphere_ScGeom,
                              InsertionSortCollider, InteractionLoop,
                              Ip2_FrictMat_FrictMat_FrictPhys, Law2_ScGeom_FrictPhys_CundallStrack,
                              NewtonIntegrator)
    from yadebreak.adapter.yade_api import interaction_counts
    O = scene
    O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
                 InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],
                                 [Ip2_FrictMat_FrictMat_FrictPhys()],
                                 [Law2_ScGeom_FrictPhys_CundallStrack()]),
                 NewtonIntegrator()]
    wall = O.bodies.append(utils.wall(0.0, axis=2))
    O.bodies.append([utils.sphere((1.9 * i, 1.9 * j, 0.9), 1.0)
                     for i in range(20) for j in range(15)])
    O.dt = 1e-8
    O.step()
    counts = interaction_counts()
    assert counts[wall] == 300 and counts.dtype == np.int64
    assert counts.tolist() == utils.numIntrsOfEachBody()
    O.bodies.erase(wall)
    O.step()
    counts = interaction_counts()
    assert counts.dtype == np.uint8 and counts[wall] == 0 and counts.max() == 4
    assert counts.tolist() == utils.numIntrsOfEachBody()


def test_many_contacts_saved_and_loaded_read_on_as_the_run_that_went_on(scene, tmp_path):
    """A scene read by the numpy path (a bed of many particles pressed by a heavy ball), saved
    with yadebreak.save mid-impact and loaded: its rows find YADE's objects again and the run
    goes on to the same contacts, numbers and events as the run that was never interrupted."""
    from yadebreak import engine, scenes
    O = scene

    brk, info = scenes.bed_impact_scene("copper_ore", 5.5e-3, 4, 3, 6.0, seed=3,
                                        packing="lattice", read_period="every_step")
    while not any(O.interactions.withBody(info["ball"])):
        engine.run_steps(50)
    scenes.hold_release(info)
    engine.run_steps(300)
    assert len(brk.reader) > brk.reader.small          # the numpy path reads this scene
    engine.save(tmp_path / "mid.yade.gz")
    engine.run_steps(400)
    went_on = (_rows(brk.reader), [dict(e) for e in brk.events])
    O.reset()
    engine.forget()
    O.load(str(tmp_path / "mid.yade.gz"))
    engine.run_steps(400)
    brk = engine.controller_of()
    rows, events = _rows(brk.reader), [dict(e) for e in brk.events]
    # YADE's save and load keep the scene to round-off (the regression cases' 1e-9)
    assert rows.keys() == went_on[0].keys()
    for key, numbers in rows.items():
        np.testing.assert_allclose(numbers, went_on[0][key], rtol=1e-9, atol=1e-300)
    assert [(e["kind"], e["id"], e["iter"]) for e in events] == \
        [(e["kind"], e["id"], e["iter"]) for e in went_on[1]]
    for e, f in zip(events, went_on[1]):
        assert e["specific_energy"] == pytest.approx(f["specific_energy"], rel=1e-9)
