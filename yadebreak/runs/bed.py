"""The bed-impact job behind scripts/bed_impact.py (coupling layer: runs YADE, writes outputs)."""
from __future__ import annotations

import csv
import json
import math
import time
from pathlib import Path

import numpy as np

from yadebreak import coupling, scenes
from yadebreak.runs import paraview
from yadebreak.scenes import poured_bed
from yadebreak.coupling.yade_api import O
from yadebreak.tools.options import (check_not_finished, check_resume_arguments, mark_finished, mark_started,
                         partial_outputs_on_failure, progress, read_checkpoint, read_period_value,
                         resume_arguments, run_wall_time, stop_point, stop_points, time_left,
                         write_atomic)

FEED_LOWER_SIEVE = 4.75e-3       # m: broken mass is the mass passing the feed's lower sieve
TAIL = 1e-4                      # s of unloading simulated after the ball's deepest point


def _fates(brk, particles):
    """'broken', 'damaged' or 'intact' for each original particle."""
    kinds = {}
    for e in brk.events:
        if e["kind"] == "breakage":
            kinds[e["id"]] = "broken"
        elif e["kind"] == "damage":
            kinds.setdefault(e["id"], "damaged")
    return [kinds.get(i, "intact") for i in particles]


def capture_radius(brk, info):
    """Largest horizontal distance (m) from the ball's axis to the centre of an original particle
    that was stressed by the impact (a damage or breakage event: Ek' reached emin). The paper's
    carbon paper under the bed records the impressions of the particles pressed onto the anvil,
    which lie under their centres."""
    fates = _fates(brk, info["particles"])
    radii = [math.hypot(c[0], c[1]) for c, f in zip(info["centers"], fates) if f != "intact"]
    return max(radii) if radii else 0.0


def _checkpoint(path, info, loop, args, start):
    """The scene, the loop's own state (with the run's wall time so far, from the invocation's
    `start`) and the run's arguments (coupling.save_checkpoint)."""
    loop["wall_s"] = run_wall_time(loop, start)
    coupling.save_checkpoint(path, {
        "loop": loop, "info": {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                               for k, v in info.items() if k != "material"},
        "arguments": resume_arguments(args)})


def _resume(path, args):
    """The checkpoint's scene, refused (naming them) if it was run with other arguments."""
    brk, data = read_checkpoint(path, coupling.load_checkpoint)
    if "arguments" in data:                 # (checkpoints written before they were recorded: not)
        check_resume_arguments(data["arguments"], args, path)
    info = data["info"]
    info["centers"] = np.array(info["centers"])
    return brk, info, data["loop"]


def _options(args, out):
    """attach() options from the script's arguments."""
    read_period = read_period_value(args.read_period)
    options = dict(time_step_fraction=args.time_step_fraction, dummies=args.dummies,
                   read_period=read_period, event_log=str(out / "events.jsonl"))
    if args.dmin > 0:
        options["dmin"] = args.dmin
    if args.global_damping > 0:
        options.update(global_damping=args.global_damping, global_damping_time=5e-4)
    if getattr(args, "stiffness_scale", 1.0) != 1.0:
        options["stiffness_scale"] = args.stiffness_scale
    return options


def _start(args, out, energy, say):
    """The scene, new or from the checkpoint (--resume 1): (controller, info, loop state)."""
    checkpoint = out / "checkpoint.yade.gz"
    if getattr(args, "resume", False):
        check_not_finished(out, args)       # a finished run: says so, nothing is run or rewritten
        brk, info, loop = _resume(checkpoint, args)
        loop["wall_before_s"] = loop.get("wall_s", 0.0)   # the run's wall time: all invocations
        say(f"resumed from {checkpoint} at t = {1e3 * O.time:.3f} ms, iteration {O.iter}")
        return brk, info, loop
    mark_started(out)
    steel_rolling = getattr(args, "steel_rolling_friction", -1.0)
    brk, info = scenes.bed_impact_scene(
        args.material, args.size, args.rings, args.layers, energy, args.seed,
        packing=None if getattr(args, "packing", "auto") == "auto" else args.packing,
        rolling=bool(getattr(args, "rolling_friction", True)),
        steel_rolling_friction=None if steel_rolling < 0 else steel_rolling,
        bed_cache=_bed_cache(getattr(args, "bed_cache", "")), say=say, **_options(args, out))
    mass = brk.total_mass()
    say(f"{len(info['particles'])} particles of {args.material} ({1e3 * args.size:g} mm), "
        f"{args.layers} layer(s); ball at {info['speed']:.3f} m/s ({energy:g} J, "
        f"{energy / mass:.0f} J per kg of bed); dt {O.dt:.3g} s")
    return brk, info, {"touched": None, "turned": None, "initial_mass": mass, "initial_dt": O.dt}


def _bed_cache(given):
    """--bed-cache: "" the default folder, "off" none."""
    return None if given == "off" else given


