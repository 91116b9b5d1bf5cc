"""Outputs of version 0.2 (before the package was split into layers) still work: a checkpoint
resumes and a settled bed in its cache loads. The data in tests/data/v0_2 were written by 0.2:

    bed_checkpoint/  yade -n -x scripts/bed_impact.py --material copper_ore --size 5.5e-3 --rings 1
                     --layers 1 --energy 0.6 --seed 3 --max-time 0.02 --checkpoint-every 0
                     --stop-after 0.0005 --out bed_checkpoint        (stopped as if killed)
    bed_uninterrupted_summary.json   the same run, not stopped
    bed_cache/       YADEBREAK_CACHE=bed_cache yade -n -x scripts/bed_impact.py --material copper_ore
                     --size 5.5e-3 --rings 1 --layers 3 --energy 1.0 --seed 1 --dmin 1.1e-3
                     --max-time 0.002 (0.2 kept beds in $YADEBREAK_CACHE itself)
    poured_summary.json              that run's summary
"""
import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest


ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data" / "v0_2"
BED = ["--material", "copper_ore", "--size", "5.5e-3", "--rings", "1", "--layers", "1",
       "--energy", "0.6", "--seed", "3", "--max-time", "0.02"]
POURED = ["--material", "copper_ore", "--size", "5.5e-3", "--rings", "1", "--layers", "3",
          "--energy", "1.0", "--seed", "1", "--dmin", "1.1e-3", "--max-time", "0.002"]


def _bed_impact(out, *options, env=None):
    proc = subprocess.run(["yade", "-n", "-x", str(ROOT / "scripts" / "bed_impact.py"), *options,
                           "--out", str(out)], capture_output=True, text=True, timeout=600,
                          env={**os.environ, **(env or {})})
    assert proc.returncode == 0, proc.stdout[-1500:] + proc.stderr[-1500:]
    return proc.stdout + proc.stderr


def _events(path):
    return [json.loads(line) for line in Path(path).read_text().splitlines()]


@pytest.mark.yade
def test_a_checkpoint_of_version_0_2_resumes(tmp_path):
    out = tmp_path / "bed"
    shutil.copytree(DATA / "bed_checkpoint", out)
    before = _events(out / "events.jsonl")
    log = _bed_impact(out, *BED, "--resume", "1")
    assert "resum" in log
    summary = json.loads((out / "summary.json").read_text())
    whole = json.loads((DATA / "bed_uninterrupted_summary.json").read_text())
    assert summary["end_reason"] == "finished"
    assert summary["mass_relative_error"] < 1e-12
    # what was decided before the checkpoint cannot change: the events logged up to it
    assert _events(out / "events.jsonl")[:len(before)] == before
    assert summary["steps"] > before[-1]["iter"]
    # the rest is a DEM run resumed on any CPU: the same set-up exactly, results within one
    # breakage of 0.2's uninterrupted run (7 particles: one breakage is 1/7 of the bed's mass)
    for key in ("particles", "initial_mass", "ball_speed", "initial_dt", "energy_per_bed_mass"):
        assert summary[key] == pytest.approx(whole[key], rel=1e-12), key
    assert abs(summary["particles_broken"] - whole["particles_broken"]) <= 1
    assert summary["broken_mass_fraction"] == pytest.approx(whole["broken_mass_fraction"],
                                                            abs=1.01 / whole["particles"])


@pytest.mark.yade
def test_a_bed_cached_by_version_0_2_loads_without_settling_again(tmp_path):
    """The cache key holds the material file's text, so the bed is 0.2's for copper_ore.toml as
    0.2 had it (tests/data/v0_2/copper_ore.toml; today's adds the fragments' global damping,
    which changes the key: a changed file is settled again, by design)."""
    cache = tmp_path / "cache"
    shutil.copytree(DATA / "bed_cache", cache)            # 0.2's layout: beds in the root
    material = ["--material", str(DATA / "copper_ore.toml")]
    log = _bed_impact(tmp_path / "poured", *POURED, *material,
                      env={"YADEBREAK_CACHE": str(cache)})
    assert "poured" not in log.split("particles of")[0]   # no new pour was reported
    summary = json.loads((tmp_path / "poured" / "summary.json").read_text())
    old = json.loads((DATA / "poured_summary.json").read_text())
    assert summary["bed_settling"]["cached"] is True
    # the bed is read from the file: its height and mass are 0.2's to the last bit
    assert summary["bed_height"] == old["bed_height"]
    assert summary["initial_mass"] == old["initial_mass"]
    assert list((cache / "beds").glob("bed-*.yade.gz"))      # moved to today's folder


def test_the_module_names_of_version_0_2_still_import():
    import yadebreak
    from yadebreak import families, materials, placement, scriptargs, sweep
    from yadebreak.model import families as new_families
    assert families is new_families and yadebreak.bed.__name__ == "yadebreak.jobs.bed"
    assert materials.load_material("copper_ore").name == "copper_ore"
    assert callable(placement.spin_scale) and callable(scriptargs.script_params)
    assert callable(sweep.read_table)


def test_one_cache_rule_for_every_kind(monkeypatch, tmp_path):
    from yadebreak.model import cache
    from yadebreak.scenes import poured_bed
    monkeypatch.delenv("YADEBREAK_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert cache.cache_folder("families") == tmp_path / "yadebreak" / "families"
    assert poured_bed.cache_folder() == tmp_path / "yadebreak" / "beds"
    monkeypatch.setenv("YADEBREAK_CACHE", str(tmp_path / "mine"))
    assert {cache.cache_folder(k).parent for k in cache.KINDS} == {tmp_path / "mine"}
    assert poured_bed.cache_folder("elsewhere") == Path("elsewhere")     # --bed-cache
    with pytest.raises(ValueError, match="cache kind 'tables'"):
        cache.cache_folder("tables")
