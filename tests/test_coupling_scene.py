"""How the engine sits in a user's scene (issue 14): it leaves the user's globals and smaller
O.dt alone, is saved with yadebreak.save (a scene saved with O.save alone refuses to go on),
detaches cleanly, and finds material files outside the repository (YADE)."""
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytestmark = pytest.mark.yade

ROOT = Path(__file__).resolve().parent.parent


def _scene(**options):
    from yade import O, utils
    from yadebreak import engine, scenes
    ip2, _ = engine.add_materials({"ore": "copper_ore", "steel": "steel"})
    O.bodies.append(utils.wall(0, axis=2, material="steel"))
    b = utils.sphere((0, 0, 0.0029), 0.00275, material="ore")
    b.state.vel = (0, 0, -5.0)
    O.bodies.append(b)
    O.engines = scenes.hertz_engines(ip2)
    return engine


def test_stepping_from_a_function_leaves_the_users_globals_alone(tmp_path):
    """PyRunners with YADE's default updateGlobals=True copy the caller's locals into __main__."""
    script = tmp_path / "user.py"
    script.write_text(textwrap.dedent(f"""
        import sys
        sys.path.insert(0, {str(ROOT)!r})
        from yade import O, utils
        from yadebreak import engine, scenes
        ip2, _ = engine.add_materials({{"ore": "copper_ore", "steel": "steel"}})
        O.bodies.append(utils.wall(0, axis=2, material="steel"))
        O.bodies.append(utils.sphere((0, 0, 0.003), 0.00275, material="ore"))
        O.engines = scenes.hertz_engines(ip2)
        engine.attach({{"ore": "copper_ore"}})
        steps = 7
        step = "mine"
        def advance(n):
            steps = n
            for _ in range(n):
                O.step()
        advance(20)
        engine.run_steps(50)
        print("GLOBALS", steps, step)
        """))
    proc = subprocess.run(["yade", "-n", "-x", str(script)], capture_output=True, text=True,
                          timeout=300)
    assert "GLOBALS 7 mine" in proc.stdout, proc.stdout[-1500:] + proc.stderr[-1500:]


def test_a_smaller_time_step_set_before_attach_is_kept_a_larger_one_lowered(scene):
    from yade import O
    from yadebreak.model import placement
    from yadebreak import load_material
    cu = load_material("copper_ore")
    tr = float(placement.rayleigh_time(0.00275, cu.density, cu.young_modulus, cu.poisson_ratio))
    engine = _scene()
    O.dt = 0.02 * tr
    engine.attach({"ore": "copper_ore"})
    assert O.dt == pytest.approx(0.02 * tr, rel=1e-12)
    engine.forget()
    O.reset()
    engine = _scene()
    O.dt = 0.5 * tr
    engine.attach({"ore": "copper_ore"})
    assert O.dt == pytest.approx(0.05 * tr, rel=1e-12)


def test_a_scene_saved_with_o_save_alone_refuses_to_go_on(scene, tmp_path):
    from yade import O
    from yadebreak.engine import AttachError
    engine = _scene()
    engine.attach({"ore": "copper_ore"})
    engine.run_steps(30)
    O.save(str(tmp_path / "plain.yade.gz"))          # yadebreak's state stays the attach's
    engine.forget()
    O.load(str(tmp_path / "plain.yade.gz"))
    with pytest.raises(AttachError, match=r"save scenes with yadebreak.save\(path\)"):
        engine.controller_of()


def test_detach_removes_the_engine_and_keeps_the_results(scene):
    from yade import O
    engine = _scene()
    brk = engine.attach({"ore": "copper_ore"}, seed=2)
    engine.run_steps(400)
    events = list(brk.events)
    assert events                                     # the impact was recorded
    assert engine.detach() is brk
    assert not [e for e in O.engines if "yadebreak" in getattr(e, "label", "")]
    engine.run_steps(50)
    assert brk.events == events and engine.attach({"ore": "copper_ore"}) is not brk


def test_materials_are_found_from_any_folder_and_a_working_folder_overrides(tmp_path):
    """Outside the repository the shipped files are found; a folder's materials/ comes first."""
    (tmp_path / "materials").mkdir()
    text = (ROOT / "materials" / "copper_ore.toml").read_text()
    (tmp_path / "materials" / "my_ore.toml").write_text(text.replace('name = "copper_ore"',
                                                                     'name = "my_ore"'))
    code = ("import yadebreak; print(yadebreak.load_material('granulite').name, "
            "yadebreak.load_material('my_ore').name)")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.stdout.split() == ["granulite", "my_ore"], proc.stderr


