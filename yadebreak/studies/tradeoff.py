"""The trade of speed for accuracy on any scene, with error bars over seeds.

    python3 -m yadebreak tradeoff scripts/bed_impact.py --vary read-period=every_step,fast
        --vary dummies=spheres,ledger --seeds 5 --metrics broken_mass_fraction --out out/trade

SCRIPT (any scene taking --seed and --out and the varied options) runs over the grid of the
varied options' values x seeds 1..N, every variant with the same seeds (common random numbers:
the differences are paired), through the sweep runner (yadebreak.studies.sweep: one Dask task per run,
DIR/<variant>_s<seed>/, DIR/sweep.json; a second call runs only what is not done). Each run's
summary.json gives the metrics (dotted keys reach nested values: results.0.broken_fraction; a list
is compared element-wise by its RMS). The reference is the variant given by --reference or the
slowest; per variant: wall time (median, spread), speed-up, each metric's mean and its paired
difference from the reference with a 95 % confidence interval, and whether that difference stands
out of the seeds' noise. Writes tradeoff.csv, tradeoff.md and pareto.png.

The statistics (no Dask, no YADE) are the functions below; run() drives the runs.
"""
from __future__ import annotations

import csv
import io
import itertools
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import stats

from yadebreak.studies import sweep
from yadebreak.jobs.lifecycle import save_figure, write_atomic

#: confidence level of the intervals
LEVEL = 0.95
#: bootstrap resamples of seeds for a list metric's interval (fixed seed: reproducible)
BOOTSTRAP = 4000


class TradeoffError(ValueError):
    """A trade-off that cannot start: one line for the user."""


# -- the grid ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Variant:
    """One combination of the varied options: ((name, value as text), ...) in --vary's order."""

    values: tuple

    @property
    def name(self):
        return ",".join(f"{k}={v}" for k, v in self.values)

    @property
    def slug(self):
        """A folder-safe name."""
        return re.sub(r"[^A-Za-z0-9_.=+-]", "_", "__".join(f"{k}={v}" for k, v in self.values))

    def argv(self):
        return [x for k, v in self.values for x in (f"--{k}", v)]


def parse_vary(items):
    """--vary NAME=V1,V2,... (repeatable) as [(name, [values])]: the script's option without
    its dashes, two or more distinct values."""
    out, seen = [], set()
    for item in items:
        name, sep, values = item.partition("=")
        name = name.strip().lstrip("-")
        vals = [v.strip() for v in values.split(",") if v.strip()]
        if not sep or not name or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_-]*", name):
            raise TradeoffError(f"--vary {item!r}: accepted NAME=V1,V2,... (the script's option "
                                "without its dashes)")
        if len(vals) < 2 or len(set(vals)) != len(vals):
            raise TradeoffError(f"--vary {item!r}: give two or more distinct values")
        if name in seen:
            raise TradeoffError(f"--vary {name} given twice")
        if name in ("seed", "out"):
            raise TradeoffError(f"--vary {name}: the tool sets --{name} itself")
        seen.add(name)
        out.append((name, vals))
    if not out:
        raise TradeoffError("--vary: give at least one NAME=V1,V2,...")
    return out


def grid(varied):
    """Every combination of the varied values, in --vary's order (the last varies fastest)."""
    names = [n for n, _ in varied]
    return [Variant(tuple(zip(names, combo))) for combo in
            itertools.product(*[vals for _, vals in varied])]


def parse_reference(text, variants):
    """The variant --reference NAME=V,... names (None for an empty text)."""
    if not text:
        return None
    wanted = {}
    for item in text.split(","):
        name, sep, value = item.partition("=")
        if not sep:
            raise TradeoffError(f"--reference {text!r}: accepted NAME=V,... for every varied "
                                "option")
        wanted[name.strip().lstrip("-")] = value.strip()
    for v in variants:
        if dict(v.values) == wanted:
            return v
    names = "; ".join(v.name for v in variants)
    raise TradeoffError(f"--reference {text!r} is not in the grid ({names})")


