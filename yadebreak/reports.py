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


def breakage_result(brk, ids, material, size, specific_energy, partner):
    """Broken fraction of the particles `ids` beside the model's probability P(e Ek/mp), and,
    when any broke, the progeny's size distribution (fines included, sieves below the feed size)
    and t10 beside the model's (t10_model: the events' mean, Eq. 8 or, for Ab-T10, Eq. 9.4) and
    Eq. 10."""
    first = first_events(brk.events, ids)
    broken = [e for e in first.values() if e["kind"] == "breakage"]
    p_model = float(material.breakage_probability(specific_energy, size, partner=partner))
    n = len(ids)
    result = {"specific_energy": specific_energy, "particles": n,
              "broken_fraction": len(broken) / n, "model_probability": p_model,
              "binomial_sigma": float(np.sqrt(p_model * (1 - p_model) / n))}
    if material.is_ab_t10:
        # the e_cum the intact particles carry: what the broken ones would have reached
        broken_ids = {e["id"] for e in broken}
        e_cum = [brk.bodies[i].e_cum for i in ids if i not in broken_ids and i in brk.bodies]
        if e_cum:
            result["e_cum_measured"] = float(np.mean(e_cum))
            result["p_of_e_cum_measured"] = float(material.fracture_energy_cdf(np.mean(e_cum), size))
    if broken:
        parent_mass = sum(e["mass"] for e in broken)
        sieves = size * np.geomspace(1e-3, 0.99, 40)    # below the feed size: progeny only
        t10_events = np.array([e["t10"] for e in broken])
        passing = 100 * brk.size_distribution(sieves).passing_mass / parent_mass
        result.update({
            "t10_simulated": float(100 * brk.size_distribution([size / 10]).passing_mass[0]
                                   / parent_mass),
            "t10_model": float(t10_events.mean()),
            "relative_sizes": (sieves / size).tolist(),
            "progeny_passing_simulated": passing.tolist(),
            "progeny_passing_model": model.progeny_passing(
                t10_events, material.beta_params, sieves / size).mean(axis=0).tolist()})
    return result


def plot_breakage(results, material, size, partner, title, path, label="simulation"):
    """Broken fraction against specific energy (model line, simulation with 3 sigma) and the
    progeny size distributions (model lines, simulation symbols), to a PNG."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    energies = [r["specific_energy"] for r in results]
    grid = np.geomspace(min(energies) / 3, max(energies) * 3, 200)
    axes[0].semilogx(grid, 100 * material.breakage_probability(grid, size, partner=partner), "k-",
                     label=("model P(e_cum), e_cum = e Ek/mp - e_min (Eqs. 4, 9.1-9.3)"
                            if material.is_ab_t10 else "model (Eqs. 1-4)"))
    measured = [(r["specific_energy"], r["p_of_e_cum_measured"]) for r in results
                if "p_of_e_cum_measured" in r]
    if measured:
        axes[0].plot(*zip(*[(e, 100 * p) for e, p in measured]), "kx", ms=8,
                     label="P(e_cum) at the e_cum measured")
    axes[0].errorbar(energies, [100 * r["broken_fraction"] for r in results],
                     yerr=[300 * r["binomial_sigma"] for r in results], fmt="o", c="C3",
                     label=f"{label} (3 sigma)")
    axes[0].set(xlabel="specific energy Ek/mp (J/kg)", ylabel="broken (%)", title=title)
    axes[0].legend(loc="upper left", fontsize=8)
    for k, r in enumerate(results):
        if "relative_sizes" in r:
            axes[1].semilogx(r["relative_sizes"], r["progeny_passing_model"], "-", c=f"C{k}",
                             label=f"model, {r['specific_energy']:g} J/kg")
            axes[1].semilogx(r["relative_sizes"], r["progeny_passing_simulated"], "o", ms=4,
                             c=f"C{k}", label=f"simulation, t10 {r['t10_simulated']:.1f} % "
                                              f"({'Eq. 9.4' if material.is_ab_t10 else 'Eq. 8'}: "
                                              f"{r['t10_model']:.1f} %)")
    axes[1].set(xlabel="relative size d / d_parent", ylabel="progeny passing (%)",
                title="progeny of broken particles (fines included)")
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
