"""Results of impact tests, shared by the scripts: first events, breakage against the model,
progeny size distribution and t10 against Eqs. 8 and 10, and the two-panel plot. No yade import:
`brk` is any object with `events` and `size_distribution` (the coupling's controller)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from yadebreak import model


def product_size_distribution(table, ledger, materials, sizes, fines, fines_model):
    """The product size distribution (model.SizeDistribution, docs/model.md Section 7) of the
    bodies of a body table (coupling.state.BodyTable) and a fines ledger.

    fines=True spreads dummy and unbreakable masses (Eqs. 11-13); fines=False counts every sphere
    at its own size, as in the paper's Fig. 13. fines_model: how the dummies' fines are spread,
    "gaudin_schuhmann" (the paper's Eqs. 11-12) or "eq10" (model.dummy_fines_passing; the
    option `outcome` chooses). materials: label -> Material.
    """
    resolved_d, resolved_m = [], []
    groups = {}

    def group(label):
        return groups.setdefault(label, {"dummy": ([], [], []), "unb": ([], [], [])})

    for row in table.values():
        kind = row.kind
        if kind == "broken":
            continue
        g = group(row.material)          # every material present gets its (maybe empty) group
        if fines and kind == "dummy":
            for lst, v in zip(g["dummy"], (row.mass, row.parent_size, row.t10)):
                lst.append(v)
        elif fines and kind == "unbreakable":
            for lst, v in zip(g["unb"], (2 * row.radius, row.mass, row.t10)):
                lst.append(v)
        else:
            resolved_d.append(2 * row.radius)
            resolved_m.append(row.mass)
    for entry in ledger:
        if fines:
            for lst, v in zip(group(entry["material"])["dummy"],
                              (entry["mass"], entry["parent_size"], entry["t10"])):
                lst.append(v)
        else:                            # the ledger's fines counted at the dummy size
            resolved_d.append(model.X_MIN * entry["parent_size"])
            resolved_m.append(entry["mass"])
    sizes = np.atleast_1d(np.asarray(sizes, dtype=float))
    sd = model.size_distribution(sizes, resolved=(resolved_d, resolved_m))
    passing = np.zeros(sizes.shape) + sd.passing_mass
    total = 0.0 + sd.total_mass
    for label, g in groups.items():
        sd = model.size_distribution(sizes, dummies=g["dummy"], unbreakable=g["unb"],
                                     beta_params=materials[label].beta_params, fines=fines_model)
        passing += sd.passing_mass
        total += sd.total_mass
    return model.SizeDistribution(sizes, passing, total)


def first_events(events, ids):
    """Each listed particle's first event (the impact itself), or none."""
    first = {}
    for e in events:
        first.setdefault(e["id"], e)
    return {i: first[i] for i in ids if i in first}


#: progeny sizes reported beside t10, as fractions 1/n of the original size (Eq. 10's t_n)
MARKERS = (2.0, 4.0, 10.0, 25.0)


#: sieves of the progeny curves, as fractions of the particle size
RELATIVE_SIEVES = np.geomspace(1e-3, 0.99, 40)


