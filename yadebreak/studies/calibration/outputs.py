"""What `python3 -m yadebreak fit` writes: the material TOML (each value with the data and fit
behind it), fit.json (estimate, standard error and 95 % interval per parameter) and report.md with
its plots. Model layer: no YADE.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from yadebreak.criteria import criterion_class
from yadebreak.jobs.lifecycle import save_figure, write_atomic
from yadebreak.studies.calibration.fit import base_value

N_KEYS = {1.2: "1.2", 1.5: "1.5", 2.0: "2", 4.0: "4", 25.0: "25", 50.0: "50", 75.0: "75"}


def _ci(est):
    return f"95 % interval [{est.lo:.4g}, {est.hi:.4g}] ({est.method})"


def material_text(cal, name, files):
    """The material file's text (TOML), or None when something it needs is missing."""
    base = cal.base
    if base is None or cal.missing:
        return None
    lines = [f"# Material fitted by `python3 -m yadebreak fit` (docs/calibration.md) from",
             *[f"#   {f}" for f in files],
             f"# Elastic and contact data from base material {base.name} ({base.source}).",
             f'name = "{name}"', f'description = "Fitted to laboratory data ({cal.model})"',
             "breakable = true", "", "[elastic]              # from the base material",
             f"density = {base.density:.6g}          # kg/m3",
             f"young_modulus = {base.young_modulus / 1e9:.6g}   # GPa",
             f"poisson_ratio = {base.poisson_ratio:.6g}", "", "[breakage]",
             f'model = "{cal.model}"']
    criterion = criterion_class(cal.model)
    for key in criterion.keys:
        if key.name in criterion.calibrated:
            est = cal.estimates.get(key.name)
            why = cal.sources[key.name] + (f"; {_ci(est)}" if est is not None else "")
            lines.append(f"# {key.name} ({key.unit}): {why}")
            lines.append(f"{key.name} = {cal.values[key.name]:.6g}")
            continue
        value = base_value(cal, key.name)
        whose = "the base material's" if value is not None else "the default"
        lines.append(f"{key.name} = {key.default if value is None else value:.6g}   # "
                     f"{'' if key.unit == '-' else key.unit + ', '}not fitted: {whose}")
    lines += ["", f"# Eq. 10, n = [alpha, beta]: {cal.beta_source}", "[breakage.beta]"]
    for n, key in N_KEYS.items():
        a, b = cal.beta[n]
        lines.append(f'"{key}" = [{a:.5g}, {b:.5g}]')
    if base.contact_like:
        lines.insert(lines.index("breakable = true") + 1, f'contact_like = "{base.contact_like}"')
    for other, c in base.contacts.items():
        lines += ["", f"[contact.{other}]      # from the base material",
                  f"friction = {c.friction:.6g}", f"rolling_friction = {c.rolling_friction:.6g}",
                  f"restitution = {c.restitution:.6g}"]
    return "\n".join(lines) + "\n"


def fit_json(cal, extra=None):
    """{parameter: {estimate, standard_error, ci95, unit, interval_method}} plus the context."""
    params = {k: e.as_json() for k, e in cal.estimates.items()}
    return {"model": cal.model, "base": None if cal.base is None else cal.base.name,
            "data": {k: t.path for k, t in cal.tables.items()}, "parameters": params,
            "from_base": {k: v for k, v in cal.values.items() if k not in cal.estimates},
            "missing": cal.missing, "notes": cal.notes, **(extra or {})}


def write_json(cal, path, extra=None):
    write_atomic(path, json.dumps(fit_json(cal, extra), indent=2, default=_plain))


def _plain(v):
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    raise TypeError(type(v))


def _fmt(v):
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.4g}"


