"""Every fit a data set allows, in order: fracture energies, then t10, repeated impacts and
progeny (which use the fracture parameters), the rest from a base material. Bootstrap intervals
refit resampled data sets. Model layer: no YADE.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from yadebreak.criteria import criterion_class
from yadebreak.studies.calibration import ab_t10, damage, data, fracture, progeny, t10
from yadebreak.studies.calibration.mle import Estimate, FitError


@dataclass
class Calibration:
    """The outcome: fitted estimates, the values of the material file and where each came from."""
    model: str
    base: object
    device: fracture.Device
    tables: dict
    fits: dict = field(default_factory=dict)
    estimates: dict = field(default_factory=dict)
    values: dict = field(default_factory=dict)
    sources: dict = field(default_factory=dict)
    beta: dict | None = None
    beta_source: str = ""
    missing: list = field(default_factory=list)
    notes: list = field(default_factory=list)


def _describe(table, what):
    return f"{what} of {table.path} ({len(table)} rows)"


def fit_all(tables, model_name="tavares", base=None, intervals=True, near=None):
    """Fit what `tables` ({kind: Table}, one Table per kind) allow. base: a Material or None.
    near: a Calibration of similar data whose gamma starts the search (bootstrap replicates)."""
    if model_name == "ab_t10" and base is None:
        raise FitError("--base: Ab-T10's e_min is an absolute energy, so the particle's share of "
                       "the device energy (its elastic constants) must come from a base material")
    device = fracture.Device()
    if base is not None:            # the base's particle on the base's device (steel by default)
        device = (fracture.Device(base.hertz_stiffness, base.criterion.device_stiffness)
                  if base.breakable else fracture.Device(base.hertz_stiffness))
    cal = Calibration(model_name, base, device, tables)
    if model_name == "tavares":
        _tavares(cal, intervals, None if near is None else near.values.get("gamma"))
    else:
        _ab_t10(cal, intervals)
    _beta(cal, intervals)
    return cal


def _take(cal, result, what):
    for name, est in result.estimates.items():
        cal.estimates[name] = est
        cal.values[name] = est.value
        cal.sources[name] = what


def base_value(cal, key):
    """The base material's value of the fitted criterion's `key` in the file's unit, or None
    (no base, or a base of another criterion)."""
    base = cal.base
    if base is None or base.breakage_model != cal.model:
        return None
    return getattr(base.params, key) / criterion_class(cal.model).key(key).factor


def _from_base(cal, keys):
    for key in keys:
        if key in cal.values:
            continue
        value = base_value(cal, key)
        if value is None:
            cal.missing.append(key)
            continue
        cal.values[key] = value
        cal.sources[key] = f"from base material {cal.base.name} (not fitted: no data for it)"


def _tavares(cal, intervals, gamma_start=None):
    base_tav = cal.base if cal.base is not None and not cal.base.is_ab_t10 and cal.base.breakable \
        else None
    if "fracture" in cal.tables:
        table = cal.tables["fracture"]
        fixed = {}
        if len(np.unique(table.columns["size"])) < fracture.MIN_CLASSES and base_tav is not None:
            fixed = {k: base_value(cal, k) for k in ("d0", "phi")}
            for k, v in fixed.items():
                cal.values[k] = v
                cal.sources[k] = (f"from base material {base_tav.name}: fewer than "
                                  f"{fracture.MIN_CLASSES} size classes in the data")
        fit = fracture.fit_fracture(table, cal.device, fixed, intervals)
        cal.fits["fracture"] = fit
        _take(cal, fit.result, "maximum likelihood, Eqs. 1-3, " + _describe(table, "fracture "
                                                                            "energies"))
    _from_base(cal, ("e_inf", "d0", "phi", "sigma", "emax_ratio"))
    frac = {k: cal.values.get(k) for k in ("e_inf", "d0", "phi", "sigma", "emax_ratio")}
    have_frac = all(v is not None for v in frac.values())
    for kind, fitter, what in (("t10", t10.fit_t10, "least squares, Eq. 7 with E50b, "),
                               ("repeated", damage.fit_gamma, "binomial likelihood, Eqs. 5-6, ")):
        if kind not in cal.tables:
            continue
        if not have_frac:
            raise FitError(f"{cal.tables[kind].path}: its fit needs the fracture-energy "
                           "parameters (Eqs. 1-3): give fracture-energy data or --base")
        result = (fitter(cal.tables[kind], frac, cal.device, intervals) if kind == "t10" else
                  fitter(cal.tables[kind], frac, cal.device, intervals, start=gamma_start))
        cal.fits[kind] = result
        _take(cal, result, what + _describe(cal.tables[kind], kind))
    _from_base(cal, ("gamma", "A", "b_prime"))


def _ab_t10(cal, intervals):
    base = cal.base
    size_ref = base_value(cal, "size_ref")
    if "fracture" in cal.tables:
        table = cal.tables["fracture"]
        if size_ref is None:
            size_ref = float(np.median(np.unique(table.columns["size"])))
        result = ab_t10.fit_ab_t10(table, cal.device, size_ref, intervals)
        cal.fits["fracture"] = result
        _take(cal, result, "maximum likelihood, Eqs. 9.1-9.3, " + _describe(table, "fracture "
                                                                            "energies"))
        cal.values["size_ref"] = size_ref
        cal.sources["size_ref"] = ("the base material's L_ref" if base.is_ab_t10 else
                                   "a convention: the median size class of the data")
    _from_base(cal, ("e_min_ref", "size_ref", "selection"))
    if "t10" in cal.tables:
        params = {k: cal.values.get(k) for k in ("e_min_ref", "selection")}
        if None in params.values() or "size_ref" not in cal.values:
            raise FitError(f"{cal.tables['t10'].path}: t10_max needs e_min_ref and selection: "
                           "give fracture-energy data or an Ab-T10 --base")
        result = t10.fit_t10_max(cal.tables["t10"], params, cal.device, cal.values["size_ref"],
                                 intervals)
        cal.fits["t10"] = result
        _take(cal, result, "least squares, t10 = M P / 2 (Eqs. 9.3-9.4), "
              + _describe(cal.tables["t10"], "t10"))
    if "repeated" in cal.tables:
        cal.notes.append(f"{cal.tables['repeated'].path}: repeated impacts are not used by the "
                         "Ab-T10 fit (its e_cum adds up without a damage parameter)")
    _from_base(cal, ("t10_max",))


def _beta(cal, intervals):
    if "progeny" in cal.tables:
        fits = progeny.fit_progeny(cal.tables["progeny"], intervals)
        cal.fits["progeny"] = fits
        cal.beta = {n: (r.estimates[f"alpha_{n:g}"].value, r.estimates[f"beta_{n:g}"].value)
                    for n, r in fits.items()}
        for r in fits.values():
            cal.estimates.update(r.estimates)
        cal.beta_source = "least squares, Eq. 10, " + _describe(cal.tables["progeny"], "progeny")
        missing = [n for n in (1.2, 1.5, 2.0, 4.0, 25.0, 50.0, 75.0) if n not in fits]
        if missing and cal.base is not None and cal.base.beta_params is not None:
            for n in missing:
                cal.beta[n] = cal.base.beta_params[n]
            cal.beta_source += f"; n = {', '.join(f'{n:g}' for n in missing)} from base " \
                               f"material {cal.base.name}"
        elif missing:
            cal.missing.append("beta (n = " + ", ".join(f"{n:g}" for n in missing) + ")")
            cal.beta = None
    elif cal.base is not None and cal.base.beta_params is not None:
        cal.beta = dict(cal.base.beta_params)
        cal.beta_source = f"from base material {cal.base.name} ({cal.base.beta_source})"
    else:
        cal.missing.append("beta (Eq. 10 table)")


# ------------------------------------------------------------------------------ bootstrap
def resample(table, rng):
    """A bootstrap copy of a Table: rows drawn with replacement within each group (size class;
    t10 value's n; a repeated-impact series particle by particle)."""
    c = table.columns
    if table.kind == "repeated":
        return _resample_series(table, rng)
    key = c["n"] if table.kind == "progeny" else c["size"]
    rows = np.concatenate([rng.choice(np.flatnonzero(key == k), np.count_nonzero(key == k))
                           for k in np.unique(key)])
    return table.subset(rows)


def _resample_series(table, rng):
    """Particles of each series as (impact at which it broke or left, broke?), redrawn."""
    out_cols = {q: [] for q in ("size", "energy", "impact", "tested", "broken")}
    for size, energy, tested, broken in damage.series(table):
        fate, broke = [], []
        for k, (n_t, n_b) in enumerate(zip(tested, broken)):
            after = tested[k + 1] if k + 1 < len(tested) else 0
            left = int(n_t - n_b - after)               # survivors not tested again
            fate += [k] * int(n_b + left)
            broke += [True] * int(n_b) + [False] * left
        fate, broke = np.array(fate), np.array(broke)
        pick = rng.integers(0, len(fate), len(fate))
        fate, broke = fate[pick], broke[pick]
        for k in range(len(tested)):
            out_cols["size"].append(size)
            out_cols["energy"].append(energy)
            out_cols["impact"].append(k + 1)
            out_cols["tested"].append(np.count_nonzero(fate >= k))
            out_cols["broken"].append(np.count_nonzero((fate == k) & broke))
    cols = {q: np.array(v, float) for q, v in out_cols.items()}
    return data.Table(table.path, "repeated", cols, np.zeros(len(cols["size"]), int), table.names)


def bootstrap(tables, model_name, base, replicates, seed, say=None, near=None):
    """Percentile 95 % intervals from `replicates` refits of resampled data (numpy Generator
    seeded with `seed`; `near`: the full data's Calibration, to start searches from); returns
    ({name: (lo, hi)}, replicates that failed)."""
    rng = np.random.default_rng(seed)
    draws, failed = {}, 0
    for i in range(replicates):
        copy = {kind: resample(t, rng) for kind, t in tables.items()}
        try:
            cal = fit_all(copy, model_name, base, intervals=False, near=near)
        except (FitError, data.DataError, ValueError):
            failed += 1
            continue
        for name, est in cal.estimates.items():
            draws.setdefault(name, []).append(est.value)
        if say and (i + 1) % 50 == 0:
            say(f"bootstrap: {i + 1}/{replicates}")
    return {k: (float(np.percentile(v, 2.5)), float(np.percentile(v, 97.5)))
            for k, v in draws.items()}, failed


def apply_bootstrap(cal, intervals, replicates):
    """Replace the intervals of `cal` by bootstrap percentile ones."""
    for name, (lo, hi) in intervals.items():
        est = cal.estimates.get(name)
        if est is not None:
            cal.estimates[name] = Estimate(est.name, est.value, est.unit, est.se, lo, hi,
                                           method=f"bootstrap percentile ({replicates} "
                                                  "replicates)", note=est.note)
