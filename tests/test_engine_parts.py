"""The engine's parts without YADE (issue 14): options, body state, event log and ledger with their
save/restore round trips, both criteria on scripted loading histories, and the judge's two paths
(body by body and with numpy) giving the same decisions."""
import json
import math

import numpy as np
import pytest

from yadebreak import load_material, model
from yadebreak.engine import judging
from yadebreak.options import table as config
from yadebreak import criteria
from yadebreak.engine.contacts import ContactReader, Loading, Strongest
from yadebreak.engine.state import (BREAKABLE, DUMMY, FORMAT_VERSION, UNBREAKABLE, BodyTable,
                                      EngineState, EventLog, FinesLedger, SHARED_COLUMNS,
                                      assembled_columns, check_format)


# -- options ----------------------------------------------------------------------------------
def test_options_are_grouped_with_their_defaults():
    cfg = config.Config.from_options(seed=3, read_period="fast", dummies="ledger")
    assert cfg.reading.read_period == "fast" and cfg.replacement.dummies == "ledger"
    assert cfg.reading.emin == 1e-4 and cfg.time_step.time_step_fraction == 0.05
    assert config.Config.from_options(**cfg.as_options()) == cfg


@pytest.mark.parametrize("option, text", [
    (dict(emin=-1.0), "emin = -1.0 J: accepted >= 0"),
    (dict(cs=2), "cs = 2: accepted [0, 1]"),
    (dict(read_period=0), "read_period = 0 steps: accepted 'fast', 'every_step', an integer >= 1 "
                          "or 'auto'"),
    (dict(dmin=0.0), "dmin = 0.0 m: accepted (0, 1] or None"),
    (dict(global_damping_time=math.nan), "global_damping_time = nan s: accepted >= 0"),
])
def test_a_bad_option_names_itself_its_value_range_and_unit(option, text):
    with pytest.raises(config.AttachError, match="bad option") as err:
        config.Config.from_options(**option)
    assert text in str(err.value)


def test_every_option_is_documented_from_the_table():
    doc = config.options_markdown()
    assert all(f"`{o.name}`" in doc for o in config.OPTIONS)


# -- state ------------------------------------------------------------------------------------
def _state():
    st = EngineState(["ore", "rock"], seed=5, event_log=None)
    st.table.add([3, 4, 7], BREAKABLE, "ore", [1e-3, 2e-3, 3e-3], [1e-3, 2e-3, 3e-3],
                 fracture_energy=[100.0, 200.0, 300.0], fracture_energy_initial=[100.0, 200, 300])
    st.table.add([9], DUMMY, "rock", 1e-4, 2e-4, t10=5.0, parent_size=4e-3)
    st.tracked.update([3, 4, 7])
    st.open_events.add(4)
    st.table[4].event_max = 0.05
    st.ledger.add(2e-5, 4e-3, 6.0, "ore", (1e-5, 0.0, -2e-5))
    st.log.record({"kind": "damage", "id": 3, "specific_energy": 12.5})
    st.warned.add("jump")
    return st


def test_body_rows_read_and_write_their_columns():
    st = _state()
    row = st.table[7]
    assert row.kind == "breakable" and row.material == "ore" and row.fracture_energy == 300.0
    row.fracture_energy = 250.0
    assert st.table.columns["fracture_energy"][7] == 250.0
    assert st.table[9].kind == "dummy" and math.isinf(st.table[9].fracture_energy)
    assert math.isnan(st.table[3].t10) and 5 not in st.table and len(st.table) == 4
    with pytest.raises(KeyError):
        st.table[5]


