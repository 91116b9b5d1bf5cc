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
    O.engines = scenes.hertz_engines(ip2) + [protocol.install(part)]
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


def test_a_part_with_an_unknown_hook_or_a_taken_kind_is_refused():
    from yadebreak.engine.parts import protocol
    _counter()
    with pytest.raises(ValueError, match="hook"):
        type("Bad", (protocol.Part,), {"kind": "test_bad", "hook": "during_lunch"})
    with pytest.raises(ValueError, match="registered already"):
        type("Again", (protocol.Part,), {"kind": "test_counter"})
