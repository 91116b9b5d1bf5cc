"""Single impacts on a plate: breakage probability and progeny size against the model.

The paper's Figs. 8-10 and 13-16: N particles of one material and size fired normally at a plate
at each specific energy Ek/mp = v^2/2. Writes summary.json and single_impact.png into --out.

    yade -n -x scripts/single_impact.py --material copper_ore --energies 100,200,400
    yade -n -x scripts/single_impact.py --material ab_t10_ore --energies 250,400,800 --particles 100

Each energy's particles are fired in independent scenes of --scene-particles (seeded from --seed +
the energy's index): a scene runs at the time step of its own finest fragment and ends with its
own cascade. An interrupted run continues with --resume 1, keeping the energies it finished
(out/partial.json); a run that fails leaves summary.json with the energies it finished and its
end_reason.
"""
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0], not __file__

import numpy as np  # noqa: E402

from yadebreak import load_material  # noqa: E402
from yadebreak.model import reports  # noqa: E402
from yadebreak.tools.options import (PartialResults, flag, integer, material_option,  # noqa: E402
                                  numbers, partial_outputs_on_failure, progress, read_period_option,
                                  read_period_value, run_script,
                                  script_params, size_option, text, time_left, time_step_option)

args = script_params([
    material_option(),
    size_option(5.5e-3),
    integer("particles", 250, "particles fired at each energy", lo=1),
    integer("scene_particles", 1, "particles per scene: independent scenes of at most this many, "
            "each at the time step of its own finest fragment and ending with its own cascade",
            lo=1),
    integer("jobs", 1, "YADE processes sharing the scenes (the results do not depend on it; this "
            "machine has " + str(os.cpu_count()) + " cores)", lo=1, unit="processes"),
    integer("seed", 1, "random seed of the first energy (the next ones: +1, +2, ...)", lo=0),
    text("target", "steel", "the plate: steel, rubber or a material"),
    numbers("energies", "100,200,400", "J/kg", "specific impact energies Ek/mp = v^2/2", lo=0,
            lo_open=True),
    flag("replace", True, "replace broken particles by their fragments (0: record events only)"),
    time_step_option(),
    read_period_option("every_step"),   # laboratory tests: the exact reference
    text("out", "out/single_impact", "output folder"),
    flag("resume", False, "continue the run in --out, keeping the energies it finished"),
    integer("stop_after", 0, "(tests) end as if killed after this many energies (0: never)", lo=0,
            unit="energies"),
], __doc__)

from yadebreak import scenes  # noqa: E402


def main(args):
    """Every energy, then summary.json and the plot; returns the last scene's controller."""
    mat, target = load_material(args.material), load_material(args.target)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.time()
    energies = [float(e) for e in args.energies.split(",")]
    partial = PartialResults(out, args, validate=lambda energy, result: (
        reports.check_breakage_result(result, mat, args.size, float(energy), target,
                                      args.particles)))
    brk = None

    def write(end_reason, end_message):
        """summary.json and the plot of the energies finished so far."""
        done = [e for e in energies if str(e) in partial.done]
        write_summary(args, mat, target, partial.ordered(done), out, start, end_reason, end_message)

    with partial_outputs_on_failure(write):
        for k, energy in partial.todo(energies):
            brk, result = impacts_at(args, mat, target, k, energy, out, start)
            partial.add(energy, result)
    limited = [r["specific_energy"] for r in partial.ordered(energies) if r["scenes_at_step_limit"]]
    write("time_limit" if limited else "finished",
          f"scenes stopped at the step limit at {limited} J/kg" if limited else "")
    partial.finish()
    progress(f"wrote {out / 'summary.json'} and {out / 'single_impact.png'}")
    return brk


def impacts_at(args, mat, target, k, energy, out, start):
    """The particles fired at `energy` (J/kg) in scenes of --scene-particles: (the last scene's
    controller, the energy's result)."""
    speed = float(np.sqrt(2 * energy))
    began, said = time.time(), [time.time()]

    def on_scene(done, scenes_total, tally):
        now = time.time()
        if now - said[0] > 5.0 and done < scenes_total:
            said[0] = now
            progress(f"{energy:g} J/kg: scene {done}/{scenes_total}, {len(tally.broken)} of "
                     f"{tally.particles} broken, {tally.breakage_events} breakages, "
                     f"{time_left(now - began, done / scenes_total)} at this energy")

    tally, brk = scenes.single_impacts(
        args.material, args.size, speed, args.particles, args.scene_particles, args.seed + k,
        target=args.target, event_log=str(out / f"events_{energy:g}.jsonl"), on_scene=on_scene,
        jobs=args.jobs, replace=args.replace, time_step_fraction=args.time_step_fraction,
        read_period=read_period_value(args.read_period))
    share = mat.energy_partition(target)
    result = reports.breakage_result_of(tally, mat, energy, target)
    intact = [e for e in tally.first if e["kind"] == "damage"]
    result.update({
        "speed": speed, "half_v_squared": energy, "steps": tally.steps, "scenes": tally.scenes,
        "scenes_at_step_limit": tally.scenes_at_step_limit,
        "mean_specific_energy_measured": (float(np.mean([e["specific_energy"] / share
                                                         for e in intact])) if intact else None),
        "mass_relative_error": tally.mass_relative_error})
    progress(f"{reports.result_line(result)}, {tally.steps} steps, {time.time() - start:.1f} s")
    return brk, result


def write_summary(args, mat, target, results, out, start, end_reason, end_message):
    """summary.json (with how the run ended) and, if an energy is done, the plot."""
    summary = {"material": mat.name, "size": args.size, "target": args.target,
               "share_e": mat.energy_partition(target), "results": results,
               "runtime_s": time.time() - start, "end_reason": end_reason,
               "end_message": end_message}
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    if results:
        reports.plot_breakage(results, mat, args.size, target,
                              f"{mat.name}, {1e3 * args.size:g} mm on {args.target}",
                              out / "single_impact.png")


brk = run_script(main, args)      # the last scene's controller, at the prompt without -x