def test_a_scene_saved_with_o_save_alone_refuses_to_go_on_in_the_same_process(scene, tmp_path):
    """As in a fresh process: O.save, running on, then O.reset() and O.load() in this process
    (the controller in memory is the later one's) refuses too."""
    from yade import O
    from yadebreak.engine import AttachError
    engine = _scene()
    engine.attach({"ore": "copper_ore"})
    engine.run_steps(30)
    O.save(str(tmp_path / "plain.yade.gz"))
    engine.run_steps(5)
    O.reset()
    O.load(str(tmp_path / "plain.yade.gz"))
    with pytest.raises(AttachError, match=r"save scenes with yadebreak.save\(path\)"):
        engine.controller_of()


def test_a_scene_saved_with_yadebreak_save_reloaded_in_the_same_process_goes_on(scene, tmp_path):
    """The same reload after yadebreak.save: the stored state is taken, events and all, and the
    stored state names its event log relative to the saved file's folder."""
    import json
    from yade import O
    engine = _scene()
    log = tmp_path / "run" / "events.jsonl"
    brk = engine.attach({"ore": "copper_ore"}, event_log=str(log))
    engine.run_steps(30)
    engine.save(tmp_path / "run" / "scene.yade.gz")
    stored = json.loads(O.tags["yadebreak:yadebreak"])
    assert stored["event_log"] == {"path": "events.jsonl", "relative_to": "scene file"}
    assert str(tmp_path) not in O.tags["yadebreak:yadebreak"]
    engine.run_steps(5)
    O.reset()
    O.load(str(tmp_path / "run" / "scene.yade.gz"))
    again = engine.controller_of()
    assert again is not brk and again.events == brk.events[:len(again.events)]
    assert again.state.log.path == log


def test_an_event_log_on_a_full_disk_stops_run_steps_without_yades_traceback(scene, capfd):
    """A write that fails inside YADE's loop (the PyRunner) would come out with YADE's traceback
    printed: run_steps raises the OSError itself once the step is done; the event stays in
    memory. /dev/full: every write fails with ENOSPC."""
    import errno
    from yade import O
    engine = _scene()
    O.bodies[1].state.vel = (0, 0, -40.0)          # 800 J/kg: it breaks at the plate
    brk = engine.attach({"ore": "copper_ore"}, seed=1, event_log="/dev/full")
    with pytest.raises(OSError) as failed:
        engine.run_steps(20000)
    assert failed.value.errno == errno.ENOSPC
    assert len(brk.events) >= 1
    out, err = capfd.readouterr()
    assert "Traceback" not in out + err


def test_a_restored_contact_whose_partner_was_erased_since_is_dropped(scene, tmp_path):
    """A scene loaded with a contact row whose partner body (the smaller id of the pair) is
    erased before the first read: the row goes (YADE's interactions.has() aborts the process
    when the pair's smaller id is an erased body; the bed's in-memory reload every 5 chunks
    restores rows often)."""
    from yade import O, utils
    from yadebreak import engine, scenes
    ip2, _ = engine.add_materials({"ore": "copper_ore", "steel": "steel"})
    O.bodies.append(utils.wall(0, axis=2, material="steel"))
    steel = utils.sphere((0, 0, 0.0029 + 0.0055 - 1e-6), 0.00275, material="steel")
    steel.state.vel = (0, 0, -10.0)            # pressing on the ore sphere from above
    O.bodies.append(steel)                     # body 1: the pair (1, 2)'s smaller id
    O.bodies.append(utils.sphere((0, 0, 0.0029), 0.00275, material="ore"))
    O.engines = scenes.hertz_engines(ip2)
    brk = engine.attach({"ore": "copper_ore"}, seed=1)
    engine.run_steps(40)
    assert (1, 2) in zip(brk.reader.table.a.tolist(), brk.reader.table.b.tolist())
    engine.save(tmp_path / "scene.yade.gz")
    saved_at = O.iter
    O.reset()
    O.load(str(tmp_path / "scene.yade.gz"))
    O.bodies.erase(1)
    restored = engine.controller_of()
    restored.reader.small = 0                 # the path that looks the restored rows up
    engine.run_steps(10)
    assert O.iter == saved_at + 10
    assert all(1 not in pair for pair in zip(restored.reader.table.a.tolist(),
                                             restored.reader.table.b.tolist()))
