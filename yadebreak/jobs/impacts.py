"""The laboratory tests behind scripts/single_impact.py, repeated_impact.py and drop_weight.py
(YADE layer: runs the scenes of yadebreak.scenes, writes outputs).

single        particles fired at a plate at each energy (paper Figs. 8-10, 13-16)
repeated      the same particles hit again and again at one energy (Fig. 11)
drop_weight   a steel striker falls on each particle on an anvil (the paper's DWT, Figs. 8, 15)

The energies of single impacts and drop-weight tests are independent units (skeleton.run_units:
--resume 1 keeps those finished); repeated impacts are a Job checkpointed after every impact.
"""
import contextlib
import dataclasses
import json
import math
import time
from pathlib import Path

import numpy as np

from yadebreak import engine, scenes
from yadebreak.scenes import view
from yadebreak.analysis import reports
from yadebreak.criteria import load_material
from yadebreak.jobs import paraview, skeleton, wall_time
from yadebreak.jobs.lifecycle import (Heartbeat, Remaining, ScriptError, progress,
                                       resume_arguments, save_figure, status, write_atomic)
from yadebreak.jobs import options as job_options
from yadebreak.process.scheduler import SchedulerError
from yadebreak.process.signals import stop_point


def _energies(args):
    """--energies as floats (J/kg)."""
    return [float(e) for e in args.energies.split(",")]


# -- single impacts -------------------------------------------------------------------------------
def single(args):
    """Every energy, then summary.json and the plot; returns the last scene's controller."""
    mat, target = job_options.material_of(args), job_options.material_of(args, "target")
    out = Path(args.out)
    start = time.time()
    earlier = _earlier_wall_time(out / "summary.json", _energies(args), args)
    if earlier is not None:
        status(f"wall time, predicted: {earlier.line()}")

    told = {}

    def write(results, end_reason, end_message):
        """summary.json and, if an energy is done, the plot."""
        told["wall_time"] = _wall_time(results, "this run's scenes", args)
        summary = {"material": mat.name, "size": args.size, "shape": args.shape,
                   "target": args.target,
                   "share_e": mat.energy_partition(target), "results": results,
                   "runtime_s": time.time() - start, "end_reason": end_reason,
                   "end_message": end_message,
                   "wall_time": told["wall_time"].to_dict()}
        write_atomic(out / "summary.json", json.dumps(summary, indent=2))
        if results:
            reports.plot_breakage(results, mat, args.size, target,
                                  f"{mat.name}, {1e3 * args.size:g} mm on {args.target}",
                                  out / "single_impact.png")

    def limited(results):
        at = [r["specific_energy"] for r in results if r["scenes_at_step_limit"]]
        return f"scenes stopped at the step limit at {at} J/kg" if at else ""

    with _queue(args) as queue:
        brk = skeleton.run_units(
            args, _energies(args), lambda k, energy: _impacts_at(args, mat, target, k, energy,
                                                                 out, start, queue),
            write, limited, validate=lambda energy, result: reports.check_breakage_result(
                result, mat, args.size, float(energy), target, args.particles))
    progress(f"wall time: {told['wall_time'].line()}")
    progress(f"wrote {out / 'summary.json'} and {out / 'single_impact.png'}")
    return brk


def _wall_time(results, source, args):
    """The scenes' wall times of `results` (an energy's scenes wait for the energy before) and
    their prediction on the usual worker counts and on --jobs."""
    stages = [r.get("scene_walls_s", []) for r in results]
    count = job_options.scheduler_of(args).count
    return wall_time.predict(stages, source, (*wall_time.WORKERS, *([count] if count else [])))


def _earlier_wall_time(path, energies, args):
    """The prediction from an earlier run's summary.json at `path` (--overwrite 1, --resume 1)
    of the same scenes (energies, particles, scene size), None if there is none."""
    each = len(scenes.scene_counts(args.particles, args.scene_particles))
    try:
        results = json.loads(Path(path).read_text())["results"]
        same = ([r["specific_energy"] for r in results] == list(energies)
                and all(r["particles"] == args.particles and len(r["scene_walls_s"]) == each
                        for r in results))
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if not same:
        return None
    return _wall_time(results, f"an earlier run's scene wall times in {path}", args)


def _queue(args):
    """The queue of every energy's scenes on --scheduler (scenes.on_workers), connected once
    for the run, where one per energy would start the workers again each time; a null context
    where this process runs them."""
    scheduler = job_options.scheduler_of(args)
    if not scenes.on_workers(scheduler, scenes.scene_counts(args.particles,
                                                           args.scene_particles)):
        return contextlib.nullcontext()
    return started_queue(scheduler, args.retries)


def started_queue(scheduler, retries):
    """A SceneQueue on `scheduler`, started (verify's too); a scheduler that does not answer
    stops the script in one line."""
    progress(f"scenes on {scheduler}")
    try:
        return scenes.SceneQueue(scheduler, retries).start()
    except SchedulerError as exc:
        raise ScriptError(str(exc)) from None


