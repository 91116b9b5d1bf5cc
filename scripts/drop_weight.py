"""Drop-weight tests (paper's DWT, Figs. 8 and 15): a steel striker falls on each particle resting
on a steel anvil; breakage probability, t10 and the progeny size distribution against the model.

    yade -n -x scripts/drop_weight.py --material copper_ore --energies 150,600

An interrupted run continues with --resume 1, keeping the energies it finished (out/partial.json);
a run that fails leaves summary.json with the energies it finished and its end_reason.
"""
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]


from yadebreak import load_material  # noqa: E402
from yadebreak.model import reports  # noqa: E402
from yadebreak.tools.options import (PartialResults, flag, integer, material_option,  # noqa: E402
                                  number, numbers, partial_outputs_on_failure, progress,
                                  read_period_option, read_period_value,
                                  run_script, script_params, size_option, text,
                                  time_step_option)

args = script_params([
    material_option(),
    size_option(5.5e-3),
    integer("particles", 60, "particles tested at each energy", lo=1),
    integer("seed", 1, "random seed of the first energy (the next ones: +1, +2, ...)", lo=0),
    numbers("energies", "150,600", "J/kg", "specific energies of the striker's fall per particle "
            "mass", lo=0, lo_open=True),
    number("striker_mass_ratio", 50.0, "-", "striker mass over particle mass", lo=0, lo_open=True),
    time_step_option(),
    read_period_option("every_step"),   # laboratory tests: the exact reference
    number("max_time", 0.003, "s", "simulated time per energy at the most", lo=0, lo_open=True),
    text("out", "out/drop_weight", "output folder"),
    flag("resume", False, "continue the run in --out, keeping the energies it finished"),
    integer("stop_after", 0, "(tests) end as if killed after this many energies (0: never)", lo=0,
            unit="energies"),
], __doc__)

from yade import O  # noqa: E402
from yadebreak import coupling, scenes  # noqa: E402


def main(args):
    """Every energy, then summary.json and the plot; returns the last energy's controller."""
    brk = None
    mat, steel = load_material(args.material), load_material("steel")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.time()
    energies = [float(e) for e in args.energies.split(",")]
    partial = PartialResults(out, args)

    def write(end_reason, end_message):
        """summary.json and the plot of the energies finished so far."""
        results = partial.ordered([e for e in energies if str(e) in partial.done])
        (out / "summary.json").write_text(json.dumps({
            "material": mat.name, "size": args.size, "results": results,
            "runtime_s": time.time() - start, "end_reason": end_reason,
            "end_message": end_message}, indent=2))
        if results:
            reports.plot_breakage(results, mat, args.size, steel, f"{mat.name} drop weight",
                                  out / "drop_weight.png", label="drop weight, simulation")

    with partial_outputs_on_failure(write):
        for k, energy in partial.todo(energies):
            brk, result = drop_at(args, mat, steel, k, energy, out)
            partial.add(energy, result)
            progress(f"{reports.result_line(result)}, {time.time() - start:.1f} s")
    limited = [r["specific_energy"] for r in partial.ordered(energies) if r["stopped_at_max_time"]]
    write("time_limit" if limited else "finished",
          f"strikers still falling at --max-time at {limited} J/kg" if limited else "")
    partial.finish()
    progress(f"wrote {out / 'summary.json'} and {out / 'drop_weight.png'}")
    return brk


def drop_at(args, mat, steel, k, energy, out):
    """The drop-weight tests at `energy` (J/kg): (controller, the energy's result)."""
    brk, ids, strikers = scenes.drop_weight_scene(
        args.material, args.size, energy, args.particles, args.striker_mass_ratio,
        seed=args.seed + k, time_step_fraction=args.time_step_fraction,
        read_period=read_period_value(args.read_period),
        event_log=str(out / f"events_{energy:g}.jsonl"))
    initial_mass = brk.total_mass()
    # until every striker rebounds (or max_time of simulated time); then open events close
    while any(O.bodies[s].state.vel[2] < 0 for s in strikers) and O.time < args.max_time:
        coupling.run_steps(500)
    stopped = any(O.bodies[s].state.vel[2] < 0 for s in strikers)
    brk.finish()
    result = reports.breakage_result(brk, ids, mat, args.size, energy, steel)
    result["mass_relative_error"] = abs(brk.total_mass() - initial_mass) / initial_mass
    result["stopped_at_max_time"] = stopped
    return brk, result


brk = run_script(main, args)      # the last scene's controller, at the prompt without -x
