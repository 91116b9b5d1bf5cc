"""The ball-mill model layer (yadebreak.model.milling): no YADE needed. Every expected number is written
out here from its closed form, not obtained by calling the function under test again."""
import math

import numpy as np
import pytest

from yadebreak.model import milling


# --------------------------------------------------------------------------- critical speed
def test_critical_speed_is_the_classical_42_3_rpm():
    # 42.3 / sqrt(D - d) rpm, D = 1 m, d = 0: 42.3 / 60 rev/s (the 42.3 is rounded: 0.05 % off)
    assert milling.critical_speed(1.0) == pytest.approx(42.3 / 60.0, rel=1e-3)
    assert milling.critical_speed(1.0, 0.0) == pytest.approx(math.sqrt(2 * 9.81) / (2 * math.pi),
                                                             rel=1e-14)
    # D = 0.25 m, d = 0.02 m: D - d = 0.23 m
    assert milling.critical_speed(0.25, 0.02) == pytest.approx(42.3 / math.sqrt(0.23) / 60.0,
                                                               rel=1e-3)


def test_critical_speed_broadcasts():
    n = milling.critical_speed(np.array([1.0, 4.0]), np.array([0.0, 0.0]))
    # 4 m is 4 times 1 m: half the speed
    np.testing.assert_allclose(n, [0.7049683721740053, 0.7049683721740053 / 2], rtol=1e-14)


@pytest.mark.parametrize("d_drum, d_ball", [(0.1, 0.1), (0.1, 0.2), (0.0, 0.0), (-1.0, 0.0)])
def test_critical_speed_needs_the_drum_larger_than_the_ball(d_drum, d_ball):
    with pytest.raises(ValueError, match="drum diameter"):
        milling.critical_speed(d_drum, d_ball)


# --------------------------------------------------------------------------- Bond
def test_bond_check_value():
    # 4.879 D^0.3 (3.2 - 3 Vp) Cs (1 - 0.1 / 2^(9 - 10 Cs)) at D = 0.25 m, Vp = 0.3, Cs = 0.75:
    # 0.25^0.3 = 0.659754..., 3.2 - 0.9 = 2.3, 9 - 7.5 = 1.5, 1 - 0.1 / 2^1.5 = 0.964644...
    expected = 4.879 * 0.25 ** 0.3 * 2.3 * 0.75 * (1.0 - 0.1 / 2.0 ** 1.5)
    assert expected == pytest.approx(5.356354, rel=1e-6)              # kW/t = W/kg of balls
    assert milling.bond_mill_power_per_ball_mass(0.25, 0.3, 0.75) == pytest.approx(expected,
                                                                                  rel=1e-14)


def test_bond_rises_with_speed_and_falls_with_filling():
    speed = np.linspace(0.6, 0.8, 21)
    p = milling.bond_mill_power_per_ball_mass(0.25, 0.3, speed)
    assert p.shape == (21,) and np.all(np.diff(p) > 0)
    filling = np.linspace(0.1, 0.5, 21)
    p = milling.bond_mill_power_per_ball_mass(0.25, filling, 0.75)
    assert p.shape == (21,) and np.all(np.diff(p) < 0)
    # D^0.3 scaling: a drum 2^(10/3) times larger draws twice the power per kg of balls
    ratio = (milling.bond_mill_power_per_ball_mass(0.25 * 2 ** (10 / 3), 0.3, 0.75)
             / milling.bond_mill_power_per_ball_mass(0.25, 0.3, 0.75))
    assert ratio == pytest.approx(2.0, rel=1e-12)


# --------------------------------------------------------------------------- torque arm
def test_charge_torque_power():
    assert milling.charge_torque_power(10.0, 0.05, 7.0) == pytest.approx(10 * 9.81 * 0.05 * 7,
                                                                         rel=1e-14)
    p = milling.charge_torque_power(np.array([10.0, 2.0]), np.array([0.05, 0.1]), 7.0)
    np.testing.assert_allclose(p, [34.335, 2 * 9.81 * 0.1 * 7], rtol=1e-14)


# --------------------------------------------------------------------------- breakage rate
def test_breakage_rate_recovers_exact_exponential():
    t = np.linspace(0.0, 1.0, 11) + 0.3                 # not starting at 0: shifted internally
    m = 0.8 * np.exp(-2.5 * (t - 0.3))
    rate, err = milling.first_order_breakage_rate(t, m)
    assert rate == pytest.approx(2.5, abs=1e-12)
    assert err < 1e-10


def test_breakage_rate_within_its_standard_error_on_noisy_data():
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 2.0, 11)
    noise = np.concatenate([[0.0], rng.normal(0.0, 0.05, t.size - 1)])   # m(0) is the reference
    m = np.exp(-2.5 * t + noise)
    rate, err = milling.first_order_breakage_rate(t, m)
    assert 0.0 < err < 0.1
    assert abs(rate - 2.5) < 3 * err
    # the slope through the origin and its standard error, written out
    y = np.log(m[1:] / m[0])
    tt = t[1:]
    slope = -np.sum(tt * y) / np.sum(tt * tt)
    se = math.sqrt(np.sum((y + slope * tt) ** 2) / (tt.size - 1) / np.sum(tt * tt))
    assert rate == pytest.approx(slope, rel=1e-12)
    assert err == pytest.approx(se, rel=1e-12)


def test_breakage_rate_drops_zero_masses():
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    m = np.array([1.0, math.exp(-0.5), math.exp(-1.0), 0.0, 0.0])
    rate, err = milling.first_order_breakage_rate(t, m)
    assert rate == pytest.approx(0.5, rel=1e-12)
    assert err < 1e-12


