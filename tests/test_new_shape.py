"""docs/architecture.md, "A new shape", to the letter: its module, its registration line and its
scene builder, taken from the page, make a shape the engine sizes, tracks and breaks, with the
progeny's mass, momentum and kinetic energy the parent's, and no other file of the package
changes."""
import re
import sys
import types
from pathlib import Path

import numpy as np
import pytest

PAGE = Path(__file__).resolve().parent.parent / "docs" / "architecture.md"
HALF_EXTENTS = (4e-3, 3e-3, 2.5e-3)            # m: the page's example
pytestmark = pytest.mark.yade


def _blocks():
    """The code blocks of the section: (language, text) in order."""
    text = PAGE.read_text()
    section = text[text.index("## A new shape"):]
    section = section[:section.index("\n## ", 1)]
    return re.findall(r"```(\w+)\n(.*?)```", section, re.S)


def _module(name, text):
    module = types.ModuleType(name)
    sys.modules[name] = module
    exec(compile(text, "docs/architecture.md", "exec"), module.__dict__)
    return module


@pytest.fixture()
def box_shape():
    """The page's module (as yadebreak.engine.shapes.box) registered by the page's line, and its
    scene builder; the package's registry is given back afterwards."""
    from yadebreak.engine import shapes
    module_text, line, builder_text = (text for _, text in _blocks())
    saved = dict(shapes.SHAPES)
    try:
        box = _module("yadebreak.engine.shapes.box", module_text)
        names = {"Sphere": shapes.sphere.Sphere, "Polyhedron": shapes.polyhedron.Polyhedron,
                 "Box": box.Box}
        found = eval(line.split("=", 1)[1], names)
        shapes.SHAPES.clear()
        shapes.SHAPES.update(found)
        yield box, found, _module("yadebreak.scenes.box_impact", builder_text)
    finally:
        shapes.SHAPES.clear()
        shapes.SHAPES.update(saved)
        sys.modules.pop("yadebreak.engine.shapes.box", None)
        sys.modules.pop("yadebreak.scenes.box_impact", None)


def test_the_section_has_the_module_the_line_and_the_builder():
    assert [lang for lang, _ in _blocks()] == ["python", "python", "python"]


def test_the_line_adds_the_box_to_the_shapes(box_shape):
    from yadebreak.engine import shapes
    box, found, _ = box_shape
    assert list(found) == ["Sphere", "Polyhedra", "Box"]
    assert type(found["Box"]) is box.Box and shapes.SHAPES is not found


def _momenta(states):
    """Linear (kg m/s) and angular momentum about the origin (kg m2/s) of bodies' states."""
    linear, angular = np.zeros(3), np.zeros(3)
    for s in states:
        rot, v = np.array(s.ori.toRotationMatrix()), s.mass * np.array(s.vel)
        spin = rot @ (np.array(s.inertia) * (rot.T @ np.array(s.angVel)))
        linear += v
        angular += np.cross(np.array(s.pos), v) + spin
    return linear, angular


def test_a_box_breaks_into_octants_that_carry_its_mass_momentum_and_energy(box_shape, scene,
                                                                          monkeypatch):
    from yadebreak.engine import run_steps
    box, _, builder = box_shape
    O = scene
    slow = builder.box_impact("copper_ore", HALF_EXTENTS, 0.2)
    size = 2.0 * sorted(HALF_EXTENTS)[1]             # the middle edge: the box's sieve size
    assert slow.bodies.columns["radius"][0] == pytest.approx(0.5 * size, rel=1e-15)
    run_steps(3000)
    assert not slow.breakage_events and O.bodies[0].state.vel.norm() > 0.1      # hit, whole
    O.reset()
    seen, replace = [], box.Box.replace

    def watched(self, breaking, body, bid, *args):
        before = _momenta([body.state])
        progeny = replace(self, breaking, body, bid, *args)
        states = [O.bodies[i].state for i in progeny.ids]
        seen.append((body.state.mass, before, progeny.ids, sum(s.mass for s in states),
                     _momenta(states)))
        return progeny
    monkeypatch.setattr(box.Box, "replace", watched)
    fast = builder.box_impact("copper_ore", HALF_EXTENTS, 60.0, global_damping=0.0)
    box_mass = O.bodies[0].state.mass
    run_steps(3000)
    events = fast.breakage_events
    assert len(events) == len(seen) >= 1 and all(len(e["fragments"]) == 8 for e in events)
    boxes = [b for b in O.bodies if b is not None and type(b.shape).__name__ == "Box"]
    assert len(boxes) == 1 + 7 * len(events)
    assert sum(b.state.mass for b in boxes) == pytest.approx(box_mass, rel=1e-14)
    for (mass, before, ids, octants_mass, after), e in zip(seen, events):
        assert e["fragments"] == ids and octants_mass == pytest.approx(mass, rel=1e-14)
        for got, want in zip(after, before):       # the octants move with the parent's field
            assert got == pytest.approx(want, rel=1e-12, abs=1e-12 * np.linalg.norm(want))
        assert e["kinetic_energy_after"] == pytest.approx(e["kinetic_energy_before"], rel=1e-12)
        assert e["family_t10"] == 0.0 and e["fragment_speed_excess"] <= 1e-9
    first = events[0]
    assert first["specific_energy"] >= first["fracture_energy"]