def finest_sphere_size():
    """Diameter (m) of the smallest sphere in the scene (a pass over the bodies: once, at the end)."""
    from yadebreak.coupling.yade_api import wrapper
    return min((2.0 * b.shape.radius for b in O.bodies
                if b is not None and isinstance(b.shape, wrapper.Sphere)), default=float("nan"))


def why_it_took_longer(summary):
    """Why a run took more steps than its start promised, or None: the time step fell for finer
    fragments (a small bed under the same ball takes more energy per kg and breaks finer)."""
    start_dt, dt = summary.get("initial_dt"), summary["final_dt"]
    if start_dt is None or not dt < 0.5 * start_dt:
        return None
    return (f"the time step fell {start_dt / dt:.0f}-fold, to {dt:.2g} s, for fragments down to "
            f"{1e3 * summary['finest_sphere_size']:.2f} mm: {summary['energy_per_bed_mass']:.0f} "
            "J/kg of bed broke them that fine (fewer particles under the same ball take more "
            "energy each, break finer and need more, shorter steps)")


def _paraview(args, out, brk, info):
    """The ParaView series, <out>/paraview, a frame every args.vtk_interval s of simulated time
    (None: 20 frames over max_time; 0: none); the anvil drawn as a square around the bed."""
    interval = getattr(args, "vtk_interval", None)
    interval = args.max_time / paraview.DEFAULT_FRAMES if interval is None else interval
    reach = np.max(np.abs(info["centers"][:, :2])) + args.size / 2.0
    return paraview.series(out / "paraview", brk, interval, resume=getattr(args, "resume", False),
                           wall_patch=((0.0, 0.0, 0.0), paraview.WALL_MARGIN * reach))


def _impact(brk, info, loop, args, out, start, say, frames):
    """Run until the ball has turned plus TAIL of unloading (or max_time), with progress lines,
    ParaView frames and checkpoints. Returns how it ended: "finished", "time_limit" (max_time),
    or None if it stopped early on purpose (--stop-after, tests)."""
    ball = O.bodies[info["ball"]]
    v0 = info["speed"]
    every = getattr(args, "checkpoint_every", 60.0)
    stop_after = getattr(args, "stop_after", 0.0)
    last_report = last_checkpoint = start
    while True:
        if loop["touched"] is None:           # the bed's motion before the ball reaches it
            before_touch = poured_bed.kinetic_energy(info["particles"])
        coupling.run_steps(100 if loop["touched"] is None else 400)
        if loop["touched"] is None and any(O.interactions.withBody(info["ball"])):
            loop["touched"] = O.time
            loop["bed_kinetic_energy_at_touch"] = before_touch
            scenes.hold_release(info)
        frames()                                  # a frame if one is due (before the checkpoint)
        vz = ball.state.vel[2]
        if loop["touched"] is not None and loop["turned"] is None and vz >= 0.0:
            loop["turned"] = O.time            # deepest penetration: loading is over
        touched, turned = loop["touched"], loop["turned"]
        # breakage happens while loading: after the turn, a short unloading, then open events
        # are closed with their largest energy (brk.finish)
        if turned is not None and O.time >= turned + TAIL:
            return "finished"
        if O.time > args.max_time:
            say(f"stopped at max_time = {args.max_time} s of simulated time")
            return "time_limit"
        now = time.time()
        if every >= 0 and now - last_checkpoint >= every:
            _checkpoint(out / "checkpoint.yade.gz", info, loop, args, start)  # --resume 1 goes on
            last_checkpoint = now
        # SIGINT, SIGTERM (run() catches them in stop_points): end here, checkpointed
        stop_point(lambda: _checkpoint(out / "checkpoint.yade.gz", info, loop, args, start))
        if stop_after and O.time >= stop_after:
            return None                           # (tests) as if the run had died here
        if now - last_report > 5.0:
            done = 0.0 if touched is None else (0.5 * (1 - max(-vz, 0.0) / v0) if turned is None
                                                else 0.5 + 0.5 * (O.time - turned) / TAIL)
            say(f"t = {1e3 * O.time:.3f} ms, {len(brk.breakage_events)} breakages, "
                f"{sum(1 for b in O.bodies if b is not None)} bodies, ball {vz:+.3f} m/s, "
                f"wall {now - start:.0f} s, {time_left(now - start, done)}")
            last_report = now


