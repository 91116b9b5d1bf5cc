"""The Ab-T10 criterion (docs/model.md Section 9): model functions on scripted histories (no YADE),
material files, and single and repeated impacts in YADE against P(e_cum)."""
import math

import numpy as np
import pytest

import yadebreak
from yadebreak import load_material, model
from yadebreak.model.materials import MaterialError

AB = load_material("ab_t10_ore")
STEEL = load_material("steel")
SIZE = 5.5e-3


def _history(e_t, e_min):
    """Run Eq. 9.2 along a scripted history; e_cum and e_max after every step."""
    e_cum = e_max = e_prev = 0.0
    cums, maxes = [], []
    for e in e_t:
        e_cum, e_max = model.ab_t10_update(e, e_prev, e_cum, e_max, e_min)
        e_prev = e
        cums.append(float(e_cum))
        maxes.append(float(e_max))
    return np.array(cums), np.array(maxes)


def test_min_energy_scales_inversely_with_size():
    assert model.ab_t10_min_energy(0.01, 40.0, 0.01) == pytest.approx(40.0)
    sizes = np.array([1e-3, 2e-3, 4e-3])
    e = model.ab_t10_min_energy(sizes, 40.0, 0.01)
    assert np.allclose(e * sizes, 40.0 * 0.01)


def test_update_step_by_step_on_a_scripted_history():
    e_min = 10.0
    #        below  cross  grow  grow  dip   reload(past 30)  unload<e_min  new loading
    e_t = [0.0, 6.0, 14.0, 22.0, 30.0, 25.0, 28.0, 33.0, 8.0, 0.0, 12.0, 16.0]
    cum, top = _history(e_t, e_min)
    # nothing below e_min; the crossing counts from e_min (14 - 10 = 4)
    assert cum[:2].tolist() == [0.0, 0.0] and cum[2] == 4.0
    # while loading, each step adds its rise, and e_max follows e_t
    assert cum[3] == 12.0 and cum[4] == 20.0 and top[4] == 30.0
    # a dip and a reload below the peak add nothing: e_max keeps the peak
    assert cum[5] == 20.0 and cum[6] == 20.0 and top[6] == 30.0
    # the reload past the peak counts only what lies above it (33 - 30), not 33 - 28
    assert cum[7] == 23.0 and top[7] == 33.0
    # unloading below e_min resets e_max, so the next loading counts again from e_min
    assert top[8] == 0.0 and cum[8] == 23.0
    assert cum[10] == 25.0 and cum[11] == 29.0


def test_without_reset_a_second_loading_below_the_peak_adds_nothing():
    # unloading stays above e_min: e_max is not reset and a second, smaller peak counts nothing
    cum, top = _history([0.0, 20.0, 40.0, 15.0, 35.0, 12.0, 39.0], 10.0)
    assert cum[-1] == 30.0 and top[-1] == 40.0


@pytest.mark.parametrize("steps", [2, 7, 50, 1000])
def test_one_loading_leaves_e_minus_e_min_at_any_step_size(steps):
    rng = np.random.default_rng(steps)
    e_t = np.sort(rng.uniform(0.0, 250.0, steps - 1)).tolist() + [250.0]
    cum, _ = _history(e_t + [0.0] + e_t, 60.0)
    assert cum[len(e_t) - 1] == pytest.approx(190.0)
    assert cum[-1] == pytest.approx(380.0)              # two loadings: twice
    assert cum[-1] == pytest.approx(2 * model.ab_t10_single_impact_cum(250.0, 60.0))


def test_update_is_vectorised_like_the_scalar_rule():
    rng = np.random.default_rng(3)
    n = 1000
    args = [rng.uniform(0, 100, n) for _ in range(4)] + [rng.uniform(5, 50, n)]
    cum, top = model.ab_t10_update(*args)
    for k in range(0, n, 97):
        c, t = model.ab_t10_update(*(a[k] for a in args))
        assert (cum[k], top[k]) == (c, t)


def test_probability_threshold_and_t10():
    e_min, s, size_ref, size = 70.0, 0.01, 0.01, 5.5e-3
    x = s * size / size_ref
    assert model.ab_t10_probability(e_min, size, e_min, s, size_ref) == 0.0
    assert model.ab_t10_probability(e_min - 5, size, e_min, s, size_ref) == 0.0
    assert model.ab_t10_probability(e_min + 1 / x, size, e_min, s, size_ref) == pytest.approx(1 - math.exp(-1))
    u = np.linspace(0.0, 0.999, 200)
    threshold = model.ab_t10_threshold(u, size, e_min, s, size_ref)
    assert np.all(np.diff(threshold) > 0) and threshold[0] == e_min
    assert np.allclose(model.ab_t10_probability(threshold, size, e_min, s, size_ref), u)
    t10 = model.ab_t10_t10(threshold, size, e_min, s, size_ref, 50.0)
    assert np.allclose(t10, 50.0 * u) and np.all(t10 <= 50.0)