@dataclass
class ImpactTally:
    """What impacts of particles of one size leave for their result, added up over independent
    scenes (plain numbers: a run's scenes are built, tallied and dropped one by one).

    first: each fired particle's first event (the impact itself; none for a particle with no
    event); e_cum_intact: Ab-T10's e_cum (J/kg) of the particles that did not break;
    progeny_mass and marker_mass: mass (kg) passing size x RELATIVE_SIEVES and size / MARKERS
    (every fragment, fines included); resolved_mass: passing size x RELATIVE_SIEVES counting the
    spheres in the scene as they are (no fines: the paper's Fig. 13); masses (kg) of the scenes at
    their start and end; scene_t10: [broken mass, mass passing size / 10] (kg) of each scene that
    broke (scenes are independently seeded: their scatter is t10's standard error);
    scene_passing: each such scene's progeny mass passing size x RELATIVE_SIEVES (kg), for the
    passing's standard errors;
    scene_wall_s: the wall time (s) of the scenes added up, wherever each ran; scene_walls: each
    scene's (s), in scene order (jobs/wall_time predicts from them); yade_engines_s: of
    it, the time YADE's own engines took (timed by YADE; the rest is yadebreak's runners and the
    scenes' building and checks); polyhedra_pair_checks: YADE's silenced do_intersect warnings
    (polyhedra on the volumetric law; 0 otherwise)."""
    size: float
    particles: int = 0
    first: list = field(default_factory=list)
    e_cum_intact: list = field(default_factory=list)
    progeny_mass: np.ndarray = None
    marker_mass: np.ndarray = None
    resolved_mass: np.ndarray = None
    breakage_events: int = 0
    initial_mass: float = 0.0
    final_mass: float = 0.0
    scenes: int = 0
    steps: int = 0
    scenes_at_step_limit: int = 0
    scene_t10: list = field(default_factory=list)
    scene_passing: list = field(default_factory=list)
    scene_wall_s: float = 0.0
    scene_walls: list = field(default_factory=list)
    yade_engines_s: float = 0.0
    polyhedra_pair_checks: int = 0

    def __post_init__(self):
        if self.progeny_mass is None:
            self.progeny_mass = np.zeros(len(RELATIVE_SIEVES))
            self.marker_mass = np.zeros(len(MARKERS))
        if self.resolved_mass is None:
            self.resolved_mass = np.zeros(len(RELATIVE_SIEVES))

    def add(self, brk, ids, initial_mass):
        """Add the scene of controller `brk`, whose fired particles are `ids` and whose mass was
        `initial_mass` (kg) at the start."""
        first = first_events(brk.events, ids)
        broken = {i for i, e in first.items() if e["kind"] == "breakage"}
        self.particles += len(ids)
        self.first += list(first.values())
        if "e_cum" in brk.bodies.columns:            # a column of Ab-T10's (intact_measures)
            self.e_cum_intact += [brk.bodies[i].e_cum for i in ids
                                  if i not in broken and i in brk.bodies]
        if broken:
            passing = brk.size_distribution(self.size * RELATIVE_SIEVES).passing_mass
            self.progeny_mass += passing
            self.scene_passing.append(passing.tolist())
            markers = brk.size_distribution(self.size / np.array(MARKERS)).passing_mass
            self.marker_mass += markers
            self.scene_t10.append([sum(first[i]["mass"] for i in broken),
                                   float(markers[MARKERS.index(10.0)])])
            self.resolved_mass += brk.size_distribution(self.size * RELATIVE_SIEVES,
                                                        fines=False).passing_mass
        self.breakage_events += len(brk.breakage_events)
        self.initial_mass += initial_mass
        self.final_mass += brk.total_mass()
        self.polyhedra_pair_checks += brk.polyhedra_pair_checks or 0
        self.scenes += 1

    def merge(self, other):
        """Add another tally of particles of the same size (another process's scenes)."""
        for name in ("particles", "breakage_events", "initial_mass", "final_mass", "scenes",
                     "steps", "scenes_at_step_limit", "scene_wall_s", "yade_engines_s",
                     "polyhedra_pair_checks"):
            setattr(self, name, getattr(self, name) + getattr(other, name))
        self.first += other.first
        self.e_cum_intact += other.e_cum_intact
        self.scene_t10 += other.scene_t10
        self.scene_passing += other.scene_passing
        self.scene_walls += other.scene_walls
        self.progeny_mass = self.progeny_mass + other.progeny_mass
        self.marker_mass = self.marker_mass + other.marker_mass
        self.resolved_mass = self.resolved_mass + other.resolved_mass

    def to_dict(self):
        """Plain JSON types (a worker process hands its tally over in a file)."""
        out = {k: getattr(self, k) for k in self.__dataclass_fields__}
        out.update(progeny_mass=self.progeny_mass.tolist(), marker_mass=self.marker_mass.tolist(),
                   resolved_mass=self.resolved_mass.tolist(),
                   e_cum_intact=[float(e) for e in self.e_cum_intact])
        return out

    @classmethod
    def from_dict(cls, data):
        return cls(**{**data, "progeny_mass": np.array(data["progeny_mass"]),
                      "marker_mass": np.array(data["marker_mass"]),
                      "resolved_mass": np.array(data["resolved_mass"])})

    @property
    def broken(self):
        """The first events that were breakages."""
        return [e for e in self.first if e["kind"] == "breakage"]

    @property
    def broken_mass(self):
        """Mass (kg) of the fired particles that broke: what the progeny curves are shares of."""
        return sum(e["mass"] for e in self.broken)

    @property
    def mass_relative_error(self):
        return abs(self.final_mass - self.initial_mass) / self.initial_mass

    @property
    def t10_standard_error(self):
        """Standard error (%) of t10 (the ratio of the scenes' passing at size / 10 to their broken
        mass) from the scatter between scenes (ratio_standard_error); None with fewer than two
        scenes that broke."""
        if len(self.scene_t10) < 2:
            return None
        m, p = np.array(self.scene_t10, dtype=float).T
        return float(ratio_standard_error(m, p[:, None])[0])

    @property
    def passing_standard_error(self):
        """Standard errors (%) of the progeny's passing at size x RELATIVE_SIEVES, as t10's; None
        with fewer than two scenes that broke (or scenes tallied before they were kept)."""
        if len(self.scene_passing) < 2 or len(self.scene_passing) != len(self.scene_t10):
            return None
        m = np.array(self.scene_t10, dtype=float)[:, 0]
        return ratio_standard_error(m, np.array(self.scene_passing, dtype=float)).tolist()


