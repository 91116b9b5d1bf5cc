"""The ball mill (issue 15): a short run of a small mill keeps the ore's mass, stays finite, the
drum's torque opposes its rotation (the motor does work on the charge) and the collision spectra
count every stressing event (bad input: tests/test_script_options.py)."""
import argparse
import json
import math
import time

import pytest

pytestmark = pytest.mark.yade


def _args(out, **changes):
    values = dict(material="limestone", size=6e-3, ball_size=15e-3, drum_diameter=0.12,
                  drum_length=0.04, lifters=6, lifter_height=6e-3, lifter_width=6e-3, speed=0.75,
                  ball_filling=0.3, ore_filling=0.1, duration=0.06, stiffness_scale=1e-3,
                  time_step_fraction=0.05, dmin=0.0, read_period="fast", seed=2,
                  sample_interval=0.01, vtk_interval=0.03, checkpoint_every=-1.0, resume=False,
                  stop_after=0.0, out=str(out))
    values.update(changes)
    return argparse.Namespace(**values)


def test_a_short_mill_run_keeps_mass_stays_finite_and_the_motor_does_work(scene, tmp_path):
    from yade import O
    from yadebreak.jobs import mill
    from yadebreak.model import milling
    brk, summary = mill.run(_args(tmp_path), quiet=True)
    assert summary["end_reason"] == "finished"
    assert summary["balls"] > 10 and summary["ore_particles"] > 50
    assert summary["mass_relative_error"] < 1e-9
    for b in O.bodies:
        if b is not None:
            assert all(math.isfinite(v) for v in (*b.state.pos, *b.state.vel, *b.state.angVel))
    # the charge drags on the turning shell: the torque on the drum is against the rotation
    assert summary["mean_power_W"] > 0 and summary["torque_arm_power_W"] > 0
    omega = 2 * math.pi * 0.75 * milling.critical_speed(0.12, 15e-3)
    assert summary["speed_rpm"] == pytest.approx(60 * omega / (2 * math.pi), rel=1e-12)
    assert summary["simulated_time"] == pytest.approx(0.06, abs=300 * summary["final_dt"])
    # the stressing events are the ore's: every damage event on an ore particle, none on a ball
    damage = [e for e in brk.events if e["kind"] == "damage"]
    assert damage and all(O.bodies[e["id"]].material.label == "ore" for e in damage)
    assert json.loads((tmp_path / "summary.json").read_text()) == json.loads(json.dumps(summary))
    # the spectra count every stressing event once, by the kind of contact that brought it
    rates = summary["stressing_events_per_second"]
    assert set(rates) == {"ball-ore", "ore-ore", "ore-liner"}
    with_partner = [e for e in brk.events if e["kind"] in ("damage", "breakage")
                    and e["partner"] >= 0]
    assert sum(rates.values()) * summary["simulated_time"] == pytest.approx(len(with_partner))
    assert rates["ore-ore"] > 0 and rates["ore-liner"] > 0
    for name in ("size_distribution.csv", "breakage_rate.csv", "power.csv", "collision_spectra.csv",
                 "mill.png",
                 "charge.png", "events.jsonl", "paraview/spheres.pvd", "paraview/surfaces.pvd"):
        assert (tmp_path / name).stat().st_size > 0, name
    rows = (tmp_path / "size_distribution.csv").read_text().splitlines()
    assert len(rows) >= 1 + 6                  # a header and a row every 0.01 s of 0.06 s


def test_the_charge_fills_the_drum_as_asked(scene, tmp_path):
    """Fillings are bulk volumes over the drum's volume, the bulk PACKING solid."""
    from yadebreak.model import milling
    args = _args(tmp_path)
    balls, ores = milling.charge_counts(args)
    volume = math.pi * 0.06 ** 2 * 0.04
    assert balls == round(0.3 * volume * milling.PACKING / (math.pi / 6 * 0.015 ** 3))
    assert ores == round(0.1 * volume * milling.PACKING / (math.pi / 6 * 0.006 ** 3))