def test_state_round_trip_continues_the_same_random_stream():
    st = _state()
    st.rng.random(3)
    data = json.loads(json.dumps(st.to_dict()))               # as stored in O.tags
    back = EngineState.from_dict(data)
    assert back.to_dict() == st.to_dict()
    assert back.rng.random(4).tolist() == st.rng.random(4).tolist()
    assert back.open_events == {4} and back.tracked == {3, 4, 7}
    assert back.table[9].kind == "dummy" and back.table[9].parent_size == 4e-3
    assert back.total_mass() == st.total_mass() == pytest.approx(1e-3 + 2e-3 + 3e-3 + 1e-4 + 2e-5)


def test_the_body_table_holds_the_columns_its_criteria_declare():
    """Each criterion declares its per-body columns (Criterion.columns) and the table assembles
    them: a Tavares scene keeps none of Ab-T10's; a state saved with more columns (an older
    version kept every criterion's) restores into the table of the criteria present."""
    cu, ab = (load_material(n).criterion for n in ("copper_ore", "ab_t10_ore"))
    assert set(assembled_columns([cu])) == set(SHARED_COLUMNS)
    both = assembled_columns([cu, ab])
    assert set(both) == set(SHARED_COLUMNS) | set(ab.columns) == set(assembled_columns([ab]))
    st = EngineState(["ore"], 0, columns=both)
    st.table.add([2], BREAKABLE, "ore", 1e-3, 1e-3, e_cum=7.5)
    data = json.loads(json.dumps(st.to_dict()))
    assert EngineState.from_dict(data, columns=both).table[2].e_cum == 7.5
    tavares_only = EngineState.from_dict(data, columns=assembled_columns([cu])).table
    assert "e_cum" not in tavares_only.columns and tavares_only[2].mass == 1e-3
    with pytest.raises(ValueError, match="column 'e_cum'"):
        assembled_columns([ab, type("Other", (), {"columns": {"e_cum": (np.int8, 0)}})()])


def test_saved_state_of_another_format_is_refused_with_its_version():
    data = _state().to_dict()
    data["format_version"] = FORMAT_VERSION + 1
    with pytest.raises(ValueError, match=f"format version {FORMAT_VERSION + 1}"):
        check_format(data)


def test_ledger_carries_mass_and_kinetic_energy():
    ledger = FinesLedger()
    ledger.add(2.0, 1e-3, 5.0, "ore", (2.0, 0.0, 0.0))          # 1 m/s
    ledger.add(1.0, 1e-3, 5.0, "ore", (0.0, 3.0, 4.0))          # 5 m/s
    assert ledger.total_mass() == 3.0
    assert ledger.kinetic_energy() == pytest.approx(0.5 * 2 * 1 + 0.5 * 1 * 25)
    assert FinesLedger(json.loads(json.dumps(ledger.to_list()))).to_list() == ledger.to_list()


# -- criteria on scripted loading histories -----------------------------------------------------
def _one_body(material_name, fracture_energy, mass=1e-4, size=5.5e-3):
    mat = load_material(material_name)
    crit = criteria.criterion_for(mat)
    table = BodyTable(["ore"], assembled_columns([crit]))
    extra = {"e_min": float(mat.min_energy(size))} if isinstance(crit, criteria.AbT10) else {}
    table.add([0], BREAKABLE, "ore", mass, size / 2, fracture_energy=fracture_energy,
              fracture_energy_initial=fracture_energy, **extra)
    return mat, crit, table


def _load(crit, table, history, mass=1e-4):
    """Judge body 0 along a history of specific energies (J/kg); the step it breaks, or None."""
    c = table.columns
    for step, specific in enumerate(history):
        j = crit.judge(table, np.array([0]), np.array([specific * mass]), np.array([specific]))
        c["specific_energy"][0] = specific
        c["event_max"][0] = max(c["event_max"][0], specific * mass)
        if j.breaks[0]:
            return step
    return None


