"""The laboratory batch ball mill behind scripts/ball_mill.py (coupling layer: runs YADE, writes
outputs). A drum of steel facets with lifter bars, turned about the x axis by YADE's
RotationEngine; steel balls and a breakable ore charge; gravity along -z.

The run records, every --sample-interval seconds of simulated time, the product size distribution
(fines included), the drum's torque and the charge's centre of mass, and writes the size
distribution against time, the first-order breakage rate of the feed size, the mill power from the
torque beside two checks (the torque-arm model and Bond's equation), a picture of the charge seen
along the axis and a ParaView series.
"""
from __future__ import annotations

import csv
import json
import math

import numpy as np

from yadebreak import engine
from yadebreak.model import milling
from yadebreak.jobs import paraview
from yadebreak.scenes import view
from yadebreak.scenes.mill import charge_state, drum_torque, mill_scene, mill_time
from yadebreak.jobs import skeleton
from yadebreak.jobs import options as job_options
from yadebreak.jobs.options import check_mill_geometry
from yadebreak.jobs.lifecycle import ScriptError, resume_arguments, write_atomic


def check_geometry(args):
    """Cross-checks of the options that one range cannot say (ScriptError, one line each)."""
    problem = check_mill_geometry(args)
    if problem:
        raise ScriptError(problem)


PAIR_TYPES = ("ball-ore", "ore-ore", "ore-liner")


def pair_type(partner, info):
    """The kind of contact that brought an ore event's largest energy, from the event's partner
    id: a ball, the drum (shell, lifters, end walls), another ore sphere; None without one."""
    if partner < 0:
        return None
    if partner in info["ball_set"]:
        return "ball-ore"
    if partner in info["liner_set"]:
        return "ore-liner"
    return "ore-ore"


def collision_spectra(events, info, duration):
    """Stressing events per second against specific energy (J/kg), per pair type: (bin edges,
    {pair type: (per bin, at or above each lower edge)}), from the engine's damage and breakage
    events, or its stressing events in a spectra run (each ore stressing event once, at its largest energy, with the contact that brought
    most of it)."""
    stressing = [e for e in events if e["kind"] in ("damage", "breakage", "stressing")]
    energies = np.array([e["specific_energy"] for e in stressing])
    positive = energies[energies > 0]
    low, high = ((positive.min(), positive.max()) if len(positive) else (1e-3, 1.0))
    edges = np.geomspace(low, high * (1 + 1e-9), 25)
    spectra = {}
    for kind in PAIR_TYPES:
        mine = [e["specific_energy"] for e in stressing
                if pair_type(e.get("partner", -1), info) == kind]
        spectra[kind] = milling.event_spectrum(mine, duration, edges)
    return edges, spectra


# -- the run ------------------------------------------------------------------------------------------
def _options(args, out):
    """attach() options from the script's arguments."""
    return job_options.attach_options("ball_mill", args, event_log=str(out / "events.jsonl"))


def sieves_for(args):
    """The root-2 sieve series from the feed size down to 1/64 of it (m)."""
    return milling.size_classes(args.size * math.sqrt(2), 13)


def _sample(brk, info, loop, args):
    """One row of the histories: time, the product's mass passing each sieve, the feed class'
    mass, torque and the charge's lever arm."""
    sieves = np.array(loop["sieves"])
    passing = brk.size_distribution(sieves).passing_mass
    feed = float(brk.size_distribution([args.size * 1.0001]).passing_mass[0]
                 - brk.size_distribution([args.size / math.sqrt(2)]).passing_mass[0])
    mass, arm = charge_state(info)
    loop["times"].append(mill_time(info))
    loop["passing"].append([float(p) for p in passing])
    loop["feed_mass"].append(feed)
    loop["charge_mass"].append(mass)
    loop["lever_arm"].append(arm)


def _loaded(brk, data):
    """A checkpoint's state, its parts checked (a damaged one fails here, before the run)."""
    for part in ("arguments", "info", "loop"):
        if not isinstance(data.get(part), dict):
            raise ValueError(f"its state has no {part!r}")
    return brk, data


