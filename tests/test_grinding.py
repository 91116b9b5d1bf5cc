"""The mechanistic mill model (yadebreak.studies.grinding): population balance against closed forms,
the capture model, the spectra file and its converter, and the known behaviours of batch ball
milling on small cases (docs/grinding.md). No YADE needed; every case runs in about a second."""
import csv
import dataclasses
import json
import math
import subprocess
import sys

import numpy as np
import pytest
from scipy.linalg import expm

from yadebreak.studies.grinding import (BatchGrinder, GrindingError, SpectraError, feed_masses,
                                from_mill_run, read_spectra, reid_batch, root2_classes,
                                synthetic_spectra, write_spectra)
from yadebreak.model.capture import PACKING_MONOLAYER
from yadebreak.studies.grinding.classes import FeedError
from yadebreak.studies.grinding.cli import parse_feed
from yadebreak.criteria import load_material
from yadebreak import model

COPPER = load_material("copper_ore")
#: copper ore so weak (E50 ~ 1e-9 J/kg) that every stressed particle breaks: the model reduces
#: to the linear population balance with the capture model's rates
BRITTLE = COPPER.with_params(e_inf=1e-9)


def single_size(d, count=4):
    return root2_classes(d * 2 ** 0.25, count)


def capture_rate(spectra, d, holdup):
    """Closed form of the capture model: the fraction of a class of size d (m) stressed per
    second, sum_j nu_j PACKING rho pi R_eff d^2 / M (capture.py), R_eff = R for two spheres."""
    r = 0.5 * spectra.ball_diameter_m
    r_eff = np.where(spectra.plane, 2 * r, r)
    mono = PACKING_MONOLAYER * COPPER.density * math.pi * r_eff * d ** 2 * spectra.ore_coverage
    return float(np.sum(spectra.rates_per_s * mono) / holdup)


# --------------------------------------------------------------------------- closed forms
def test_mass_is_conserved_to_round_off_batch_and_continuous():
    sp = synthetic_spectra(0.025)
    classes = single_size(4e-3, 6)
    g = BatchGrinder(COPPER, sp, classes, cells=50)
    m, f = feed_masses(classes, 4e-3, sp.ore_mass_kg)
    batch = g.run(m, f, [0.0, 60.0, 120.0])
    assert batch.fines[-1] > 0 and batch.masses[-1, 0] < 0.99 * m[0]     # it did grind
    assert batch.mass_relative_error < 1e-13
    cont = g.run(m, f, [0.0, 120.0], residence_time_s=30.0)
    assert cont.fed_mass > 3 * cont.initial_mass and cont.discharged_mass > 0
    assert cont.mass_relative_error < 1e-13


def test_single_class_with_constant_rate_decays_as_exp_minus_s_t():
    sp = synthetic_spectra(0.025)
    d = 2e-3
    classes = single_size(d, 2)
    to_fines = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 1.0]])   # broken mass leaves for the fines
    g = BatchGrinder(BRITTLE, sp, classes, cells=30, breakage_matrix=to_fines)
    m, f = feed_masses(classes, d, sp.ore_mass_kg)
    times = np.array([0.0, 5.0, 20.0, 60.0])
    res = g.run(m, f, times)
    s = capture_rate(sp, classes.sizes[0], sp.ore_mass_kg)
    assert s > 0.01                                               # e^-St well away from 1
    np.testing.assert_allclose(res.masses[:, 0] / m[0], np.exp(-s * times), rtol=1e-12)
    np.testing.assert_allclose(res.rates[1:, 0], s, rtol=1e-10)


def test_reid_solution_matches_the_matrix_exponential():
    s = np.array([0.3, 0.1, 0.05])
    b = np.array([[0, 0, 0], [0.6, 0, 0], [0.3, 0.7, 0]])
    m0 = np.array([1.0, 0.2, 0.0])
    a = -np.diag(s) + b * s[None, :]            # dm/dt = A m
    t = np.array([0.0, 1.0, 7.0, 30.0])
    exact = np.array([expm(a * ti) @ m0 for ti in t])
    np.testing.assert_allclose(reid_batch(s, b, m0, t), exact, rtol=1e-12, atol=1e-15)