def test_breakage_against_uniform_strengths_follows_p_of_e_cum():
    """Particles with uniform strengths under repeated scripted loadings: the fraction broken after
    k loadings is P(e_cum after k) (4000 particles: binomial sigma <= 0.8 %, tolerance 3 sigma)."""
    rng = np.random.default_rng(7)
    n, e_min = 4000, 72.7
    strength = rng.random(n)
    e_cum = np.zeros(n)
    e_max = np.zeros(n)
    broken = np.zeros(n, bool)
    loading = np.concatenate([np.linspace(0, 150.0, 40), np.linspace(150.0, 0, 20)])
    fractions = []
    for _ in range(5):
        e_prev = 0.0
        for e in loading:
            e_cum, e_max = model.ab_t10_update(e, e_prev, e_cum, e_max, e_min)
            e_prev = e
            broken |= model.ab_t10_probability(e_cum, SIZE, e_min, 0.01, 0.01) > strength
        fractions.append(broken.mean())
    expected = model.ab_t10_repeated_broken_fraction(150.0, SIZE, e_min, 0.01, 0.01, 5)
    assert np.all(np.abs(np.array(fractions) - expected) <= 3 * np.sqrt(expected * (1 - expected) / n))


# ----------------------------------------------------------------------------- material files
def test_example_material_loads_and_dispatches():
    assert AB.is_ab_t10 and AB.params.size_ref == pytest.approx(0.01) and AB.params.t10_max == 50.0
    assert AB.min_energy(SIZE) == pytest.approx(40.0 * 10.0 / 5.5)
    e = np.linspace(0, 1000, 50)
    assert np.allclose(AB.fracture_energy_cdf(e, SIZE),
                       model.ab_t10_probability(e, SIZE, AB.min_energy(SIZE), 0.01, 0.01))
    draws = AB.sample_fracture_energy(np.random.default_rng(0), np.full(20000, SIZE))
    # the thresholds are distributed as P: their cdf at the median is one half
    assert abs(np.mean(draws < AB.median_fracture_energy(SIZE)) - 0.5) < 3 * 0.5 / math.sqrt(20000)
    share = AB.energy_partition(STEEL)
    assert AB.breakage_probability(300.0, SIZE, partner=STEEL) == pytest.approx(
        AB.fracture_energy_cdf(share * 300.0 - AB.min_energy(SIZE), SIZE))
    with pytest.raises(ValueError, match="Ab-T10"):
        AB.t10(1.0)


AB_GOOD = (yadebreak.model.materials.MATERIALS_DIR / "ab_t10_ore.toml").read_text()


@pytest.mark.parametrize("old, new, message", [
    ("selection = 0.01 ", "selection = 0 ", r"breakage.selection = 0 kg/J is out of range: accepted \(0, inf\)"),
    ("t10_max = 50.0 ", "t10_max = 120 ", r"breakage.t10_max = 120 % is out of range: accepted \(0, 100\]"),
    ("e_min_ref = 40.0 ", "e_min_ref = -1 ", r"breakage.e_min_ref = -1 J/kg is out of range: accepted \[0, inf\)"),
    ("size_ref = 10.0 ", "", "breakage.size_ref: missing"),
    ("t10_max = 50.0 ", "t10_max = 50.0\nsigma = 0.8 ", "breakage.sigma: unknown key"),
    ('model = "ab_t10"', 'model = "ab-t10"', "breakage.model = 'ab-t10': accepted 'tavares'"),
])
def test_ab_t10_validation_names_field_and_range(tmp_path, old, new, message):
    assert old in AB_GOOD
    path = tmp_path / "bad.toml"
    path.write_text(AB_GOOD.replace(old, new))
    with pytest.raises(MaterialError, match=message):
        load_material(path)