def ratio_standard_error(masses, passing):
    """Standard error (%) of the ratio sum p_i / sum m_i of independent scenes i (masses (n,),
    passing (n, k): k ratios at once): 100 sqrt(n / (n - 1) sum (p_i - t m_i)^2) / sum m_i, t the
    ratio (the delta method for a ratio estimator)."""
    n, total = len(masses), masses.sum()
    t = passing.sum(axis=0) / total
    return 100.0 * np.sqrt(n / (n - 1) * np.sum((passing - t * masses[:, None]) ** 2,
                                                axis=0)) / total


def breakage_result(brk, ids, material, size, specific_energy, partner):
    """breakage_result_of(the tally of one scene: controller `brk`, fired particles `ids`)."""
    tally = ImpactTally(size)
    tally.add(brk, ids, brk.total_mass())
    return breakage_result_of(tally, material, specific_energy, partner)


def breakage_result_of(tally, material, specific_energy, partner):
    """Broken fraction of the fired particles beside the model's probability P(e Ek/mp), and the
    progeny of the broken ones (fines included, every generation of fragments) beside the model
    at that energy: t10 against Eq. 7 (material.t10_model: the absorbed energy e Ek/mp over the
    median fracture energy of the particles that break at it; Ab-T10: Eq. 9.4), the passing at
    1/2, 1/4 and 1/25 of the original size against Eq. 10 at that t10, and the whole curve.
    Also the mean t10' of the primary breakage events (Eq. 8 or 9.4), for the record.
    `tally`: an ImpactTally."""
    size, n = tally.size, tally.particles
    broken = tally.broken
    p_model = float(material.breakage_probability(specific_energy, size, partner=partner))
    t10_model = float(material.t10_model(specific_energy, size, partner))
    result = {"specific_energy": specific_energy, "particles": n,
              "broken_fraction": len(broken) / n, "model_probability": p_model,
              "binomial_sigma": float(np.sqrt(p_model * (1 - p_model) / n)),
              "t10_model": t10_model if np.isfinite(t10_model) else None}
    # Ab-T10: the e_cum the intact particles carry, what the broken ones would have reached
    result.update(material.criterion.intact_measures(tally.e_cum_intact, size))
    if not broken:
        result["t10_note"] = "no particle broke: no progeny to measure"
        return result
    parent_mass = tally.broken_mass
    passing = 100 * tally.progeny_mass / parent_mass
    markers = 100 * tally.marker_mass / parent_mass
    result.update({
        "t10_simulated": float(markers[MARKERS.index(10.0)]),
        "t10_standard_error": tally.t10_standard_error,
        "progeny_passing_standard_error": tally.passing_standard_error,
        "t10_primary_events": float(np.mean([e["t10"] for e in broken])),
        "breakage_events_all_generations": tally.breakage_events,
        "progeny_markers": {f"t{n:g}": {"simulated": float(sim), "model": _t_n(material, t10_model, n)}
                            for n, sim in zip(MARKERS, markers)},
        "relative_sizes": RELATIVE_SIEVES.tolist(),
        "progeny_passing_simulated": passing.tolist(),
        "progeny_passing_model": (model.progeny_passing(t10_model, material.beta_params,
                                                        RELATIVE_SIEVES).tolist()
                                  if np.isfinite(t10_model) else None)})
    return result


