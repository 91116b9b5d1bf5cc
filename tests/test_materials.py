"""The material library and its validation (no YADE needed)."""
import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

import yadebreak
from yadebreak import model
from yadebreak.model.materials import MaterialError, available_materials
from yadebreak.criteria import load_material

GOOD = (yadebreak.model.materials.MATERIALS_DIR / "copper_ore.toml").read_text()


def test_every_shipped_material_loads():
    names = available_materials()
    for expected in ["copper_ore", "limestone", "granulite", "iron_ore_1", "iron_ore_2",
                     "limestone_2", "steel", "rubber"]:
        assert expected in names
    for name in names:
        mat = load_material(name)
        assert mat.name == name
        if mat.breakable:
            assert set(mat.beta_params) == set(model.N_VALUES)
            assert 0 < mat.t10_min < mat.t10_ceiling


def test_units_converted_to_si_once():
    cu = load_material("copper_ore")
    assert cu.young_modulus == 52e9 and cu.params.d0 == pytest.approx(8.07e-3)
    assert cu.params.device_stiffness == 230e9 and cu.params.A == 67.7
    assert cu.beta_params[1.2] == (0.51, 11.95) and cu.beta_source == "material"
    assert load_material("iron_ore_1").beta_params == model.TABLE1_BETA_PARAMS
    assert load_material("rubber").hertz_stiffness == pytest.approx(1.3e9, rel=1e-9)


def test_material_is_immutable():
    cu = load_material("copper_ore")
    with pytest.raises(dataclasses.FrozenInstanceError):
        cu.params.sigma = 1.0
    with pytest.raises(TypeError):
        cu.beta_params[1.2] = (1, 1)


def test_contacts_table6_and_rubber_borrows_steel():
    cu, st, ru = (load_material(n) for n in ("copper_ore", "steel", "rubber"))
    assert cu.contact_with(st).restitution == 0.39
    assert st.contact_with(cu).restitution == 0.39
    assert cu.contact_with(cu).rolling_friction == 0.27
    assert st.contact_with(st).restitution == 0.50
    assert cu.contact_with(ru) == cu.contact_with(st)
    assert cu.energy_partition(st) == pytest.approx(0.806, abs=5e-4)


def test_breakage_probability_uses_partner_share():
    cu, st = load_material("copper_ore"), load_material("steel")
    e50 = cu.median_fracture_energy(5.5e-3)
    assert cu.breakage_probability(e50 * cu.params.emax_ratio / (cu.params.emax_ratio + 1) / 0.8062, 5.5e-3,
                                   partner=st) == pytest.approx(0.5, abs=1e-3)


def test_unknown_name_lists_available():
    with pytest.raises(MaterialError, match="available are .*copper_ore"):
        load_material("unobtainium")


def _write(tmp_path, text, name="bad.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("old, new, message", [
    ("sigma = 0.799 ", "sigma = 0 ", r"breakage.sigma = 0 - is out of range: accepted \(0, 10\]"),
    ("sigma = 0.799 ", "sigma = -1 ", "breakage.sigma"),
    ("emax_ratio = 100 ", "emax_ratio = 1 ", r"breakage.emax_ratio = 1 - is out of range: accepted \(1, inf\)"),
    ("A = 67.7 ", "A = 0 ", r"breakage.A = 0 % is out of range: accepted \(0, 100\]"),
    ("A = 67.7 ", "A = 101 ", "breakage.A = 101 %"),
    ("b_prime = 0.029 ", "b_prime = 0 ", "breakage.b_prime"),
    ("gamma = 5.0 ", "gamma = -2 ", "breakage.gamma"),
    ("d0 = 8.07 ", "d0 = -8.07 ", "breakage.d0 = -8.07 mm is out of range"),
    ('"1.2" = [0.51, 11.95]', '"1.2" = [0, 11.95]', r'breakage.beta."1.2" = \[0, 11.95\]: alpha and beta must be > 0'),
    ('"75" = [1.03, 0.30]', '"75" = [1.03, -0.30]', 'breakage.beta."75"'),
    ("density = 2930 ", "density = 29300000 ", "elastic.density"),
    ("young_modulus = 52 ", "young_modulus = 0 ", "elastic.young_modulus = 0 GPa is out of range"),
    ("poisson_ratio = 0.25 ", "poisson_ratio = 0.7 ", r"elastic.poisson_ratio = 0.7 - is out of range: accepted \[0, 0.5\)"),
    ("restitution = 0.39", "restitution = 1.5", "contact.steel.restitution"),
    ("sigma = 0.799 ", 'sigma = "wide" ', "breakage.sigma: must be a number"),
    ("phi = 1.22 ", "phi = true ", "breakage.phi: must be a number"),
    ("gamma = 5.0 ", "gamma = 5.0\ncolour = 3 ", "breakage.colour: unknown key"),
    ("e_inf = 213.5 ", "", "breakage.e_inf: missing"),
    ('"50" = [1.03, 0.36]\n', "", 'breakage.beta."50": missing'),
    ("breakable = true", "breakable = 1", "breakable: missing or not true/false"),
])
def test_each_validation_error_names_field_and_range(tmp_path, old, new, message):
    assert old in GOOD
    with pytest.raises(MaterialError, match=message) as info:
        load_material(_write(tmp_path, GOOD.replace(old, new)))
    assert str(tmp_path / "bad.toml") in str(info.value)


