"""The paper's single-particle settings (its Section 3), one set of impacts (`Run`) and the runner
that runs each set once however many figures share it."""
from __future__ import annotations

import dataclasses
import json
import math
import time

import numpy as np

from yadebreak.criteria import load_material
from yadebreak.analysis import reports
from yadebreak.jobs import wall_time
from yadebreak.jobs.lifecycle import progress, status
from yadebreak.options.engine_flags import OPTION, Override

#: the paper's single-particle verification (its Section 3)
EMAX_RATIO = 4.0
PROBABILITY_SIZE = 5.5e-3
FRAGMENT_SIZE = 29e-3
RT_PROBABILITY, RT_FRAGMENTATION, RT_DAMPING = 0.05, 0.02, 0.01
PAPER_MATERIALS = ("copper_ore", "granulite", "limestone")
#: the model probabilities at which Figs. 8-10 are sampled
PROBABILITY_LEVELS = (0.1, 0.3, 0.5, 0.7, 0.9)
QUICK_LEVELS = (0.2, 0.5, 0.8)
#: the paper's settings that differ from attach()'s defaults (cs, emin and dmin: the table's
#: defaults are the paper's)
PAPER = {
    "emax_ratio": Override(EMAX_RATIO, "the paper's single-particle runs take Emax/E50 = 4"),
    "kappa": Override(1.0, "the paper's single-particle runs take kappa = 1 (Eq. 8)"),
    "read_period": Override("every_step", "Figs. 8-11 read every contact every step (exact); "
                                          "--read-period sets Figs. 13-19's")}
#: attach()'s defaults that are the paper's settings
PAPER_DEFAULTS = ("cs", "emin", "dmin")

@dataclasses.dataclass
class Run:
    """One set of impacts: `particles` particles of `material` (name) and `size` (m) at each
    energy and each of `seeds`, with attach() options; `test` "single" (fired at the target) or
    "drop_weight" (a steel striker 50 times the particle's mass falls on it on a steel anvil:
    the paper's DWT); `per_scene` particles (strikers) side by side in each scene, scene k of
    seed s seeded scenes.scene_seed(s, k). The seeds' scenes are pooled into one result."""

    material: str
    size: float
    energies: list
    particles: int
    seeds: tuple
    options: dict
    per_scene: int = 1
    target: str = "steel"
    test: str = "single"

    def key(self, energy, seed=None):
        """The result's key at `energy`: of one seed's scenes, or (seed None) of all pooled."""
        return json.dumps([self.material, self.size, energy, self.particles,
                           list(self.seeds) if seed is None else seed, self.target, self.test,
                           sorted(self.options.items())])


def paper_material(name):
    """The material as the paper's single-particle verification ran it (Emax/E50 = 4)."""
    return load_material(name).with_params(emax_ratio=EMAX_RATIO)


def probability_energies(material, size, levels, partner):
    """Specific energies (J/kg, rounded to 2 digits) at which the model's probability is each of
    `levels`."""
    grid = np.geomspace(1.0, 1e5, 4000)
    p = material.breakage_probability(grid, size, partner=partner)
    return [float(f"{np.interp(level, p, grid):.2g}") for level in levels]


def paper_options(time_step, **more):
    """attach() options of the paper's settings at `time_step` (fraction of the Rayleigh time),
    contacts read at every step unless `more` says otherwise."""
    return {"time_step_fraction": time_step, **{k: o.value for k, o in PAPER.items()},
            **{k: OPTION[k].default for k in PAPER_DEFAULTS}, **more}


@dataclasses.dataclass(frozen=True)
class Task:
    """Scenes that are calls, not impacts: scene k is function(spec, k) for spec["task"] =
    "module:function" and len(spec["counts"]) scenes, on a worker or here. `cost` orders
    the queue with the impacts' (run_cost)."""

    key: str
    spec: dict
    cost: float

    def call(self, k):
        from yadebreak.scenes.queue import call_task
        return call_task(self.spec, k)


