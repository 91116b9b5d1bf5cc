"""Results of impact tests, shared by the scripts: first events, breakage against the model,
progeny size distribution and t10 against Eqs. 8 and 10, and the two-panel plot. No yade import:
`brk` is any object with `events` and `size_distribution` (the coupling's controller)."""
from __future__ import annotations

import numpy as np

from . import model


def product_size_distribution(table, ledger, materials, sizes, fines=True,
                              fines_model="gaudin_schuhmann"):
    """The product size distribution (model.SizeDistribution, docs/model.md Section 7) of the
    bodies of a body table (coupling.state.BodyTable) and a fines ledger.

    fines=True spreads dummy and unbreakable masses (Eqs. 11-13); fines=False counts every sphere
    at its own size, as in the paper's Fig. 13. fines_model: "gaudin_schuhmann" (the paper's
    Eqs. 11-12) or "eq10" (see model.dummy_fines_passing). materials: label -> Material.
    """
    resolved_d, resolved_m = [], []
    groups = {}

    def group(label):
        return groups.setdefault(label, {"dummy": ([], [], []), "unb": ([], [], [])})

    for row in table.values():
        kind = row.kind
        if kind == "broken":
            continue
        g = group(row.material)          # every material present gets its (maybe empty) group
        if fines and kind == "dummy":
            for lst, v in zip(g["dummy"], (row.mass, row.parent_size, row.t10)):
                lst.append(v)
        elif fines and kind == "unbreakable":
            for lst, v in zip(g["unb"], (2 * row.radius, row.mass, row.t10)):
                lst.append(v)
        else:
            resolved_d.append(2 * row.radius)
            resolved_m.append(row.mass)
    for entry in ledger:
        if fines:
            for lst, v in zip(group(entry["material"])["dummy"],
                              (entry["mass"], entry["parent_size"], entry["t10"])):
                lst.append(v)
        else:                            # the ledger's fines counted at the dummy size
            resolved_d.append(model.X_MIN * entry["parent_size"])
            resolved_m.append(entry["mass"])
    sizes = np.atleast_1d(np.asarray(sizes, dtype=float))
    sd = model.size_distribution(sizes, resolved=(resolved_d, resolved_m))
    passing = np.zeros(sizes.shape) + sd.passing_mass
    total = 0.0 + sd.total_mass
    for label, g in groups.items():
        sd = model.size_distribution(sizes, dummies=g["dummy"], unbreakable=g["unb"],
                                     beta_params=materials[label].beta_params, fines=fines_model)
        passing += sd.passing_mass
        total += sd.total_mass
    return model.SizeDistribution(sizes, passing, total)


def first_events(events, ids):
    """Each listed particle's first event (the impact itself), or none."""
    first = {}
    for e in events:
        first.setdefault(e["id"], e)
    return {i: first[i] for i in ids if i in first}


#: progeny sizes reported beside t10, as fractions 1/n of the original size (Eq. 10's t_n)
MARKERS = (2.0, 4.0, 10.0, 25.0)


def breakage_result(brk, ids, material, size, specific_energy, partner):
    """Broken fraction of the particles `ids` beside the model's probability P(e Ek/mp), and the
    progeny of the broken ones (fines included, every generation of fragments) beside the model
    at that energy: t10 against Eq. 7 (material.t10_model: the absorbed energy e Ek/mp over the
    median fracture energy of the particles that break at it; Ab-T10: Eq. 9.4), the passing at
    1/2, 1/4 and 1/25 of the original size against Eq. 10 at that t10, and the whole curve.
    Also the mean t10' of the primary breakage events (Eq. 8 or 9.4), for the record."""
    first = first_events(brk.events, ids)
    broken = [e for e in first.values() if e["kind"] == "breakage"]
    p_model = float(material.breakage_probability(specific_energy, size, partner=partner))
    n = len(ids)
    t10_model = float(material.t10_model(specific_energy, size, partner))
    result = {"specific_energy": specific_energy, "particles": n,
              "broken_fraction": len(broken) / n, "model_probability": p_model,
              "binomial_sigma": float(np.sqrt(p_model * (1 - p_model) / n)),
              "t10_model": t10_model if np.isfinite(t10_model) else None}
    if material.is_ab_t10:
        # the e_cum the intact particles carry: what the broken ones would have reached
        broken_ids = {e["id"] for e in broken}
        e_cum = [brk.bodies[i].e_cum for i in ids if i not in broken_ids and i in brk.bodies]
        if e_cum:
            result["e_cum_measured"] = float(np.mean(e_cum))
            result["p_of_e_cum_measured"] = float(material.fracture_energy_cdf(np.mean(e_cum), size))
    if not broken:
        result["t10_note"] = "no particle broke: no progeny to measure"
        return result
    parent_mass = sum(e["mass"] for e in broken)
    sieves = size * np.geomspace(1e-3, 0.99, 40)    # below the feed size: progeny only
    passing = 100 * brk.size_distribution(sieves).passing_mass / parent_mass
    markers = 100 * brk.size_distribution(size / np.array(MARKERS)).passing_mass / parent_mass
    result.update({
        "t10_simulated": float(markers[MARKERS.index(10.0)]),
        "t10_primary_events": float(np.mean([e["t10"] for e in broken])),
        "breakage_events_all_generations": len(brk.breakage_events),
        "progeny_markers": {f"t{n:g}": {"simulated": float(sim), "model": _t_n(material, t10_model, n)}
                            for n, sim in zip(MARKERS, markers)},
        "relative_sizes": (sieves / size).tolist(),
        "progeny_passing_simulated": passing.tolist(),
        "progeny_passing_model": (model.progeny_passing(t10_model, material.beta_params,
                                                        sieves / size).tolist()
                                  if np.isfinite(t10_model) else None)})
    return result


