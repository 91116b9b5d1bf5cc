"""Drop-weight tests (paper's DWT, Figs. 8 and 15): a steel striker falls on each particle resting
on a steel anvil; breakage probability, t10 and the progeny size distribution against the model.

    yade -n -x scripts/drop_weight.py --material copper_ore --energies 150,600
"""
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

import numpy as np  # noqa: E402

from yadebreak import load_material, model  # noqa: E402
from yadebreak.scriptargs import progress, script_params  # noqa: E402

args = script_params(dict(material="copper_ore", size=5.5e-3, particles=60, seed=1,
                          energies="150,600", striker_mass_ratio=50.0, time_step_fraction=0.05,
                          max_time=0.003, out="out/drop_weight"), __doc__)

from yade import O  # noqa: E402
from yadebreak import scenes  # noqa: E402

mat, steel = load_material(args.material), load_material("steel")
out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)
results = []
start = time.time()
for k, energy in enumerate(float(e) for e in args.energies.split(",")):
    brk, ids, strikers = scenes.drop_weight_scene(
        args.material, args.size, energy, args.particles, args.striker_mass_ratio,
        seed=args.seed + k, time_step_fraction=args.time_step_fraction,
        event_log=str(out / f"events_{energy:g}.jsonl"))
    initial_mass = brk.total_mass()
    # until every striker rebounds (or max_time of simulated time); then open events close
    while any(O.bodies[s].state.vel[2] < 0 for s in strikers) and O.time < args.max_time:
        O.run(500, True)
    brk.finish()
    first = {}
    for e in brk.events:
        first.setdefault(e["id"], e)
    broken = [first[i] for i in ids if i in first and first[i]["kind"] == "breakage"]
    p_model = float(mat.breakage_probability(energy, args.size, partner=steel))
    sieves = args.size * np.geomspace(1e-3, 0.99, 40)   # below the feed size: progeny only
    result = {"specific_energy": energy, "particles": args.particles,
              "broken_fraction": len(broken) / args.particles, "model_probability": p_model,
              "binomial_sigma": float(np.sqrt(p_model * (1 - p_model) / args.particles)),
              "mass_relative_error": abs(brk.total_mass() - initial_mass) / initial_mass}
    if broken:
        parent_mass = sum(e["mass"] for e in broken)
        t10_events = np.array([e["t10"] for e in broken])
        sd = brk.size_distribution(sieves)
        result.update({
            "t10_simulated": float(100 * brk.size_distribution([args.size / 10]).passing_mass[0]
                                   / parent_mass),
            "t10_model_eq8": float(t10_events.mean()),
            "relative_sizes": (sieves / args.size).tolist(),
            "progeny_passing_simulated": (100 * sd.passing_mass / parent_mass).tolist(),
            "progeny_passing_model": model.progeny_passing(
                t10_events, mat.beta_params, sieves / args.size).mean(axis=0).tolist()})
    results.append(result)
    progress(f"{energy:g} J/kg: {len(broken)}/{args.particles} broken (model "
             f"{100 * p_model:.1f} %), {time.time() - start:.1f} s")

(out / "summary.json").write_text(json.dumps({"material": mat.name, "size": args.size,
                                              "results": results,
                                              "runtime_s": time.time() - start}, indent=2))
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
grid = np.geomspace(min(r["specific_energy"] for r in results) / 3,
                    max(r["specific_energy"] for r in results) * 3, 200)
axes[0].semilogx(grid, 100 * mat.breakage_probability(grid, args.size, partner=steel), "k-",
                 label="model (Eqs. 1-4)")
axes[0].errorbar([r["specific_energy"] for r in results], [100 * r["broken_fraction"] for r in results],
                 yerr=[300 * r["binomial_sigma"] for r in results], fmt="s", c="C3",
                 label="drop weight, simulation (3 sigma)")
axes[0].set(xlabel="specific energy Ek/mp (J/kg)", ylabel="broken (%)", title=f"{mat.name} DWT")
axes[0].legend()
for k, r in enumerate(results):
    if "relative_sizes" in r:
        axes[1].semilogx(r["relative_sizes"], r["progeny_passing_model"], "-", c=f"C{k}",
                         label=f"model, {r['specific_energy']:g} J/kg")
        axes[1].semilogx(r["relative_sizes"], r["progeny_passing_simulated"], "o", ms=4, c=f"C{k}",
                         label=f"simulation, t10 {r['t10_simulated']:.1f} % "
                               f"(Eq. 8 {r['t10_model_eq8']:.1f} %)")
axes[1].set(xlabel="relative size", ylabel="progeny passing (%)", title="progeny (fines included)")
axes[1].legend(fontsize=7)
fig.tight_layout()
fig.savefig(out / "drop_weight.png", dpi=110)
progress(f"wrote {out / 'summary.json'} and {out / 'drop_weight.png'}")