class Mill(skeleton.Job):
    """The drum turns for --duration s of simulated time: samples, torque, ParaView frames."""

    BATCH = 200                       # steps between two readings of the torque

    def check(self):
        check_geometry(self.args)

    def build(self):
        args = self.args
        self.brk, self.info = mill_scene(args, _options(args, self.out),
                                         job_options.material_of(args))
        self.loop = {"initial_mass": self.brk.total_mass(), "initial_dt": view.time_step(),
                     "sieves": sieves_for(args).tolist(), "times": [], "passing": [],
                     "feed_mass": [], "charge_mass": [], "lever_arm": [], "torque_time": [],
                     "torque": [], "next_sample": 0.0}
        self.say(f"{len(self.info['balls'])} balls ({1e3 * args.ball_size:g} mm) and "
                 f"{len(self.info['ore'])} particles of {args.material} ({1e3 * args.size:g} "
                 f"mm) in a {1e3 * args.drum_diameter:g} x {1e3 * args.drum_length:g} mm drum at "
                 f"{60 * self.info['speed_rps']:.1f} rpm ({100 * args.speed:g} % of critical); "
                 f"dt {view.time_step():.3g} s")

    def resume(self, path):
        self.brk, data = skeleton.load_checked(
            path, lambda p: _loaded(*engine.load_checkpoint(p)), self.args)
        self.info, self.loop = data["info"], data["loop"]
        self.say(f"resumed from {path} at t = {mill_time(self.info):.3f} s")
        self.loop["wall_before_s"] = self.loop.get("wall_s", 0.0)   # earlier invocations
        return self.loop["wall_before_s"]

    def open(self):
        self.frames = paraview.series(self.out / "paraview", self.brk, self.args.vtk_interval,
                                      resume=getattr(self.args, "resume", False))

    def advance(self):
        args, info, loop = self.args, self.info, self.loop
        if mill_time(info) >= args.duration:
            _sample(self.brk, info, loop, args)
            return "finished"
        engine.run_steps(self.BATCH)
        now_s = mill_time(info)
        loop["torque_time"].append(now_s)
        loop["torque"].append(drum_torque(info["drum"]))
        if now_s >= loop["next_sample"]:
            _sample(self.brk, info, loop, args)
            loop["next_sample"] = now_s + args.sample_interval
        self.frames()
        return None

    def elapsed(self):
        return mill_time(self.info)

    def status(self):
        return (f"t = {mill_time(self.info):.3f} of {self.args.duration:g} s, "
                f"{len(self.brk.breakage_events)} breakages, "
                f"{view.body_count()} bodies, dt {view.time_step():.2g} s")

    def done(self):
        return mill_time(self.info) / self.args.duration

    def save(self, path, wall_s):
        """The scene and the loop's state, with the run's wall time so far: --resume 1 goes on
        from it."""
        self.loop["wall_s"] = wall_s
        engine.save_checkpoint(path, {"loop": self.loop, "info": self.info,
                                        "arguments": resume_arguments(self.args)})

    def close(self):
        self.brk.finish()
        self.frames.close()

    def outputs(self, end_reason, end_message, runtime_s):
        return _report(self.brk, self.info, self.loop, self.args, self.out, runtime_s,
                       end_reason, end_message)

    def finished(self, summary):
        self.say(f"done in {summary['runtime_s']:.0f} s: {summary['breakage_events']} "
                 f"breakages, broken mass {100 * summary['broken_mass_fraction']:.2f} % of the "
                 f"ore, mean power {summary['mean_power_W']:.1f} W; outputs in {self.out}")

    def result(self, summary):
        return getattr(self, "brk", None), summary


def run(args, quiet=False):
    """Build, run and report one mill. Returns (controller, summary dict); the summary is None if
    the run stopped at --stop-after (tests)."""
    return skeleton.run(Mill(args, quiet))