def resolved_progeny_passing(tally):
    """Passing (%) of the broken particles' progeny at tally.size x RELATIVE_SIEVES counting the
    spheres as they stand in the scene (no fines: the paper's Fig. 13); None if none broke."""
    parent_mass = tally.broken_mass
    return (100 * tally.resolved_mass / parent_mass).tolist() if parent_mass else None


def check_breakage_result(result, material, size, specific_energy, partner, particles):
    """Raise ValueError (saying what) unless `result` is one breakage_result_of could have given
    for `particles` particles of `material` of `size` (m) at `specific_energy` (J/kg) on
    `partner`: a result read back from a file (--resume 1) damaged, edited or of another run."""
    def number(name, lo=-np.inf, hi=np.inf):
        value = result.get(name)
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not lo <= value <= hi:
            raise ValueError(f"{name} = {value!r}: must be a number in [{lo:g}, {hi:g}]")
        return value
    if number("specific_energy") != specific_energy:
        raise ValueError(f"specific_energy = {result['specific_energy']!r}, not "
                         f"{specific_energy!r}")
    if result.get("particles") != particles:
        raise ValueError(f"particles = {result.get('particles')!r}, not {particles}")
    broken = number("broken_fraction", 0.0, 1.0) * particles
    if abs(broken - round(broken)) > 1e-9 * particles:
        raise ValueError(f"broken_fraction = {result['broken_fraction']!r} is not a count of "
                         f"{particles} particles")
    p_model = float(material.breakage_probability(specific_energy, size, partner=partner))
    if not np.isclose(number("model_probability", 0.0, 1.0), p_model, rtol=1e-9, atol=0.0):
        raise ValueError(f"model_probability = {result['model_probability']!r}, the model gives "
                         f"{p_model!r}")
    if round(broken) and result.get("t10_simulated") is not None:
        number("t10_simulated", 0.0, 100.0)


def result_line(result):
    """One progress line for an energy: broken fraction and t10 against the model."""
    line = (f"{result['specific_energy']:g} J/kg: {100 * result['broken_fraction']:.1f} % broken "
            f"(model {100 * result['model_probability']:.1f} %)")
    if result.get("t10_simulated") is None:
        return line + f", no t10 ({result.get('t10_note', 'no model value')})"
    model_t10 = result["t10_model"]
    return line + (f", t10 {result['t10_simulated']:.2f} % (model "
                   f"{'-' if model_t10 is None else f'{model_t10:.2f}'} %)")


def _t_n(material, t10, n):
    """Eq. 10's t_n (%) at t10 (%), with t10 itself for n = 10."""
    if not np.isfinite(t10):
        return None
    if n == 10.0:
        return float(t10)
    return float(model.t_n(t10, *material.beta_params[n]))