def test_tavares_breaks_at_the_first_read_above_its_fracture_energy_and_is_weakened_below():
    mat, crit, table = _one_body("copper_ore", 200.0)
    assert _load(crit, table, np.linspace(0, 190, 20)) is None
    fields = crit.unload(table, 0)                       # the event ends at 190 J/kg
    expected = float(model.weakened_fracture_energy(200.0, 190.0 / 200.0, mat.params.gamma))
    assert fields["fracture_energy_after"] == pytest.approx(expected, rel=1e-12)
    assert table[0].damage == pytest.approx(1 - expected / 200.0, rel=1e-12)
    table[0].specific_energy = table[0].event_max = 0.0
    history = np.linspace(0, 2 * expected, 41)
    assert _load(crit, table, history) == int(np.argmax(history > expected))
    ratio, t10, _ = crit.breakage(table, 0, history[-1] * 1e-4)
    assert t10 == pytest.approx(float(model.t10(ratio, mat.params.A, mat.params.b_prime, mat.params.kappa)))


def test_ab_t10_accumulates_e_minus_e_min_per_loading_and_breaks_past_its_threshold():
    mat, crit, table = _one_body("ab_t10_ore", 1e9)
    e_min = table[0].e_min
    for loading in range(3):                              # three loadings to 150 J/kg
        _load(crit, table, np.concatenate([np.linspace(0, 150, 30), np.linspace(150, 0, 10)]))
        crit.unload(table, 0)
        assert table[0].e_cum == pytest.approx((loading + 1) * (150 - e_min), rel=1e-12)
    table[0].fracture_energy = threshold = table[0].e_cum + 40.0
    history = np.linspace(0, 150, 151)
    step = _load(crit, table, history)
    assert history[step] - e_min > 40.0 >= history[step - 1] - e_min   # crossed at that read
    _, t10, extra = crit.breakage(table, 0, 0.0)
    assert extra["e_cum"] > threshold
    assert t10 == pytest.approx(float(mat.t10_of_cumulative_energy(extra["e_cum"], 5.5e-3)))


# -- the contact work law on closed forms -------------------------------------------------------
KNO = 3.2e9          # N/m^1.5, a copper-ore sphere of a few mm on steel


def _work(law, d0, f0, delta, force, first_touch=0.8):
    """A contact's work on floats (as the reader reads a few contacts), checked to the last bit
    against the same contact among arrays (as it reads many)."""
    one = (law.from_overlap(d0, f0, KNO, delta, force, math.sqrt) if d0 > 0.0 else
           law.from_first_touch(KNO, delta, force, first_touch, math.sqrt))
    many = law.loading(np.array([d0, 2e-6]), np.array([f0, KNO * 2e-6 ** 1.5]),
                       np.array([KNO, KNO]), np.array([delta, 3e-6]),
                       np.array([force, KNO * 3e-6 ** 1.5]), first_touch)
    assert isinstance(one, float) and many[0] == one
    return one


def test_hertz_normal_work_is_two_fifths_k_d_to_the_five_halves():
    from yadebreak.engine.contacts import HertzMindlinWork as law
    overlaps = np.linspace(0.0, 4e-6, 41)[1:]
    force = KNO * overlaps ** 1.5
    # from first touch in one read (the elastic force has no dashpot part)...
    assert _work(law, 0.0, 0.0, 4e-6, force[-1]) == pytest.approx(0.4 * KNO * 4e-6 ** 2.5,
                                                                   rel=1e-14)
    # ...and read by read: the Hertz part is exact, whatever the reads
    total = _work(law, 0.0, 0.0, overlaps[0], force[0]) + sum(
        _work(law, d0, f0, d1, f1) for d0, f0, d1, f1 in zip(overlaps[:-1], force[:-1],
                                                            overlaps[1:], force[1:]))
    assert total == pytest.approx(0.4 * KNO * 4e-6 ** 2.5, rel=1e-12)


