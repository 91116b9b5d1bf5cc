"""The report: one plot per figure with its settings printed under it, report.md, results.json."""
from __future__ import annotations

import json
import textwrap


def plt_module():
    """pyplot without a screen."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save(fig, path, settings):
    """The figure saved to `path` with its settings printed under it."""
    wrapped = textwrap.fill("Settings: " + settings, 150)
    lines = wrapped.count("\n") + 1
    fig.tight_layout(rect=(0, 0.035 * lines + 0.02, 1, 1))
    fig.text(0.01, 0.01, wrapped, fontsize=7, va="bottom")
    from yadebreak.jobs.lifecycle import save_figure
    save_figure(fig, path, dpi=110)
    plt_module().close(fig)
    return path


def table(header, rows):
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def write_report(out, figures, runner, args, wall, told=None):
    """report.md (a summary of the checks met, then each figure: plot, settings, table, checks)
    and results.json (every figure's entry, every run's result, the scenes' wall times and
    `told`, the jobs.wall_time.WallTime predicted from them)."""
    checks = [c for f in figures for c in f["checks"]]
    met = sum(bool(c["ok"]) for c in checks)
    lines = ["# The paper's Section 4.1 verification", "",
             f"`python3 -m yadebreak verify {' '.join(args.argv)}`: {wall:.0f} s of wall time "
             f"({'quick subset' if args.quick else 'the figures asked for'}). Model lines: "
             "docs/model.md; settings under each figure.", "",
             f"**Checks met: {met} of {len(checks)}.**", ""]
    if told is not None:
        lines += [f"Wall time: {told.line()}.", ""]
    lines += [f"- {f['name']}: {sum(bool(c['ok']) for c in f['checks'])} of {len(f['checks'])}"
              for f in figures]
    lines.append("")
    for f in figures:
        lines += [f"## {f['name']}", "", f"![{f['name']}]({f['plot']})", "",
                  f"Settings: {f['settings']}.", "", f["table"], ""]
        lines += [f"- {c['what']}: {c['detail']} ({'met' if c['ok'] else '**not met**'})"
                  for c in f["checks"] if "detail" in c]
        lines.append("")
    from yadebreak.jobs.lifecycle import write_atomic
    write_atomic(out / "report.md", "\n".join(lines))
    write_atomic(out / "results.json", json.dumps(
        {"argv": args.argv, "wall_s": wall, "figures": figures,
         "runs": list(runner.results.values()),
         "wall_time": None if told is None else told.to_dict(),
         "scene_walls": {key: runner.walls[key] for key in runner.order if key in runner.walls}},
        indent=1, default=float))