def test_three_classes_with_a_known_breakage_matrix_follow_reid():
    """P = 1 in every stressing: S_i from the capture model (halving class to class: d^2), a fixed
    matrix: the linear population balance. The progeny of a step join their class at the step's
    end, an error of first order in the step: halving max_stressed halves it."""
    sp = synthetic_spectra(0.025, bins=10)
    classes = single_size(2e-3, 3)
    matrix = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.3, 0.6, 0.0], [0.2, 0.4, 1.0]])
    m, f = feed_masses(classes, 2e-3, sp.ore_mass_kg)
    s = np.array([capture_rate(sp, d, sp.ore_mass_kg) for d in classes.sizes])
    times = np.array([0.0, 10.0, 30.0, 60.0])
    exact = reid_batch(s, matrix[:3], m, times)
    errors = []
    for fraction in (0.04, 0.02):
        g = BatchGrinder(BRITTLE, sp, classes, cells=30, breakage_matrix=matrix,
                         max_stressed=fraction)
        res = g.run(m, f, times)
        errors.append(np.max(np.abs(res.masses - exact)) / m[0])
        assert res.mass_relative_error < 1e-13
    assert errors[1] < 2e-3                 # 0.072 % of the feed measured at 2 %/step
    assert errors[0] / errors[1] == pytest.approx(2.0, rel=0.15)    # first order in the step


# --------------------------------------------------------------------------- the DEM's conventions
def eq10_split(classes, i, t10):
    """Eq. 10 at t10 (%) for a parent of class i: the fractions landing in each class (those
    coarser than class i's lower sieve stay in it) and, last, the fines."""
    passing = model.progeny_passing(t10, BRITTLE.beta_params,
                                    classes.sieves[i:] / classes.sizes[i]) / 100.0
    passing[0] = 1.0
    out = np.zeros(classes.count + 1)
    out[i:classes.count] = passing[:-1] - passing[1:]
    out[-1] = passing[-1]
    return out


def test_t10_at_threshold_gives_every_breakage_eq9s_t10():
    """After one step from a one-class feed (progeny join their classes at its end, unbroken),
    the product below the feed class is Eq. 10 at Eq. 9's t10_min, whatever the collision's
    energy: here e_j / E ~ 1e9, where Eq. 8 gives t10 ~ A."""
    sp = synthetic_spectra(0.025, bins=10)
    d = 2e-3
    classes = single_size(d, 4)
    m, f = feed_masses(classes, d, sp.ore_mass_kg)
    expected = eq10_split(classes, 0, BRITTLE.t10_min)[1:]
    below = {}
    for t10_at in ("threshold", "collision"):
        res = BatchGrinder(BRITTLE, sp, classes, cells=30, t10_at=t10_at).run(m, f, [0.0, 0.05])
        assert res.steps == 1 and res.masses[1, 0] < 0.999 * m[0]
        below[t10_at] = np.append(res.masses[1, 1:], res.fines[1])
    np.testing.assert_allclose(below["threshold"] / below["threshold"].sum(),
                               expected / expected.sum(), rtol=1e-10)
    assert below["collision"][-1] / below["collision"].sum() > 5 * expected[-1] / expected.sum()


