"""The bed sweep's report: its runs gathered by configuration, and the paper's Figs. 20-23.

    /usr/bin/python3 scripts/gather_sweep.py [--sweep out/sweep] [--out out/sweep_report]
                                             [--table scripts/bed_sweep.table]

A partial sweep is gathered as far as it went: runs without summary.json, or that ended in an
error or were interrupted (summary.json's end_reason), are listed as unfinished. Writes
configurations.csv and configurations.md (a row per configuration: means and standard deviations
over seeds) and the paper's figures with our points (error bars: one standard deviation over
seeds): capture_radius.png (Fig. 20), size_by_energy.png (copper ore monolayer at each energy,
Fig. 21), broken_mass.png (per bed configuration and material, the steel-particle rolling
friction 0.33 apart, Fig. 22), size_by_bed.png (copper ore and granulite at 3.05 J, Fig. 23).
The sweep's own DIR/sweep.csv (a row per table line, every summary.json flattened) is written by
`python3 -m yadebreak sweep` and `python3 -m yadebreak gather`: one shape, one writer
(yadebreak.studies.sweep.gather).
"""
from __future__ import annotations

import csv
import json
from collections import defaultdict
from pathlib import Path

import numpy as np

from yadebreak.analysis.reports import bounded_errors
from yadebreak.studies import sweep as sweep_tables


def read_table(path):
    """The descriptions (output folder names) of a yade-batch table's lines."""
    try:
        return [line.description for line in sweep_tables.read_table(path)]
    except sweep_tables.SweepError as exc:
        raise SystemExit(f"--table: {exc}") from None


def gather(sweep, expected):
    """(finished runs' summaries, unfinished lines with why): a partial sweep is gathered as far
    as it went."""
    runs, unfinished = [], []
    folders = {p.name: p for p in Path(sweep).iterdir() if p.is_dir()} if Path(sweep).is_dir() else {}
    for name in sorted(set(folders) | set(expected)):
        path = folders.get(name, Path(sweep) / name) / "summary.json"
        if not path.exists():
            unfinished.append((name, "not run" if name not in folders else "no summary.json"))
            continue
        summary = json.loads(path.read_text())
        reason = summary.get("end_reason", "finished")
        if reason in ("finished", "time_limit"):
            runs.append({**summary, "folder": str(path.parent)})
        else:
            unfinished.append((name, f"{reason}: {summary.get('end_message', '')}"))
    return runs, unfinished




def steel_rolling(run):
    """The particle-steel rolling friction a run used (0 for runs made before it existed)."""
    return run.get("rolling_friction", {}).get("particle_steel", 0.0)


def size_distribution(rs):
    """(sizes in mm, mean and standard deviation over the runs of the cumulative % passing)."""
    paths = [Path(r["folder"]) / "size_distribution.csv" for r in rs]
    tables = [np.loadtxt(p, delimiter=",", skiprows=1) for p in paths if p.exists()]
    if not tables:                  # (summaries gathered without their folders' other files)
        return None
    passing = np.array([t[:, 1] for t in tables])
    sd = passing.std(axis=0, ddof=1) if len(tables) > 1 else np.zeros(passing.shape[1])
    return 1e3 * tables[0][:, 0], passing.mean(axis=0), sd


def psd_panel(ax, sel, label_of, title):
    """Cumulative passing against size, one line per configuration, error bars at every fourth
    sieve (paper Figs. 21 and 23: 0.1 mm to the feed size)."""
    for k, r in enumerate(sel):
        found = size_distribution(r["_runs"])
        if found is None:
            continue
        sizes, mean, sd = found
        keep = (sizes >= 0.08) & (sizes <= 8.0)
        ax.semilogx(sizes[keep], mean[keep], "-", c=f"C{k}", label=label_of(r))
        marks = np.flatnonzero(keep)[::4]
        ax.errorbar(sizes[marks], mean[marks], yerr=sd[marks], fmt="o", ms=3, c=f"C{k}",
                    capsize=2)
    ax.axvline(4.75, ls=":", c="k")
    ax.set(xlabel="size (mm)", ylabel="cumulative passing (%)", title=title, ylim=(0, None))
    ax.legend(fontsize=8)


def configurations(runs):
    """A row per bed configuration (material, rings, layers, energy, steel rolling friction,
    outcome): means and standard deviations over its runs (seeds)."""
    groups = defaultdict(list)
    for r in runs:
        groups[(r["material"], r["rings"], r["layers"], r["energy"], steel_rolling(r),
                r.get("outcome", "paper"))].append(r)
    rows = []
    for (mat, rings, layers, energy, crf, outcome), rs in sorted(groups.items()):
        bm = np.array([r["broken_mass"] for r in rs]) * 1e3
        cr = np.array([r["capture_radius"] for r in rs]) * 1e3
        rows.append({"material": mat, "rings": rings, "layers": layers, "energy_J": energy,
                     "steel_rolling_friction": crf, "packing": rs[0].get("bed_packing", "lattice"),
                     "outcome": outcome,
                     "runs": len(rs), "broken_mass_g": bm.mean(), "broken_mass_sd": bm.std(ddof=1)
                     if len(rs) > 1 else 0.0,
                     "broken_fraction": np.mean([r["broken_mass_fraction"] for r in rs]),
                     "capture_radius_mm": cr.mean(), "capture_radius_sd": cr.std(ddof=1)
                     if len(rs) > 1 else 0.0,
                     "runtime_s": np.mean([r["runtime_s"] for r in rs]), "_runs": rs})
    return rows


