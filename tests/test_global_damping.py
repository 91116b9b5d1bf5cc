"""The paper's global damping (docs/high_energy.md, "Global damping"): a per-material value (0.3
for copper ore), overridden by attach's global_damping; YADE's Newton damping on fragments only,
so the impact that stresses the parent is untouched, and it only takes kinetic energy away."""
import pytest

from yadebreak import load_material
from yadebreak.options import table as config
from yadebreak.model.materials import MaterialError


def _copper_text():
    return open(load_material("copper_ore").source).read()


def test_copper_ore_carries_the_papers_0_3_and_the_other_materials_0():
    assert load_material("copper_ore").global_damping == 0.3
    for name in ("granulite", "limestone", "ab_t10_ore"):
        assert load_material(name).global_damping == 0.0


def test_a_material_file_with_damping_out_of_range_is_refused_in_one_line(tmp_path):
    path = tmp_path / "ore.toml"
    path.write_text(_copper_text().replace("global_damping = 0.3", "global_damping = 1.0"))
    with pytest.raises(MaterialError) as err:
        load_material(str(path))
    assert "breakage.global_damping = 1 - is out of range: accepted [0, 1)" in str(err.value)


def test_the_option_is_checked_and_defaults_to_the_files():
    with pytest.raises(config.AttachError) as err:
        config.Config.from_options(global_damping=1.0)
    assert "global_damping = 1.0: accepted [0, 1) or None" in str(err.value)
    cfg = config.Config.from_options()
    assert cfg.time_step.global_damping is None and cfg.time_step.global_damping_time is None


def _run(material, speed, seed=3, **options):
    """One 5.5 mm particle at `speed` (m/s) on steel, run to its end with energy tracking:
    (controller, fired ids, the Newton engine, the damping work recorded at every check)."""
    from yade import O
    from yadebreak import scenes
    brk, ids = scenes.impact_scene(material, 5.5e-3, speeds=[speed], seed=seed,
                                   time_step_fraction=0.05, read_period="every_step", **options)
    O.trackEnergy = True
    work = []
    for _ in range(400):
        O.run(50, True)
        work.append(O.energy["nonviscDamp"] if "nonviscDamp" in O.energy.keys() else 0.0)
        if all(scenes.impacts._left(i) for i in ids) and O.time > 2e-4:
            break
    newton = next(e for e in O.engines if type(e).__name__ == "NewtonIntegrator")
    return brk, ids, newton, work


@pytest.mark.yade
def test_damping_zero_is_the_undamped_run_of_a_file_without_the_field(scene, tmp_path):
    """global_damping=0 and a copper ore file without the field (today's file) give the same
    events and leave YADE's damping off: the run is exactly what it was before the field."""
    from yade import O
    from yadebreak import engine
    path = tmp_path / "ore.toml"
    path.write_text(_copper_text().replace("global_damping = 0.3", ""))
    assert load_material(str(path)).global_damping == 0.0
    runs = []
    for material, options in ((str(path), {}), ("copper_ore", {"global_damping": 0.0})):
        engine.forget()
        brk, ids, newton, _ = _run(material, 70.0, **options)
        assert newton.damping == 0.0
        assert len(brk.breakage_events) >= 1
        runs.append([(e["kind"], e["id"], e["iter"], e.get("specific_energy"))
                     for e in brk.events])
        engine.forget()
        O.reset()
    assert runs[0] == runs[1]


@pytest.mark.yade
def test_damping_leaves_the_parents_impact_and_only_takes_energy_from_fragments(scene):
    """Copper ore's 0.3 against 0: the fired particle's breakage (its stressing energy, the
    iteration, its t10') is the same to the last digit, because the parent is never damped; the
    work of the damping (YADE's nonviscDamp) is never negative nor decreasing, and positive once
    fragments move; the fragments, not the target, carry isDamped."""
    from yade import O
    from yadebreak import engine
    first = {}
    for gd in (0.0, None):                    # None: the file's 0.3
        engine.forget()
        brk, ids, newton, work = _run("copper_ore", 70.0, global_damping=gd)
        first[gd] = next(e for e in brk.events if e["id"] == ids[0])
        if gd is None:
            assert newton.damping == pytest.approx(0.3)
            fragments = first[gd]["fragments"]
            assert fragments and all(O.bodies[i].state.isDamped for i in fragments
                                     if O.bodies[i] is not None)
            assert not O.bodies[0].state.isDamped             # the plate
            assert all(b >= a for a, b in zip(work, work[1:])) and work[0] >= 0.0
            assert work[-1] > 0.0
        else:
            assert newton.damping == 0.0 and max(work) == 0.0
        engine.forget()
        O.reset()
    assert first[0.0]["kind"] == first[None]["kind"] == "breakage"
    for key in ("iter", "specific_energy", "t10", "fracture_energy"):
        assert first[0.0][key] == first[None][key]


@pytest.mark.yade
def test_damped_fragments_are_released_after_the_damping_time(scene):
    from yade import O
    brk, ids, newton, _ = _run("copper_ore", 70.0, global_damping_time=1e-6)
    fragments = next(e for e in brk.events if e["id"] == ids[0])["fragments"]
    assert O.time > 1e-5
    assert not any(O.bodies[i].state.isDamped for i in fragments if O.bodies[i] is not None)


@pytest.mark.yade
@pytest.mark.parametrize("flags, damping", [([], 0.3), (["--global-damping", "0"], 0.0),
                                            (["--global-damping", "0.1"], 0.1)])
def test_the_bed_scripts_flag_switches_damping_off_at_0_and_keeps_the_files_by_default(
        scene, flags, damping):
    """--global-damping as bed_impact.py reads it: by default the material file's (0.3 for
    copper ore), 0 none, a value that value."""
    from yade import O
    from yadebreak import engine
    from yadebreak.jobs import options as job_options
    args = job_options.read("bed_impact", None, flags)
    options = job_options.attach_options("bed_impact", args)
    engine.forget()
    _, _, newton, _ = _run("copper_ore", 70.0, global_damping=options["global_damping"],
                           global_damping_time=options["global_damping_time"])
    assert newton.damping == pytest.approx(damping)
    engine.forget()
    O.reset()