def _report(brk, info, loop, args, out, runtime, end_reason, end_message):
    """summary.json, the histories (CSV) and the plots."""
    info = {**info, "ball_set": set(info["balls"]),
            "liner_set": set(info["drum"]) | set(info.get("ends", ()))}
    times = np.array(loop["times"])
    ore_mass = loop["initial_mass"]
    lower = args.size / math.sqrt(2)            # the feed class' lower sieve
    broken = float(brk.size_distribution([lower]).passing_mass[0])
    torque = np.array(loop["torque"])
    power = -torque * info["omega"]             # the motor's power: against the charge's torque
    steady = np.array(loop["torque_time"]) >= 0.25 * args.duration   # past the start-up
    mean_power = float(power[steady].mean()) if steady.any() else float("nan")
    arm = np.array(loop["lever_arm"])
    charge = np.array(loop["charge_mass"])
    sample_steady = times >= 0.25 * args.duration
    torque_arm = (float(milling.charge_torque_power(charge[sample_steady], np.abs(
        arm[sample_steady]), info["omega"]).mean()) if sample_steady.any() else float("nan"))
    bond = float(milling.bond_mill_power_per_ball_mass(args.drum_diameter, args.ball_filling,
                                                       args.speed)) * info["ball_mass"]
    feed = np.array(loop["feed_mass"])
    try:
        rate, rate_error = milling.first_order_breakage_rate(times, feed)
    except ValueError:
        rate, rate_error = float("nan"), float("nan")
    events = brk.events
    duration = mill_time(info)
    edges, spectra = (collision_spectra(events, info, duration) if duration > 0
                      else (None, {}))
    summary = {
        "material": args.material, "size": args.size, "ball_size": args.ball_size,
        "drum_diameter": args.drum_diameter, "drum_length": args.drum_length,
        "lifters": args.lifters, "speed_fraction": args.speed,
        "speed_rpm": 60 * info["speed_rps"], "ball_filling": args.ball_filling,
        "ore_filling": args.ore_filling, "stiffness_scale": args.stiffness_scale,
        "seed": args.seed, "balls": len(info["balls"]), "ore_particles": len(info["ore"]),
        "bodies_start": len(info["balls"]) + len(info["ore"]) + len(info["drum"]) + 2,
        "bodies_end": view.body_count(),
        "breakage_events": sum(e["kind"] == "breakage" for e in events),
        "damage_events": sum(e["kind"] == "damage" for e in events),
        "breakage": bool(getattr(args, "breakage", True)),
        "stressing_events": sum(e["kind"] == "stressing" for e in events),
        "initial_mass": ore_mass, "final_mass": brk.total_mass(),
        "mass_relative_error": abs(brk.total_mass() - ore_mass) / ore_mass,
        "broken_mass": broken, "broken_mass_fraction": broken / ore_mass,
        "feed_breakage_rate": rate, "feed_breakage_rate_error": rate_error,
        "stressing_events_per_second": {kind: float(rates[1][0]) for kind, rates
                                        in spectra.items()},
        "mean_power_W": mean_power, "torque_arm_power_W": torque_arm,
        "bond_power_W": bond, "ball_mass": info["ball_mass"],
        "simulated_time": mill_time(info), "steps": view.iteration(),
        "initial_dt": loop["initial_dt"], "final_dt": view.time_step(), "runtime_s": runtime,
        "throughput_s_per_hour": 3600.0 * mill_time(info) / runtime if runtime > 0 else None,
        "end_reason": end_reason, "end_message": end_message}
    write_atomic(out / "summary.json", json.dumps(summary, indent=2))
    _write_histories(out, loop, power, edges, spectra)
    if edges is not None and not summary["breakage"]:   # the spectra run: the grinding model's
        _write_grinding_spectra(out)                      # input
    _plots(out, summary, loop, info, power, edges, spectra)
    return summary


def _write_histories(out, loop, power, edges, spectra):
    """The histories of a run as CSV: size distribution, feed class, power, and the collision
    energy spectra (if the mill turned)."""
    times, feed = np.array(loop["times"]), np.array(loop["feed_mass"])
    ore_mass = loop["initial_mass"]
    torque = np.array(loop["torque"])
    sieves = np.array(loop["sieves"])
    with open(out / "size_distribution.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time_s"] + [f"passing_{1e3 * s:.4g}mm_percent" for s in sieves])
        for t, p in zip(times, loop["passing"]):
            w.writerow([t] + [100 * m / ore_mass for m in p])
    with open(out / "breakage_rate.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time_s", "feed_class_mass_kg", "feed_class_fraction"])
        w.writerows((t, m, m / feed[0] if len(feed) and feed[0] > 0 else float("nan"))
                    for t, m in zip(times, feed))
    with open(out / "power.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time_s", "torque_Nm", "power_W"])
        w.writerows(zip(loop["torque_time"], torque, power))
    if edges is not None:
        with open(out / "collision_spectra.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["energy_low_J_per_kg", "energy_high_J_per_kg"]
                       + [f"{kind}_{what}" for kind in PAIR_TYPES
                          for what in ("per_s", "at_or_above_per_s")])
            for k in range(len(edges) - 1):
                w.writerow([edges[k], edges[k + 1]] + [float(v) for kind in PAIR_TYPES
                                                       for v in (spectra[kind][0][k],
                                                                 spectra[kind][1][k])])


