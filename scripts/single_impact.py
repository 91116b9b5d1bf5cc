"""Single impacts on a plate: breakage probability and progeny size against the model.

The paper's Figs. 8-10 and 13-16: N particles of one material and size fired normally at a plate
at each specific energy Ek/mp = v^2/2. Writes summary.json and single_impact.png into --out.

    yade -n -x scripts/single_impact.py --material copper_ore --energies 100,200,400
    yade -n -x scripts/single_impact.py --material ab_t10_ore --energies 250,400,800 --particles 100

Each energy is one scene with its own seed (--seed + its index); an interrupted run continues with
--resume 1, keeping the energies it finished (out/partial.json).
"""
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0], not __file__

import numpy as np  # noqa: E402

from yadebreak import load_material, reports  # noqa: E402
from yadebreak.scriptargs import PartialResults, progress, script_params  # noqa: E402

args = script_params(dict(material="copper_ore", size=5.5e-3, particles=250, seed=1,
                          target="steel", energies="100,200,400", replace=True,
                          time_step_fraction=0.05, out="out/single_impact", resume=False,
                          stop_after=0), __doc__)

from yadebreak import scenes  # noqa: E402
from yadebreak.scriptargs import run_script  # noqa: E402


def main(args):
    mat, target = load_material(args.material), load_material(args.target)
    share = mat.energy_partition(target)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.time()
    energies = [float(e) for e in args.energies.split(",")]
    partial = PartialResults(out, args)
    for k, energy in partial.todo(energies):
        speed = float(np.sqrt(2 * energy))
        brk, ids = scenes.impact_scene(args.material, args.size, [speed] * args.particles,
                                       target=args.target, seed=args.seed + k, replace=args.replace,
                                       time_step_fraction=args.time_step_fraction,
                                       event_log=str(out / f"events_{energy:g}.jsonl"))
        initial_mass = brk.total_mass()
        steps = scenes.run_until_rebound(ids, brk=brk)
        result = reports.breakage_result(brk, ids, mat, args.size, energy, target)
        intact = [e for e in reports.first_events(brk.events, ids).values() if e["kind"] == "damage"]
        result.update({
            "speed": speed, "half_v_squared": energy, "steps": steps,
            "mean_specific_energy_measured": (float(np.mean([e["specific_energy"] / share
                                                             for e in intact])) if intact else None),
            "mass_relative_error": abs(brk.total_mass() - initial_mass) / initial_mass})
        partial.add(energy, result)
        progress(f"{reports.result_line(result)}, {steps} steps, {time.time() - start:.1f} s")

    results = partial.ordered(energies)
    summary = {"material": mat.name, "size": args.size, "target": args.target, "share_e": share,
               "results": results, "runtime_s": time.time() - start}
    (out / "summary.json").write_text(json.dumps(summary, indent=2))

    reports.plot_breakage(results, mat, args.size, target,
                          f"{mat.name}, {1e3 * args.size:g} mm on {args.target}",
                          out / "single_impact.png")
    progress(f"wrote {out / 'summary.json'} and {out / 'single_impact.png'}")


run_script(main, args)
