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

from yadebreak import engine, scenes
from yadebreak.model import milling
from yadebreak.jobs import paraview
from yadebreak.adapter.yade_api import O, utils, wrapper as _w
from yadebreak.engine.stepping import smallest_rayleigh_time
from yadebreak.jobs import skeleton
from yadebreak.jobs import options as job_options
from yadebreak.jobs.options import check_mill_geometry
from yadebreak.jobs.lifecycle import ScriptError, resume_arguments, write_atomic

PACKING = 0.6                    # solid fraction of a settled charge (bulk volume -> solid volume)
SETTLE_TIME = 0.25               # s of settling under gravity, drum still, before the engine


# -- geometry ---------------------------------------------------------------------------------------
def drum_profile(radius, lifters, lifter_height, lifter_width, segments=48):
    """The drum's cross-section (y, z points, m): a circle of `segments` chords with `lifters`
    rectangular bars (height and width in m) standing inward, evenly spaced, closed."""
    half = 0.5 * lifter_width / radius              # half the angle a lifter's foot spans
    points = []
    for k in range(segments):
        theta0, theta1 = 2 * math.pi * k / segments, 2 * math.pi * (k + 1) / segments
        points.append((radius * math.cos(theta0), radius * math.sin(theta0)))
        for j in range(lifters):
            at = 2 * math.pi * (j + 0.5) / lifters
            if theta0 <= at < theta1:
                inner = radius - lifter_height
                for angle, r in ((at - half, radius), (at - half, inner), (at + half, inner),
                                 (at + half, radius)):
                    points.append((r * math.cos(angle), r * math.sin(angle)))
    return points + [points[0]]


def drum_facets(profile, length, material):
    """Facets of the drum's shell: two per chord of the profile, between x = -length/2 and
    length/2. The end walls are planes (end_walls): a fan of thin facets from the axis gave NaN
    contacts with YADE 2023.02's facet geometry (measured: a ball at the end wall's centre)."""
    x0, x1 = -0.5 * length, 0.5 * length
    facets = []
    for (ya, za), (yb, zb) in zip(profile[:-1], profile[1:]):
        a0, b0, a1, b1 = (x0, ya, za), (x0, yb, zb), (x1, ya, za), (x1, yb, zb)
        facets += [utils.facet((a0, b0, b1), material=material),
                   utils.facet((a0, b1, a1), material=material)]
    return facets


def end_walls(length, material):
    """The drum's two end walls, planes x = -length/2 and x = length/2, still (their friction on
    the charge is the only difference from walls that turn with the shell)."""
    return [utils.wall(-0.5 * length, axis=0, sense=1, material=material),
            utils.wall(0.5 * length, axis=0, sense=-1, material=material)]


def charge_positions(radius, length, clearance, ball_size, balls, ore_size, ores, rng):
    """Centres (m) of `balls` balls and `ores` ore particles, as low in the drum as they go: the
    lowest points of a jittered lattice inside the drum (at least `clearance` from the shell), the
    balls first, then the ore among them without overlap. Raises ScriptError if they do not fit."""
    def lattice(size):
        step = 1.02 * size
        reach = radius - clearance - 0.5 * size
        xs = np.arange(-0.5 * length + 0.51 * size, 0.5 * length - 0.51 * size + 1e-12, step)
        ys = np.arange(-reach, reach + 1e-12, step)
        grid = np.array(np.meshgrid(xs, ys, ys, indexing="ij")).reshape(3, -1).T
        inside = np.hypot(grid[:, 1], grid[:, 2]) <= reach
        grid = grid[inside]
        return grid[np.lexsort((rng.random(len(grid)), grid[:, 2]))]     # lowest first
    ball_at = lattice(ball_size)[:balls]
    ore_at = lattice(ore_size)
    if len(ore_at) and len(ball_at):
        gap = np.min(np.linalg.norm(ore_at[:, None, :] - ball_at[None, :, :], axis=2), axis=1)
        ore_at = ore_at[gap > 0.51 * (ball_size + ore_size)]
    ore_at = ore_at[:ores]
    if len(ball_at) < balls or len(ore_at) < ores:
        raise ScriptError(f"the charge does not fit: {len(ball_at)} of {balls} balls and "
                          f"{len(ore_at)} of {ores} ore particles placed; lower --ball-filling or "
                          "--ore-filling, or use a larger drum")
    return ball_at, ore_at


def charge_counts(args):
    """(balls, ore particles) for the fillings: a filling is the bulk volume of the charge over the
    drum's volume; the bulk is PACKING solid."""
    volume = math.pi * (0.5 * args.drum_diameter) ** 2 * args.drum_length
    ball_volume = math.pi / 6 * args.ball_size ** 3
    ore_volume = math.pi / 6 * args.size ** 3
    return (max(1, round(args.ball_filling * volume * PACKING / ball_volume)),
            max(1, round(args.ore_filling * volume * PACKING / ore_volume)))


def check_geometry(args):
    """Cross-checks of the options that one range cannot say (ScriptError, one line each)."""
    problem = check_mill_geometry(args)
    if problem:
        raise ScriptError(problem)