def test_progeny_dmin_makes_progeny_break_once_and_be_spread_by_eq10():
    """Every stressed particle breaks (BRITTLE) and no progeny may break again (progeny_dmin 1 m
    against classes of 2 mm): the feed leaves at S_0, its progeny (Eq. 10 at t10_min, the part
    coarser than the class's lower sieve staying in it) join unbreakable pools that are
    stressed at S_l and, stressed once, are spread by Eq. 10 at t10_min and stop. That linear
    system (matrix exponential) gives the product and the mass stressed once, to the step's
    first-order error (progeny join at the step's end)."""
    sp = synthetic_spectra(0.025, bins=10)
    d = 2e-3
    classes = single_size(d, 4)
    n = classes.count
    m, f = feed_masses(classes, d, sp.ore_mass_kg)
    t10 = BRITTLE.t10_min
    s = np.array([capture_rate(sp, di, sp.ore_mass_kg) for di in classes.sizes])
    b = eq10_split(classes, 0, t10)
    # state: feed, unbreakable pools u_0..u_(n-1), stressed-once pools w_0..w_(n-1)
    a = np.zeros((1 + 2 * n, 1 + 2 * n))
    a[0, 0] = -s[0]
    a[1:n + 1, 0] = b[:n] * s[0]
    a[range(1, n + 1), range(1, n + 1)] = -s
    a[range(n + 1, 2 * n + 1), range(1, n + 1)] = s
    spread = np.array([eq10_split(classes, i, t10) for i in range(n)])       # (n, n + 1)
    times = np.array([0.0, 2.0, 6.0])
    exact = []
    for t in times:
        x = expm(a * t) @ np.concatenate([[m[0]], np.zeros(2 * n)])
        product = np.append(x[1:n + 1], b[n] * (m[0] - x[0])) + x[n + 1:] @ spread
        product[0] += x[0]
        exact.append(np.append(product, x[n + 1:].sum()))      # classes, fines, stressed once
    errors = []
    for fraction in (0.02, 0.01):
        g = BatchGrinder(BRITTLE, sp, classes, cells=30, t10_at="threshold", progeny_dmin=1.0,
                         max_stressed=fraction)
        assert g.unbreakable_class.all()
        res = g.run(m, f, times)
        got = np.column_stack([res.masses, res.fines, res.once_broken])
        errors.append(np.max(np.abs(got - np.array(exact))) / m[0])
        assert res.mass_relative_error < 1e-13
    assert errors[1] < 2e-3                 # 0.14 % of the feed measured at 1 %/step
    assert errors[0] / errors[1] == pytest.approx(2.0, rel=0.15)    # first order in the step
    assert res.once_broken[-1] > 0.5 * m[0]                  # the pools did break, once
    # without the rule the progeny break again and again: a finer product
    free = BatchGrinder(BRITTLE, sp, classes, cells=30, t10_at="threshold").run(m, f, times)
    assert free.fines[-1] > 1.25 * res.fines[-1]


def test_progeny_dmin_spares_the_feed_and_coarse_enough_progeny():
    """Only classes with X_MIN d < progeny_dmin receive unbreakable progeny; the feed breaks at
    its fresh rate whatever the rule (the same as without it over the first step)."""
    sp = synthetic_spectra(0.025, bins=10)
    classes = single_size(8e-3, 6)
    limit = model.X_MIN * classes.sizes[2] * 1.001                # classes 2.. are below it
    g = BatchGrinder(COPPER, sp, classes, cells=40, progeny_dmin=limit)
    np.testing.assert_array_equal(g.unbreakable_class, [False, False, True, True, True, True])
    m, f = feed_masses(classes, 8e-3, sp.ore_mass_kg)
    with_rule = g.run(m, f, [0.0, 1e-3])
    without = BatchGrinder(COPPER, sp, classes, cells=40).run(m, f, [0.0, 1e-3])
    np.testing.assert_allclose(with_rule.masses, without.masses, rtol=1e-12)
    cont = g.run(m, f, [0.0, 60.0], residence_time_s=20.0)
    assert cont.once_broken[-1] > 0 and cont.mass_relative_error < 1e-13


@pytest.mark.parametrize("options, message", [
    ({"t10_at": "read"}, "t10_at = 'read'"),
    ({"progeny_dmin": 0.0}, "progeny_dmin = 0.0 m"),
    ({"t10_at": "threshold", "breakage_matrix": np.eye(5, 4)}, "breakage_matrix"),
])
def test_bad_convention_options_are_refused(options, message):
    with pytest.raises(GrindingError, match=message):
        BatchGrinder(COPPER, synthetic_spectra(0.025), single_size(2e-3, 4), cells=20, **options)


