"""Bad scenes and options get one clear message before the run starts (YADE)."""
import pytest

pytestmark = pytest.mark.yade


def _scene(with_engines=True):
    from yade import O, utils
    from yadebreak import engine, scenes
    ip2, _ = engine.add_materials({"ore": "copper_ore", "steel": "steel"})
    O.bodies.append(utils.wall(0, axis=2, material="steel"))
    O.bodies.append(utils.sphere((0, 0, 0.003), 0.00275, material="ore"))
    if with_engines:
        O.engines = scenes.hertz_engines(ip2)
    return engine


def test_unknown_material_label(scene):
    engine = _scene()
    with pytest.raises(engine.AttachError, match=r"unknown YADE material label\(s\) \['rock'\].*'ore'"):
        engine.attach({"rock": "copper_ore"})


def test_unknown_material_file(scene):
    engine = _scene()
    with pytest.raises(engine.AttachError, match="unknown material 'unobtainium'"):
        engine.attach({"ore": "unobtainium"})


def test_attach_before_engines(scene):
    engine = _scene(with_engines=False)
    with pytest.raises(engine.AttachError, match="no InteractionLoop: set O.engines"):
        engine.attach({"ore": "copper_ore"})


def test_attach_twice(scene):
    engine = _scene()
    engine.attach({"ore": "copper_ore"})
    with pytest.raises(engine.AttachError, match="already attached"):
        engine.attach({"ore": "copper_ore"})


def test_a_stiffness_scale_that_makes_a_modulus_absurd_is_refused(scene):
    """stiffness_scale multiplies the files' moduli: 1e-300 would overflow the time step midway;
    refused, one line, naming the material, its file, the value, the range and the unit."""
    from yadebreak import engine
    with pytest.raises(engine.AttachError) as info:
        engine.add_materials({"ore": "copper_ore", "steel": "steel"}, stiffness_scale=1e-300)
    message = str(info.value)
    assert message.startswith("material 'ore' (") and "copper_ore.toml) with stiffness_scale = " \
        "1e-300: young = 5.2e-290 Pa is out of range: accepted in [100000, 1.5e+12] Pa" in message
    assert "\n" not in message


@pytest.mark.parametrize("field, value, shown", [
    ("young", 1e-300, "young = 1e-300 Pa is out of range: accepted in [100000, 1.5e+12] Pa"),
    ("density", 0.0, "density = 0 kg/m3 is out of range: accepted in [100, 25000] kg/m3"),
    ("poisson", 0.7, "poisson = 0.7 is out of range: accepted in [0, 0.5)"),
])
def test_a_scene_material_out_of_its_physical_range_is_refused(scene, field, value, shown):
    """A partner's YADE material made by hand (not from a file) is checked as files are."""
    from yade import O, utils, wrapper
    engine = _scene()
    wall = wrapper.FrictMat(label="wall", **{field: value})
    O.materials.append(wall)
    O.bodies.append(utils.wall(0.05, axis=0, material="wall"))
    with pytest.raises(engine.AttachError) as info:
        engine.attach({"ore": "copper_ore"})
    assert str(info.value) == f"YADE material 'wall': {shown}"


def test_non_sphere_with_breakable_material(scene):
    from yade import O, utils
    engine = _scene()
    O.bodies.append(utils.box((0.1, 0, 0.01), (0.005, 0.005, 0.005), material="ore"))
    with pytest.raises(engine.AttachError, match="Box.*only spheres and polyhedra can break"):
        engine.attach({"ore": "copper_ore"})


def test_non_breakable_material_mapped(scene):
    engine = _scene()
    with pytest.raises(engine.AttachError, match="'steel' .* is not breakable"):
        engine.attach({"ore": "steel"})


def test_scene_without_breakable_body_warns(scene):
    from yade import O
    engine = _scene()
    O.bodies.erase(1)
    with pytest.warns(RuntimeWarning, match="no breakable body"):
        brk = engine.attach({"ore": "copper_ore"})
    O.run(10, True)                       # and runs, doing nothing
    assert brk.events == []


@pytest.mark.parametrize("option, message", [
    (dict(cs=2.0), r"cs = 2.0: accepted \[0, 1\]"),
    (dict(emin=-1.0), "emin"),
    (dict(emax_ratio=1.0), r"emax_ratio = 1.0: accepted > 1"),
    (dict(dmin=-1e-3), "dmin"),
    (dict(local_damping=1.5), "local_damping"),
    (dict(time_step_fraction=0.0), "time_step_fraction"),
    (dict(read_period=0), "read_period"),
    (dict(dummies="dust"), "dummies"),
    (dict(colour="red"), r"unknown option\(s\) \['colour'\]"),
])
def test_bad_options(scene, option, message):
    engine = _scene()
    with pytest.raises(engine.AttachError, match=message):
        engine.attach({"ore": "copper_ore"}, **option)


def test_time_step_too_large_warns_with_the_remedy(scene):
    from yade import O
    engine = _scene()
    O.dt = 1e-6                     # the 5.5 mm sphere's Rayleigh time is 3.5e-6 s
    with pytest.warns(RuntimeWarning, match=r"O.dt = 1e-06 s is 28 % of the Rayleigh time.*time_step_fraction"):
        engine.attach({"ore": "copper_ore"}, time_step_fraction=None)
    assert O.dt == 1e-6             # the user's time step is left alone


@pytest.mark.parametrize("read_period, fraction, remedy", [(1, 0.4, "time_step_fraction"),
                                                         (8, 0.05, "read_period"),
                                                         (1, 0.05, None)])