def result_line(result):
    """One progress line for an energy: broken fraction and t10 against the model."""
    line = (f"{result['specific_energy']:g} J/kg: {100 * result['broken_fraction']:.1f} % broken "
            f"(model {100 * result['model_probability']:.1f} %)")
    if result.get("t10_simulated") is None:
        return line + f", no t10 ({result.get('t10_note', 'no model value')})"
    model_t10 = result["t10_model"]
    return line + (f", t10 {result['t10_simulated']:.2f} % (model "
                   f"{'-' if model_t10 is None else f'{model_t10:.2f}'} %)")


def _t_n(material, t10, n):
    """Eq. 10's t_n (%) at t10 (%), with t10 itself for n = 10."""
    if not np.isfinite(t10):
        return None
    if n == 10.0:
        return float(t10)
    return float(model.t_n(t10, *material.beta_params[n]))


def plot_breakage(results, material, size, partner, title, path, label="simulation"):
    """Three panels to a PNG: broken fraction against specific energy (model line, simulation
    with 3 sigma); t10 against specific energy (the model's Eq. 7 or 9.4 from 50 to 3,000 J/kg
    and beyond the energies run, the simulation, the primary events' mean t10'); the progeny
    size distributions (model lines, simulation symbols)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(17, 4.8))
    energies = [r["specific_energy"] for r in results]
    _plot_probability(axes[0], results, material, size, partner, energies, title, label)
    grid = np.geomspace(min(50.0, min(energies) / 2), max(3000.0, 2 * max(energies)), 200)
    axes[1].semilogx(grid, material.t10_model(grid, size, partner), "k-",
                     label="model: Eq. 9.4" if material.is_ab_t10 else
                     "model: Eq. 7, e Ek/mp over E50b of the broken particles")
    done = [r for r in results if r.get("t10_simulated") is not None]
    if done:
        axes[1].plot([r["specific_energy"] for r in done], [r["t10_simulated"] for r in done],
                     "o", c="C3", label=f"{label}: progeny t10, all generations")
        axes[1].plot([r["specific_energy"] for r in done], [r["t10_primary_events"] for r in done],
                     "x", c="C0", label="mean t10' of the primary breakages (Eq. 8)")
    axes[1].set(xlabel="specific energy Ek/mp (J/kg)", ylabel="t10 (%)",
                title="t10 against the model at each energy")
    axes[1].legend(fontsize=7, loc="upper left")
    for k, r in enumerate(results):
        if "relative_sizes" not in r:
            continue
        if r["progeny_passing_model"] is not None:
            axes[2].semilogx(r["relative_sizes"], r["progeny_passing_model"], "-", c=f"C{k}",
                             label=f"model, {r['specific_energy']:g} J/kg (t10 "
                                   f"{r['t10_model']:.1f} %)")
        axes[2].semilogx(r["relative_sizes"], r["progeny_passing_simulated"], "o", ms=4,
                         c=f"C{k}", label=f"simulation, t10 {r['t10_simulated']:.1f} %")
    axes[2].set(xlabel="relative size d / d_parent", ylabel="progeny passing (%)",
                title="progeny of broken particles (fines included)")
    axes[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _plot_probability(ax, results, material, size, partner, energies, title, label):
    grid = np.geomspace(min(energies) / 3, max(energies) * 3, 200)
    ax.semilogx(grid, 100 * material.breakage_probability(grid, size, partner=partner), "k-",
                label=("model P(e_cum), e_cum = e Ek/mp - e_min (Eqs. 4, 9.1-9.3)"
                       if material.is_ab_t10 else "model (Eqs. 1-4)"))
    measured = [(r["specific_energy"], r["p_of_e_cum_measured"]) for r in results
                if "p_of_e_cum_measured" in r]
    if measured:
        ax.plot(*zip(*[(e, 100 * p) for e, p in measured]), "kx", ms=8,
                label="P(e_cum) at the e_cum measured")
    ax.errorbar(energies, [100 * r["broken_fraction"] for r in results],
                yerr=[np.clip(300 * r["binomial_sigma"], 0.0, None) for r in results], fmt="o",
                c="C3", label=f"{label} (3 sigma)")
    ax.set(xlabel="specific energy Ek/mp (J/kg)", ylabel="broken (%)", title=title)
    ax.legend(loc="upper left", fontsize=8)
