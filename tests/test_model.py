"""The pure model (Eqs. 1-13): no YADE needed."""
import numpy as np
import pytest
from scipy import stats

from yadebreak import model

T1 = model.TABLE1_BETA_PARAMS


@pytest.mark.parametrize("sigma, emax_ratio", [(0.01, 1.001), (0.8, 4.0), (0.8, 100.0), (3.0, 1e4)])
def test_cdf_ppf_are_inverse_over_the_whole_support(sigma, emax_ratio):
    e50 = 347.3
    u = np.concatenate([[0.0, 1e-12, 1e-6], np.linspace(0.001, 0.999, 999), [1 - 1e-9, 1.0]])
    e = model.fracture_energy_ppf(u, e50, sigma, emax_ratio)
    assert np.all(np.diff(e) >= 0)
    assert np.all((e >= 0) & (e <= e50 * emax_ratio))
    assert e[-1] == pytest.approx(e50 * emax_ratio, rel=1e-12)           # the truncation end
    np.testing.assert_allclose(model.fracture_energy_cdf(e, e50, sigma, emax_ratio), u, atol=1e-10)
    inner = (u > 1e-6) & (u < 1 - 1e-9)
    back = model.fracture_energy_ppf(model.fracture_energy_cdf(e[inner], e50, sigma, emax_ratio),
                                     e50, sigma, emax_ratio)
    np.testing.assert_allclose(back, e[inner], rtol=1e-10)


def test_cdf_is_zero_below_and_one_at_truncation():
    assert model.fracture_energy_cdf(0.0, 100, 0.8, 4) == 0.0
    assert model.fracture_energy_cdf(400.0, 100, 0.8, 4) == 1.0
    assert model.fracture_energy_cdf(1e9, 100, 0.8, 4) == 1.0
    assert model.fracture_energy_cdf(100.0 * 4 / 5, 100, 0.8, 4) == pytest.approx(0.5)  # E* = E50


def test_fig1_check_values():
    # docs/model.md: E50 = 347.3 J/kg; u = 0.71 -> 534.1 J/kg and the 35.5th percentile 258.0 J/kg;
    # sigma 0.8 / Emax/E50 100 within 0.8 %, sigma 0.790 / 222 "exactly" (to the printed digits).
    e = model.fracture_energy_ppf([0.71, 0.355], 347.3, 0.80, 100.0)
    np.testing.assert_allclose(e, [534.1, 258.0], rtol=0.008)
    e = model.fracture_energy_ppf([0.71, 0.355], 347.3, 0.790, 222.0)
    np.testing.assert_allclose(e, [534.1, 258.0], atol=0.1)


@pytest.mark.parametrize("seed", [1, 2])
def test_samples_follow_the_cdf(seed):
    rng = np.random.default_rng(seed)
    e = model.sample_fracture_energy(rng, 347.3, 0.8, 4.0, size=20000)
    res = stats.kstest(e, lambda x: model.fracture_energy_cdf(x, 347.3, 0.8, 4.0))
    assert res.pvalue > 0.01
    assert e.max() < 4 * 347.3 and e.min() > 0


def test_energy_partition():
    kp = model.hertz_stiffness(52e9, 0.25)
    ks = model.hertz_stiffness(210e9, 0.30)
    assert kp == pytest.approx(55.47e9, rel=1e-3)
    assert ks == pytest.approx(230.8e9, rel=1e-3)
    assert model.energy_partition(kp, ks) == pytest.approx(0.806, abs=5e-4)
    assert model.energy_partition(kp, kp) == 0.5
    assert model.energy_partition(kp, 1.3e9) == pytest.approx(0.023, abs=5e-4)


def test_median_fracture_energy_and_stiffness_cancel_on_steel():
    # Eq. 3 times Eq. 4 on the calibration device: e * E50 = Einf [1 + (d0/d)^phi]
    d = np.array([1e-3, 5.5e-3, 37.5e-3])
    kp, ks = model.hertz_stiffness(52e9, 0.25), 230e9
    e50 = model.median_fracture_energy(d, 213.5, 8.07e-3, 1.22, kp, ks)
    np.testing.assert_allclose(e50 / model.energy_partition(kp, ks),
                               213.5 * (1 + (8.07e-3 / d) ** 1.22), rtol=1e-12)
    assert np.all(np.diff(e50) < 0)                        # finer is stronger


@pytest.mark.parametrize("gamma", [0.5, 1.0, 5.0, 20.0, 50.0])
def test_damage_at_the_extremes(gamma):
    r = np.concatenate([np.geomspace(1e-9, 0.5, 60), 1 - np.geomspace(0.49, 1e-12, 60)])
    d = model.damage(r, gamma)
    assert np.all(np.isfinite(d)) and np.all((d >= 0) & (d < 1))
    assert np.all(np.diff(d) > 0)
    rhs = (2 * gamma / (2 * gamma - 5 * d + 5) * r) ** (2 * gamma / 5)
    np.testing.assert_allclose(d, rhs, atol=1e-10, rtol=0)
    assert model.damage(0.0, gamma) == 0.0


