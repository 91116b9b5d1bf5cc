"""The bed-impact job behind scripts/bed_impact.py (coupling layer: runs YADE, writes outputs)."""
from __future__ import annotations

import csv
import json
import math

import numpy as np

from yadebreak import engine, scenes
from yadebreak.jobs import paraview
from yadebreak.scenes import poured_bed
from yadebreak.scenes import view
from yadebreak.scenes.view import finest_sphere_size
from yadebreak.jobs import skeleton
from yadebreak.jobs.lifecycle import resume_arguments, write_atomic
from yadebreak.jobs import options as job_options

FEED_LOWER_SIEVE = 4.75e-3       # m: broken mass is the mass passing the feed's lower sieve
TAIL = 1e-4                      # s of unloading simulated after the ball's deepest point
SAFE_EVERY = 5                   # chunks of steps between the points where a checkpoint may be


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


def _options(args, out):
    """attach() options from the script's arguments."""
    return job_options.attach_options("bed_impact", args, event_log=str(out / "events.jsonl"))


def _bed_cache(given):
    """--bed-cache: "" the default folder, "off" none."""
    return None if given == "off" else given


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


class BedImpact(skeleton.Job):
    """The ball falls on the bed until it has turned plus TAIL of unloading (or --max-time)."""

    report_every = 5.0

    def __init__(self, args, quiet=False):
        super().__init__(args, quiet)
        self.energy = args.energy if args.speed <= 0 else 0.5 * scenes.BALL_MASS * args.speed ** 2

    def build(self):
        args, energy = self.args, self.energy
        steel_rolling = getattr(args, "steel_rolling_friction", -1.0)
        self.brk, self.info = scenes.bed_impact_scene(
            job_options.material_of(args), args.size, args.rings, args.layers, energy, args.seed,
            packing=None if getattr(args, "packing", "auto") == "auto" else args.packing,
            rolling=bool(getattr(args, "rolling_friction", True)),
            steel_rolling_friction=None if steel_rolling < 0 else steel_rolling,
            bed_cache=_bed_cache(getattr(args, "bed_cache", "")),
            stiffness_scale=getattr(args, "stiffness_scale", 1.0), say=self.say,
            **_options(args, self.out))
        mass = self.brk.total_mass()
        self.say(f"{len(self.info['particles'])} particles of {args.material} "
                 f"({1e3 * args.size:g} mm), {args.layers} layer(s); ball at "
                 f"{self.info['speed']:.3f} m/s ({energy:g} J, {energy / mass:.0f} J per kg of "
                 f"bed); dt {view.time_step():.3g} s")
        self.loop = {"touched": None, "turned": None, "initial_mass": mass,
                     "initial_dt": view.time_step()}

    def resume(self, path):
        self.brk, data = skeleton.load_checked(path, engine.load_checkpoint, self.args)
        self.info, self.loop = data["info"], data["loop"]
        self.info["centers"] = np.array(self.info["centers"])
        self.loop["wall_before_s"] = self.loop.get("wall_s", 0.0)   # all invocations
        self.say(f"resumed from {path} at t = {1e3 * view.now():.3f} ms, "
                 f"iteration {view.iteration()}")
        return self.loop["wall_before_s"]

    def open(self):
        self.frames = _paraview(self.args, self.out, self.brk, self.info)

    def advance(self):
        loop, info = self.loop, self.info
        if loop["touched"] is None:           # the bed's motion before the ball reaches it
            before_touch = poured_bed.kinetic_energy(info["particles"])
        engine.run_steps(100 if loop["touched"] is None else 400)
        if loop["touched"] is None and view.touching(info["ball"]):
            loop["touched"] = view.now()
            loop["bed_kinetic_energy_at_touch"] = before_touch
            scenes.hold_release(info)
        loop["chunks"] = loop.get("chunks", 0) + 1
        if self.at_safe_point():          # saved and loaded back where a checkpoint may be
            self.brk = self.frames.brk = engine.reload()     # taken: resumed from one, a run
            #                                                   goes on as this one, bit for bit
        self.frames()                             # a frame if one is due (before the checkpoint)
        vz = view.velocity(self.info["ball"])[2]
        self._follow_the_ball()
        if loop["touched"] is not None and loop["turned"] is None and vz >= 0.0:
            loop["turned"] = view.now()            # deepest penetration: loading is over
        # breakage happens while loading: after the turn, a short unloading, then open events
        # are closed with their largest energy (brk.finish)
        if loop["turned"] is not None and view.now() >= loop["turned"] + TAIL:
            return "finished"
        if view.now() > self.args.max_time:
            self.say(f"stopped at max_time = {self.args.max_time} s of simulated time")
            return "time_limit"
        return None

    def _follow_the_ball(self):
        """The ball's height at the first chunk's end that finds it in contact, and its lowest
        at a chunk's end since (the penetration's two ends, within one chunk's travel)."""
        loop, z = self.loop, view.position(self.info["ball"])[2]
        if loop.get("first_contact_z") is None:
            if view.in_contact(self.info["ball"]):
                loop["first_contact_z"] = loop["lowest_z"] = z
        else:
            loop["lowest_z"] = min(loop["lowest_z"], z)

    def at_safe_point(self):
        """Every SAFE_EVERY chunks (engine.reload costs 20 to 30 ms, 400 steps 80 to 220 ms)."""
        return self.loop.get("chunks", 0) % SAFE_EVERY == 0

    def elapsed(self):
        return view.now()

    def status(self):
        vz = view.velocity(self.info["ball"])[2]
        return (f"t = {1e3 * view.now():.3f} ms, {len(self.brk.breakage_events)} breakages, "
                f"{view.body_count()} bodies, ball {vz:+.3f} m/s")

    def done(self):
        touched, turned = self.loop["touched"], self.loop["turned"]
        if touched is None:
            return 0.0
        if turned is None:
            return 0.5 * (1 - max(-view.velocity(self.info["ball"])[2], 0.0) / self.info["speed"])
        return 0.5 + 0.5 * (view.now() - turned) / TAIL

    def save(self, path, wall_s):
        """The scene, the loop's own state (with the run's wall time so far) and the run's
        arguments (engine.save_checkpoint)."""
        self.loop["wall_s"] = wall_s
        engine.save_checkpoint(path, {
            "loop": self.loop,
            "info": {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                     for k, v in self.info.items() if k != "material"},
            "arguments": resume_arguments(self.args)})

    def close(self):
        self.brk.finish()
        self.frames.close()                       # the last frame, with the events closed

    def end_message(self, ended):
        return "" if ended == "finished" else f"stopped at --max-time {self.args.max_time} s"

    def outputs(self, end_reason, end_message, runtime_s):
        return _report(self.brk, self.info, self.loop, self.args, self.out, self.energy,
                       runtime_s, end_reason, end_message)

    def finished(self, summary):
        self.say(f"done in {summary['runtime_s']:.1f} s: {summary['breakage_events']} "
                 f"breakages, broken mass {1e3 * summary['broken_mass']:.3f} g "
                 f"({100 * summary['broken_mass_fraction']:.1f} %), capture radius "
                 f"{1e3 * summary['capture_radius']:.1f} mm; outputs in {self.out}")
        why = why_it_took_longer(summary)
        if why:
            self.say(f"{summary['steps']} steps: {why}")

    def result(self, summary):
        return self.brk, summary


def run(args, quiet=False):
    """Build, run and report one bed impact. Returns (controller, summary dict); the summary is
    None if the run stopped at --stop-after (tests)."""
    return skeleton.run(BedImpact(args, quiet))


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
        "outcome": brk.config.criteria.outcome,
        "particles": len(info["particles"]),
        "initial_mass": initial_mass, "final_mass": brk.total_mass(),
        "mass_relative_error": abs(brk.total_mass() - initial_mass) / initial_mass,
        "broken_mass": broken_mass, "broken_mass_fraction": broken_mass / initial_mass,
        "capture_radius": capture_radius(brk, info),
        "penetration": (None if loop.get("first_contact_z") is None
                        else loop["first_contact_z"] - loop["lowest_z"]),
        "breakage_events": len(brk.breakage_events),
        "damage_events": sum(1 for e in brk.events if e["kind"] == "damage"),
        "particles_broken": fates.count("broken"), "particles_damaged": fates.count("damaged"),
        "energy_per_bed_mass": energy / initial_mass,
        "simulated_time": view.now(), "steps": view.iteration(),
        "initial_dt": loop.get("initial_dt"), "final_dt": view.time_step(),
        "finest_sphere_size": finest_sphere_size(), "runtime_s": runtime,
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