# --------------------------------------------------------------------------- capture model
def test_a_collision_gives_the_mills_energy_to_what_it_catches():
    """Single size: e = E share (1 - exp(-nbar)) / m_cap, nbar = m_cap / m_p: the monolayer's
    E / m_cap when many are caught, one particle's E / m_p when nbar << 1."""
    sp = synthetic_spectra(0.025)
    classes = single_size(5e-3, 3)
    g = BatchGrinder(COPPER, sp, classes, cells=30)
    m, f = feed_masses(classes, 5e-3, sp.ore_mass_kg)
    e, nbar = g.stressing(*g.fresh_state(m, f))
    d = classes.sizes[0]
    m_cap = PACKING_MONOLAYER * COPPER.density * math.pi * 0.0125 * d ** 2
    m_p = COPPER.density * math.pi / 6 * d ** 3
    share = 1 / (1 + COPPER.hertz_stiffness / load_material("steel").hertz_stiffness)
    np.testing.assert_allclose(nbar, m_cap / m_p, rtol=1e-12)
    np.testing.assert_allclose(e, sp.energy_J * share * -np.expm1(-m_cap / m_p) / m_cap,
                               rtol=1e-12)


# --------------------------------------------------------------------------- batch behaviour
def test_first_order_at_first_then_the_published_departure():
    """A single-size feed leaves its class at first at the rate of the fresh distribution:
    S0 = sum_j lambda_j P(e_j) (Eqs. 1-3 and the capture closed form), net of the progeny that
    stay in the class (Eqs. 8 and 10, at quantiles of the fresh distribution). Without damage
    the weakest go first and the rate falls; with damage (Eqs. 5-6) the survivors weaken and
    the rate rises above the no-damage one: both departures of coarse feeds from first order."""
    sp = synthetic_spectra(0.025)
    d = 4e-3
    classes = single_size(d, 4)
    m, f = feed_masses(classes, d, sp.ore_mass_kg)
    d_class = classes.sizes[0]
    m_cap = PACKING_MONOLAYER * COPPER.density * math.pi * 0.0125 * d_class ** 2
    nbar = m_cap / (COPPER.density * math.pi / 6 * d_class ** 3)
    share = 1 / (1 + COPPER.hertz_stiffness / load_material("steel").hertz_stiffness)
    e = sp.energy_J * share * -np.expm1(-nbar) / m_cap
    lam = capture_rate(sp, d_class, sp.ore_mass_kg) / sp.rates_per_s.sum() * sp.rates_per_s
    gross = np.sum(lam * COPPER.fracture_energy_cdf(e, d_class))
    plain_model = BatchGrinder(COPPER, sp, classes, cells=120, damage=False)
    assert plain_model.initial_rates(m)[0] == pytest.approx(gross, rel=1e-12)
    net = plain_model.initial_rates(m, net=True)[0]
    assert 0.2 * gross < net < gross
    # the first ms: first order at S0, to the discretisation in 120 cells (2 %; 0.6 % with 480).
    # Not for long: the weakest tail breaks under the frequent weak collisions within ~0.1 s.
    times = [0.0, 1e-3, 120.0, 240.0]
    plain = plain_model.run(m, f, times)
    damaged = BatchGrinder(COPPER, sp, classes, cells=120).run(m, f, times)
    assert plain.rates[1, 0] == pytest.approx(net, rel=0.03)
    assert damaged.rates[1, 0] == pytest.approx(net, rel=0.03)
    # no damage: the weakest went first, the rest breaks ever slower
    assert plain.rates[3, 0] < 0.5 * plain.rates[1, 0]
    # damage: the survivors weaken, breakage speeds up and more is gone
    assert damaged.rates[3, 0] > 2.0 * plain.rates[3, 0]
    assert damaged.masses[-1, 0] < plain.masses[-1, 0]


def initial_rate(spectra, d):
    classes = single_size(d, 3)
    g = BatchGrinder(COPPER, spectra, classes, cells=40)
    return g.initial_rates(*feed_masses(classes, d, spectra.ore_mass_kg))[0]