def _impacts_at(args, mat, target, k, energy, out, start, queue=None):
    """The particles fired at `energy` (J/kg) in scenes of --scene-particles, by the workers of
    `queue` if any: (the last scene's controller, the energy's result)."""
    speed = float(np.sqrt(2 * energy))
    counts = scenes.scene_counts(args.particles, args.scene_particles)
    seen = {"done": 0, "tally": None}
    in_process = queue is None         # _queue made one wherever there are workers
    remaining = Remaining()

    def on_scene(done, scenes_total, tally):
        seen["done"], seen["tally"] = done, tally

    def describe(elapsed_s):
        """The energy's line every few seconds, also inside one long scene."""
        tally, done = seen["tally"], seen["done"]
        broken = (f", {len(tally.broken)} of {tally.particles} broken, "
                  f"{tally.breakage_events} breakages" if tally is not None else "")
        running = (f", scene {done + 1} at {1e6 * view.now():.4g} us simulated"
                   if in_process and done < len(counts) else "")
        return (f"{energy:g} J/kg: {done}/{len(counts)} scenes done{broken}{running}, "
                f"{elapsed_s:.0f} s, {remaining(elapsed_s, done / len(counts))} at this energy")

    with Heartbeat(describe):
        tally, brk = scenes.single_impacts(
            mat, args.size, speed, args.particles, args.scene_particles, args.seed + k,
            target=target, event_log=str(out / f"events_{energy:g}.jsonl"), on_scene=on_scene,
            queue=queue, shape=args.shape, watch=_frames(args, out, energy),
            **job_options.attach_options("single_impact", args))
    share = mat.energy_partition(target)
    result = reports.breakage_result_of(tally, mat, energy, target)
    intact = [e for e in tally.first if e["kind"] == "damage"]
    result.update({
        "speed": speed, "half_v_squared": energy, "steps": tally.steps, "scenes": tally.scenes,
        "scenes_at_step_limit": tally.scenes_at_step_limit,
        "scenes_wall_s": tally.scene_wall_s, "scene_walls_s": tally.scene_walls,
        "yade_engines_s": tally.yade_engines_s,
        "mean_specific_energy_measured": (float(np.mean([e["specific_energy"] / share
                                                         for e in intact])) if intact else None),
        "mass_relative_error": tally.mass_relative_error})
    if args.shape == "polyhedra":
        result["polyhedra_pair_checks"] = tally.polyhedra_pair_checks
    progress(f"{reports.result_line(result)}, {tally.steps} steps, {time.time() - start:.1f} s "
             f"(the scenes {tally.scene_wall_s:.1f} s, YADE's own engines "
             f"{tally.yade_engines_s:.1f} s of them)")
    return brk, result


def _frames(args, out, energy):
    """watch() of the first scene at `energy`: a ParaView series in <out>/paraview_<energy>
    every --vtk-interval s of simulated time (None without one)."""
    if not args.vtk_interval:
        return None
    folder = out / f"paraview_{energy:g}"
    return lambda scene, brk: (paraview.series(folder, brk, args.vtk_interval) if scene == 0
                               else None)


# -- drop-weight tests ----------------------------------------------------------------------------
def drop_weight(args):
    """Every energy, then summary.json and the plot; returns the last energy's controller."""
    mat, steel = job_options.material_of(args), load_material("steel")
    out = Path(args.out)
    start = time.time()

    def write(results, end_reason, end_message):
        """summary.json and, if an energy is done, the plot."""
        write_atomic(out / "summary.json", json.dumps({
            "material": mat.name, "size": args.size, "results": results,
            "runtime_s": time.time() - start, "end_reason": end_reason,
            "end_message": end_message}, indent=2))
        if results:
            reports.plot_breakage(results, mat, args.size, steel, f"{mat.name} drop weight",
                                  out / "drop_weight.png", label="drop weight, simulation")

    def limited(results):
        at = [r["specific_energy"] for r in results if r["stopped_at_max_time"]]
        return f"strikers still falling at --max-time at {at} J/kg" if at else ""

    def compute(k, energy):
        brk, result = _drop_at(args, mat, steel, k, energy, out)
        progress(f"{reports.result_line(result)}, {time.time() - start:.1f} s")
        return brk, result

    brk = skeleton.run_units(args, _energies(args), compute, write, limited)
    progress(f"wrote {out / 'summary.json'} and {out / 'drop_weight.png'}")
    return brk