def plot_breakage(results, material, size, partner, title, path, label="simulation"):
    """Three panels to a PNG: broken fraction against specific energy (model line, simulation
    with 3 sigma); t10 against specific energy (the model's Eq. 7 or 9.4 from 50 to 3,000 J/kg
    and beyond the energies run, the simulation, the primary events' mean t10'); the progeny
    size distributions (model lines, simulation symbols)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(17, 4.8))
    energies = [r["specific_energy"] for r in results]
    _plot_probability(axes[0], results, material, size, partner, energies, title, label)
    grid = np.geomspace(min(50.0, min(energies) / 2), max(3000.0, 2 * max(energies)), 200)
    axes[1].semilogx(grid, material.t10_model(grid, size, partner), "k-",
                     label=material.criterion.t10_label)
    done = [r for r in results if r.get("t10_simulated") is not None]
    if done:
        axes[1].plot([r["specific_energy"] for r in done], [r["t10_simulated"] for r in done],
                     "o", c="C3", label=f"{label}: progeny t10, all generations")
        axes[1].plot([r["specific_energy"] for r in done], [r["t10_primary_events"] for r in done],
                     "x", c="C0", label="mean t10' of the primary breakages (Eq. 8)")
    axes[1].set(xlabel="specific energy Ek/mp (J/kg)", ylabel="t10 (%)",
                title="t10 against the model at each energy")
    axes[1].legend(fontsize=7, loc="upper left")
    for k, r in enumerate(results):
        if "relative_sizes" not in r:
            continue
        if r["progeny_passing_model"] is not None:
            axes[2].semilogx(r["relative_sizes"], r["progeny_passing_model"], "-", c=f"C{k}",
                             label=f"model, {r['specific_energy']:g} J/kg (t10 "
                                   f"{r['t10_model']:.1f} %)")
        axes[2].semilogx(r["relative_sizes"], r["progeny_passing_simulated"], "o", ms=4,
                         c=f"C{k}", label=f"simulation, t10 {r['t10_simulated']:.1f} %")
    axes[2].set(xlabel="relative size d / d_parent", ylabel="progeny passing (%)",
                title="progeny of broken particles (fines included)")
    if any(r.get("relative_sizes") for r in results):
        axes[2].legend(fontsize=7)
    else:                                     # nothing broke: no progeny to plot
        axes[2].text(0.5, 0.5, "no particle broke", ha="center", transform=axes[2].transAxes)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def bounded_errors(values, errors, lo=0.0, hi=None):
    """matplotlib's yerr (2 x n: below, above) for `values` +- `errors`, cut at `lo` and `hi`: a
    share, a mass or a radius has no error bar below zero (nor a share above 100 %)."""
    values, errors = np.asarray(values, float), np.abs(np.asarray(errors, float))
    below = np.minimum(errors, values - lo) if lo is not None else errors
    above = np.minimum(errors, hi - values) if hi is not None else errors
    return np.vstack([np.clip(below, 0.0, None), np.clip(above, 0.0, None)])


def _plot_probability(ax, results, material, size, partner, energies, title, label):
    grid = np.geomspace(min(energies) / 3, max(energies) * 3, 200)
    ax.semilogx(grid, 100 * material.breakage_probability(grid, size, partner=partner), "k-",
                label=material.criterion.probability_label)
    measured = [(r["specific_energy"], r["p_of_e_cum_measured"]) for r in results
                if "p_of_e_cum_measured" in r]
    if measured:
        ax.plot(*zip(*[(e, 100 * p) for e, p in measured]), "kx", ms=8,
                label="P(e_cum) at the e_cum measured")
    broken = [100 * r["broken_fraction"] for r in results]
    ax.errorbar(energies, broken, yerr=bounded_errors(broken, [300 * r["binomial_sigma"]
                                                               for r in results], 0.0, 100.0),
                fmt="o", c="C3", label=f"{label} (3 sigma)")
    ax.set(xlabel="specific energy Ek/mp (J/kg)", ylabel="broken (%)", title=title)
    ax.legend(loc="upper left", fontsize=8)
