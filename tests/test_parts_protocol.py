"""The part protocol (engine/parts/protocol.py): a part acts at its trigger's steps, its state
goes with the scene through O.save / O.load (restored in the process that loads it), and bad
declarations are refused when the class is made."""
import pytest

pytestmark = pytest.mark.yade


def _toy_kind():
    from yadebreak.engine.parts import protocol

    class Counter(protocol.Part):
        """Counts its calls and the steps it was called at."""
        kind = "test_counter"
        hook = protocol.AFTER_NEWTON

        def __init__(self, label, period=1, calls=0):
            super().__init__(label, period)
            self.calls, self.steps = calls, []

        def act(self):
            from yade import O
            self.calls += 1
            self.steps.append(O.iter)

        def to_state(self, folder=None):
            return {"calls": self.calls}

        @classmethod
        def from_state(cls, label, period, state):
            return cls(label, period, state["calls"])
    return Counter


_COUNTER = None


def _counter():
    global _COUNTER
    if _COUNTER is None:
        _COUNTER = _toy_kind()
    return _COUNTER


def test_a_part_acts_every_period_and_its_state_survives_save_and_load(scene):
    from yade import utils
    from yadebreak import scenes
    from yadebreak.engine import add_materials, run_steps
    from yadebreak.engine.parts import protocol
    O = scene
    ip2, _ = add_materials({"ore": "copper_ore"})
    O.bodies.append(utils.sphere((0, 0, 0), 1e-3, material="ore"))
    part = _counter()("counter", period=3)
    O.engines = scenes.hertz_engines(ip2)
    protocol.install(part)
    run_steps(30)
    assert len(part.steps) >= 9 and set(b - a for a, b in zip(part.steps, part.steps[1:])) == {3}
    calls = part.calls
    protocol.store()
    O.saveTmp("protocol")
    protocol.forget()
    O.loadTmp("protocol")
    run_steps(30)
    restored = protocol._LIVE["counter"]
    assert restored is not part and restored.calls == calls + 10     # 30 steps at period 3
    assert restored.period == 3


def test_a_part_acts_when_its_trigger_says_and_yade_does_the_waiting(scene):
    """A trigger (parts/triggers.py) whose gaps double: the part acts at 0, 1, 3, 7, 15, and its
    runner runs at those steps only (YADE's iterPeriod waits, not Python). An integer is a
    Periodic trigger; set_trigger changes it from the last act on; anything else is refused."""
    from yade import utils
    from yadebreak import scenes
    from yadebreak.engine import add_materials, run_steps
    from yadebreak.engine.parts import protocol
    from yadebreak.engine.parts.triggers import Periodic, Trigger, as_trigger

    class Doubling(Trigger):
        def __init__(self):
            self.gap = 1

        def next_step(self, now):
            due, self.gap = now + self.gap, 2 * self.gap
            return due

    O = scene
    ip2, _ = add_materials({"ore": "copper_ore"})
    O.bodies.append(utils.sphere((0, 0, 0), 1e-3, material="ore"))
    O.engines = scenes.hertz_engines(ip2)
    part = _counter()("doubling")
    part.trigger = Doubling()
    protocol.install(part)
    run_steps(20)
    assert part.steps == [0, 1, 3, 7, 15]
    runner = next(e for e in O.engines
                  if getattr(e, "label", "") == protocol.runner_label(protocol.AFTER_NEWTON))
    assert runner.nDone == 5
    protocol.set_trigger("doubling", 2)              # due 2 steps after its last act (15):
    run_steps(6)                                     # overdue at 20, then 22, 24
    assert part.steps[5:] == [20, 22, 24] and part.period == 2
    assert isinstance(as_trigger(3), Periodic) and as_trigger(3).next_step(10) == 13
    for bad in (0, 2.5, True, "auto"):
        with pytest.raises((ValueError, TypeError), match="accepted"):
            as_trigger(bad)


def test_a_part_with_an_unknown_hook_or_a_taken_kind_is_refused():
    from yadebreak.engine.parts import protocol
    _counter()
    with pytest.raises(ValueError, match="hook"):
        type("Bad", (protocol.Part,), {"kind": "test_bad", "hook": "during_lunch"})
    with pytest.raises(ValueError, match="registered already"):
        type("Again", (protocol.Part,), {"kind": "test_counter"})