def test_breakage_rate_has_a_maximum_against_feed_size():
    sp = synthetic_spectra(0.025)
    sizes = np.array([0.1, 0.3, 1.0, 2.0, 4.0, 8.0]) * 1e-3
    rates = np.array([initial_rate(sp, d) for d in sizes])
    top = int(np.argmax(rates))
    assert 0 < top < len(sizes) - 1
    assert rates[top] > 3 * rates[0] and rates[top] > 3 * rates[-1]


def test_larger_balls_grind_coarse_feed_faster_and_fine_feed_slower():
    """Synthetic spectra (same power, Bond): 40 mm balls give fewer, stronger collisions than
    25 mm ones: faster for 8 mm feed, slower for 0.1 mm feed, where every capture breaks and
    the rate goes with the number of collisions; the maximum moves to coarser sizes."""
    small, large = synthetic_spectra(0.025), synthetic_spectra(0.040)
    assert initial_rate(large, 8e-3) > 5 * initial_rate(small, 8e-3)
    assert initial_rate(large, 1e-4) < initial_rate(small, 1e-4)
    sizes = np.array([0.3, 0.7, 1.4, 2.8, 5.6]) * 1e-3
    peak = [sizes[np.argmax([initial_rate(sp, d) for d in sizes])] for sp in (small, large)]
    assert peak[1] > peak[0]


# --------------------------------------------------------------------------- spectra file
def test_spectra_file_round_trip(tmp_path):
    sp = synthetic_spectra(0.03, bins=12)
    back = read_spectra(write_spectra(tmp_path / "s.csv", sp))
    assert back.pair_type == sp.pair_type and back.energy_basis == "collision"
    np.testing.assert_array_equal(back.events, sp.events)
    np.testing.assert_array_equal(back.energy_low_J, sp.energy_low_J)
    assert back.extra["power_W"] == sp.extra["power_W"]


def _bad(tmp_path, text):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(SpectraError) as info:
        read_spectra(path)
    message = str(info.value)
    assert "\n" not in message and str(path) in message
    return message


GOOD_META = {"format": "yadebreak-spectra", "version": 1, "simulated_time_s": 1.0,
             "ore_mass_kg": 1.0, "ball_diameter_m": 0.025, "energy_basis": "collision"}
HEADER = "pair_type,energy_low_J,energy_high_J,events\n"


def test_bad_spectra_files_get_one_line(tmp_path):
    meta = "# " + json.dumps(GOOD_META) + "\n"
    assert "events = -3.0" in _bad(tmp_path, meta + HEADER + "ball-ball,0.001,0.002,-3\n")
    assert "pair_type = 'ball-rock'" in _bad(tmp_path, meta + HEADER + "ball-rock,0.001,0.002,3\n")
    assert "energy bin" in _bad(tmp_path, meta + HEADER + "ball-ball,0.002,0.001,3\n")
    assert "not a yadebreak-spectra file" in _bad(tmp_path, "energy_low_J_per_kg,x\n1,2\n")
    assert "simulated_time_s = 0" in _bad(tmp_path, "# " + json.dumps(
        {**GOOD_META, "simulated_time_s": 0}) + "\n" + HEADER + "ball-ball,0.001,0.002,3\n")
    assert "energy_basis" in _bad(tmp_path, "# " + json.dumps(
        {**GOOD_META, "energy_basis": "kinetic"}) + "\n" + HEADER + "ball-ball,0.001,0.002,3\n")
    assert "no events" in _bad(tmp_path, meta + HEADER)


def test_a_feed_distribution_is_split_at_the_sieves():
    size = np.array([0.5, 1.0, 2.0, 4.0]) * 1e-3
    passing = np.array([10.0, 30.0, 60.0, 100.0])
    classes = root2_classes(4e-3, 4)                  # sieves 4, 2.83, 2, 1.41, 1 mm
    masses, fines = feed_masses(classes, (size, passing), 2.0)
    # linear in passing against ln size: 2.83 mm is half-way from 2 to 4 mm in ln size
    np.testing.assert_allclose(masses, 2.0 * np.array([20.0, 20.0, 15.0, 15.0]) / 100, rtol=1e-12)
    assert fines == pytest.approx(2.0 * 0.30, rel=1e-12)
    with pytest.raises(FeedError, match="passes the top sieve"):
        feed_masses(root2_classes(3e-3, 4), (size, passing), 2.0)