def test_a_constant_dashpot_force_adds_its_force_times_the_displacement():
    from yadebreak.engine.contacts import HertzMindlinWork as law
    d0, d1, dashpot = 1e-6, 3e-6, 0.7
    work = _work(law, d0, KNO * d0 ** 1.5 + dashpot, d1, KNO * d1 ** 1.5 + dashpot)
    assert work == pytest.approx(0.4 * KNO * (d1 ** 2.5 - d0 ** 2.5) + dashpot * (d1 - d0),
                                 rel=1e-12)
    # from first touch, the dashpot's work is first_touch x F d (Mindlin's delta^(1/4) growth)
    work = _work(law, 0.0, 0.0, d1, KNO * d1 ** 1.5 + dashpot, first_touch=0.8 - 0.3 / 9)
    assert work == pytest.approx(0.4 * KNO * d1 ** 2.5 + (0.8 - 0.3 / 9) * dashpot * d1,
                                 rel=1e-12)
    assert law.first_touch_factor(3) == 0.8 - 0.3 / 9
    assert law.trapezoid(1.0, 2.0, 3.0, 4.0) == 6.0        # the shear work: 0.5 (2 + 4) (3 - 1)


def test_a_contact_that_peaked_between_reads_counts_its_work_to_the_parabola_top():
    from yadebreak.engine.contacts import HertzMindlinWork as law
    peak, t_peak, a = 5e-6, 2.4e-6, 1e6         # m, s, m/s^2: overlap = peak - a (t - t_peak)^2
    times = np.array([1e-6, 2e-6, 3e-6])        # reads at t0 < t1 < t2, the top between t1, t2
    x0, x1, x2 = peak - a * (times - t_peak) ** 2
    assert law.peaked(x1, x2, x0, times[0], times[1])
    assert law.peaked(np.array([x1]), np.array([x2]), np.array([x0]), times[:1], times[1:2])[0]
    assert not law.peaked(x1, x1 * 1.01, x0, times[0], times[1])       # still growing
    work = law.past_peak(x1, KNO * x1 ** 1.5, KNO, x0, times[0], times[1], times[2], x2)
    assert work == pytest.approx(0.4 * KNO * (peak ** 2.5 - x1 ** 2.5), rel=1e-9)
    # no top above the last overlap read (a convex fall): nothing counts
    assert law.past_peak(x1, KNO * x1 ** 1.5, KNO, x1 + 1e-6, times[0], times[1], times[2],
                         x1 - 0.5e-6) is None


def test_a_body_counts_its_share_of_a_contacts_work_since_its_offset_from_emin_on():
    from yadebreak.engine.contacts import own_share, total_work
    assert total_work(2.0, 4.0, 0.5) == 4.0 and total_work(2.0, 4.0, 0.0) == 2.0
    assert own_share(3.0, 1.0, 0.25, 1e-4) == (True, 0.5)
    assert own_share(3.0, 3.0 - 5e-5, 0.25, 1e-4)[0] is False
    counted, share = own_share(np.array([3.0, 3.0]), np.array([1.0, 3.0 - 5e-5]), 0.25, 1e-4)
    assert counted.tolist() == [True, False] and share[0] == 0.5


# -- the judge: body by body and with numpy, the same ---------------------------------------------
def _scene(seed):
    rng = np.random.default_rng(seed)
    mats = [load_material("copper_ore"), load_material("ab_t10_ore")]
    st = EngineState(["cu", "ab"], seed, columns=assembled_columns(m.criterion for m in mats))
    n = 40
    ids = np.arange(n) * 2 + 1
    mat_index = rng.integers(0, 2, n)
    st.table.add(ids, np.where(rng.random(n) < 0.9, BREAKABLE, UNBREAKABLE), mat_index,
                 rng.uniform(1e-5, 1e-4, n), 1e-3, fracture_energy=rng.uniform(20, 400, n),
                 specific_energy=rng.uniform(0, 100, n), generation=rng.integers(0, 2, n),
                 pause_until=rng.integers(0, 20, n), e_min=rng.uniform(0, 30, n),
                 e_cum=rng.uniform(0, 50, n), e_prev=rng.uniform(0, 80, n))
    loaded = rng.random(n) < 0.6
    st.table.columns["event_max"][ids] = np.where(rng.random(n) < 0.5,
                                                  rng.uniform(0, 2e-2, n), 0.0)
    st.tracked.update(ids[rng.random(n) < 0.9].tolist())
    st.open_events.update(ids[(st.table.columns["event_max"][ids] > 0)].tolist())
    loading = Loading()
    for i, load, m in zip(ids.tolist(), loaded, st.table.columns["mass"][ids]):
        if load:
            loading.energy[i] = float(m * rng.uniform(0, 500))
            loading.strongest[i] = Strongest(loading.energy[i], (0.0, 0.0, 1.0), 1.0,
                                             int(rng.integers(n)))
    return st, [criteria.criterion_for(m) for m in mats], loading