def test_energy_jumping_past_the_fracture_energy_warns_once_with_the_remedy(
        scene, recwarn, read_period, fraction, remedy):
    """A 60 m/s impact (1800 J/kg) on particles whose fracture energy is 100 J/kg, read every 8
    steps or with a time step at 40 % of the Rayleigh time: the energy passes E by far in one read,
    and the warning names the knob that fixes it, once; read every step at 5 %, no warning."""
    from yadebreak import scenes
    brk, ids = scenes.impact_scene("copper_ore", 5.5e-3, [60.0, 60.0], read_period=read_period,
                                   time_step_fraction=fraction, replace=False)
    for i in ids:
        brk.bodies[i].fracture_energy = 100.0
    scenes.run_until_rebound(ids)
    jumps = [w for w in recwarn.list if "between two reads" in str(w.message)]
    assert len(brk.breakage_events) == 2
    if remedy is None:
        assert not jumps
        return
    assert len(jumps) == 1
    message = str(jumps[0].message)
    assert "of the fracture energy" in message and f"reduce {remedy}" in message
    assert f"read every {read_period} step(s)" in message


@pytest.mark.parametrize("emin", [1e-4, 0.0])
def test_a_body_below_emin_breaks_on_its_first_count_and_the_warning_names_emin(
        scene, recwarn, emin):
    """A 5.5 mm copper ore sphere (0.24 g) at 2 m/s on steel, read every step, its fracture
    energy a fifth of emin / m: with the paper's emin (1e-4 J) its contact counts only from emin
    on, so it breaks on that first count at several times its fracture energy; the warning says
    so and names emin, not a late read. With emin = 0 it breaks at the crossing (within one
    step's rise, under 1 + LATE_JUMP) and nothing is said."""
    from yadebreak import scenes
    from yadebreak.engine.judging import LATE_JUMP
    brk, ids = scenes.impact_scene("copper_ore", 5.5e-3, [2.0], read_period=1,
                                   time_step_fraction=0.05, replace=False, emin=emin)
    body = brk.bodies[ids[0]]
    body.fracture_energy = 0.2 * 1e-4 / body.mass
    scenes.run_until_rebound(ids)
    said = [str(w.message) for w in recwarn.list if "yadebreak:" in str(w.message)]
    late = [m for m in said if "between two reads" in m]
    first = [m for m in said if "first counted energy" in m]
    [event] = brk.breakage_events
    assert not late
    if emin:
        assert event["ratio"] > 1.0 + LATE_JUMP
        assert len(first) == 1 and "lower emin" in first[0]
    else:
        assert 1.0 < event["ratio"] < 1.0 + LATE_JUMP and not first


def _unchanged(O):
    """What attach changes in a scene: a refusal must leave all of it as it was."""
    return (O.dt, [type(e).__name__ for e in O.engines], len(O.materials),
            sorted(O.tags.keys()))


@pytest.mark.parametrize("event_log, shown", [
    ("{tmp}", r"event_log = '.*': a folder; accepted: a file path"),
    ("{tmp}/ro/events.jsonl", r"event_log = '.*/ro/events.jsonl': cannot be written here"),
    ("/proc/yadebreak_events.jsonl", r"event_log = '/proc/yadebreak_events.jsonl': cannot be "
                                     r"written \("),
])
def test_a_bad_event_log_is_refused_before_the_scene_changes(scene, tmp_path, event_log, shown):
    import os
    import subprocess
    from yade import O
    engine = _scene()
    before = _unchanged(O)
    ro = tmp_path / "ro"
    ro.mkdir()
    # a read-only folder (root writes through chmod 555: a read-only tmpfs is what refuses it)
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "ro,size=64k", "tmpfs", str(ro)],
                             capture_output=True).returncode == 0
    if "ro" in event_log and not mounted and os.access(ro, os.W_OK):
        pytest.skip("no read-only folder can be made here")
    import yadebreak
    assert yadebreak.AttachError is engine.AttachError          # the README's name for it
    try:
        with pytest.raises(engine.AttachError, match=shown):
            engine.attach({"ore": "copper_ore"}, event_log=event_log.format(tmp=tmp_path))
    finally:
        if mounted:
            subprocess.run(["umount", str(ro)], check=True)
    assert _unchanged(O) == before


def test_an_event_log_in_a_missing_folder_makes_the_folder(scene, tmp_path):
    engine = _scene()
    path = tmp_path / "a" / "b" / "events.jsonl"
    engine.attach({"ore": "copper_ore"}, event_log=str(path))
    assert path.is_file()


def test_materials_not_a_mapping_is_refused_before_the_scene_changes(scene):
    from yade import O
    engine = _scene()
    before = _unchanged(O)
    with pytest.raises(engine.AttachError, match=r"materials = \['copper_ore'\]: accepted a "
                                                   r"dict \{YADE material label"):
        engine.attach(["copper_ore"])
    assert _unchanged(O) == before


def test_a_second_label_over_bodies_another_tracks_is_refused(scene):
    """Two engines over the same bodies would judge each twice (one broke body 1 while the other
    recorded a damage event on it)."""
    from yade import O
    engine = _scene()
    engine.attach({"ore": "copper_ore"}, label="first")
    before = _unchanged(O)
    with pytest.raises(engine.AttachError, match=r"bodies \[1\] are tracked by the yadebreak "
                                                   r"engine 'first' already"):
        engine.attach({"ore": "copper_ore"}, label="second")
    assert _unchanged(O) == before