def run(args, quiet=False):
    """Build, run and report one bed impact. Returns (controller, summary dict)."""
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    energy = args.energy if args.speed <= 0 else 0.5 * scenes.BALL_MASS * args.speed ** 2
    start = time.time()
    say = (lambda m: None) if quiet else progress
    # SIGINT, SIGTERM from here on: the run ends at its loop's next stop_point, checkpointed
    with stop_points():
        brk, info, loop = _start(args, out, energy, say)
        frames = _paraview(args, out, brk, info)

        def runtime():                                # s: the whole run's, over its invocations
            return run_wall_time(loop, start)

        def partial(end_reason, end_message):         # the outputs so far; the checkpoint is kept
            _report(brk, info, loop, args, out, energy, runtime(), end_reason, end_message)

        with partial_outputs_on_failure(partial):
            ended = _impact(brk, info, loop, args, out, start, say, frames)
    if ended is None:
        return brk, None
    brk.finish()
    frames.close()                                # the last frame, with the events closed
    summary = _report(brk, info, loop, args, out, energy, runtime(), ended,
                      "" if ended == "finished" else f"stopped at --max-time {args.max_time} s")
    mark_finished(out, args)                      # --resume 1 now says so and does nothing
    (out / "checkpoint.yade.gz").unlink(missing_ok=True)    # a mid-run state, of no more use
    say(f"done in {summary['runtime_s']:.1f} s: {summary['breakage_events']} breakages, broken "
        f"mass {1e3 * summary['broken_mass']:.3f} g ({100 * summary['broken_mass_fraction']:.1f} "
        f"%), capture radius {1e3 * summary['capture_radius']:.1f} mm; outputs in {out}")
    why = why_it_took_longer(summary)
    if why:
        say(f"{summary['steps']} steps: {why}")
    return brk, summary


def _report(brk, info, loop, args, out, energy, runtime, end_reason, end_message):
    """summary.json (with how the run ended), the size distribution (CSV and plot) and the top
    view."""
    initial_mass = loop["initial_mass"]
    sieves = np.geomspace(1e-5, 2 * args.size, 80)
    sd = brk.size_distribution(sieves)
    broken_mass = float(brk.size_distribution([FEED_LOWER_SIEVE]).passing_mass[0])
    fates = _fates(brk, info["particles"])
    summary = {
        "material": args.material, "size": args.size, "rings": args.rings, "layers": args.layers,
        "bed_packing": info["packing"], "bed_height": info["bed_height"],
        "bed_settling": info["settled"],
        "bed_kinetic_energy_at_touch": loop.get("bed_kinetic_energy_at_touch"),
        "rolling_friction": info["rolling_friction"],
        "energy": energy, "ball_speed": info["speed"], "seed": args.seed,
        "particles": len(info["particles"]),
        "initial_mass": initial_mass, "final_mass": brk.total_mass(),
        "mass_relative_error": abs(brk.total_mass() - initial_mass) / initial_mass,
        "broken_mass": broken_mass, "broken_mass_fraction": broken_mass / initial_mass,
        "capture_radius": capture_radius(brk, info),
        "breakage_events": len(brk.breakage_events),
        "damage_events": sum(1 for e in brk.events if e["kind"] == "damage"),
        "particles_broken": fates.count("broken"), "particles_damaged": fates.count("damaged"),
        "energy_per_bed_mass": energy / initial_mass,
        "simulated_time": O.time, "steps": O.iter, "initial_dt": loop.get("initial_dt"),
        "final_dt": O.dt, "finest_sphere_size": finest_sphere_size(), "runtime_s": runtime,
        "wall_time_read_s": brk.wall_time["read"], "wall_time_replace_s": brk.wall_time["replace"],
        "end_reason": end_reason, "end_message": end_message,
    }
    write_atomic(out / "summary.json", json.dumps(summary, indent=2))
    with open(out / "size_distribution.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["size_m", "passing_percent"])
        w.writerows(zip(sd.sizes, sd.passing_percent))
    _plots(out, sd, info, fates, summary)
    return summary


def _plots(out, sd, info, fates, summary):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.semilogx(1e3 * sd.sizes, sd.passing_percent, "o-", ms=3)
    ax.axvline(1e3 * FEED_LOWER_SIEVE, ls=":", c="k", label="4.75 mm (broken mass)")
    ax.set(xlabel="size (mm)", ylabel="cumulative passing (%)",
           title=f"{summary['material']}, {summary['rings']} rings x {summary['layers']} layer(s), "
                 f"{summary['energy']:g} J")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "size_distribution.png", dpi=110)
    plt.close(fig)
    colours = {"intact": "0.8", "damaged": "tab:orange", "broken": "tab:red"}
    fig, ax = plt.subplots(figsize=(5.5, 5.5))
    r = summary["size"] / 2.0
    for c, f in sorted(zip(info["centers"], fates), key=lambda cf: cf[0][2]):
        ax.add_patch(Circle((1e3 * c[0], 1e3 * c[1]), 1e3 * r, fc=colours[f], ec="k", lw=0.5))
    reach = 1e3 * (np.max(np.abs(info["centers"][:, :2])) + 2 * r)
    ax.add_patch(Circle((0, 0), 1e3 * summary["capture_radius"], fill=False, ls="--", ec="b"))
    ax.set(xlim=(-reach, reach), ylim=(-reach, reach), aspect="equal", xlabel="x (mm)",
           ylabel="y (mm)", title="top view: grey intact, orange damaged, red broken;\n"
                                  "dashed: capture radius")
    fig.tight_layout()
    fig.savefig(out / "bed_top_view.png", dpi=110)
    plt.close(fig)
