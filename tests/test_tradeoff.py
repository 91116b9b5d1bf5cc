"""The trade-off tool (issue 21): its statistics against hand computations, its input errors, and
a tiny scene through the tool (2 x 2 variants, 2 seeds) against a hand-run of the same runs."""
import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from yadebreak.studies import tradeoff as to

ROOT = Path(__file__).resolve().parent.parent


def test_scalar_paired_difference_is_the_t_interval_of_the_differences():
    x, r = [0.40, 0.35, 0.38, 0.42, 0.37], [0.36, 0.33, 0.35, 0.37, 0.36]
    d = np.subtract(x, r)
    got = to.paired_difference(x, r)
    half = stats.t.ppf(0.975, 4) * d.std(ddof=1) / math.sqrt(5)
    assert got.error == pytest.approx(d.mean())
    assert (got.low, got.high) == pytest.approx((d.mean() - half, d.mean() + half))
    assert got.distinguishable == (d.mean() - half > 0)
    assert got.mean == pytest.approx(np.mean(x))
    noisy = to.paired_difference([0.40, 0.30, 0.38, 0.32, 0.37], r)   # same mean shift, noisier
    assert noisy.low < 0 < noisy.high and not noisy.distinguishable
    one = to.paired_difference([1.0], [0.5])
    assert one.error == 0.5 and math.isnan(one.low) and not one.distinguishable


def test_list_metric_is_compared_element_wise_by_rms():
    rng = np.random.default_rng(1)
    ref = [rng.normal(size=6) for _ in range(8)]
    same = [r + rng.normal(scale=0.01, size=6) for r in ref]
    shifted = [r + np.array([0, 0, 0.5, 0, 0, 0]) + rng.normal(scale=0.01, size=6) for r in ref]
    a, b = to.paired_difference(same, ref), to.paired_difference(shifted, ref)
    mean_d = np.mean(np.subtract(shifted, ref), axis=0)
    assert b.error == pytest.approx(np.sqrt(np.mean(mean_d**2)))
    assert b.distinguishable and not a.distinguishable
    assert b.low <= b.error <= b.high


def test_pareto_front():
    speed = [1.0, 2.0, 3.0, 4.0, 2.5]
    error = [0.0, 0.1, 0.05, 0.3, 0.2]
    assert to.pareto_front(speed, error) == [0, 2, 3]     # 1 and 4 are beaten by 2 (#3)


def test_metric_keys_and_input_errors():
    summary = {"results": [{"broken_fraction": 0.3, "t": [1, 2]}], "mass": 2}
    assert to.metric_value(summary, "results.0.broken_fraction") == 0.3
    np.testing.assert_array_equal(to.metric_value(summary, "results.0.t"), [1.0, 2.0])
    with pytest.raises(KeyError, match="no item 3"):
        to.metric_value(summary, "results.3.t")
    with pytest.raises(KeyError, match="no 'broken'"):
        to.metric_value(summary, "results.0.broken")
    with pytest.raises(to.TradeoffError, match="two or more distinct values"):
        to.parse_vary(["dmin=1"])
    with pytest.raises(to.TradeoffError, match="sets --seed"):
        to.parse_vary(["seed=1,2"])
    with pytest.raises(to.TradeoffError, match="NAME=V1,V2"):
        to.parse_vary(["dmin"])
    variants = to.grid(to.parse_vary(["a=1,2", "b=x,y"]))
    assert [v.name for v in variants] == ["a=1,b=x", "a=1,b=y", "a=2,b=x", "a=2,b=y"]
    assert to.parse_reference("b=y,a=2", variants) == variants[3]
    with pytest.raises(to.TradeoffError, match="not in the grid"):
        to.parse_reference("a=3,b=x", variants)


SCRIPT = ROOT / "scripts" / "agglomerate_impact.py"
COMMON = ["--particles", "60", "--duration", "5e-5", "--vtk-interval", "0"]
METRICS = ["damage_ratio", "findings.damaged_share_by_height"]


