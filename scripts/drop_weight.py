"""Drop-weight tests (paper's DWT, Figs. 8 and 15): a steel striker falls on each particle resting
on a steel anvil; breakage probability, t10 and the progeny size distribution against the model.

    yade -n -x scripts/drop_weight.py --material copper_ore --energies 150,600

An interrupted run continues with --resume 1, keeping the energies it finished (out/partial.json).
"""
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]


from yadebreak import load_material, reports  # noqa: E402
from yadebreak.scriptargs import PartialResults, progress, script_params  # noqa: E402

args = script_params(dict(material="copper_ore", size=5.5e-3, particles=60, seed=1,
                          energies="150,600", striker_mass_ratio=50.0, time_step_fraction=0.05,
                          max_time=0.003, out="out/drop_weight", resume=False,
                          stop_after=0), __doc__)

from yade import O  # noqa: E402
from yadebreak import coupling, scenes  # noqa: E402
from yadebreak.scriptargs import run_script  # noqa: E402


def main(args):
    mat, steel = load_material(args.material), load_material("steel")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.time()
    energies = [float(e) for e in args.energies.split(",")]
    partial = PartialResults(out, args)
    for k, energy in partial.todo(energies):
        brk, ids, strikers = scenes.drop_weight_scene(
            args.material, args.size, energy, args.particles, args.striker_mass_ratio,
            seed=args.seed + k, time_step_fraction=args.time_step_fraction,
            event_log=str(out / f"events_{energy:g}.jsonl"))
        initial_mass = brk.total_mass()
        # until every striker rebounds (or max_time of simulated time); then open events close
        while any(O.bodies[s].state.vel[2] < 0 for s in strikers) and O.time < args.max_time:
            coupling.run_steps(500)
        brk.finish()
        result = reports.breakage_result(brk, ids, mat, args.size, energy, steel)
        result["mass_relative_error"] = abs(brk.total_mass() - initial_mass) / initial_mass
        partial.add(energy, result)
        progress(f"{reports.result_line(result)}, {time.time() - start:.1f} s")

    results = partial.ordered(energies)
    (out / "summary.json").write_text(json.dumps({"material": mat.name, "size": args.size,
                                                  "results": results,
                                                  "runtime_s": time.time() - start}, indent=2))
    reports.plot_breakage(results, mat, args.size, steel, f"{mat.name} drop weight",
                          out / "drop_weight.png", label="drop weight, simulation")
    progress(f"wrote {out / 'summary.json'} and {out / 'drop_weight.png'}")


run_script(main, args)
