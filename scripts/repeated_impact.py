"""Repeated impacts at one specific energy: the fraction broken after each impact (paper Fig. 11).

Particles hit a steel plate again and again; the survivors carry their damage (Eqs. 5-6, or the
Ab-T10 e_cum of Eq. 9.2) into the next impact. Default: 37.5 mm copper ore at 94.7 J/kg,
20 impacts, 100 particles.

    yade -n -x scripts/repeated_impact.py --gamma 3
    yade -n -x scripts/repeated_impact.py --material ab_t10_ore --size 5.5e-3 --energy 180 --impacts 8

The scene is checkpointed after every impact (out/checkpoint.yade.gz); an interrupted run continues
with --resume 1 exactly as if it had not stopped.
"""
import dataclasses
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(sys.argv[0]).resolve().parent.parent))   # yade sets argv[0]

import numpy as np  # noqa: E402

from yadebreak import load_material, model  # noqa: E402
from yadebreak.model import reports  # noqa: E402
from yadebreak.tools.options import (ScriptError, check_not_finished,  # noqa: E402
                                  check_resume_arguments, flag, integer, mark_finished,
                                  mark_started, material_option, number,
                                  partial_outputs_on_failure, progress, read_checkpoint,
                                  read_period_option, read_period_value,
                                  resume_arguments, run_script, script_params, size_option,
                                  stop_if_asked, text, time_step_option)

args = script_params([
    material_option(),
    size_option(37.5e-3),
    integer("particles", 100, "particles", lo=1),
    integer("impacts", 20, "impacts of each particle", lo=1),
    number("energy", 94.7, "J/kg", "specific impact energy Ek/mp = v^2/2 of every impact", lo=0,
           lo_open=True),
    number("gamma", 0.0, "-", "damage exponent of Eq. 5, replacing the material's (0: the "
           "material's)", lo=0),
    integer("seed", 1, "random seed", lo=0),
    text("target", "steel", "the plate: steel, rubber or a material"),
    time_step_option(),
    read_period_option("every_step"),   # laboratory tests: the exact reference
    text("out", "out/repeated_impact", "output folder"),
    flag("resume", False, "continue the run in --out from the checkpoint after its last impact"),
    integer("stop_after", 0, "(tests) end as if killed after this many impacts (0: never)", lo=0,
            unit="impacts"),
], __doc__)

from yade import O  # noqa: E402
from yadebreak import coupling, scenes  # noqa: E402


def main(args):
    """Every impact, then summary.json and the plot; returns the controller."""
    mat = load_material(args.material)
    if args.gamma > 0:
        if mat.is_ab_t10:
            raise ScriptError(f"--gamma applies to Tavares materials; {mat.name} uses Ab-T10")
        mat = dataclasses.replace(mat, gamma=args.gamma)
    share = mat.energy_partition(load_material(args.target))
    speed = float(np.sqrt(2 * args.energy))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.time()
    checkpoint = out / "checkpoint.yade.gz"
    if args.resume:
        check_not_finished(out, args)     # a finished run: says so, nothing is run or rewritten
        brk, loop = read_checkpoint(checkpoint, coupling.load_checkpoint)   # damaged: one line
        check_resume_arguments(loop["arguments"], args, checkpoint)
        ids, alive, fractions = loop["ids"], loop["alive"], loop["fractions"]
        home = {int(i): tuple(p) for i, p in loop["home"].items()}
        progress(f"resumed from {checkpoint} after impact {len(fractions)}")
    else:
        mark_started(out)
        brk, ids = scenes.impact_scene(mat, args.size, [speed] * args.particles, target=args.target,
                                       seed=args.seed, replace=False,
                                       time_step_fraction=args.time_step_fraction,
                                       read_period=read_period_value(args.read_period),
                                       event_log=str(out / "events.jsonl"))
        home = {i: tuple(O.bodies[i].state.pos) for i in ids}
        alive = list(ids)
        fractions = []
    with partial_outputs_on_failure(lambda reason, message: write_outputs(
            args, mat, share, fractions, brk, out, start, reason, message)):
        for k in range(len(fractions), args.impacts):
            alive = scenes.impact_again(brk, alive, home, speed)  # the broken leave the test
            fractions.append(1 - len(alive) / args.particles)
            progress(f"impact {k + 1}: {100 * fractions[-1]:.0f} % broken, "
                     f"{time.time() - start:.1f} s")
            coupling.save_checkpoint(checkpoint, {
                "ids": ids, "alive": alive, "fractions": fractions, "home": home,
                "arguments": resume_arguments(args)})
            stop_if_asked(args, len(fractions))
    write_outputs(args, mat, share, fractions, brk, out, start, "finished", "")
    mark_finished(out, args)              # a later --resume 1 says so and does nothing
    progress(f"wrote {out / 'summary.json'} and {out / 'repeated_impact.png'}")
    return brk


def write_outputs(args, mat, share, fractions, brk, out, start, end_reason, end_message):
    """summary.json (with how the run ended) and the plot, for the impacts done."""
    if mat.is_ab_t10:
        model_fractions = model.ab_t10_repeated_broken_fraction(
            share * args.energy, args.size, float(mat.min_energy(args.size)), mat.selection,
            mat.size_ref, len(fractions))
        model_label = "model P(e_cum), e_cum = k (e Ek/mp - e_min) (Eqs. 9.1-9.3)"
    else:
        e50 = float(mat.median_fracture_energy(args.size))
        model_fractions = model.repeated_impact_broken_fraction(share * args.energy, e50, mat.sigma,
                                                                mat.emax_ratio, mat.gamma,
                                                                len(fractions))
        model_label = f"model (Eqs. 1-6), gamma = {mat.gamma:g}"
    absorbed = [e["specific_energy"] for e in brk.events if e["kind"] == "damage"]
    summary = {"material": mat.name, "model": mat.breakage_model, "size": args.size,
               "energy": args.energy, "gamma": mat.gamma,
               "particles": args.particles, "share_e": share,
               "broken_fraction": fractions, "model_broken_fraction": model_fractions.tolist(),
               "mean_absorbed_specific_energy": float(np.mean(absorbed)) if absorbed else None,
               "expected_absorbed_specific_energy": share * args.energy,
               "runtime_s": time.time() - start, "end_reason": end_reason,
               "end_message": end_message}
    (out / "summary.json").write_text(json.dumps(summary, indent=2))

    import matplotlib  # noqa: E402
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: E402
    from matplotlib.ticker import MaxNLocator  # noqa: E402

    n = np.arange(1, len(fractions) + 1)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(n, 100 * model_fractions, "k-", label=model_label)
    sigma = np.sqrt(model_fractions * (1 - model_fractions) / args.particles)
    ax.errorbar(n, 100 * np.array(fractions),
                yerr=reports.bounded_errors(100 * np.array(fractions), 300 * sigma, 0.0, 100.0),
                fmt="o", c="C3", label="simulation (3 sigma of the model)")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))      # impacts are counted
    ax.set(xlabel="number of impacts", ylabel="broken (%)",
           title=f"{mat.name}, {1e3 * args.size:g} mm at {args.energy:g} J/kg on {args.target}")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "repeated_impact.png", dpi=110)
    plt.close(fig)


brk = run_script(main, args)      # the controller, at the prompt without -x