@pytest.mark.parametrize("gamma", [0.5, 1.0, 5.0, 20.0, 50.0])
def test_damage_of_one_ratio_is_the_arrays_damage(gamma):
    """The scalar path (one stressing event) solves Eq. 6 like the array path: within 1e-8 where
    D nears 1 (Eq. 6 is flat there), and both to the same accuracy on the equation itself."""
    r = np.concatenate([[0.0, -1.0, 1.0, 2.0], np.geomspace(1e-9, 0.5, 30),
                        1 - np.geomspace(0.49, 1e-12, 30)])
    one = np.array([model.damage(float(x), gamma) for x in r])
    np.testing.assert_allclose(one, model.damage(r, gamma), rtol=1e-8, atol=0)
    live = (r > 0) & (r < 1)
    d = one[live]
    np.testing.assert_allclose(d, (2 * gamma / (2 * gamma - 5 * d + 5) * r[live]) ** (2 * gamma / 5),
                               atol=1e-10, rtol=0)
    assert isinstance(model.damage(0.3, gamma), float)


@pytest.mark.parametrize("gamma", [0.5, 2.0, 5.0, 50.0])
def test_damage_of_a_light_touch_is_eq6_limit(gamma):
    """Ratios far below 1 (tough particles touched lightly at process scale): D tends to
    g(0) = (2 gamma / (2 gamma + 5) r)^(2 gamma / 5), Eq. 6 with D = 0 on its right, and both
    paths give it to round-off (the scalar path returns that end of the bracket directly)."""
    r = np.geomspace(1e-300, 1e-6, 40)
    limit = (2 * gamma / (2 * gamma + 5) * r) ** (2 * gamma / 5)
    one = np.array([model.damage(float(x), gamma) for x in r])
    np.testing.assert_allclose(one, model.damage(r, gamma), rtol=1e-11, atol=0)
    tiny = limit < 1e-14                        # 5 D / (2 gamma + 5) below round-off of 1
    np.testing.assert_allclose(one[tiny], limit[tiny], rtol=1e-11, atol=0)
    assert np.all(np.diff(one[one > 0.0]) > 0)      # (large gammas underflow to 0)


def test_weakened_fracture_energy_of_one_body_is_the_array_value():
    """A closing event weakens one body on floats: the numbers of a 0-d array exactly, of the
    array path to round-off (Eq. 6's scalar and array solvers)."""
    rng = np.random.default_rng(4)
    energy, ratio = rng.uniform(1.0, 1e4, 400), 10 ** rng.uniform(-20, -1e-3, 400)
    one = [model.weakened_fracture_energy(float(e), float(r), 2.5) for e, r in zip(energy, ratio)]
    assert all(type(x) is float for x in one)
    assert one == [float(model.weakened_fracture_energy(e, r, 2.5)) for e, r in zip(energy, ratio)]
    np.testing.assert_allclose(one, model.weakened_fracture_energy(energy, ratio, 2.5),
                               rtol=1e-12, atol=0)


def test_damage_by_fixed_point_from_zero_agrees():
    # The paper solves Eq. 6 "iteratively from an initial guess of D = 0".
    r, gamma = 0.6, 5.0
    d = 0.0
    for _ in range(2000):
        d = (2 * gamma / (2 * gamma - 5 * d + 5) * r) ** (2 * gamma / 5)
    assert model.damage(r, gamma) == pytest.approx(d, rel=1e-12)
    assert model.weakened_fracture_energy(100.0, r, gamma) == pytest.approx(100 * (1 - d))


def test_t10_increasing_and_bounded():
    ratio = np.geomspace(1e-3, 500.0, 400)     # beyond ~1000 it equals A to round-off
    t = model.t10(ratio, 67.7, 0.029)
    assert np.all(np.diff(t) > 0) and np.all(t < 67.7)
    assert model.t10(1e6, 67.7, 0.029) == pytest.approx(67.7)
    assert model.t10_primary(67.7, 0.029) == pytest.approx(67.7 * (1 - np.exp(-0.029)))
    assert model.t10(2.0, 67.7, 0.029, kappa=2.0) == pytest.approx(model.t10(1.0, 67.7, 0.029))


def test_eq10_table1_at_t10_3_percent():
    # docs/model.md: Table 1 gives t1.2 61.1, t1.5 36.1, t2 17.6, t4 5.70 % at t10 = 3 %.
    t = model.t_markers(3.0, T1)[:4]
    np.testing.assert_allclose(t, [61.1, 36.1, 17.6, 5.70], atol=0.05)


