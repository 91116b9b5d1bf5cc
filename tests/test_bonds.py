"""The bonded-agglomerate model (yadebreak.model.bonds): no YADE needed."""
import math

import numpy as np
import pytest
from scipy import stats

from yadebreak.model import bonds
from yadebreak.model.materials import MATERIALS_DIR, MaterialError, available_materials
from yadebreak.criteria import load_material

E, NU = 3e9, 0.4


def timoshenko_matrix(e, nu, radius, length):
    """The planar two-node Timoshenko beam element (transverse v, rotation theta at each end;
    Przemieniecki): nodal forces (V1, M1, V2, M2) = K (v1, theta1, v2, theta2)."""
    area, inertia, _ = bonds.section(radius)
    g = e / (2 * (1 + nu))
    phi = 12 * e * inertia / (bonds.SHEAR_COEFFICIENT * g * area * length**2)
    c = e * inertia / (length**3 * (1 + phi))
    el = length
    return c * np.array([[12, 6 * el, -12, 6 * el],
                         [6 * el, (4 + phi) * el**2, -6 * el, (2 - phi) * el**2],
                         [-12, -6 * el, 12, -6 * el],
                         [6 * el, (2 - phi) * el**2, -6 * el, (4 + phi) * el**2]])


def test_phi_is_timoshenko_with_the_circular_shear_coefficient():
    area, inertia, _ = bonds.section(0.4e-3)
    g = E / (2 * (1 + NU))
    expected = 12 * E * inertia / (0.9 * g * area * (1.5e-3) ** 2)
    assert bonds.timoshenko_phi(0.4e-3, 1.5e-3, NU) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("radius,length", [(0.375e-3, 1.5e-3), (0.67e-3, 12.5e-3),
                                           (0.7e-3, 1.4e-3)])
def test_beam_stiffness_in_yades_form_is_the_timoshenko_element(radius, length):
    """Eq. B6: YADE's decomposition (k_s on the displacement at the mid contact point, k_b on the
    relative rotation, the shear force's lever L/2) gives the element's nodal forces exactly, for
    any end displacements and rotations."""
    k = bonds.beam_stiffness(E, NU, radius, length)
    matrix = timoshenko_matrix(E, NU, radius, length)
    rng = np.random.default_rng(3)
    for _ in range(20):
        v1, t1, v2, t2 = rng.normal(size=4) * [1e-6, 1e-3, 1e-6, 1e-3]
        slip = (v2 - v1) - 0.5 * length * (t1 + t2)   # contact point of 2 relative to that of 1
        f1 = k.shear * slip                          # the bond's force on sphere 1
        m1 = k.bending * (t2 - t1) + 0.5 * length * f1
        f2 = -f1
        m2 = -k.bending * (t2 - t1) + 0.5 * length * f1   # lever -L/2 times f2
        nodal = -matrix @ [v1, t1, v2, t2]           # the beam's forces on its nodes
        np.testing.assert_allclose([f1, m1, f2, m2], nodal, rtol=1e-10,
                                   atol=1e-12 * np.abs(nodal).max())


def test_axial_and_twist_stiffness_closed_forms():
    k = bonds.beam_stiffness(E, NU, 0.5e-3, 2e-3)
    area, inertia, polar = bonds.section(0.5e-3)
    assert k.axial == pytest.approx(E * area / 2e-3)
    assert k.twist == pytest.approx(E / (2 * (1 + NU)) * polar / 2e-3)
    assert polar == pytest.approx(math.pi * 0.5e-3**4 / 2)
    slender = bonds.beam_stiffness(E, NU, 1e-6, 2e-3)     # Euler-Bernoulli limit
    assert slender.shear == pytest.approx(12 * E * bonds.section(1e-6)[1] / 2e-3**3, rel=1e-5)


def test_stresses_against_closed_forms_and_modes():
    r = 0.5e-3
    area, inertia, polar = bonds.section(r)
    t, s, c = bonds.bond_stresses(100.0, 0.0, 0.0, 0.0, r)
    assert t == pytest.approx(100 / area) and c == pytest.approx(-100 / area) and s == 0
    t, s, c = bonds.bond_stresses(0.0, 0.0, 1e-3, 0.0, r)
    assert t == pytest.approx(4e-3 / (math.pi * r**3)) == c          # M R / I = 4 M / (pi R^3)
    t, s, c = bonds.bond_stresses(0.0, 10.0, 0.0, 1e-3, r)
    assert s == pytest.approx(10 / area + 2e-3 / (math.pi * r**3))    # + M_t R / J
    strengths = (np.array([10.0, 10, 10, 10]), np.array([10.0, 10, 10, 10]),
                 np.array([100.0, 100, 100, 100]))
    modes = bonds.failure_modes([11, 9, 9, 12], [0, 12, 9, 15], [0, 0, 101, 0], strengths)
    assert list(modes) == [bonds.TENSION, bonds.SHEAR, bonds.COMPRESSION, bonds.SHEAR]