def _write_grinding_spectra(out):
    """spectra.csv for `python3 -m yadebreak grind` (docs/grinding.md, Section 2), from this
    run's summary.json and collision_spectra.csv."""
    from yadebreak.criteria import load_material
    from yadebreak.model.spectra import SPECTRA_NAME, from_mill_run, write_spectra
    write_spectra(out / SPECTRA_NAME, from_mill_run(out, load_material))


def _plots(out, summary, loop, info, power, edges, spectra):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Polygon
    times, sieves = np.array(loop["times"]), np.array(loop["sieves"])
    ore = summary["initial_mass"]
    fig, axes = plt.subplots(1, 4, figsize=(20, 4.5))
    picks = sorted(set(np.linspace(0, len(times) - 1, min(5, len(times))).astype(int)))
    for k in picks:
        axes[0].semilogx(1e3 * sieves, 100 * np.array(loop["passing"][k]) / ore, "o-", ms=3,
                         label=f"t = {times[k]:.2f} s")
    axes[0].set(xlabel="size (mm)", ylabel="ore passing (%)", title="size distribution")
    axes[0].legend(fontsize=8)
    feed = np.array(loop["feed_mass"])
    if len(feed) and feed[0] > 0:
        axes[1].plot(times, feed / feed[0], "o", ms=3, label="simulation")
        rate = summary["feed_breakage_rate"]
        if math.isfinite(rate):
            axes[1].plot(times, np.exp(-rate * (times - times[0])), "k-",
                         label=f"first order, S = {rate:.3g} 1/s")
    axes[1].set(xlabel="time (s)", ylabel="feed class mass remaining (-)",
                title="breakage rate of the feed size")
    axes[1].legend(fontsize=8)
    axes[2].plot(loop["torque_time"], power, lw=0.5, c="0.6", label="from the drum's torque")
    axes[2].axhline(summary["mean_power_W"], c="C0", label=f"mean {summary['mean_power_W']:.1f} W")
    axes[2].axhline(summary["torque_arm_power_W"], c="C2", ls="--",
                    label=f"torque arm M g x w: {summary['torque_arm_power_W']:.1f} W")
    axes[2].axhline(summary["bond_power_W"], c="C3", ls=":",
                    label=f"Bond's equation: {summary['bond_power_W']:.1f} W")
    axes[2].set(xlabel="time (s)", ylabel="power (W)", title="mill power")
    axes[2].legend(fontsize=8)
    for kind, (_, above) in (spectra or {}).items():
        if above[0] > 0:
            axes[3].loglog(edges[:-1], above, drawstyle="steps-post", label=kind)
    axes[3].set(xlabel="specific energy Ek'/m (J/kg)", ylabel="stressing events per second >= it",
                title="collision energy spectra")
    if any(above[0] > 0 for _, above in (spectra or {}).values()):
        axes[3].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "mill.png", dpi=110)
    plt.close(fig)
    # the charge seen along the axis
    fig, ax = plt.subplots(figsize=(6, 6))
    angle = mill_time(info) * info["omega"]   # the drum's profile has turned with it
    c, s = math.cos(angle), math.sin(angle)
    profile = [(c * y - s * z, s * y + c * z) for y, z in info["profile"]]
    ax.add_patch(Polygon(1e3 * np.array(profile), closed=True, fill=False, ec="k"))
    balls = set(info["balls"])
    spheres = view.spheres()
    for i, pos, radius in zip(spheres.ids.tolist(), spheres.pos, spheres.radius.tolist()):
        colour = "0.55" if i in balls else "tab:orange"
        ax.add_patch(Circle((1e3 * pos[1], 1e3 * pos[2]), 1e3 * radius, fc=colour, ec="k",
                            lw=0.2, alpha=0.8))
    reach = 550 * summary["drum_diameter"]
    ax.set(xlim=(-reach, reach), ylim=(-reach, reach), aspect="equal", xlabel="y (mm)",
           ylabel="z (mm)", title=f"charge at t = {mill_time(info):.2f} s (grey balls, orange ore)")
    fig.tight_layout()
    fig.savefig(out / "charge.png", dpi=110)
    plt.close(fig)