def write_tables(rows, out):
    """configurations.csv and configurations.md in `out`."""
    with open(out / "configurations.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=[k for k in rows[0] if not k.startswith("_")],
                           extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    lines = ["| material | rings | layers | packing | steel Crf | energy (J) | outcome | runs | "
             "broken mass (g) | broken % | capture radius (mm) | run (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['material']} | {r['rings']} | {r['layers']} | {r['packing']} | "
              f"{r['steel_rolling_friction']:g} | {r['energy_J']:g} | {r['outcome']} | {r['runs']} | "
              f"{r['broken_mass_g']:.3f} ± {r['broken_mass_sd']:.3f} | {100 * r['broken_fraction']:.1f} | "
              f"{r['capture_radius_mm']:.1f} ± {r['capture_radius_sd']:.1f} | {r['runtime_s']:.0f} |"
              for r in rows]
    (out / "configurations.md").write_text("\n".join(lines) + "\n")


def plot_figures(rows, out):
    """The paper's Figs. 20-23 with the runs' points; returns the files written."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    at_305 = [r for r in rows if abs(r["energy_J"] - 3.05) < 1e-9]
    configs = sorted({(r["rings"], r["layers"]) for r in at_305}, key=lambda c: (c[1], c[0]))
    k = 0
    for mat in sorted({r["material"] for r in at_305}):
        for crf in sorted({r["steel_rolling_friction"] for r in at_305 if r["material"] == mat}):
            sel = sorted((r for r in at_305 if r["material"] == mat
                          and r["steel_rolling_friction"] == crf),
                         key=lambda r: configs.index((r["rings"], r["layers"])))
            mass = [r["broken_mass_g"] for r in sel]
            modified = crf != min(r["steel_rolling_friction"] for r in at_305)
            ax.errorbar([configs.index((r["rings"], r["layers"])) + (0.12 if modified else 0.0)
                         for r in sel], mass,
                        yerr=bounded_errors(mass, [r["broken_mass_sd"] for r in sel]),
                        fmt="s--" if modified else "o-", mfc="none" if modified else None,
                        c=f"C{k}", capsize=3,
                        label=mat + (f", steel-particle Crf {crf:g}" if modified else ""))
            k += 1
    ax.set_xticks(range(len(configs)), [f"{rings}R" if layers == 1 else f"{layers} layers"
                                         for rings, layers in configs])
    ax.set(xlabel="bed configuration (monolayer rings, or layers)", ylabel="broken mass (g)",
           title="broken mass at 3.05 J (paper Fig. 22)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "broken_mass.png", dpi=110)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for k, mat in enumerate(sorted({r["material"] for r in rows})):
        sel = [r for r in rows if r["material"] == mat and r["layers"] == 1 and r["rings"] == 3
               and r["steel_rolling_friction"] == min(x["steel_rolling_friction"] for x in rows)]
        if len(sel) < 2:
            continue
        radius = [r["capture_radius_mm"] for r in sel]
        ax.errorbar([r["energy_J"] for r in sel], radius,
                    yerr=bounded_errors(radius, [r["capture_radius_sd"] for r in sel]), fmt="o-",
                    c=f"C{k}", capsize=3, label=mat)
    ax.set(xlabel="impact energy (J)", ylabel="capture radius (mm)",
           title="capture radius, monolayer of 3 rings (paper Fig. 20)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "capture_radius.png", dpi=110)
    written = ["configurations.csv", "configurations.md", "broken_mass.png", "capture_radius.png"]
    by_energy = sorted((r for r in rows if r["material"] == "copper_ore" and r["layers"] == 1
                        and r["rings"] == 3), key=lambda r: r["energy_J"])
    if len(by_energy) > 1:
        fig, ax = plt.subplots(figsize=(6, 4.5))
        psd_panel(ax, by_energy, lambda r: f"{r['energy_J']:g} J",
                  "copper ore, monolayer of 3 rings (paper Fig. 21)")
        fig.tight_layout()
        fig.savefig(out / "size_by_energy.png", dpi=110)
        written.append("size_by_energy.png")
    panels = [m for m in ("copper_ore", "granulite") if any(r["material"] == m for r in at_305)]
    if panels:
        fig, axes = plt.subplots(len(panels), 1, figsize=(6, 4.2 * len(panels)), squeeze=False)
        for ax, mat in zip(axes[:, 0], panels):
            sel = [r for r in at_305 if r["material"] == mat and r["steel_rolling_friction"]
                   == min(x["steel_rolling_friction"] for x in at_305)]
            sel.sort(key=lambda r: configs.index((r["rings"], r["layers"])))
            psd_panel(ax, sel, lambda r: (f"{r['rings']} rings" if r["layers"] == 1
                                          else f"{r['layers']} layers"),
                      f"{mat}, 3.05 J (paper Fig. 23)")
        fig.tight_layout()
        fig.savefig(out / "size_by_bed.png", dpi=110)
        written.append("size_by_bed.png")
    return written


def report(sweep, out, table=""):
    """Gather the runs under `sweep`, write the tables and figures into `out`; returns a line to
    print. Unfinished lines (of `table`, if given) are printed first."""
    runs, unfinished = gather(sweep, read_table(table) if table else [])
    for name, why in unfinished:
        print(f"unfinished: {name} ({why})")
    if not runs:
        raise SystemExit(f"no finished run under {sweep}: run the sweep first "
                         "(yade-batch -j 2 scripts/bed_sweep.table scripts/bed_impact.py)")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows = configurations(runs)
    write_tables(rows, out)
    written = plot_figures(rows, out)
    return (f"{len(runs)} runs in {len(rows)} configurations"
          + (f" ({len(unfinished)} unfinished, listed above)" if unfinished else "")
          + f"; wrote {', '.join(written)} in {out}")