@pytest.mark.yade
def test_a_tiny_scene_through_the_tool_matches_a_hand_run(tmp_path):
    pytest.importorskip("distributed")
    out = tmp_path / "trade"
    proc = subprocess.run(
        [sys.executable, "-m", "yadebreak", "tradeoff", str(SCRIPT), *COMMON,
         "--vary", "check-period=1,8", "--vary", "radius-multiplier=0.4,0.6", "--seeds", "2",
         "--metrics", ",".join(METRICS), "--reference", "check-period=1,radius-multiplier=0.6",
         "--out", str(out), "--scheduler", "local:2"],
        capture_output=True, text=True, timeout=900, cwd=ROOT)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    with open(out / "tradeoff.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["variant"] for r in rows] == [
        "check-period=1,radius-multiplier=0.4", "check-period=1,radius-multiplier=0.6",
        "check-period=8,radius-multiplier=0.4", "check-period=8,radius-multiplier=0.6"]
    for key in METRICS:
        for column in ("mean", "diff", "ci_low", "ci_high", "distinguishable"):
            assert f"{key}:{column}" in rows[0]
    assert [r["reference"] for r in rows] == ["False", "True", "False", "False"]
    variants = [("1", "0.4"), ("1", "0.6"), ("8", "0.4"), ("8", "0.6")]
    hand = {(period, lam, seed): json.loads((out / f"v{k:02d}_s{seed}" / "summary.json").read_text())
            for k, (period, lam) in enumerate(variants, 1) for seed in (1, 2)}
    # one line run by hand, outside the tool, is that line of the tool: the statistics below
    # are then those of hand runs (one suffices: every line is the same command with its values)
    folder = tmp_path / "hand"
    run = subprocess.run(["yade", "-n", "-x", str(SCRIPT), *COMMON, "--check-period", "8",
                          "--radius-multiplier", "0.4", "--seed", "2", "--out", str(folder)],
                         capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert run.returncode == 0, run.stderr[-2000:]
    by_hand = json.loads((folder / "summary.json").read_text())
    for key in ("damage_ratio", "findings"):
        assert by_hand[key] == hand[("8", "0.4", 2)][key]
    status = {r["description"]: r for r in json.loads((out / "sweep.json").read_text())["lines"]}
    wall = {k: [status[f"v{k:02d}_s{s}"]["wall_s"] for s in (1, 2)] for k in range(1, 5)}
    for k, (period, lam) in enumerate(variants, 1):
        row = rows[k - 1]
        assert float(row["speedup"]) == pytest.approx(np.median(wall[2]) / np.median(wall[k]))
        # scalar: the mean paired difference and its t interval (1 degree of freedom)
        x = np.array([hand[(period, lam, s)]["damage_ratio"] for s in (1, 2)])
        r = np.array([hand[("1", "0.6", s)]["damage_ratio"] for s in (1, 2)])
        d = x - r
        assert float(row["damage_ratio:mean"]) == pytest.approx(x.mean(), rel=1e-12)
        assert float(row["damage_ratio:diff"]) == pytest.approx(d.mean(), rel=1e-9, abs=1e-15)
        half = stats.t.ppf(0.975, 1) * d.std(ddof=1) / math.sqrt(2)
        assert float(row["damage_ratio:ci_low"]) == pytest.approx(d.mean() - half, abs=1e-12)
        assert float(row["damage_ratio:ci_high"]) == pytest.approx(d.mean() + half, abs=1e-12)
        # list: the RMS over the ten height bands of the mean paired difference
        key = "findings.damaged_share_by_height"
        xs = np.array([hand[(period, lam, s)]["findings"]["damaged_share_by_height"]
                       for s in (1, 2)])
        rs = np.array([hand[("1", "0.6", s)]["findings"]["damaged_share_by_height"]
                       for s in (1, 2)])
        assert float(row[f"{key}:diff"]) == pytest.approx(
            np.sqrt(np.mean(np.mean(xs - rs, axis=0) ** 2)), abs=1e-12)
    assert rows[1]["damage_ratio:diff"] == "0.0"              # the reference against itself
    # a weaker bond breaks more, in every seed: lambda 0.4 against 0.6
    assert float(rows[0]["damage_ratio:diff"]) > 0
    assert (out / "pareto.png").exists() and "| 1 |" in (out / "tradeoff.md").read_text()
