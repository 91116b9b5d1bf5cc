"""Single impacts on a plate: breakage probability and progeny size against the model.

The paper's Figs. 8-10 and 13-16: N particles of one material and size fired normally at a plate
at each specific energy Ek/mp = v^2/2. Writes summary.json and single_impact.png into --out.

    yade -n -x scripts/single_impact.py --material copper_ore --energies 100,200,400
"""
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0], not __file__

import numpy as np  # noqa: E402

from yadebreak import load_material, model  # noqa: E402
from yadebreak.scriptargs import progress, script_params  # noqa: E402

args = script_params(dict(material="copper_ore", size=5.5e-3, particles=250, seed=1,
                          target="steel", energies="100,200,400", replace=True,
                          time_step_fraction=0.05, out="out/single_impact"), __doc__)

from yadebreak import scenes  # noqa: E402

mat, target = load_material(args.material), load_material(args.target)
share = mat.energy_partition(target)
out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)
results = []
start = time.time()
for k, energy in enumerate(float(e) for e in args.energies.split(",")):
    speed = float(np.sqrt(2 * energy))
    brk, ids = scenes.impact_scene(args.material, args.size, [speed] * args.particles,
                                   target=args.target, seed=args.seed + k, replace=args.replace,
                                   time_step_fraction=args.time_step_fraction,
                                   event_log=str(out / f"events_{energy:g}.jsonl"))
    initial_mass = brk.total_mass()
    steps = scenes.run_until_rebound(ids)
    first = {}                       # each particle's first event: the impact itself
    for e in brk.events:
        first.setdefault(e["id"], e)
    broken = [first[i] for i in ids if i in first and first[i]["kind"] == "breakage"]
    intact = [first[i] for i in ids if i in first and first[i]["kind"] == "damage"]
    n_broken = len(broken)
    p_model = float(mat.breakage_probability(energy, args.size, partner=target))
    result = {
        "specific_energy": energy, "speed": speed, "particles": args.particles,
        "broken_fraction": n_broken / args.particles, "model_probability": p_model,
        "binomial_sigma": float(np.sqrt(p_model * (1 - p_model) / args.particles)),
        "mean_specific_energy_measured": (float(np.mean([e["specific_energy"] / share for e in intact]))
                                          if intact else None),
        "half_v_squared": energy, "steps": steps,
        "mass_relative_error": abs(brk.total_mass() - initial_mass) / initial_mass,
    }
    if args.replace and n_broken:
        parent_mass = sum(e["mass"] for e in broken)
        sieves = args.size * np.geomspace(1e-3, 0.99, 40)   # below the feed size: progeny only
        sd = brk.size_distribution(sieves)
        # passing mass below the feed size comes from the progeny only
        progeny_passing = 100 * sd.passing_mass / parent_mass
        t10_events = np.array([e["t10"] for e in broken])
        result.update({
            "t10_simulated": float(100 * brk.size_distribution([args.size / 10]).passing_mass[0]
                                   / parent_mass),
            "t10_model_eq8": float(t10_events.mean()),
            "relative_sizes": (sieves / args.size).tolist(),
            "progeny_passing_simulated": progeny_passing.tolist(),
            "progeny_passing_model": model.progeny_passing(t10_events, mat.beta_params,
                                                           sieves / args.size).mean(axis=0).tolist(),
        })
    results.append(result)
    progress(f"{energy:g} J/kg: {n_broken}/{args.particles} broken "
             f"(model {100 * p_model:.1f} %), {steps} steps, {time.time() - start:.1f} s")

summary = {"material": mat.name, "size": args.size, "target": args.target, "share_e": share,
           "results": results, "runtime_s": time.time() - start}
(out / "summary.json").write_text(json.dumps(summary, indent=2))

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
grid = np.geomspace(min(r["specific_energy"] for r in results) / 3,
                    max(r["specific_energy"] for r in results) * 3, 200)
axes[0].semilogx(grid, 100 * mat.breakage_probability(grid, args.size, partner=target), "k-",
                 label="model (Eqs. 1-4)")
axes[0].errorbar([r["specific_energy"] for r in results], [100 * r["broken_fraction"] for r in results],
                 yerr=[300 * r["binomial_sigma"] for r in results], fmt="o", c="C3",
                 label="simulation (3 sigma)")
axes[0].set(xlabel="specific impact energy Ek/mp (J/kg)", ylabel="broken (%)",
            title=f"{mat.name}, {1e3 * args.size:g} mm on {args.target}")
axes[0].legend()
for k, r in enumerate(results):
    if "relative_sizes" in r:
        axes[1].semilogx(r["relative_sizes"], r["progeny_passing_model"], "-", c=f"C{k}",
                         label=f"model, {r['specific_energy']:g} J/kg")
        axes[1].semilogx(r["relative_sizes"], r["progeny_passing_simulated"], "o", c=f"C{k}", ms=4,
                         label=f"simulation, t10 {r['t10_simulated']:.1f} % (Eq. 8: {r['t10_model_eq8']:.1f} %)")
axes[1].set(xlabel="relative size d / d_parent", ylabel="progeny passing (%)",
            title="progeny of broken particles (fines included)")
axes[1].legend(fontsize=7)
fig.tight_layout()
fig.savefig(out / "single_impact.png", dpi=110)
progress(f"wrote {out / 'summary.json'} and {out / 'single_impact.png'}")