# ----------------------------------------------------------------------------- in YADE
@pytest.mark.yade
@pytest.mark.parametrize("energy", [250.0, 400.0, 800.0])
def test_single_impact_broken_fraction_against_p_of_e_cum(scene, energy):
    """200 particles per energy: broken fraction within 3 binomial sigma of P(e_cum), e_cum as the
    intact particles carry it; that e_cum within 3 % of the closed form e Ek/mp - e_min."""
    from yadebreak import scenes
    n = 200
    brk, ids = scenes.impact_scene("ab_t10_ore", SIZE, [math.sqrt(2 * energy)] * n, seed=5,
                                   replace=False, read_period="every_step")
    scenes.run_until_rebound(ids)
    broken = {e["id"] for e in brk.breakage_events} & set(ids)
    e_cum = [brk.bodies[i].e_cum for i in ids if i not in broken]
    assert np.ptp(e_cum) < 1e-6 * e_cum[0]          # identical impacts, identical e_cum
    p = float(AB.fracture_energy_cdf(e_cum[0], SIZE))
    assert 0.05 < p < 0.95
    assert abs(len(broken) / n - p) <= 3 * math.sqrt(p * (1 - p) / n)
    closed = AB.energy_partition(STEEL) * energy - AB.min_energy(SIZE)
    assert e_cum[0] == pytest.approx(closed, rel=0.03)
    # each broken particle broke with e_cum past its threshold and t10 = M P(e_cum)
    for e in brk.breakage_events:
        assert e["e_cum"] >= e["fracture_energy"]
        assert e["t10"] == pytest.approx(AB.t10_of_cumulative_energy(e["e_cum"], SIZE))


@pytest.mark.yade
def test_repeated_impacts_accumulate_and_follow_the_closed_form(scene):
    from yade import O
    from yadebreak import scenes
    n, impacts, energy = 200, 4, 180.0
    speed = math.sqrt(2 * energy)
    brk, ids = scenes.impact_scene("ab_t10_ore", SIZE, [speed] * n, seed=8, replace=False)
    home = {i: tuple(O.bodies[i].state.pos) for i in ids}
    alive, got = list(ids), []
    for _ in range(impacts):
        alive = scenes.impact_again(brk, alive, home, speed)
        got.append(1 - len(alive) / n)
    absorbed = AB.energy_partition(STEEL) * energy
    expected = model.ab_t10_repeated_broken_fraction(absorbed, SIZE, AB.min_energy(SIZE),
                                                     AB.params.selection, AB.params.size_ref, impacts)
    sigma = np.sqrt(expected * (1 - expected) / n)
    assert np.all(np.abs(np.array(got) - expected) <= 3 * sigma + 0.01)
    assert got[-1] > 2 * got[0]


@pytest.mark.yade
def test_one_scene_runs_both_criteria_and_fragments_pause(scene):
    """Tavares and Ab-T10 particles side by side; fragments count no energy for pause_steps."""
    from yade import O, utils
    from yadebreak import scenes
    from yadebreak.engine import add_materials, attach
    ip2, _ = add_materials({"cu": "copper_ore", "ab": "ab_t10_ore", "plate": "steel"})
    O.bodies.append(utils.wall(0.0, axis=2, sense=1, material="plate"))
    r = SIZE / 2
    ids = {}
    for k, lab in enumerate(["cu", "ab"] * 10):
        b = utils.sphere((4 * SIZE * k, 0, r * 1.02), r, material=lab)
        b.state.vel = (0, 0, -40.0)                   # 800 J/kg: about half the copper ore
                                                      # and 95 % of the Ab-T10 ore break
        ids[O.bodies.append(b)] = lab
    O.engines = scenes.hertz_engines(ip2)
    brk = attach({"cu": "copper_ore", "ab": "ab_t10_ore"}, seed=2)
    assert brk.pause_steps == {"cu": 0, "ab": 25}
    scenes.run_until_rebound(list(ids))
    first = {e["id"]: e for e in brk.breakage_events if e["id"] in ids}
    kinds = {lab: sum(1 for i in first if ids[i] == lab) for lab in ("cu", "ab")}
    assert kinds["cu"] >= 2 and kinds["ab"] >= 7
    assert all(("e_cum" in e) == (ids[i] == "ab") for i, e in first.items())
    for e in first.values():
        for f in e["fragments"]:
            st = brk.bodies[f]
            if ids[e["id"]] == "ab":
                assert st.pause_until == e["iter"] + 25
                assert (st.e_min > 0) == (st.kind != "dummy")
            else:
                assert st.pause_until == -1
    # no fragment broke or was damaged within its pause
    born = {f: e["iter"] for e in brk.breakage_events for f in e["fragments"]}
    for e in brk.events:
        if e["id"] in born and ids.get(e["id"]) is None and brk.bodies[e["id"]].material == "ab":
            assert e["iter"] >= born[e["id"]] + 25