class Runner:
    """Runs impacts once per key (figures share runs) and keeps every result. On a `scheduler`
    with workers (process.scheduler.Scheduler; local:1 runs here) the scenes go to one
    scenes.SceneQueue kept for the whole command, the costliest first: queue() takes every
    figure's runs at the start (plan() finds them), run_all those of one figure, so that no
    worker idles while another ends a run. close() lets the workers go."""

    def __init__(self, scheduler, retries=1):
        self.scheduler, self.retries = scheduler, retries
        self.results = {}
        self.returned = {}                     # Task key -> what its scenes returned
        self._queue = None
        self._queued = {}                      # run key -> its scenes in the queue
        self.order = []                        # every run key (of one seed) in queue order
        self.walls = {}                        # run key -> its scenes' wall times (s)

    def run(self, run):
        return self.run_all([run])[0]

    def run_all(self, runs):
        """The results of each run (a list per run, one result per energy: its seeds' scenes
        pooled), run together."""
        self.queue(runs)
        for run in runs:
            for energy in run.energies:
                if run.key(energy) not in self.results:
                    self._keep(run, energy, self._pooled(run, energy))
        return [[self.results[run.key(energy)] for energy in run.energies] for run in runs]

    def _pooled(self, run, energy):
        """The tally of the run's scenes at `energy` over its seeds (on the workers, or here)."""
        tally = None
        for seed in run.seeds:
            key = run.key(energy, seed)
            if key in self._queued:
                one = self._queue.collect(self._queued.pop(key), on_wait=_waiting(run, energy))
            else:
                one = _tally_here(run, energy, seed)
            self.walls[key] = list(one.scene_walls)
            if tally is None:
                tally = one
            else:
                tally.merge(one)
        return tally

    def run_tasks(self, tasks):
        """What each Task's scenes returned (a list per task, in scene order; kept apart from
        `results`, which the figure fills with what it makes of them)."""
        self.queue(tasks)
        for task in tasks:
            if task.key in self.returned:
                continue
            if task.key in self._queued:
                self.returned[task.key] = self._queue.collect(self._queued.pop(task.key),
                                                              on_wait=_waiting(task, None))
            else:
                self.returned[task.key] = [task.call(k) for k in range(len(task.spec["counts"]))]
            self.walls[task.key] = [r["wall_s"] for r in self.returned[task.key]]
        return [self.returned[task.key] for task in tasks]

    def queue(self, runs):
        """Send the scenes of `runs` (Runs and Tasks) to the workers now (if any), the costliest
        first; their keys join `order` (what the wall time is predicted from)."""
        impacts = [r for r in runs if not isinstance(r, Task)]
        todo = [(key, run_cost(run, energy), (run, energy, seed))
                for key, (run, energy, seed) in _each(impacts).items()]
        todo += [(t.key, t.cost, t) for t in runs if isinstance(t, Task)]
        for key, _, what in sorted(todo, key=lambda item: -item[1]):
            if key in self.order:
                continue
            self.order.append(key)
            if not self.scheduler.in_process:
                spec = what.spec if isinstance(what, Task) else _spec(*what)
                self._queued[key] = self._queue_of().submit(spec)

    def wall_time(self, source, walls=None):
        """The WallTime of the runs queued so far (jobs/wall_time.py: one stage, every run's
        scenes a set, in queue order) from `walls` ({run key: scene wall times}; default this
        command's own), None where a run's are missing."""
        walls = self.walls if walls is None else walls
        if not self.order or any(key not in walls for key in self.order):
            return None
        count = self.scheduler.count
        return wall_time.predict([[list(walls[key]) for key in self.order]], source,
                                 (*wall_time.WORKERS, 4, 16, *([count] if count else [])))

    def close(self):
        if self._queue is not None:
            self._queue.close()
            self._queue = None

    def _queue_of(self):
        if self._queue is None:
            from yadebreak.jobs.impacts import started_queue
            self._queue = started_queue(self.scheduler, self.retries)
        return self._queue

    def _keep(self, run, energy, tally):
        mat, steel = paper_material(run.material), load_material(run.target)
        result = reports.breakage_result_of(tally, mat, energy, steel)
        if run.options.get("replace") is False:      # no progeny: no t10 to show
            for name in ("t10_simulated", "t10_primary_events", "progeny_markers",
                         "relative_sizes", "progeny_passing_simulated",
                         "progeny_passing_model"):
                result.pop(name, None)
            result["t10_note"] = "broken particles not replaced (probability only)"
        else:
            result["progeny_passing_resolved"] = reports.resolved_progeny_passing(tally)
        # wall_s: the scenes' own (worker seconds), whichever process ran them and whatever ran
        # beside them
        result.update(steps=tally.steps, scenes_at_step_limit=tally.scenes_at_step_limit,
                      wall_s=tally.scene_wall_s, yade_engines_s=tally.yade_engines_s,
                      material=mat.name, size=run.size,
                      options=run.options, seeds=list(run.seeds), test=run.test)
        self.results[run.key(energy)] = result
        progress(f"{mat.name} {1e3 * run.size:g} mm {run.test} "
                 f"{_settings_short(run.options)}: "
                 f"{reports.result_line(result)} ({result['wall_s']:.0f} s)")