@pytest.mark.parametrize("at_peak", (False, True))
@pytest.mark.parametrize("seed", range(6))
def test_both_judge_paths_make_the_same_decisions(seed, at_peak):
    results = []
    for path in ("plan_each", "plan_all"):
        st, crits, loading = _scene(seed)
        if at_peak:                   # some bodies passed their threshold at an earlier read
            ids = np.array(sorted(st.tracked))
            st.table.columns["cracked"][ids[::3]] = 1
        records = []
        rules = judging.Rules(0.7 if seed % 2 else 1.0, 0.02, at_peak, pausing=True)
        judge = judging.Judge(st, crits, ContactReader({}, 0.0, 1e-4), rules,
                              record=lambda kind, i, **f: records.append((kind, i, f)))
        candidates = list(st.open_events.union(loading.energy))
        plan = getattr(judge, path)(candidates, loading, 3, 10, True)
        broken = judge.settle(candidates, plan, loading)
        results.append((broken, records, sorted(st.open_events), plan.need, plan.order,
                        sorted(plan.limits),
                        json.dumps({k: v.tolist() for k, v in st.table.columns.items()})))
    each, every = results
    assert each[0] and each[1]          # the scene breaks some bodies and closes some events
    assert each == every


def _reader_with_rows(rng, ids, cs):
    """A ContactReader whose numpy block holds 60 random rows among the bodies `ids`."""
    from yadebreak.engine.contacts.table import FIELDS
    reader = ContactReader({}, cs, 1e-4)
    a, b = rng.choice(ids, 60), rng.choice(ids, 60)
    reader.table.set(a, b, rng.uniform(0.0, 1e-3, (len(FIELDS), 60)), [None] * 60, [None] * 60)
    return reader


@pytest.mark.parametrize("seed", range(4))
def test_events_closed_together_are_those_closed_one_by_one(seed):
    """close_events on a read's events at once (numpy) = on each in turn (criteria's unload on
    floats): the same log, columns, offsets of the bodies' rows and weakened bodies, to the
    last digit."""
    results = []
    for together in (True, False):
        st, crits, _ = _scene(seed)
        rng = np.random.default_rng(seed)
        reader = _reader_with_rows(rng, np.array(sorted(st.tracked)), 0.3 * (seed % 2))
        records, weakened = [], []
        judge = judging.Judge(st, crits, reader, judging.Rules(1.0, 0.02),
                              record=lambda kind, i, **f: records.append((kind, i, f)),
                              weakened=weakened.extend)
        closing = sorted(st.open_events)[::-1]            # logged in the order given
        if together:
            judge.close_events(closing)
        else:
            for i in closing:
                judge.close_events([i])
        results.append((records, weakened, sorted(st.open_events), reader.table.data.tolist(),
                        json.dumps({k: v.tolist() for k, v in st.table.columns.items()})))
    together, one_by_one = results
    assert len(together[0]) >= 5 and together[1]        # damage logged, energies lowered
    assert {"e_cum" in f for _, _, f in together[0]} == {True, False}   # both criteria
    assert together == one_by_one