# -- reading the runs ------------------------------------------------------------------------------
def metric_value(summary, key):
    """The value of dotted `key` in a summary (dict keys, list indices): a float, or a 1-D float
    array for a list of numbers. KeyError naming the part missing."""
    value = summary
    for part in key.split("."):
        if isinstance(value, list):
            if not (part.lstrip("-").isdigit() and -len(value) <= int(part) < len(value)):
                raise KeyError(f"{key}: no item {part} in a list of {len(value)}")
            value = value[int(part)]
        elif isinstance(value, dict):
            if part not in value:
                raise KeyError(f"{key}: no {part!r} (there: {', '.join(map(str, value))})")
            value = value[part]
        else:
            raise KeyError(f"{key}: {part!r} below a number")
    if isinstance(value, list):
        return np.array([np.nan if v is None else float(v) for v in value], float)
    return float("nan") if value is None else float(value)


# -- the statistics --------------------------------------------------------------------------------
@dataclass(frozen=True)
class Difference:
    """A variant's metric against the reference's, paired by seed."""

    mean: float            # the variant's mean (a list metric: the RMS of its mean list)
    error: float           # scalar: mean paired difference; list: RMS of the mean difference
    low: float             # 95 % interval of `error`
    high: float
    distinguishable: bool  # the difference stands out of the seeds' noise
    seeds: int


def paired_difference(values, reference):
    """The paired comparison of one metric over common seeds. `values`, `reference`: lists (one
    per seed) of floats, or of equal-length arrays for a list metric.

    Scalar: the mean of d_s = x_s - r_s, its Student t interval (n - 1 degrees of freedom), and
    distinguishable when the interval excludes 0.
    List: the RMS over elements of the mean difference vector; its interval by a bootstrap over
    seeds (percentiles, fixed seed); distinguishable when some element's paired t test rejects
    zero at 5 % with Bonferroni's correction over the elements (the RMS alone is never 0).
    With one seed the interval is NaN and nothing is distinguishable."""
    x = np.asarray(values, float)
    r = np.asarray(reference, float)
    d = x - r
    n = len(d)
    if x.ndim == 1:
        mean_d = float(np.mean(d))
        if n < 2:
            return Difference(float(np.mean(x)), mean_d, math.nan, math.nan, False, n)
        sd = float(np.std(d, ddof=1))
        half = float(stats.t.ppf(0.5 + LEVEL / 2, n - 1)) * sd / math.sqrt(n)
        return Difference(float(np.mean(x)), mean_d, mean_d - half, mean_d + half,
                          (mean_d - half > 0) or (mean_d + half < 0), n)
    rms = float(np.sqrt(np.nanmean(np.nanmean(d, axis=0) ** 2)))
    level = float(np.sqrt(np.nanmean(np.nanmean(x, axis=0) ** 2)))
    if n < 2:
        return Difference(level, rms, math.nan, math.nan, False, n)
    rng = np.random.default_rng(0)
    picks = rng.integers(0, n, size=(BOOTSTRAP, n))
    boot = np.sqrt(np.nanmean(np.nanmean(d[picks], axis=1) ** 2, axis=1))
    low, high = np.percentile(boot, [50 * (1 - LEVEL), 50 * (1 + LEVEL)])
    sd = np.nanstd(d, axis=0, ddof=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(sd > 0, np.nanmean(d, axis=0) / (sd / math.sqrt(n)),
                     np.where(np.nanmean(d, axis=0) != 0, np.inf, 0.0))
    p = 2 * stats.t.sf(np.abs(t), n - 1)
    cols = d.shape[1]
    return Difference(level, rms, float(low), float(high), bool(np.any(p < (1 - LEVEL) / cols)), n)


def pareto_front(speedups, errors):
    """Indices of the variants no other beats on both counts (a higher speed-up and a smaller
    |error|, at least as good on one and better on the other), by speed-up."""
    s = np.asarray(speedups, float)
    e = np.abs(np.asarray(errors, float))
    tol = 1e-9 * np.nanmax(np.where(np.isfinite(e), e, 0.0), initial=0.0) + 1e-300
    front = []
    for i in range(len(s)):
        if not np.isfinite(e[i]):
            continue
        # errors equal to round-off count as equal (two settings that give the same result)
        no_worse = e <= e[i] + tol
        better = (s > s[i]) | (e < e[i] - tol)
        dominated = np.any((s >= s[i]) & no_worse & better & np.isfinite(e))
        if not dominated:
            front.append(i)
    return sorted(front, key=lambda i: s[i])


@dataclass
class VariantResult:
    variant: Variant
    wall: np.ndarray            # s per seed
    metrics: dict               # metric -> list per seed (float or array)


def analyse(results, reference, metrics):
    """Rows of the trade-off table (dicts), one per variant, in the grid's order."""
    ref = next(r for r in results if r.variant == reference)
    ref_wall = float(np.median(ref.wall))
    rows = []
    for k, res in enumerate(results, 1):
        wall = float(np.median(res.wall))
        row = {"number": k, "variant": res.variant.name,
               "reference": res.variant == reference,
               "seeds": len(res.wall), "wall_median_s": wall,
               "wall_min_s": float(np.min(res.wall)), "wall_max_s": float(np.max(res.wall)),
               "speedup": ref_wall / wall if wall > 0 else math.inf}
        for key in metrics:
            diff = paired_difference(res.metrics[key], ref.metrics[key])
            row[f"{key}:mean"] = diff.mean
            row[f"{key}:diff"] = diff.error
            row[f"{key}:ci_low"] = diff.low
            row[f"{key}:ci_high"] = diff.high
            row[f"{key}:distinguishable"] = diff.distinguishable
        rows.append(row)
    return rows


# -- outputs ---------------------------------------------------------------------------------------
def write_outputs(rows, metrics, out, title):
    """tradeoff.csv, tradeoff.md and pareto.png into `out`."""
    out = Path(out)
    columns = list(rows[0])
    table = io.StringIO(newline="")
    writer = csv.DictWriter(table, columns)
    writer.writeheader()
    writer.writerows(rows)
    write_atomic(out / "tradeoff.csv", table.getvalue())
    lines = [f"# {title}", "",
             "Paired over common seeds; diff = the variant's mean minus the reference's (a list "
             "metric: the RMS of the mean difference), with its 95 % interval; 'yes' where the "
             "difference stands out of the seeds' noise.", ""]
    head = "| # | variant | wall median (min-max) s | speed-up |"
    rule = "|---|---|---|---|"
    for key in metrics:
        head += f" {key} mean | diff [95 % CI] | distinguishable |"
        rule += "---|---|---|"
    lines += [head, rule]
    for r in rows:
        name = r["variant"] + (" (reference)" if r["reference"] else "")
        line = (f"| {r['number']} | {name} | {r['wall_median_s']:.3g} "
                f"({r['wall_min_s']:.3g}-{r['wall_max_s']:.3g}) | {r['speedup']:.2f} |")
        for key in metrics:
            if r["reference"]:
                line += f" {_g(r[f'{key}:mean'])} | - | - |"
                continue
            line += (f" {_g(r[f'{key}:mean'])} | {_g(r[f'{key}:diff'])} "
                     f"[{_g(r[f'{key}:ci_low'])}, {_g(r[f'{key}:ci_high'])}] | "
                     f"{'yes' if r[f'{key}:distinguishable'] else 'no'} |")
        lines.append(line)
    write_atomic(out / "tradeoff.md", "\n".join(lines) + "\n")
    plot_pareto(rows, metrics, out / "pareto.png", title)


def _g(x):
    return "nan" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.4g}"