def test_eq10_against_the_paper_table2_family_mixture():
    # The probability-weighted families of Table 2, read at the class boundaries as docs/model.md does
    # (59.5, 40.0, 17.9, 5.72 %), agree with Eq. 10 to within 4 %: the confirmation of Eq. 10.
    from yadebreak.model import families
    counts = np.array([[0, 1, 0, 1, 0, 1, 1, 0, 1, 1, 5], [0, 1, 0, 0, 2, 0, 1, 1, 2, 1, 5],
                       [0, 0, 2, 0, 1, 1, 0, 1, 0, 2, 5], [0, 0, 1, 2, 0, 1, 1, 2, 0, 0, 6],
                       [0, 1, 0, 1, 0, 1, 1, 1, 0, 1, 4], [0, 1, 0, 1, 0, 1, 0, 2, 1, 1, 5],
                       [0, 1, 0, 0, 2, 1, 0, 0, 2, 1, 4]])
    p = np.array([34, 27, 23, 9, 5, 1, 1]) / 100
    frac = counts * families.CLASS_VOLUMES
    frac /= frac.sum(axis=1, keepdims=True)
    passing = families.boundary_passing(p @ frac)
    at_boundaries = passing[[1, 2, 4, 8]]                    # x = 0.841, 0.707, 0.5, 0.25
    np.testing.assert_allclose(at_boundaries, [59.5, 40.0, 17.9, 5.72], atol=0.05)
    np.testing.assert_allclose(at_boundaries, model.t_markers(3.0, T1)[:4], atol=4.0)


def test_progeny_passing_shape_and_anchors():
    x = np.array([1.0, 1 / 1.2, 0.5, 0.1, 1 / 75, 1e-3])
    p = model.progeny_passing(3.0, T1, x)
    t = model.t_markers(3.0, T1)
    np.testing.assert_allclose(p[:5], [100.0, t[0], t[2], 3.0, t[6]], rtol=1e-12)
    assert 0 < p[5] < p[4]
    grid = model.progeny_passing(np.array([2.0, 20.0, 60.0]), T1, np.geomspace(1e-4, 1, 50))
    assert grid.shape == (3, 50)
    assert np.all(np.diff(grid, axis=1) >= 0)
    assert np.all(np.diff(grid, axis=0) >= -1e-12)           # finer at higher t10


def test_fines_exponent_eq12():
    t4, t75 = model.t_n(10.0, *T1[4.0]), model.t_n(10.0, *T1[75.0])
    assert model.fines_exponent(10.0, T1) == pytest.approx(np.log(t4 / t75) / np.log(75 / 4))
    assert model.fines_passing(model.X_MIN, model.X_MIN, 0.7) == 1.0
    assert model.fines_passing(model.X_MIN / 2, model.X_MIN, 0.7) == pytest.approx(0.5 ** 0.7)


def test_size_distribution_conserves_mass():
    rng = np.random.default_rng(3)
    d = rng.uniform(1e-3, 5.5e-3, 200)
    m = rng.uniform(1e-6, 1e-4, 200)
    dummies = (rng.uniform(1e-7, 1e-5, 50), rng.uniform(2e-3, 5.5e-3, 50), rng.uniform(2, 60, 50))
    unb = (rng.uniform(2e-4, 3e-4, 30), rng.uniform(1e-8, 1e-7, 30),
           np.where(rng.random(30) < 0.3, np.nan, rng.uniform(2, 60, 30)))
    sieves = np.geomspace(1e-7, 1e-2, 80)
    sd = model.size_distribution(sieves, resolved=(d, m), dummies=dummies, unbreakable=unb,
                                 beta_params=T1)
    total = m.sum() + dummies[0].sum() + unb[1].sum()
    assert sd.total_mass == pytest.approx(total, rel=1e-12)
    assert sd.passing_mass[-1] == pytest.approx(total, rel=1e-12)
    assert np.all(np.diff(sd.passing_mass) >= 0)
    # a dummy mass lies entirely below X_MIN of its parent
    one = model.size_distribution([model.X_MIN * 5e-3], dummies=([1.0], [5e-3], [10.0]),
                                  beta_params=T1)
    assert one.passing_mass[0] == pytest.approx(1.0)


def test_pouring_column_is_loose_and_inside_its_holder():
    """placement.pouring_column: the requested count, every sphere clear of the others, of the
    holder's wall and of the anvil, in levels from the bottom up; refuses a holder too narrow."""
    from yadebreak.model import placement
    r, holder = 2.75e-3, 19.5e-3
    pos = placement.pouring_column(169, r, holder, np.random.default_rng(4))
    assert pos.shape == (169, 3)
    gaps = np.linalg.norm(pos[:, None] - pos[None], axis=2)[np.triu_indices(169, 1)] - 2 * r
    assert gaps.min() > 0.0
    assert np.linalg.norm(pos[:, :2], axis=1).max() < holder - r
    assert pos[:, 2].min() > r
    again = placement.pouring_column(169, r, holder, np.random.default_rng(4))
    assert np.array_equal(pos, again)                    # from its Generator alone
    with pytest.raises(ValueError, match="holder radius"):
        placement.pouring_column(3, r, 1.05 * r, np.random.default_rng(0))