def test_tracked_bodies_keep_their_mask_in_step_with_every_change():
    from yadebreak.engine.state import TrackedBodies
    tracked = TrackedBodies([1, 5])
    tracked.mask(8)
    changes = [lambda t: t.add(3), lambda t: t.add(9), lambda t: t.discard(5),
               lambda t: t.discard(42), lambda t: t.update([0, 2]), lambda t: t.remove(0),
               lambda t: t.__isub__({2}), lambda t: t.__ior__({6}), lambda t: t.pop(),
               lambda t: t.difference_update([6]), lambda t: t.symmetric_difference_update({7})]
    for change in changes:
        change(tracked)
        n = max(tracked, default=0) + 3
        assert tracked.mask(n).nonzero()[0].tolist() == sorted(tracked)
    copy = __import__("copy").copy(tracked)
    copy.add(11)                                          # a copy has a mask of its own
    assert 11 not in tracked.mask(12).nonzero()[0]
    assert not tracked.mask(12).flags.writeable
    few = TrackedBodies([1, 30])              # built for ids below the largest tracked one (the
    assert few.mask(5).tolist() == [False, True, False, False, False]      # judge asks so)
    assert few.mask(31).nonzero()[0].tolist() == [1, 30]


def test_docs_options_is_the_table_as_rendered_now():
    """docs/options.md is `python3 -m yadebreak options`: regenerate it when config.py changes."""
    import contextlib
    import io
    from pathlib import Path
    from yadebreak.cli import main
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        main(["options"])
    assert (Path(__file__).resolve().parent.parent / "docs" / "options.md").read_text() == out.getvalue()


def test_kappa_successive_sets_eq8_for_fragments_only():
    """kappa_successive is Eq. 8's kappa for bodies of generation >= 1; the parent (generation 0)
    keeps the material's kappa, and None keeps it for every generation."""
    cu = load_material("copper_ore")
    table = BodyTable(["ore"])
    table.add([0, 1], BREAKABLE, "ore", mass=2e-3, radius=5e-3, fracture_energy=400.0,
              generation=np.array([0, 1]))
    ek = 1.7 * 2e-3 * 400.0                        # J: the ratio of Eq. 8 is 1.7 for both
    paper, successive = criteria.Tavares(cu), criteria.Tavares(cu, kappa_successive=0.5)
    for crit, kappas in ((paper, (cu.params.kappa, cu.params.kappa)), (successive, (cu.params.kappa, 0.5))):
        for i, kappa in zip((0, 1), kappas):
            ratio, t10, _ = crit.breakage(table, i, ek)
            assert ratio == pytest.approx(1.7)
            assert t10 == pytest.approx(cu.params.A * (1 - math.exp(-cu.params.b_prime * 1.7 / kappa)))
    cfg = config.Config.from_options(kappa_successive=0.5)
    assert cfg.criteria.kappa_successive == 0.5
    with pytest.raises(config.AttachError, match="kappa_successive"):
        config.Config.from_options(kappa_successive=0.0)


@pytest.mark.parametrize("kind", (BREAKABLE, UNBREAKABLE))
def test_break_at_peak_waits_for_the_event_to_stop_rising_and_takes_its_largest_energy(kind):
    """break_at="threshold" (the paper): the body breaks at the first read above its fracture
    energy, Ek' of that read. "peak": it is marked cracked there, breaks at the first read whose
    energy no longer rises (here falling back below the threshold), with the event's largest Ek'
    for Eq. 8; an unbreakable fragment's recorded t10' is the same."""
    cu = load_material("copper_ore")
    mass, energy = 2e-3, 400.0                          # kg, J/kg
    history = [300.0, 450.0, 600.0, 390.0]              # J/kg at four reads
    found = {}
    for at_peak in (False, True):
        st = EngineState(["ore"], 0)
        st.table.add([0], kind, "ore", mass, 5e-3, fracture_energy=energy,
                     fracture_energy_initial=energy)
        st.tracked.add(0)
        judge = judging.Judge(st, [criteria.criterion_for(cu)], ContactReader({}, 0.0, 1e-4),
                              judging.Rules(1.0, 0.02, at_peak))
        for read, specific in enumerate(history):
            loading = Loading({0: specific * mass})
            broken, _ = judge.judge(loading, 1, read, False)
            if broken:
                found[at_peak] = (read, broken[0][1])
                break
    assert found[False] == (1, pytest.approx(450.0 * mass))
    assert found[True] == (3, pytest.approx(600.0 * mass))
    ratio, t10, _ = criteria.criterion_for(cu).breakage(st.table, 0, found[True][1])
    assert ratio == pytest.approx(1.5)
    assert t10 == pytest.approx(float(model.t10(1.5, cu.params.A, cu.params.b_prime, cu.params.kappa)))
    with pytest.raises(config.AttachError, match="break_at"):
        config.Config.from_options(break_at="late")


