"""The main job (issue 6): a small bed runs headless, writes every output, conserves mass (YADE)."""
import argparse
import json
import subprocess
from pathlib import Path

import pytest

pytestmark = pytest.mark.yade

ROOT = Path(__file__).resolve().parent.parent


def _args(out, energy, seed=3, rings=1):
    return argparse.Namespace(material="copper_ore", size=5.5e-3, rings=rings, layers=1,
                              energy=energy, speed=0.0, seed=seed, time_step_fraction=0.05,
                              dmin=0.0, global_damping="material", dummies="ledger",
                              read_period="fast",
                              max_time=0.02, out=str(out))


def test_small_bed_writes_every_output_and_conserves_mass(scene, tmp_path):
    from yadebreak.jobs import bed
    brk, summary = bed.run(_args(tmp_path, 0.6), quiet=True)
    for name in ("summary.json", "events.jsonl", "size_distribution.csv", "size_distribution.png",
                 "bed_top_view.png", "paraview/spheres.pvd", "paraview/surfaces.pvd"):
        assert (tmp_path / name).stat().st_size > 0, name
    saved = json.loads((tmp_path / "summary.json").read_text())
    for key in ("broken_mass", "broken_mass_fraction", "capture_radius", "breakage_events",
                "initial_mass", "final_mass", "runtime_s"):
        assert key in saved
    assert saved["final_mass"] == pytest.approx(saved["initial_mass"], rel=1e-9)
    assert saved["particles"] == 7
    assert 0.0 <= saved["broken_mass_fraction"] <= 1.0
    lines = (tmp_path / "events.jsonl").read_text().splitlines()
    assert len(lines) == len(brk.events)


def test_higher_energy_breaks_more_mass_and_sinks_the_ball_deeper(scene, tmp_path):
    """Three times the energy: more broken mass, and the ball sinks deeper into the one-layer bed
    (its penetration positive and less than the particles' size: it never reaches the anvil)."""
    from yadebreak.jobs import bed
    from yadebreak import engine
    from yade import O
    masses, depths = [], []
    for energy in (0.3, 0.9):
        engine.forget()
        O.reset()
        _, summary = bed.run(_args(tmp_path / f"e{energy}", energy, seed=5), quiet=True)
        masses.append(summary["broken_mass"])
        depths.append(summary["penetration"])
    assert masses[1] > masses[0]
    assert 0.0 < depths[0] < depths[1] < 5.5e-3


def test_bed_script_runs_headless(tmp_path):
    """The script itself, as users run it: yade -n -x scripts/bed_impact.py ..."""
    out = tmp_path / "bed"
    proc = subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / "bed_impact.py"),
                           "--rings", "1", "--energy", "0.5", "--out", str(out)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["final_mass"] == pytest.approx(summary["initial_mass"], rel=1e-9)
    assert "[yadebreak] done in" in proc.stdout


def test_resume_continues_exactly_like_an_uninterrupted_run(scene, tmp_path):
    """A run that dies after a checkpoint and goes on with --resume gives the same results."""
    from yadebreak.jobs import bed
    from yadebreak import engine
    from yade import O
    whole = _args(tmp_path / "whole", 0.9, seed=5)
    whole.checkpoint_every = -1                    # never
    _, reference = bed.run(whole, quiet=True)
    reference_events = (tmp_path / "whole" / "events.jsonl").read_text()

    engine.forget()
    O.reset()
    died = _args(tmp_path / "died", 0.9, seed=5)
    died.checkpoint_every = 0.0                    # after every chunk
    died.stop_after = 6e-4          # dies here: after the first breakage (0.40 ms), before the rest
    brk, summary = bed.run(died, quiet=True)
    assert summary is None and (tmp_path / "died" / "checkpoint.yade.gz").exists()
    assert 0 < len(brk.breakage_events) < reference["breakage_events"]
    engine.forget()
    O.reset()
    died.stop_after, died.resume = 0.0, True
    _, resumed = bed.run(died, quiet=True)
    for key in ("broken_mass", "breakage_events", "damage_events", "final_mass", "capture_radius",
                "steps", "simulated_time"):
        assert resumed[key] == reference[key], key
    assert (tmp_path / "died" / "events.jsonl").read_text() == reference_events

    def series(out):
        return {p.name: p.read_text() for p in (out / "paraview").glob("spheres*")}
    whole_series = series(tmp_path / "whole")   # the .pvd; frames at 0, 1 ms (max_time / 20), end
    assert len(whole_series) == 4 and series(tmp_path / "died") == whole_series   # frames go on