def test_bad_feed_and_material_are_refused():
    sp = synthetic_spectra(0.025)
    classes = single_size(2e-3, 4)
    with pytest.raises(FeedError, match="outside the classes"):
        feed_masses(classes, 10e-3, 1.0)
    with pytest.raises(GrindingError, match="--material steel"):
        BatchGrinder(load_material("steel"), sp, classes)
    with pytest.raises(GrindingError, match="--material ab_t10_ore"):
        BatchGrinder(load_material("ab_t10_ore"), sp, classes)


def test_cli_refuses_bad_spectra_before_integrating(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("# " + json.dumps(GOOD_META) + "\n" + HEADER + "ball-ball,0.001,0.002,-1\n")
    out = tmp_path / "out"
    run = subprocess.run([sys.executable, "-m", "yadebreak", "grind", str(bad), "--out", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 2
    assert run.stderr.count("\n") == 1 and "events = -1.0" in run.stderr
    assert not (out / "psd.csv").exists()


# --------------------------------------------------------------------------- mill converter
def test_mill_spectra_convert_so_the_model_gives_back_the_dem_rate(tmp_path):
    """A mill run records particle stressing events of its feed size; converted to collisions
    (spectra.from_mill_run), the model's initial rate at that size is the DEM's own:
    sum over bins of events/s P(e) / number of particles."""
    d0, ore_mass, duration = 5.5e-3, 0.8, 0.5
    edges = np.geomspace(0.5, 2000.0, 13)
    rates = {"ball-ore": np.linspace(400, 10, 12), "ore-ore": np.linspace(900, 1, 12),
             "ore-liner": np.linspace(80, 0, 12)}
    (tmp_path / "summary.json").write_text(json.dumps({
        "material": "copper_ore", "size": d0, "ball_size": 0.025, "initial_mass": ore_mass,
        "simulated_time": duration}))
    with open(tmp_path / "collision_spectra.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["energy_low_J_per_kg", "energy_high_J_per_kg"] + [
            f"{k}_{what}" for k in rates for what in ("per_s", "at_or_above_per_s")])
        for j in range(12):
            w.writerow([edges[j], edges[j + 1]] + [v for k in rates for v in (
                rates[k][j], rates[k][j:].sum())])
    sp = read_spectra(write_spectra(tmp_path / "spectra.csv", from_mill_run(tmp_path, load_material)))
    assert sp.energy_basis == "absorbed" and sp.ore_mass_kg == ore_mass
    e = np.sqrt(edges[:-1] * edges[1:])
    particles = ore_mass / (COPPER.density * math.pi / 6 * d0 ** 3)
    dem = sum(np.sum(r * COPPER.fracture_energy_cdf(e, d0)) for r in rates.values()) / particles
    classes = root2_classes(d0 * 2 ** 0.25, 3)
    g = BatchGrinder(COPPER, sp, classes, cells=40)
    m = np.array([ore_mass, 0.0, 0.0])
    # the class's representative size is d0 itself: the same P and the same energies
    assert classes.sizes[0] == pytest.approx(d0, rel=1e-14)
    assert g.initial_rates(m)[0] == pytest.approx(dem, rel=1e-10)


def test_grind_command_writes_the_product_over_time(tmp_path):
    spectra = write_spectra(tmp_path / "s.csv", synthetic_spectra(0.03, bins=20))
    out = tmp_path / "g"
    run = subprocess.run([sys.executable, "-m", "yadebreak", "grind", str(spectra), "--feed",
                          "3", "--minutes", "1", "--interval", "0.5", "--classes", "6",
                          "--cells", "40", "--out", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["mass_relative_error"] < 1e-13
    with open(out / "psd.csv") as f:
        rows = list(csv.DictReader(f))
    assert set(rows[0]) == {"minutes", "size_mm", "passing_percent"}
    assert sorted({float(r["minutes"]) for r in rows}) == [0.0, 0.5, 1.0]
    last = [float(r["passing_percent"]) for r in rows if float(r["minutes"]) == 1.0]
    assert last[0] == pytest.approx(100.0) and np.all(np.diff(last) <= 1e-9) and last[1] < 100
    assert summary["specific_energy_kWh_per_t"] > 0 and (out / "grind.png").is_file()


# --------------------------------------------------------------------------- units and the disk
@pytest.mark.parametrize("text_value", ["8", "8mm", "8 mm", "0.8cm", "0.008 m", "8e-3m"])
def test_feed_size_plain_in_mm_or_with_a_length_unit(text_value):
    assert parse_feed(text_value) == pytest.approx(8e-3, rel=1e-15)


def test_feed_outside_the_particle_sizes_or_not_a_size_is_refused(tmp_path):
    with pytest.raises(FeedError, match=r"--feed = 2 m: must be in \[0.001, 1000\] \(mm\)"):
        parse_feed("2 m")
    with pytest.raises(FeedError, match=r"--feed = 0: must be in \[0.001, 1000\] \(mm\)"):
        parse_feed("0")
    for other in ("8 kg", "5.5km", "5.5kg"):                    # a quantity, not a length
        with pytest.raises(FeedError, match=rf"--feed = {other}: a size takes a length unit"):
            parse_feed(other)
    with pytest.raises(FeedError, match="--feed = abc: neither a size .* nor a CSV file"):
        parse_feed("abc")


@pytest.mark.parametrize("argv, line", [
    (["--feed", "5.5kg"], "--feed = 5.5kg: a size takes a length unit"),
    (["--feed", "abc"], "--feed = abc: neither a size"),
    (["--interval", "20", "--minutes", "1"], "--interval = 20 min: accepted up to --minutes"),
])
def test_grind_refuses_nonsense_in_one_line_before_writing(tmp_path, capsys, argv, line):
    """Every quantity read as one (a unit that is not a length is not a file name), and an
    interval longer than the grinding: one line, exit 2, no --out left."""
    from yadebreak.cli import main
    out = tmp_path / "g"
    with pytest.raises(SystemExit) as end:
        main(["grind", "synthetic:30", "--material", "copper_ore", "--feed", "8mm", *argv,
              "--out", str(out)])
    err = [l for l in capsys.readouterr().err.splitlines() if "error" in l]
    assert end.value.code == 2 and len(err) == 1 and line in err[0], err
    assert not out.exists()


def test_grind_on_a_full_disk_ends_in_one_line_and_leaves_whole_files(tmp_path, capsys,
                                                                      monkeypatch):
    """The disk fills at the third file (psd.csv and breakage_rate.csv written before): exit 1,
    one line naming the two files kept, each whole, and no temporary file."""
    import errno
    import os
    from yadebreak.cli import main
    real, calls = os.replace, []

    def replace(src, dst):
        calls.append(dst)
        if len(calls) > 3:              # spectra.csv, psd.csv, breakage_rate.csv, then full
            raise OSError(errno.ENOSPC, "No space left on device")
        real(src, dst)
    monkeypatch.setattr(os, "replace", replace)
    out = tmp_path / "g"
    with pytest.raises(SystemExit) as end:
        main(["grind", "synthetic:30", "--feed", "3mm", "--minutes", "60 s", "--classes", "6",
              "--cells", "40", "--out", str(out)])
    assert end.value.code == 1
    err = [line for line in capsys.readouterr().err.splitlines() if "error" in line]
    assert err == ["[yadebreak] error: cannot write: No space left on device; kept in "
                   f"{out}: breakage_rate.csv, psd.csv, spectra.csv"]
    assert sorted(p.name for p in out.iterdir()) == [".yadebreak.lock", "breakage_rate.csv",
                                                     "psd.csv", "spectra.csv"]   # the run's lock
    with open(out / "psd.csv") as f:
        rows = list(csv.DictReader(f))
    assert sorted({float(r["minutes"]) for r in rows}) == [0.0, 0.5, 1.0]     # whole
