"""docs/architecture.md, "A new criterion", to the letter: its module, its registration line and
its material file, taken from the page, make a criterion the package reads, calibrates and breaks
bodies with, and no other file of the package changes."""
import re
import sys
import tomllib
import types
from pathlib import Path

import numpy as np
import pytest

from yadebreak.criteria import CRITERIA
from yadebreak.criteria.base import registry
from yadebreak.model import materials

PAGE = Path(__file__).resolve().parent.parent / "docs" / "architecture.md"


def _blocks():
    """The code blocks of the section: (language, text) in order."""
    text = PAGE.read_text()
    section = text[text.index("## A new criterion"):]
    section = section[:section.index("\n## ", 1)]
    return re.findall(r"```(\w+)\n(.*?)```", section, re.S)


@pytest.fixture(scope="module")
def threshold(tmp_path_factory):
    """The page's module (as yadebreak.criteria.threshold), the registry with its line, and the
    Material of its file."""
    module_text, line, material_text = (text for _, text in _blocks())
    module = types.ModuleType("yadebreak.criteria.threshold")
    sys.modules[module.__name__] = module          # dataclasses look their module up
    try:
        exec(compile(module_text, "docs/architecture.md", "exec"), module.__dict__)
        names = {c.__name__: c for c in CRITERIA.values()} | {"Threshold": module.Threshold,
                                                              "registry": registry}
        found = eval(line.split("=", 1)[1], names)
        path = tmp_path_factory.mktemp("materials") / "glassy.toml"
        path.write_text(material_text)
        yield module, found, materials.load_material(path, found)
    finally:
        del sys.modules[module.__name__]


def test_the_section_has_the_module_the_line_and_the_file():
    assert [lang for lang, _ in _blocks()] == ["python", "python", "toml"]


def test_the_file_is_read_by_the_criterion_it_names(threshold):
    module, found, glassy = threshold
    assert list(found) == [*CRITERIA, "threshold"]
    assert glassy.breakage_model == "threshold" and type(glassy.criterion) is module.Threshold
    assert glassy.params == module.ThresholdParams(e_break=100.0, t10=12.0)
    assert glassy.global_damping == 0.0 and glassy.beta_source == "table1"
    doc = tomllib.loads(Path(glassy.source).read_text())
    doc["breakage"]["e_break"] = -1.0
    doc["breakage"]["sigma"] = 0.8
    with pytest.raises(materials.MaterialError) as err:
        materials.parse(doc, glassy.source, found)
    assert "breakage.e_break = -1 J/kg is out of range: accepted (0, inf)" in str(err.value)
    assert "breakage.sigma: unknown key" in str(err.value)
    with pytest.raises(materials.MaterialError, match="breakage.model = 'threshold'"):
        materials.load_material(glassy.source, CRITERIA)       # the package's own registry


def test_the_model_side_and_the_keys_fit_writes(threshold):
    _, _, glassy = threshold
    crit = glassy.criterion
    sizes = np.full(3, 5e-3)
    assert glassy.median_fracture_energy(5e-3) == 100.0
    np.testing.assert_array_equal(crit.probability_once(np.array([99.0, 100.0, 101.0]), sizes),
                                  [0.0, 1.0, 1.0])
    assert crit.in_file_unit(glassy.params) == {"e_break": 100.0, "t10": 12.0}
    assert [crit.key(k).unit for k in crit.calibrated] == ["J/kg", "%"]


@pytest.mark.yade
def test_bodies_break_by_the_threshold_in_yade(threshold, scene):
    """Six 5 mm particles on steel: those that absorb more than e_break break, each with the
    file's t10'; the others stay whole."""
    from yadebreak import scenes
    _, _, glassy = threshold
    steel = materials.load_material("steel", CRITERIA)
    share = glassy.energy_partition(steel)
    energies = np.array([0.5, 0.8, 0.95, 1.05, 1.3, 1.6]) * 100.0 / share      # Ek/mp, J/kg
    brk, ids = scenes.impact_scene(glassy, 5e-3, np.sqrt(2.0 * energies), target=steel, seed=1,
                                   time_step_fraction=0.05, read_period="every_step")
    scenes.run_until_rebound(ids, brk=brk)
    broken = {e["id"]: e for e in brk.events if e["kind"] == "breakage"}
    assert sorted(broken.keys() & set(ids)) == ids[3:]
    assert all(e["t10"] == 12.0 for e in brk.events if e["kind"] == "breakage")