# -- the scene ----------------------------------------------------------------------------------------
def mill_scene(args, options):
    """Build the mill, settle the charge with the drum still, attach yadebreak and start the drum.
    Returns (controller, info)."""
    O.reset()
    ip2, mats = engine.add_materials({"ore": args.material, "steel": "steel"},
                                       stiffness_scale=args.stiffness_scale)
    radius = 0.5 * args.drum_diameter
    profile = drum_profile(radius, args.lifters, args.lifter_height, args.lifter_width)
    drum = O.bodies.append(drum_facets(profile, args.drum_length, "steel"))
    ends = O.bodies.append(end_walls(args.drum_length, "steel"))
    n_balls, n_ore = charge_counts(args)
    rng = np.random.default_rng(args.seed)
    ball_at, ore_at = charge_positions(radius, args.drum_length, args.lifter_height,
                                       args.ball_size, n_balls, args.size, n_ore, rng)
    balls = [O.bodies.append(utils.sphere(tuple(c), 0.5 * args.ball_size, material="steel"))
             for c in ball_at]
    ore = [O.bodies.append(utils.sphere(tuple(c), 0.5 * args.size, material="ore"))
           for c in ore_at]
    speed = args.speed * milling.critical_speed(args.drum_diameter, args.ball_size)  # rev/s
    omega = 2 * math.pi * speed
    O.engines = scenes.hertz_engines(ip2, gravity=(0.0, 0.0, -9.81), facets=True) + [
        _w.RotationEngine(rotationAxis=(1, 0, 0), rotateAroundZero=True, zeroPoint=(0, 0, 0),
                          angularVelocity=0.0, ids=list(drum), label="drum")]
    # settle with the drum still, damped, before anything is tracked (the fill is not milling)
    O.dt = args.time_step_fraction * smallest_rayleigh_time()
    newton = O.engines[-2]
    newton.damping = 0.5
    O.run(int(SETTLE_TIME / O.dt), True)
    newton.damping = 0.0
    for i in balls + ore:
        O.bodies[i].state.vel = (0, 0, 0)
        O.bodies[i].state.angVel = (0, 0, 0)
    brk = engine.attach({"ore": args.material}, seed=args.seed, **options)
    next(e for e in O.engines if isinstance(e, _w.RotationEngine)).angularVelocity = omega
    info = {"drum": list(drum), "ends": list(ends), "balls": balls, "ore": ore, "omega": omega, "speed_rps": speed,
            "start_time": O.time,                 # the settling's end: the mill's t = 0
            "profile": profile, "ball_mass": sum(O.bodies[i].state.mass for i in balls)}
    return brk, info


def drum_torque(drum):
    """Torque (N m) of the charge on the drum about its axis (x): sum over the drum's facets of
    (position x force + torque), from the last step's forces."""
    total = 0.0
    for i in drum:
        f, t, p = O.forces.f(i), O.forces.t(i), O.bodies[i].state.pos
        total += p[1] * f[2] - p[2] * f[1] + t[0]
    return total


def mill_time(info):
    """Simulated time (s) since the drum started (the settling before it is not milling)."""
    return O.time - info["start_time"]


def charge_state(info):
    """(mass (kg), horizontal lever arm y of its centre of mass (m)) of every sphere in the drum:
    balls, ore and fragments (a pass over the bodies, once per sample)."""
    mass = moment = 0.0
    for b in O.bodies:
        if b is not None and b.dynamic:
            mass += b.state.mass
            moment += b.state.mass * b.state.pos[1]
    return mass, (moment / mass if mass else 0.0)


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
        self.brk, self.info = mill_scene(args, _options(args, self.out))
        self.loop = {"initial_mass": self.brk.total_mass(), "initial_dt": O.dt,
                     "sieves": sieves_for(args).tolist(), "times": [], "passing": [],
                     "feed_mass": [], "charge_mass": [], "lever_arm": [], "torque_time": [],
                     "torque": [], "next_sample": 0.0}
        self.say(f"{len(self.info['balls'])} balls ({1e3 * args.ball_size:g} mm) and "
                 f"{len(self.info['ore'])} particles of {args.material} ({1e3 * args.size:g} "
                 f"mm) in a {1e3 * args.drum_diameter:g} x {1e3 * args.drum_length:g} mm drum at "
                 f"{60 * self.info['speed_rps']:.1f} rpm ({100 * args.speed:g} % of critical); "
                 f"dt {O.dt:.3g} s")

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
                f"{sum(1 for b in O.bodies if b is not None)} bodies, dt {O.dt:.2g} s")

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
        "bodies_end": sum(1 for b in O.bodies if b is not None),
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
        "simulated_time": mill_time(info), "steps": O.iter, "initial_dt": loop["initial_dt"],
        "final_dt": O.dt, "runtime_s": runtime,
        "throughput_s_per_hour": 3600.0 * mill_time(info) / runtime if runtime > 0 else None,
        "end_reason": end_reason, "end_message": end_message}
    write_atomic(out / "summary.json", json.dumps(summary, indent=2))
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
        if not summary["breakage"]:            # the spectra run: the grinding model's input
            _write_grinding_spectra(out)
    _plots(out, summary, loop, info, power, edges, spectra)
    return summary


def _write_grinding_spectra(out):
    """spectra.csv for `python3 -m yadebreak grind` (docs/grinding.md, Section 2), from this
    run's summary.json and collision_spectra.csv."""
    from yadebreak.studies.grinding.cli import SPECTRA_NAME
    from yadebreak.studies.grinding.spectra import from_mill_run, write_spectra
    write_spectra(out / SPECTRA_NAME, from_mill_run(out))


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
    for b in O.bodies:
        if b is not None and isinstance(b.shape, _w.Sphere):
            colour = "0.55" if b.id in balls else "tab:orange"
            ax.add_patch(Circle((1e3 * b.state.pos[1], 1e3 * b.state.pos[2]),
                                1e3 * b.shape.radius, fc=colour, ec="k", lw=0.2, alpha=0.8))
    reach = 550 * summary["drum_diameter"]
    ax.set(xlim=(-reach, reach), ylim=(-reach, reach), aspect="equal", xlabel="y (mm)",
           ylabel="z (mm)", title=f"charge at t = {mill_time(info):.2f} s (grey balls, orange ore)")
    fig.tight_layout()
    fig.savefig(out / "charge.png", dpi=110)
    plt.close(fig)