def report_text(cal, plots, timings):
    """report.md: estimates, intervals, correlations, goodness of fit, plots."""
    out = [f"# Calibration report ({cal.model})", "",
           "Fitted by `python3 -m yadebreak fit`; methods in docs/calibration.md. Data: "
           + ", ".join(f"{k}: `{t.path}`" for k, t in cal.tables.items()) + ".", ""]
    if cal.base is not None:
        out += [f"Base material: `{cal.base.name}` (elastic and contact data; parameters without "
                "data).", ""]
    out += ["## Estimates", "", "| parameter | estimate | standard error | 95 % interval | "
            "unit | interval | from |", "|---|---|---|---|---|---|---|"]
    for k, e in cal.estimates.items():
        out.append(f"| {k} | {_fmt(e.value)} | {_fmt(e.se)} | [{_fmt(e.lo)}, {_fmt(e.hi)}] | "
                   f"{e.unit} | {e.method} | {cal.sources.get(k, 'Eq. 10 fit')} |")
    for k, v in cal.values.items():
        if k not in cal.estimates:
            unit = criterion_class(cal.model).key(k).unit
            out.append(f"| {k} | {_fmt(v)} | - | - | {unit} | - | {cal.sources[k]} |")
    if cal.missing:
        out += ["", "Missing (no data, no base): " + ", ".join(cal.missing)]
    for note in cal.notes:
        out += ["", note]
    out += ["", "Standard errors from the observed information (the Hessian of the negative "
            "log-likelihood at its optimum, delta method to the parameter); they mean little "
            "where an interval is far from symmetric."]
    fr = cal.fits.get("fracture")
    if fr is not None and hasattr(fr, "result"):
        names = [c.name for c in fr.result.coords]
        out += ["", "## Correlations of the fracture-energy estimates", "",
                "| | " + " | ".join(names) + " |", "|---" * (len(names) + 1) + "|"]
        for i, n in enumerate(names):
            out.append(f"| {n} | " + " | ".join(_fmt(v) for v in fr.result.correlation[i]) + " |")
        out += ["", "## Goodness of fit per size class (fracture energies)", "",
                "Kolmogorov-Smirnov test of each class's broken particles against the fitted "
                "distribution (conditional on breaking below the class's lowest censoring energy). "
                "With the parameters fitted to the same data the p-values err towards acceptance.",
                "", "| size (mm) | particles | broken | censored | fitted E50 (J/kg) | KS D | "
                "p-value |", "|---|---|---|---|---|---|---|"]
        for c in fr.classes:
            out.append(f"| {c['size_mm']:g} | {c['particles']} | {c['broken']} | {c['censored']} "
                       f"| {_fmt(c['e50_J_per_kg'])} | {_fmt(c['ks_statistic'])} | "
                       f"{_fmt(c['ks_p_value'])} |")
    t = cal.fits.get("t10")
    if t is not None:
        out += ["", "## t10 against energy", "", f"{t.extra['points']} points, residual standard "
                f"deviation {t.extra['residual_sd']:.3g} % (t10)."]
    rep = cal.fits.get("repeated")
    if rep is not None:
        out += ["", "## Repeated impacts: deviance test per series", "",
                "| size (mm) | energy (J/kg) | impacts | deviance | p-value |",
                "|---|---|---|---|---|"]
        for s in rep.extra["series"]:
            out.append(f"| {s['size_mm']:g} | {s['energy_J_per_kg']:.4g} | {len(s['tested'])} | "
                       f"{s['deviance']:.3g} | {s['p_value']:.3g} |")
    prog = cal.fits.get("progeny")
    if prog:
        out += ["", "## Progeny (Eq. 10)", "", "| n | alpha | beta | residual sd (%) |",
                "|---|---|---|---|"]
        for n, r in prog.items():
            out.append(f"| {n:g} | {_fmt(r.estimates[f'alpha_{n:g}'].value)} | "
                       f"{_fmt(r.estimates[f'beta_{n:g}'].value)} | {r.extra['residual_sd']:.3g} |")
    if plots:
        out += ["", "## Plots", ""] + [f"![{p.stem}]({p.name})" for p in plots]
    if timings:
        out += ["", "Run time: " + ", ".join(f"{k} {v:.2f} s" for k, v in timings.items()) + "."]
    return "\n".join(out) + "\n"


def plots(cal, out):
    """The figures of report.md (PNG, matplotlib Agg); returns their paths."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from yadebreak.studies.calibration.plots import FIGURES
    paths = []
    for name, draw in FIGURES:
        fig = draw(cal, plt)
        if fig is None:
            continue
        path = Path(out) / f"{name}.png"
        fig.tight_layout()
        save_figure(fig, path, dpi=100)
        plt.close(fig)
        paths.append(path)
    return paths