def test_breakage_rate_two_points_has_no_standard_error():
    rate, err = milling.first_order_breakage_rate([0.0, 2.0], [1.0, math.exp(-3.0)])
    assert rate == pytest.approx(1.5, rel=1e-12)
    assert math.isnan(err)


@pytest.mark.parametrize("t, m, match", [
    ([0.0, 1.0, 2.0], [0.0, 0.5, 0.2], "first mass"),
    ([0.0, 1.0, 2.0], [-1.0, 0.5, 0.2], "first mass"),
    ([0.0, 1.0, 2.0], [1.0, 0.0, 0.0], "fewer than 2"),
    ([0.0], [1.0], "fewer than 2"),
    ([], [], "first mass"),
    ([0.0, 1.0, 2.0], [1.0, -0.1, 0.2], "non-negative"),
    ([0.0, 0.0, 2.0], [1.0, 0.5, 0.2], "after times"),
    ([0.0, 1.0], [1.0, 0.5, 0.2], "masses"),
])
def test_breakage_rate_errors(t, m, match):
    with pytest.raises(ValueError, match=match):
        milling.first_order_breakage_rate(t, m)


# --------------------------------------------------------------------------- sieves
def test_size_classes_root_two_series():
    s = milling.size_classes(1e-3, 4)
    r = math.sqrt(2)
    np.testing.assert_allclose(s, [1e-3, 1e-3 / r, 0.5e-3, 0.5e-3 / r, 0.25e-3], rtol=1e-15)
    np.testing.assert_array_equal(milling.size_classes(4e-3, 2, ratio=2.0), [4e-3, 2e-3, 1e-3])


@pytest.mark.parametrize("top, n, ratio", [(0.0, 3, 2.0), (1e-3, 0, 2.0), (1e-3, 2.5, 2.0),
                                           (1e-3, 3, 1.0)])
def test_size_classes_errors(top, n, ratio):
    with pytest.raises(ValueError):
        milling.size_classes(top, n, ratio)


def test_mass_in_classes_hand_example():
    sieves = [4e-3, 2e-3, 1e-3]                  # class 0: (2, 4] mm, class 1: (1, 2] mm
    sizes = [4e-3, 3e-3, 2e-3, 1.5e-3, 1e-3, 5e-3, 0.5e-3]
    masses = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0]
    # 4 mm (at the top sieve) and 3 mm -> class 0; 2 mm (at the sieve topping class 1) and 1.5 mm
    # -> class 1; 1 mm (at the finest sieve), 5 mm (above the top) and 0.5 mm -> nowhere
    np.testing.assert_array_equal(milling.mass_in_classes(sizes, masses, sieves), [3.0, 12.0])


def test_mass_in_classes_conserves_mass_inside_the_range():
    rng = np.random.default_rng(3)
    sieves = milling.size_classes(8e-3, 10)
    sizes = np.concatenate([rng.uniform(sieves[-1], sieves[0], 500), sieves[:-1]])
    sizes = sizes[sizes > sieves[-1]]
    masses = rng.uniform(0.1, 1.0, sizes.size)
    out = milling.mass_in_classes(sizes, masses, sieves)
    assert out.shape == (10,)
    assert out.sum() == pytest.approx(masses.sum(), rel=1e-12)
    # against a plain loop over the classes
    loop = [masses[(sizes > sieves[k + 1]) & (sizes <= sieves[k])].sum() for k in range(10)]
    np.testing.assert_allclose(out, loop, rtol=1e-12)


@pytest.mark.parametrize("sieves", [[1e-3], [1e-3, 2e-3], [2e-3, 2e-3, 1e-3]])
def test_mass_in_classes_needs_descending_sieves(sieves):
    with pytest.raises(ValueError, match="descending"):
        milling.mass_in_classes([1e-3], [1.0], sieves)


# --------------------------------------------------------------------------- energy spectrum
def test_event_spectrum_hand_example():
    energies = [0.5, 1.0, 1.5, 2.0, 3.0, 10.0]          # J/kg, seen in 2 s
    rate, cumulative = milling.event_spectrum(energies, 2.0, [1.0, 2.0, 4.0])
    # [1, 2): 1.0 and 1.5; [2, 4): 2.0 and 3.0; >= 1: five events; >= 2: three (10.0 included)
    np.testing.assert_array_equal(rate, [2 / 2.0, 2 / 2.0])
    np.testing.assert_array_equal(cumulative, [5 / 2.0, 3 / 2.0])


def test_event_spectrum_cumulative_is_non_increasing():
    rng = np.random.default_rng(3)
    energies = rng.lognormal(0.0, 1.5, 2000)
    edges = np.logspace(-2, 2, 30)
    rate, cumulative = milling.event_spectrum(energies, 0.5, edges)
    assert np.all(np.diff(cumulative) <= 0)
    assert cumulative[0] == pytest.approx(np.sum(energies >= edges[0]) / 0.5, rel=1e-14)
    # the bins' rates are the steps of the cumulative rate
    np.testing.assert_allclose(rate[:-1], cumulative[:-1] - cumulative[1:], rtol=1e-12)
    assert rate.sum() == pytest.approx(
        np.sum((energies >= edges[0]) & (energies < edges[-1])) / 0.5, rel=1e-14)


@pytest.mark.parametrize("duration", [0.0, -1.0])
def test_event_spectrum_needs_a_positive_duration(duration):
    with pytest.raises(ValueError, match="duration"):
        milling.event_spectrum([1.0], duration, [0.0, 2.0])


def test_event_spectrum_needs_ascending_bins():
    with pytest.raises(ValueError, match="ascending"):
        milling.event_spectrum([1.0], 1.0, [2.0, 1.0])