def test_one_runner_per_hook_calls_each_part_at_its_own_steps(scene):
    """Two parts after Newton's step, every 2 and every 3 steps, share one PyRunner: each acts at
    its own steps (the runner runs every step); one asleep leaves the runner the other's period
    and last step, so YADE waits for it; none awake leaves the runner dead; the last one taken
    out takes the runner with it."""
    from yade import utils
    from yadebreak import scenes
    from yadebreak.engine import add_materials, run_steps
    from yadebreak.engine.parts import protocol
    O = scene
    ip2, _ = add_materials({"ore": "copper_ore"})
    O.bodies.append(utils.sphere((0, 0, 0), 1e-3, material="ore"))
    O.engines = scenes.hertz_engines(ip2)
    every_2, every_3 = _counter()("two", period=2), _counter()("three", period=3)
    protocol.install(every_2)
    protocol.install(every_3)
    label = protocol.runner_label(protocol.AFTER_NEWTON)
    runners = [e for e in O.engines if getattr(e, "label", "") == label]
    assert len(runners) == 1 and type(O.engines[O.engines.index(runners[0]) - 1]).__name__ \
        == "NewtonIntegrator"
    run_steps(12)
    assert every_2.steps == [0, 2, 4, 6, 8, 10] and every_3.steps == [0, 3, 6, 9]
    runner = runners[0]
    assert runner.iterPeriod == 1 and runner.nDone == 12
    protocol.sleep("two")
    assert runner.iterPeriod == 3 and not runner.dead
    done = runner.nDone
    run_steps(6)                                      # steps 12..17: "three" at 12 and 15
    assert every_3.steps[-2:] == [12, 15] and every_2.steps[-1] == 10
    assert runner.nDone == done + 2                   # YADE did the waiting
    protocol.sleep("three")
    assert runner.dead
    protocol.wake("two")
    run_steps(2)
    assert every_2.steps[-1] == 18 and not runner.dead
    protocol.uninstall("two")
    assert runner.dead and protocol.installed("three")      # "three" sleeps still
    protocol.uninstall("three")
    assert not any(getattr(e, "label", "") == label for e in O.engines)
    assert not protocol.installed("two") and not protocol.installed("three")


PART_MODULE = '''
from yadebreak.engine.parts import protocol


class SavedCounter(protocol.Part):
    kind = "test_saved_counter"
    hook = protocol.AFTER_NEWTON

    def __init__(self, label, period=1, calls=0):
        super().__init__(label, period)
        self.calls = calls

    def act(self):
        self.calls += 1

    def to_state(self, folder=None):
        return {"calls": self.calls}

    @classmethod
    def from_state(cls, label, period, state):
        return cls(label, period, state["calls"])
'''

PROCESS = '''
import sys
sys.path.insert(0, {folder!r})
from yadebreak.adapter.yadepath import ensure_yade_importable
ensure_yade_importable()
from yade import O, utils
import yadebreak
from yadebreak.engine import run_steps
from yadebreak.engine.parts import protocol
'''


def test_a_loaded_scene_finds_each_parts_module_without_importing_it_first(tmp_path):
    """A part's kind maps to its module: the package's by PART_MODULES, a user's by the module
    saved with its state, so a process that loads the scene need not import either first."""
    import subprocess
    import sys
    from yadebreak.engine.parts import protocol
    for kind, module in protocol.PART_MODULES.items():
        assert protocol.part_class(kind).__module__ == module
    (tmp_path / "user_parts.py").write_text(PART_MODULE)
    scene = tmp_path / "scene.yade.gz"
    save = PROCESS.format(folder=str(tmp_path)) + f'''
import user_parts
from yadebreak import scenes
from yadebreak.engine import add_materials
ip2, _ = add_materials({{"ore": "copper_ore"}})
O.bodies.append(utils.sphere((0, 0, 0), 1e-3, material="ore"))
O.engines = scenes.hertz_engines(ip2)
protocol.install(user_parts.SavedCounter("counted", period=2))
run_steps(10)
yadebreak.save({str(scene)!r})
'''
    load = PROCESS.format(folder=str(tmp_path)) + f'''
assert "user_parts" not in sys.modules
O.load({str(scene)!r})
run_steps(10)
print("calls", protocol.live("test_saved_counter")["counted"].calls)
'''
    for code in (save, load):
        done = subprocess.run(["/usr/bin/python3", "-c", code], capture_output=True, text=True,
                              timeout=120)
        assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split()[-2:] == ["calls", "10"]           # 5 before the save, 5 after


def test_the_engines_runner_waits_as_long_as_its_read_schedule_says(scene):
    """read_period "auto" sets k after the first read (0.5 of the smallest body's Rayleigh time,
    O.dt 0.05 of it: k = 10): the runner after the InteractionLoop then runs every k steps, YADE
    doing the waiting, not every step to find that nothing is due."""
    from yade import utils
    from yadebreak import scenes
    from yadebreak.engine import add_materials, attach, run_steps
    from yadebreak.engine.parts import protocol
    O = scene
    ip2, _ = add_materials({"ore": "copper_ore"})
    O.bodies.append(utils.sphere((0, 0, 0), 1e-3, material="ore"))
    O.bodies.append(utils.sphere((0, 0, 3e-3), 1e-3, material="ore"))
    O.engines = scenes.hertz_engines(ip2)
    brk = attach({"ore": "copper_ore"}, read_period="auto", read_fraction=0.5)   # k = 10
    runner = next(e for e in O.engines
                  if getattr(e, "label", "") == protocol.runner_label(protocol.AFTER_INTERACTIONS))
    run_steps(400)
    assert brk.period > 1 and runner.iterPeriod == brk.period
    assert runner.nDone <= 1 + 400 // brk.period + 1