def test_a_resumed_mill_goes_on_from_its_checkpoint_and_refuses_other_arguments(scene, tmp_path):
    """Killed at 0.02 s (its checkpoint written at every batch of steps), resumed with the same
    arguments: the events before the cut are the uninterrupted run's, the run ends at the same
    time with the ore's mass kept, and its counts of events are the uninterrupted run's within
    10 %. Not bit for bit: the turning drum's facets come back from the saved scene rounded in
    the last digit (measured: the first event after the cut differs at 1e-16), and a granular flow
    amplifies that. Resumed with another speed: refused, naming it."""
    from yade import O
    from yadebreak import engine
    from yadebreak.jobs import mill
    from yadebreak.jobs.lifecycle import ScriptError
    _, whole = mill.run(_args(tmp_path / "whole", duration=0.04, checkpoint_every=0.0),
                        quiet=True)
    whole_events = [json.loads(x) for x in
                    (tmp_path / "whole" / "events.jsonl").read_text().splitlines()]
    engine.forget()
    O.reset()
    cut = _args(tmp_path / "cut", duration=0.04, checkpoint_every=0.0, stop_after=0.02)
    began = time.time()
    assert mill.run(cut, quiet=True)[1] is None
    first = time.time() - began                  # (its last checkpoint: at its very end)
    before_cut = [json.loads(x) for x in
                  (tmp_path / "cut" / "events.jsonl").read_text().splitlines()]
    engine.forget()
    O.reset()
    with pytest.raises(ScriptError, match=r"other values of \['speed'\]"):
        mill.run(_args(tmp_path / "cut", duration=0.04, checkpoint_every=0.0, resume=True,
                       speed=0.7), quiet=True)
    engine.forget()
    O.reset()
    began = time.time()
    _, resumed = mill.run(_args(tmp_path / "cut", duration=0.04, checkpoint_every=0.0,
                                resume=True), quiet=True)
    second = time.time() - began
    # the run's wall time and throughput count both invocations, not the last one alone (the
    # first up to its last checkpoint: a busy disk may delay that one's end)
    assert second + 0.5 * first < resumed["runtime_s"] < second + first
    assert resumed["throughput_s_per_hour"] == pytest.approx(
        3600 * resumed["simulated_time"] / resumed["runtime_s"], rel=1e-12)
    assert before_cut and before_cut == whole_events[:len(before_cut)]
    assert resumed["end_reason"] == "finished" and resumed["mass_relative_error"] < 1e-9
    assert resumed["simulated_time"] == pytest.approx(whole["simulated_time"],
                                                      abs=200 * whole["final_dt"])
    for key in ("damage_events", "breakage_events"):
        assert abs(resumed[key] - whole[key]) <= 0.1 * whole[key] + 1, key


def test_the_spectra_run_breaks_nothing_and_feeds_the_grinding_model(scene, tmp_path):
    """--breakage 0: the same mill with nothing broken or damaged; every ore stressing event
    recorded once, by its pair type, into spectra.csv, which `python3 -m yadebreak grind` reads."""
    import subprocess
    import sys
    from yade import O
    from yadebreak.jobs import mill
    from yadebreak.model.spectra import read_spectra
    brk, summary = mill.run(_args(tmp_path, breakage=False, vtk_interval=0.0), quiet=True)
    assert summary["breakage"] is False and summary["end_reason"] == "finished"
    assert summary["breakage_events"] == summary["damage_events"] == 0
    assert summary["stressing_events"] > 50
    assert summary["bodies_end"] == summary["bodies_start"] and summary["mass_relative_error"] == 0
    assert all(brk.bodies[i].damage == 0.0 for i in mill_ore_ids(brk, O))
    spectra = read_spectra(tmp_path / "spectra.csv")
    assert spectra.simulated_time_s == pytest.approx(summary["simulated_time"], rel=1e-12)
    assert spectra.ore_mass_kg == pytest.approx(summary["initial_mass"], rel=1e-12)
    with_partner = [e for e in brk.events if e["kind"] == "stressing" and e["partner"] >= 0]
    rates = summary["stressing_events_per_second"]
    assert sum(rates.values()) * summary["simulated_time"] == pytest.approx(len(with_partner))
    out = tmp_path / "grind"
    proc = subprocess.run([sys.executable, "-m", "yadebreak", "grind", str(tmp_path / "spectra.csv"),
                           "--material", "limestone", "--feed", "6e-3", "--minutes", "0.5",
                           "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-1500:] + proc.stderr[-1500:]
    ground = json.loads((out / "summary.json").read_text())
    assert ground["mass_relative_error"] < 1e-9


def mill_ore_ids(brk, O):
    return [b.id for b in O.bodies if b is not None and b.material.label == "ore"]