# physically absurd values, refused before a run (a modulus of 1e-300 GPa used to overflow the
# time step midway): the ranges of yadebreak/intervals.py, in the file's unit
@pytest.mark.parametrize("old, new, message", [
    ("young_modulus = 52 ", "young_modulus = 1e-300 ",
     r"elastic.young_modulus = 1e-300 GPa is out of range: accepted \[0.0001, 1500\] GPa$"),
    ("young_modulus = 52 ", "young_modulus = 1e4 ", r"elastic.young_modulus = 10000 GPa"),
    ("density = 2930 ", "density = 1e-300 ",
     r"elastic.density = 1e-300 kg/m3 is out of range: accepted \[100, 25000\] kg/m3$"),
    ("poisson_ratio = 0.25 ", "poisson_ratio = -0.3 ",
     r"elastic.poisson_ratio = -0.3 - is out of range: accepted \[0, 0.5\)$"),
    ("d0 = 8.07 ", "d0 = 1e300 ", r"breakage.d0 = 1e\+300 mm is out of range: accepted "
                                  r"\[0.001, 1000\] mm$"),
    ("d0 = 8.07 ", "d0 = 1e-300 ", r"breakage.d0 = 1e-300 mm"),
    ("device_stiffness = 230 ", "device_stiffness = 1e-300 ",
     r"breakage.device_stiffness = 1e-300 GPa is out of range: accepted \[0.0001, 1500\] GPa$"),
])
def test_physically_absurd_values_are_refused_in_one_line(tmp_path, old, new, message):
    assert old in GOOD
    with pytest.raises(MaterialError) as info:
        load_material(_write(tmp_path, GOOD.replace(old, new)))
    assert len(info.value.problems) == 1
    assert re.search(message, info.value.problems[0]), info.value.problems[0]


def test_within_the_ranges_the_rayleigh_time_step_is_finite_and_positive():
    """What intervals.py's ranges promise: at their corners, the Rayleigh time of a sphere of
    radius R (m) lies within 4.1e-5 R and 2.9 R s, so no material file can overflow the time step
    (the smallest radius of the size range gives a step well above float's smallest)."""
    from yadebreak.model import intervals, placement
    corners = [placement.rayleigh_time(1.0, rho, young, nu)
               for rho in (intervals.DENSITY.lo, intervals.DENSITY.hi)
               for young in (intervals.YOUNG_MODULUS.lo, intervals.YOUNG_MODULUS.hi)
               for nu in (intervals.POISSON_RATIO.lo, np.nextafter(intervals.POISSON_RATIO.hi, 0))]
    assert 4.1e-5 < min(corners) and max(corners) < 2.9
    assert 4.1e-5 * intervals.PARTICLE_SIZE.lo / 2 > 1e-12


@pytest.mark.yade
def test_a_script_refuses_an_absurd_material_in_one_line_before_running(tmp_path):
    import subprocess
    path = _write(tmp_path, GOOD.replace("young_modulus = 52 ", "young_modulus = 1e-300 "))
    script = Path(yadebreak.__file__).resolve().parent.parent / "scripts" / "single_impact.py"
    proc = subprocess.run(["yade", "-n", "-x", str(script), "--material", str(path),
                           "--energies", "100", "--particles", "2", "--jobs", "1",
                           "--out", str(tmp_path / "o")],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2
    errors = [line for line in proc.stderr.splitlines() if "[yadebreak]" in line]
    assert errors == [f"[yadebreak] error: --material = {path}: elastic.young_modulus = 1e-300 "
                      "GPa is out of range: accepted [0.0001, 1500] GPa"]
    assert not (tmp_path / "o").exists()


def test_all_problems_reported_at_once(tmp_path):
    text = GOOD.replace("sigma = 0.799 ", "sigma = 0 ").replace("A = 67.7 ", "A = 0 ") \
        .replace("density = 2930 ", "")
    with pytest.raises(MaterialError) as info:
        load_material(_write(tmp_path, text))
    assert len(info.value.problems) == 3


def test_missing_empty_and_not_toml(tmp_path):
    with pytest.raises(MaterialError, match="file not found"):
        load_material(tmp_path / "nothing.toml")
    with pytest.raises(MaterialError, match="empty"):
        load_material(_write(tmp_path, "  \n"))
    with pytest.raises(MaterialError, match="not valid TOML"):
        load_material(_write(tmp_path, "density = = 3\n[[["))


def test_defaults_for_emax_ratio_and_kappa(tmp_path):
    text = GOOD.replace("emax_ratio = 100 ", "").replace("kappa = 1.0 ", "")
    mat = load_material(_write(tmp_path, text))
    assert mat.params.emax_ratio == 100.0 and mat.params.kappa == 1.0


def test_sampling_uses_the_generator(tmp_path):
    cu = load_material("copper_ore")
    a = cu.sample_fracture_energy(np.random.default_rng(5), np.full(10, 5.5e-3))
    b = cu.sample_fracture_energy(np.random.default_rng(5), np.full(10, 5.5e-3))
    np.testing.assert_array_equal(a, b)


def test_the_criterion_is_chosen_once_by_the_material_and_the_engine_uses_it():
    """The material's file names its criterion (Material.criterion, from the one registry); the
    engine's criterion_for gives that same object."""
    from yadebreak import criteria
    from yadebreak.criteria import CRITERIA
    assert CRITERIA == {"tavares": criteria.Tavares, "ab_t10": criteria.AbT10}
    for name in available_materials():
        mat = load_material(name)
        if not mat.breakable:
            assert mat.params is None and mat.breakage_model is None
            continue
        assert mat.criterion.name == mat.breakage_model
        assert mat.is_ab_t10 == (mat.criterion.name == "ab_t10")
        if mat.breakable:
            assert criteria.criterion_for(mat) is mat.criterion
            assert type(mat.criterion) is criteria.criterion_class(mat.criterion.name)
            assert mat.t10_ceiling == (mat.params.t10_max if mat.is_ab_t10 else mat.params.A)