def test_strengths_mean_and_cv_from_a_seed():
    rng = np.random.default_rng(7)
    n = 20000
    draws = bonds.draw_strengths(23e6, 0.1, n, rng)
    dist = stats.truncnorm(-3, 3, loc=23e6, scale=2.3e6)
    # the sample mean within 4 standard errors of the truncated law's mean
    assert abs(draws.mean() - dist.mean()) < 4 * dist.std() / math.sqrt(n)
    assert draws.std() == pytest.approx(dist.std(), rel=0.03)        # 4 x 1/sqrt(2n) = 2.8 %
    assert draws.min() > 0
    again = bonds.draw_strengths(23e6, 0.1, n, np.random.default_rng(7))
    np.testing.assert_array_equal(draws, again)


def test_diameters_follow_the_truncated_gaussian():
    mat = bonds.load_agglomerate_material("glass_epoxy")
    sp = mat.spheres
    d = bonds.sphere_diameters(20000, sp, np.random.default_rng(1))
    assert d.min() >= sp.diameter_min and d.max() <= sp.diameter_max
    lo, hi = (sp.diameter_min - sp.diameter_mean) / sp.diameter_sd, (
        sp.diameter_max - sp.diameter_mean) / sp.diameter_sd
    law = stats.truncnorm(lo, hi, loc=sp.diameter_mean, scale=sp.diameter_sd)
    assert abs(d.mean() - law.mean()) < 4 * law.std() / math.sqrt(len(d))


def test_packing_fits_the_mould_without_overlaps_and_is_reproducible():
    mat = bonds.load_agglomerate_material("glass_epoxy")
    rng = np.random.default_rng(5)
    d = bonds.sphere_diameters(400, mat.spheres, rng)
    mould = bonds.mould_diameter_for(400, mat.spheres, 0.52)
    pk = bonds.pack_in_sphere(d, mould, rng)
    dist = np.linalg.norm(pk.positions[:, None] - pk.positions[None], axis=2)
    gap = dist - (pk.radii[:, None] + pk.radii[None])
    np.fill_diagonal(gap, np.inf)
    assert gap.min() >= -1e-3 * d.mean()
    assert (np.linalg.norm(pk.positions, axis=1) + pk.radii).max() <= pk.mould_radius * (1 + 1e-9)
    # the spheres fill the mould as asked: every sphere lies inside, so the lens sum is exact
    assert bonds.solid_fraction_within(pk.positions, pk.radii, pk.mould_radius) == pytest.approx(
        float(np.sum(d**3)) / mould**3, rel=1e-9)
    rng2 = np.random.default_rng(5)
    pk2 = bonds.pack_in_sphere(bonds.sphere_diameters(400, mat.spheres, rng2), mould, rng2)
    np.testing.assert_array_equal(pk.positions, pk2.positions)


def test_packing_refuses_more_than_random_close_packing():
    with pytest.raises(ValueError, match="0.64"):
        bonds.pack_in_sphere(np.full(100, 1e-3), 4.5e-3, np.random.default_rng(0))


def test_lens_volume_of_a_sphere_cut_by_the_ball():
    # a sphere of radius r centred on the surface of a much larger ball: about half inside
    r, big = 1e-3, 1.0
    inside = bonds.solid_fraction_within(np.array([[big, 0, 0]]), np.array([r]), big)
    half = 0.5 * 4 / 3 * math.pi * r**3 / (4 / 3 * math.pi * big**3)
    assert inside == pytest.approx(half, rel=1e-3)
    # equal spheres, centres one radius apart: the lens is 5 pi r^3 / 12
    lens = bonds.solid_fraction_within(np.array([[r, 0, 0]]), np.array([r]), r)
    assert lens == pytest.approx((5 * math.pi * r**3 / 12) / (4 / 3 * math.pi * r**3), rel=1e-12)


def test_bond_pairs_match_a_brute_force_search():
    rng = np.random.default_rng(2)
    pos = rng.random((300, 3)) * 10e-3
    radii = rng.uniform(0.5e-3, 0.8e-3, 300)
    pairs, lengths = bonds.bond_pairs(pos, radii, 1.2)
    expected = {(i, j) for i in range(300) for j in range(i + 1, 300)
                if np.linalg.norm(pos[i] - pos[j]) <= 1.2 * (radii[i] + radii[j])}
    assert {tuple(p) for p in pairs} == expected
    np.testing.assert_allclose(lengths, np.linalg.norm(pos[pairs[:, 1]] - pos[pairs[:, 0]], axis=1))