def plot_pareto(rows, metrics, path, title):
    """One panel per metric: speed-up against |difference| with its interval, numbered points
    (the key lists them), the Pareto front as a line, the reference at speed-up 1 and error 0."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    n = len(metrics)
    key_text = "\n".join(f"{r['number']}: {r['variant']}" for r in rows)
    key_inches = 0.06 * max(len(line) for line in key_text.splitlines()) + 0.3
    width = 5.2 * n + key_inches
    fig, axes = plt.subplots(1, n, figsize=(width, 4.6), squeeze=False)
    speed = np.array([r["speedup"] for r in rows])
    for ax, key in zip(axes[0], metrics):
        err = np.array([0.0 if r["reference"] else r[f"{key}:diff"] for r in rows], float)
        low = np.array([0.0 if r["reference"] else r[f"{key}:ci_low"] for r in rows], float)
        high = np.array([0.0 if r["reference"] else r[f"{key}:ci_high"] for r in rows], float)
        # |difference| and its interval folded to the positive side
        mag = np.abs(err)
        lo = np.where(np.isfinite(low), np.where((low <= 0) & (high >= 0), 0.0,
                                                  np.minimum(np.abs(low), np.abs(high))), mag)
        hi = np.where(np.isfinite(high), np.maximum(np.abs(low), np.abs(high)), mag)
        for i, r in enumerate(rows):
            colour = "k" if r["reference"] else ("C3" if r[f"{key}:distinguishable"] else "C0")
            ax.errorbar(speed[i], mag[i], yerr=[[mag[i] - lo[i]], [hi[i] - mag[i]]], fmt="o",
                        color=colour, ms=5, capsize=3)
            ax.annotate(str(r["number"]), (speed[i], mag[i]), textcoords="offset points",
                        xytext=(5, 4 + 9 * (i % 2)), fontsize=8)
        front = pareto_front(speed, mag)
        ax.plot(speed[front], mag[front], "-", color="0.4", lw=1, label="Pareto front")
        if speed.max() / speed.min() > 3:     # a log axis only where it spans a few-fold
            ax.set_xscale("log")
            ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
            ax.xaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.set_ylim(bottom=0)
        ax.set_xlabel("speed-up against the reference")
        ax.set_ylabel(f"|difference| of {key}")
        ax.set_title(key, fontsize=9)
        ax.plot([], [], "o", color="C3", label="stands out of the noise")
        ax.plot([], [], "o", color="C0", label="within the noise")
        ax.plot([], [], "o", color="k", label="reference")
        ax.legend(fontsize=7, loc="best")
    key_width = key_inches / width                 # the key's share of the figure's width
    fig.text(1 - key_width + 0.005, 0.5, key_text, fontsize=7, va="center", ha="left",
             family="monospace")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0, 1 - key_width, 0.95))
    save_figure(fig, path, dpi=110)
    plt.close(fig)


# -- the driver ------------------------------------------------------------------------------------
def run(script, script_args, varied, seeds, metrics, out, reference_text="", scheduler="local",
        retries=1, say=print, yade="yade", tell=None):
    """Run the grid x seeds through the sweep runner, read the metrics, write the outputs.
    Returns the rows. say(line): the outcome; tell(line): the progress on the way (default:
    say)."""
    script, out = Path(script).resolve(), Path(out).resolve()
    if not script.is_file():
        raise TradeoffError(f"script {script}: no such file")
    for arg in script_args:
        if arg.split("=")[0] in ("--seed", "--out"):
            raise TradeoffError(f"{arg}: the tool sets --seed and --out of every run itself")
    if seeds < 1:
        raise TradeoffError(f"--seeds = {seeds}: accepted >= 1")
    if not metrics:
        raise TradeoffError("--metrics: name at least one summary.json key")
    variants = grid(varied)
    reference = parse_reference(reference_text, variants)
    jobs, where = [], {}
    for k, variant in enumerate(variants, 1):
        for seed in range(1, seeds + 1):
            name = f"v{k:02d}_s{seed}"
            folder = out / name
            argv = (yade, "-n", "-x", str(script), *script_args, *variant.argv(),
                    "--seed", str(seed), "--out", str(folder))
            jobs.append(sweep.Job(name, 0, argv, {}))
            where[(variant, seed)] = name
    identity = ("tradeoff " + json.dumps([v.name for v in variants]) + f" seeds {seeds}",
                str(script) + " " + " ".join(script_args))
    status = sweep.run_jobs(jobs, out, identity, scheduler, retries, say=tell or say)
    failed = [d for d, row in status.rows.items() if row["state"] != "done"]
    if failed:
        first = status.rows[failed[0]]
        raise TradeoffError(f"{len(failed)} of {len(jobs)} runs did not finish (e.g. "
                            f"{failed[0]}: {first['message']}); see {out}/<run>/log.txt, then "
                            "run the same command again")
    results = []
    for variant in variants:
        wall, values = [], {key: [] for key in metrics}
        for seed in range(1, seeds + 1):
            name = where[(variant, seed)]
            wall.append(status.rows[name]["wall_s"])
            summary = json.loads((out / name / "summary.json").read_text())
            for key in metrics:
                try:
                    values[key].append(metric_value(summary, key))
                except KeyError as exc:
                    raise TradeoffError(f"--metrics: {exc.args[0]} in {out / name}/summary.json"
                                        ) from None
        results.append(VariantResult(variant, np.array(wall, float), values))
    if reference is None:                  # the slowest variant
        reference = max(results, key=lambda r: float(np.median(r.wall))).variant
    rows = analyse(results, reference, metrics)
    title = (f"{script.name} {' '.join(script_args)}: {len(variants)} variants x {seeds} seeds, "
             f"reference {reference.name}")
    write_outputs(rows, metrics, out, title)
    say(f"tradeoff: wrote {out / 'tradeoff.md'}, tradeoff.csv and pareto.png")
    return rows
