"""Every registered criterion: its fracture-energy distribution is consistent (ppf inverts cdf,
rvs follows cdf), and the model and the engine ask the same object (criteria/base.py)."""
import numpy as np
import pytest
from scipy import stats

from yadebreak import criteria, load_material
from yadebreak.model.materials import available_materials
from yadebreak.criteria import CRITERIA
from yadebreak.criteria.base import registry

SIZE = 5.5e-3          # m
#: draws of the KS test: its critical distance at 1 % is 1.63 / sqrt(N) = 0.0073
KS_SAMPLE = 50000


def _material_of(name):
    """The first shipped material of criterion `name`."""
    for material in available_materials():
        mat = load_material(material)
        if mat.breakable and mat.criterion.name == name:
            return mat
    pytest.skip(f"no shipped material uses criterion {name!r}")


def test_the_registry_holds_the_criteria_once():
    assert set(CRITERIA) == {"tavares", "ab_t10"}
    assert all(criteria.criterion_class(name) is cls for name, cls in CRITERIA.items())
    with pytest.raises(ValueError, match="criterion = 'nope': accepted 'tavares', 'ab_t10'"):
        criteria.criterion_class("nope")
    with pytest.raises(ValueError, match="registered twice"):
        registry(criteria.Tavares, type("Again", (criteria.Criterion,), {"name": "tavares"}))


@pytest.mark.parametrize("name", sorted(CRITERIA))
def test_a_criterion_owns_its_keys_parameters_and_columns(name):
    """Its Params has one field per [breakage] key; the keys fit calibrates are its own; its
    per-body columns are not the shared ones; a shipped file read back in the file's units gives
    the numbers written in it."""
    import dataclasses
    import tomllib
    from yadebreak.engine.state import SHARED_COLUMNS
    cls = CRITERIA[name]
    assert {f.name for f in dataclasses.fields(cls.Params)} == cls.file_keys()
    assert set(cls.calibrated) <= cls.file_keys()
    assert not set(cls.columns) & set(SHARED_COLUMNS)
    mat = _material_of(name)
    written = tomllib.loads(open(mat.source, "rb").read().decode())["breakage"]
    for key, value in cls.in_file_unit(mat.params).items():
        assert value == pytest.approx(written.get(key, cls.key(key).default), rel=1e-12), key


@pytest.mark.parametrize("name", sorted(CRITERIA))
def test_ppf_inverts_cdf(name):
    crit = _material_of(name).criterion
    u = np.linspace(0.01, 0.99, 99)
    x = crit.ppf(u, np.full(u.shape, SIZE))
    np.testing.assert_allclose(crit.ppf(crit.cdf(x, SIZE), SIZE), x, rtol=1e-9)
    np.testing.assert_allclose(crit.cdf(x, SIZE), u, atol=1e-10)


@pytest.mark.parametrize("name", sorted(CRITERIA))
def test_rvs_with_a_fixed_seed_follows_cdf(name):
    crit = _material_of(name).criterion
    draws = crit.rvs(np.random.default_rng(20261203), np.full(KS_SAMPLE, SIZE))
    result = stats.kstest(draws, lambda x: crit.cdf(x, SIZE))
    assert result.pvalue > 0.01, result


@pytest.mark.parametrize("name", sorted(CRITERIA))
def test_the_engine_and_the_model_use_the_same_object(name):
    mat = _material_of(name)
    assert mat.criterion is mat.criterion
    assert criteria.criterion_for(mat) is mat.criterion
    recording = criteria.criterion_for(mat, breakage=False)
    assert isinstance(recording, criteria.Recording) and recording.inner is mat.criterion
    rng = np.random.default_rng(3)
    sizes = np.full(10, SIZE)
    np.testing.assert_array_equal(criteria.criterion_for(mat).sample(np.random.default_rng(3),
                                                                     sizes)[0],
                                  mat.sample_fracture_energy(rng, sizes))