class Planner:
    """Stands for the Runner in a figure's first lines to learn which runs it asks for (plan):
    run_all and run_tasks stop the figure there."""

    class Asked(Exception):
        pass

    def __init__(self):
        self.runs = []

    def run(self, run):
        return self.run_all([run])

    def run_all(self, runs):
        self.runs += runs
        raise Planner.Asked

    def run_tasks(self, tasks):
        self.runs += tasks
        raise Planner.Asked



def plan(figures, args, out):
    """The runs the `figures` (functions of (args, runner, out)) will ask for first."""
    from yadebreak.studies.verify.report import plt_module
    planner = Planner()
    for make in figures:
        try:
            make(args, planner, out)
        except Planner.Asked:
            pass
    plt_module().close("all")                  # a figure stopped after its plot was begun
    return planner.runs


def _each(runs):
    """{key: (run, energy, seed)} of every energy and seed of `runs`, once each."""
    return {run.key(energy, seed): (run, energy, seed) for run in runs
            for energy in run.energies for seed in run.seeds}


def run_cost(run, energy):
    """A guess of a run's cost, to start the longest first: breakage cascades grow with the
    energy, the steps with 1 / time step, the shear share adds breakage. Probability runs
    (nothing replaced) take seconds: they go first, so that their figures come in minutes."""
    if run.options.get("replace") is False:
        return math.inf
    return (energy * run.particles * (1.0 + run.options.get("cs", 0.0))
            / run.options["time_step_fraction"]
            * (DROP_WEIGHT_COST if run.test == "drop_weight" else 1.0))


#: a drop-weight scene costs about this many single impacts at the same energy and time step
#: (the striker loads the particle for milliseconds): measured in the whole command, 29 mm copper
#: ore at 2 % RT and 150-3000 J/kg, one particle per scene: 345 s against 88 s
DROP_WEIGHT_COST = 4.0


def _waiting(run, energy):
    """A progress line while a run's (or a Task's, energy None) scenes wait on the workers
    behind costlier ones."""
    began = time.time()
    what = (json.loads(run.key)[0].replace("_", " ") if energy is None else
            f"{run.material} {1e3 * run.size:g} mm {energy:g} J/kg")

    def line(done, submitted):
        status(f"waiting for {what}: {done} of {submitted} scenes of the command done "
               f"({time.time() - began:.0f} s)")
    return line


#: simulated time after which a drop-weight scene stops even if a striker still falls (s)
DROP_WEIGHT_MAX_TIME = 0.05


