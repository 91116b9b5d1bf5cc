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
from yadebreak.scriptargs import (PartialResults, flag, integer, material_option,  # noqa: E402
                                  numbers, progress, run_script, script_params, size_option,
                                  text, time_step_option)

args = script_params([
    material_option(),
    size_option(5.5e-3),
    integer("particles", 250, "particles fired at each energy", lo=1),
    integer("seed", 1, "random seed of the first energy (the next ones: +1, +2, ...)", lo=0),
    text("target", "steel", "the plate: steel, rubber or a material"),
    numbers("energies", "100,200,400", "J/kg", "specific impact energies Ek/mp = v^2/2", lo=0,
            lo_open=True),
    flag("replace", True, "replace broken particles by their fragments (0: record events only)"),
    time_step_option(),
    text("out", "out/single_impact", "output folder"),
    flag("resume", False, "continue the run in --out, keeping the energies it finished"),
    integer("stop_after", 0, "(tests) end as if killed after this many energies (0: never)", lo=0,
            unit="energies"),
], __doc__)

from yadebreak import scenes  # noqa: E402


def main(args):
    """Every energy, then summary.json and the plot; returns the last energy's controller."""
    brk = None
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
    partial.finish()
    progress(f"wrote {out / 'summary.json'} and {out / 'single_impact.png'}")
    return brk


brk = run_script(main, args)      # the last scene's controller, at the prompt without -x