def test_damage_ratio_and_fragments_of_a_chain():
    # 0-1-2-3-4 in a chain, 4-5 a tail; the bond 1-2 broken
    pairs = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5]])
    broken = np.array([False, True, False, False, False])
    ratios = bonds.damage_ratios(7, pairs, broken)
    np.testing.assert_allclose(ratios[:6], [0, 0.5, 0.5, 0, 0, 0])
    assert np.isnan(ratios[6])                                      # sphere 6 had no bond
    labels, counts = bonds.fragments(7, pairs, ~broken)
    assert sorted(counts) == [1, 2, 4]
    assert labels[0] == labels[1] and labels[2] == labels[5] and labels[6] not in labels[:6]
    masses = bonds.fragment_masses(labels, np.arange(1.0, 8.0))
    assert sorted(masses) == [3.0, 7.0, 18.0]


def test_time_scale_of_one_bond():
    k = bonds.beam_stiffness(E, NU, np.array([0.4e-3]), np.array([1.6e-3]))
    m, i = np.array([1e-5, 2e-5]), np.array([1e-12, 1e-12])
    lever = np.array([0.8e-3])
    got = bonds.bond_time_scale(m, i, np.array([[0, 1]]), k, lever, lever)
    rot = k.bending[0] + k.twist[0] + k.shear[0] * 0.8e-3**2
    assert got == pytest.approx(min(math.sqrt(1e-5 / max(k.axial[0], k.shear[0])),
                                    math.sqrt(1e-12 / rot)))


def test_material_file_checked_field_by_field(tmp_path):
    good = (MATERIALS_DIR / "glass_epoxy.toml").read_text()
    mat = bonds.load_agglomerate_material("glass_epoxy")
    assert mat.binder.young_modulus == 3e9 and mat.binder.tensile_strength == 23e6
    assert mat.spheres.diameter_mean == pytest.approx(1.5e-3)
    bad = tmp_path / "bad.toml"
    bad.write_text(good.replace("tensile_strength = 23.0", "tensile_strength = -1")
                   .replace("radius_multiplier = 0.6", "radius_multiplier = 2"))
    with pytest.raises(MaterialError) as info:
        bonds.load_agglomerate_material(bad)
    text = str(info.value)
    assert "binder.tensile_strength = -1 MPa is out of range" in text
    assert "binder.radius_multiplier = 2 - is out of range: accepted (0, 1]" in text


@pytest.mark.parametrize("old, new, problem", [
    ("young_modulus = 3.0 ", "young_modulus = 1e-300 ",
     "binder.young_modulus = 1e-300 GPa is out of range: accepted [0.0001, 1500] GPa"),
    ("poisson_ratio = 0.4 ", "poisson_ratio = -0.5 ",
     "binder.poisson_ratio = -0.5 - is out of range: accepted [0, 0.5)"),
    ("density = 2500 ", "density = 1e-300 ",
     "spheres.density = 1e-300 kg/m3 is out of range: accepted [100, 25000] kg/m3"),
    ("young_modulus = 63 ", "young_modulus = 1e300 ",
     "spheres.young_modulus = 1e+300 GPa is out of range: accepted [0.0001, 1500] GPa"),
    ("diameter_min = 1.4 ", "diameter_min = 1e-300 ",
     "spheres.diameter_min = 1e-300 mm is out of range: accepted [0.001, 1000] mm"),
])
def test_physically_absurd_values_are_refused(tmp_path, old, new, problem):
    """The physical ranges of yadebreak/intervals.py, as for replacement materials: a binder of
    1e-300 GPa would make the bonds' time scale overflow; spheres of 1e-300 mm, the time step."""
    good = (MATERIALS_DIR / "glass_epoxy.toml").read_text()
    assert old in good
    bad = tmp_path / "bad.toml"
    bad.write_text(good.replace(old, new))
    with pytest.raises(MaterialError) as info:
        bonds.load_agglomerate_material(bad)
    assert info.value.problems == [problem]


def test_the_two_kinds_of_material_file_are_told_apart():
    assert "glass_epoxy" not in available_materials()
    assert available_materials(kind="bonded_agglomerate") == ["glass_epoxy"]
    with pytest.raises(MaterialError, match="load_agglomerate_material"):
        load_material("glass_epoxy")
    with pytest.raises(MaterialError) as err:          # one line, naming what is accepted
        bonds.load_agglomerate_material("copper_ore")
    assert err.value.problems == ['a particle material (for the other scripts), not a bonded '
                                  'agglomerate: accepted a file with kind = "bonded_agglomerate" '
                                  '(glass_epoxy, or a .toml path)']