def _spec(run, energy, seed):
    """The run's scenes at `energy` of `seed` as a spec of scenes.run_scenes (a worker's or
    this process's)."""
    from yadebreak import scenes
    if run.test == "drop_weight":
        return scenes.drop_weight_spec(run.material, run.size, energy, run.particles,
                                       run.per_scene, seed, DROP_WEIGHT_MAX_TIME,
                                       **run.options)
    return scenes.impact_spec(run.material, run.size, float(np.sqrt(2.0 * energy)), run.particles,
                              run.per_scene, seed, target=run.target,
                              wait_for_arrivals=True, **run.options)


def _tally_here(run, energy, seed):
    """A run's scenes of one seed in this process (local:1): the same tally as the workers'."""
    from yadebreak import scenes
    spec = _spec(run, energy, seed)
    tally, _ = scenes.run_scenes(spec, range(len(spec["counts"])))
    return tally


def _settings_short(options):
    gd = options.get("global_damping")
    return (f"dt {100 * options['time_step_fraction']:g} % RT, global damping "
            f"{'file' if gd is None else f'{gd:g}'}")


def _kappa_text(kappa):
    if kappa == "batch":
        return "beyond the paper's kappa 1: kappa of Eq. 7's batch at each breakage, "
    return "kappa of each material file, " if kappa is None else f"kappa {kappa:g}, "


def settings_text(options, material_names, size, particles, seeds, extra="", damping=None,
                  target="steel"):
    """One line of a figure's settings; `seeds` one seed or a tuple of them (pooled);
    `damping` (text) replaces the files' global damping; `size` in m or a text (several
    sizes), `target` the text after "on"; `particles` per seed, a number or a text."""
    gd = options.get("global_damping")
    if damping is None:
        damping = ("each material file's (" + ", ".join(
            f"{n} {load_material(n).global_damping:g}" for n in material_names) + ")"
                   if gd is None else f"{gd:g}")
    size = size if isinstance(size, str) else f"{1e3 * size:g} mm"
    seeds = (seeds,) if isinstance(seeds, int) else tuple(seeds)
    seeds = (f"seed {seeds[0]}" if len(seeds) == 1 else
             "seeds " + ", ".join(map(str, seeds)) + " pooled")
    outcome = options.get("outcome", OPTION["outcome"].default)
    return (f"{size} on {target}, {particles} particles per point and seed, {seeds}; "
            f"Emax/E50 {EMAX_RATIO:g}, time step {100 * options['time_step_fraction']:g} % of "
            f"the Rayleigh time, dmin = {OPTION['dmin'].none}, emin {options['emin']:g} J, "
            + _kappa_text(options["kappa"])
            + f"cs {options['cs']:g}, global damping {damping}, "
            f"contacts read "
            f"{'every step' if options['read_period'] == 'every_step' else 'in fast mode'}"
            + ("" if options.get("replace", True) else ", broken particles not replaced")
            + (f"; beyond the paper: kappa {options['kappa_successive']:g} for fragments"
               if options.get("kappa_successive") else "")
            + ("; outcome 'model': breakage at the stressing event's peak (t10' of its "
               "whole energy), the dummies' fines spread by Eq. 10" if outcome == "model" else
               "; beyond the paper: breakage at the stressing event's peak (t10' of its "
               "largest energy)" if options.get("break_at") == "peak" else "")
            + ("; beyond the paper: t10' over E50b of the energy absorbed at the break "
               "(Rocky's e50b option)" if options.get("t10_energy") == "e50b" else "")
            + ("; the elastic energy of a broken particle's contacts carried to the fragments "
               "that take them over" if options.get("contact_energy_at_break") == "carried"
               else "")
            + (f"; beyond the paper: dummy spheres {options['dummy_stiffness']:g} times as stiff"
               if options.get("dummy_stiffness", OPTION["dummy_stiffness"].default)
               != OPTION["dummy_stiffness"].default else "")
            + (f"; {extra}" if extra else ""))