def test_could_break_asks_for_the_fracture_energy_left_after_what_the_event_counted(scene):
    """Controller.could_break (a scene's end rule asks it): a breakable body could break if its
    event's counted Ek'/m plus what it may still get reaches its fracture energy (after damage),
    an unbreakable fragment until its first would-be breakage, a dummy or a body yadebreak does
    not know never; Ab-T10 accumulates, so any energy could be the last."""
    from yadebreak import scenes
    from yadebreak.engine.state import DUMMY, UNBREAKABLE
    brk, ids = scenes.impact_scene("copper_ore", 5.5e-3, speeds=[5.0, 5.0, 5.0, 5.0], seed=2)
    c = brk.bodies.columns
    energy = c["fracture_energy"][ids].copy()
    assert brk.could_break(ids, energy).all()
    assert not brk.could_break(ids, energy * (1 - 1e-9)).any()
    c["specific_energy"][ids[0]] = 0.5 * energy[0]            # half counted already
    assert brk.could_break(ids[:1], [0.5 * energy[0]]).all()
    assert not brk.could_break(ids[:1], [0.49 * energy[0]]).any()
    c["kind"][ids[1]] = DUMMY                                 # dummies are not tracked
    brk.state.tracked.discard(ids[1])
    c["kind"][ids[2]] = UNBREAKABLE                           # still tracked: its first stress
    assert brk.could_break(ids[1:3], [1e9, energy[2]]).tolist() == [False, True]
    brk.state.tracked.discard(ids[2])                         # stressed once: its t10' is set
    assert not brk.could_break([ids[2], 0], [1e9, 1e9]).any()  # 0: the plate
    ab = criteria.AbT10(load_material("ab_t10_ore"))
    assert ab.energy_to_break(brk.bodies, np.array(ids)).tolist() == [0.0] * 4


# -- the event log: a read's events in one write ---------------------------------------------------
def test_an_event_log_writes_a_reads_events_at_once_and_keeps_them_on_an_error(tmp_path):
    path = tmp_path / "events.jsonl"
    log = EventLog(path)
    log.start()

    def on_file():
        return [json.loads(line) for line in path.read_text().splitlines()]
    log.record({"kind": "damage", "id": 1})
    assert on_file() == log.events                        # outside a read: at once
    with log.held():
        log.record({"kind": "damage", "id": 2})
        log.record({"kind": "breakage", "id": 3})
        assert len(log.events) == 3 and len(on_file()) == 1   # in memory now, on file at the end
    assert on_file() == log.events
    with pytest.raises(RuntimeError):
        with log.held():
            log.record({"kind": "damage", "id": 4})
            raise RuntimeError("a replacement failed")
    assert on_file() == log.events and len(log.events) == 4
    full = EventLog("/dev/full")                          # every write fails: nothing half written
    with pytest.raises(OSError):
        with full.held():
            full.record({"kind": "damage", "id": 5})
    assert full.events == [{"kind": "damage", "id": 5}]