def _drop_at(args, mat, steel, k, energy, out):
    """The drop-weight tests at `energy` (J/kg): (controller, the energy's result)."""
    brk, ids, strikers = scenes.drop_weight_scene(
        mat, args.size, energy, args.particles, args.striker_mass_ratio,
        seed=args.seed + k, event_log=str(out / f"events_{energy:g}.jsonl"),
        **job_options.attach_options("drop_weight", args))
    initial_mass = brk.total_mass()
    # until every striker rebounds (or max_time of simulated time); then open events close
    while any(view.velocity(s)[2] < 0 for s in strikers) and view.now() < args.max_time:
        engine.run_steps(500)
        stop_point()                  # SIGINT, SIGTERM: end here (skeleton.run's stop points)
    stopped = any(view.velocity(s)[2] < 0 for s in strikers)
    brk.finish()
    result = reports.breakage_result(brk, ids, mat, args.size, energy, steel)
    result["mass_relative_error"] = abs(brk.total_mass() - initial_mass) / initial_mass
    result["stopped_at_max_time"] = stopped
    return brk, result


# -- repeated impacts -----------------------------------------------------------------------------
class Repeated(skeleton.Job):
    """The particles hit the plate again and again at one energy; the broken leave the test. A
    checkpoint after every impact (the scene, the particles alive and their home positions);
    --stop-after counts impacts."""

    report_every = math.inf           # a line after every impact instead
    checkpoint_every = 0.0            # after every impact

    def check(self):
        args = self.args
        self.mat = job_options.material_of(args)
        if args.gamma > 0:
            if self.mat.criterion.name != "tavares":
                raise ScriptError(f"--gamma applies to Tavares materials; {self.mat.name} uses "
                                  f"{self.mat.criterion.name}")
            self.mat = self.mat.with_params(gamma=args.gamma)
        self.share = self.mat.energy_partition(job_options.material_of(args, "target"))
        self.speed = float(np.sqrt(2 * args.energy))
        self.began = time.time()

    def build(self):
        args = self.args
        self.brk, self.ids = scenes.impact_scene(
            self.mat, args.size, [self.speed] * args.particles,
            target=job_options.material_of(args, "target"),
            seed=args.seed, **job_options.attach_options(
                "repeated_impact", args, event_log=str(self.out / "events.jsonl")))
        self.home = {i: view.position(i) for i in self.ids}
        self.alive = list(self.ids)
        self.fractions = []

    def resume(self, path):
        self.brk, state = skeleton.load_checked(path, engine.load_checkpoint, self.args)
        self.ids, self.alive, self.fractions = state["ids"], state["alive"], state["fractions"]
        self.home = {int(i): tuple(p) for i, p in state["home"].items()}
        self.say(f"resumed from {path} after impact {len(self.fractions)}")
        return 0.0                    # runtime_s: this invocation's, as it always was

    def advance(self):
        if len(self.fractions) >= self.args.impacts:
            return "finished"
        self.alive = scenes.impact_again(self.brk, self.alive, self.home, self.speed)
        self.fractions.append(1 - len(self.alive) / self.args.particles)
        self.say(f"impact {len(self.fractions)}: {100 * self.fractions[-1]:.0f} % broken, "
                 f"{time.time() - self.began:.1f} s")
        return None

    def elapsed(self):
        return len(self.fractions)

    def save(self, path, wall_s):
        engine.save_checkpoint(path, {
            "ids": self.ids, "alive": self.alive, "fractions": self.fractions, "home": self.home,
            "arguments": resume_arguments(self.args)})

    def outputs(self, end_reason, end_message, runtime_s):
        return _repeated_outputs(self.args, self.mat, self.share, self.fractions, self.brk,
                                 self.out, runtime_s, end_reason, end_message)

    def finished(self, summary):
        self.say(f"wrote {self.out / 'summary.json'} and {self.out / 'repeated_impact.png'}")

    def result(self, summary):
        return getattr(self, "brk", None)


def repeated(args):
    """Every impact, then summary.json and the plot; returns the controller."""
    return skeleton.run(Repeated(args))


def _repeated_outputs(args, mat, share, fractions, brk, out, runtime_s, end_reason, end_message):
    """summary.json (with how the run ended) and the plot, for the impacts done."""
    criterion = mat.criterion
    model_fractions = criterion.repeated_broken_fraction(share * args.energy, args.size,
                                                         len(fractions))
    model_label = criterion.repeated_label.format(**dataclasses.asdict(mat.params))
    absorbed = [e["specific_energy"] for e in brk.events if e["kind"] == "damage"]
    summary = {"material": mat.name, "model": mat.breakage_model, "size": args.size,
               "energy": args.energy, "gamma": getattr(mat.params, "gamma", None),
               "particles": args.particles, "share_e": share,
               "broken_fraction": fractions, "model_broken_fraction": model_fractions.tolist(),
               "mean_absorbed_specific_energy": float(np.mean(absorbed)) if absorbed else None,
               "expected_absorbed_specific_energy": share * args.energy,
               "runtime_s": runtime_s, "end_reason": end_reason,
               "end_message": end_message}
    write_atomic(out / "summary.json", json.dumps(summary, indent=2))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

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
    save_figure(fig, out / "repeated_impact.png", dpi=110)
    plt.close(fig)
    return summary
