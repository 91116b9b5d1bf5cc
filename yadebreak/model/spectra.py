"""The spectra file: stressing events of a mill per second against their energy, per pair type
(docs/grinding.md, Section 2). Reader with validation, writer, the converter from a mill run's
outputs and spectra synthesised from a documented rule.

File: line 1 is '# ' and a JSON object (the metadata), then a CSV table with the header
`pair_type,energy_low_J,energy_high_J,events`: the events counted in `simulated_time_s` seconds
with energy in [energy_low_J, energy_high_J). Energies are per collision, in J.
"""
from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from yadebreak.model import milling
from yadebreak.model.capture import CaptureModel

#: a spectra file's name in a run folder (a mill's spectra run, `grind`'s conversions)
SPECTRA_NAME = "spectra.csv"
FORMAT = "yadebreak-spectra"
VERSION = 1
COLUMNS = ("pair_type", "energy_low_J", "energy_high_J", "events")
#: pair types and the capture geometry of each: two spheres, or a sphere on the liner (a plane)
PAIR_GEOMETRY = {"ball-ball": "spheres", "ball-ore": "spheres", "ore-ore": "spheres",
                 "ball-liner": "plane", "ore-liner": "plane"}
#: energy_basis: "collision" (the media's collision energy; the ore absorbs its Eq. 4 share
#: against steel) or "absorbed" (already the ore's share, as the mill's stressing events are)
ENERGY_BASES = ("collision", "absorbed")


class SpectraError(ValueError):
    """A spectra file that cannot be used: one line naming the file, the field and the value."""


@dataclass(frozen=True)
class Spectra:
    """Collision energy spectra of one mill (SI units). One row per (pair type, energy bin)."""

    simulated_time_s: float
    ore_mass_kg: float
    ball_diameter_m: float
    energy_basis: str
    pair_type: tuple
    energy_low_J: np.ndarray
    energy_high_J: np.ndarray
    events: np.ndarray
    ore_coverage: float = 1.0
    source: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def rates_per_s(self):
        """Events per second of each row."""
        return self.events / self.simulated_time_s

    @property
    def energy_J(self):
        """Each row's representative energy (J): the geometric mean of its bin."""
        return np.sqrt(self.energy_low_J * self.energy_high_J)

    @property
    def plane(self):
        """True for rows whose pair type has a plane (the liner) on one side."""
        return np.array([PAIR_GEOMETRY[p] == "plane" for p in self.pair_type])

    def metadata(self):
        return {"format": FORMAT, "version": VERSION, "simulated_time_s": self.simulated_time_s,
                "ore_mass_kg": self.ore_mass_kg, "ball_diameter_m": self.ball_diameter_m,
                "energy_basis": self.energy_basis, "ore_coverage": self.ore_coverage,
                "source": self.source, **self.extra}


def write_spectra(path, spectra):
    """Write `spectra` in the file format above (whole or not at all)."""
    import io
    from yadebreak.process.files import write_atomic
    path = Path(path)
    f = io.StringIO(newline="")
    f.write("# " + json.dumps(spectra.metadata()) + "\n")
    w = csv.writer(f)
    w.writerow(COLUMNS)
    for row in zip(spectra.pair_type, spectra.energy_low_J, spectra.energy_high_J,
                   spectra.events):
        w.writerow([row[0]] + [repr(float(v)) for v in row[1:]])
    write_atomic(path, f.getvalue())
    return path


def _metadata_number(meta, key, path, lo, lo_open, hi=math.inf, unit="", default=None):
    value = meta.get(key, default)
    if value is None:
        raise SpectraError(f"{path}: metadata field {key} is missing ({unit})")
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    ok = ok and (value > lo if lo_open else value >= lo) and value <= hi
    if not ok:
        bound = f"{'>' if lo_open else '>='} {lo:g}" + (f" and <= {hi:g}" if hi < math.inf else "")
        raise SpectraError(f"{path}: metadata {key} = {value!r}: accepted a number {bound} "
                           f"({unit})")
    return float(value)


def read_spectra(path):
    """Read and validate a spectra file. Raises SpectraError with one line naming the file and
    the field on any problem, so that nothing is integrated from a bad file."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise SpectraError(f"{path}: cannot be read ({exc.strerror})") from None
    first, _, rest = text.partition("\n")
    if not first.startswith("# "):
        raise SpectraError(f"{path}: not a {FORMAT} file (line 1 must be '# ' and its JSON "
                           "metadata; a mill run's --out folder is converted when given as "
                           "SPECTRA)")
    try:
        meta = json.loads(first[2:])
    except json.JSONDecodeError:
        raise SpectraError(f"{path}: line 1 is not valid JSON metadata") from None
    if not isinstance(meta, dict):
        raise SpectraError(f"{path}: line 1 = {first[2:]!r}: accepted a JSON object")
    if meta.get("format") != FORMAT:
        raise SpectraError(f"{path}: metadata format = {meta.get('format')!r}: "
                           f"accepted '{FORMAT}'")
    if meta.get("version") != VERSION:
        raise SpectraError(f"{path}: metadata version = {meta.get('version')!r}: "
                           f"accepted {VERSION}")
    time_s = _metadata_number(meta, "simulated_time_s", path, 0.0, True, unit="s")
    ore = _metadata_number(meta, "ore_mass_kg", path, 0.0, True, unit="kg")
    ball = _metadata_number(meta, "ball_diameter_m", path, 0.0, True, 1.0, unit="m")
    coverage = _metadata_number(meta, "ore_coverage", path, 0.0, True, 1.0, unit="-", default=1.0)
    basis = meta.get("energy_basis")
    if basis not in ENERGY_BASES:
        raise SpectraError(f"{path}: metadata energy_basis = {basis!r}: accepted "
                           + " or ".join(repr(b) for b in ENERGY_BASES))
    reader = csv.reader(io.StringIO(rest))
    header = next(reader, None)
    if header is None or tuple(h.strip() for h in header) != COLUMNS:
        raise SpectraError(f"{path}: line 2 = {header!r}: accepted the header {','.join(COLUMNS)}")
    pairs, low, high, events = [], [], [], []
    for line, row in enumerate(reader, start=3):
        if not row:
            continue
        if len(row) != 4:
            raise SpectraError(f"{path}: line {line} has {len(row)} fields, accepted 4")
        pair = row[0].strip()
        if pair not in PAIR_GEOMETRY:
            raise SpectraError(f"{path}: line {line}: pair_type = {pair!r}: accepted "
                               + ", ".join(PAIR_GEOMETRY))
        try:
            lo, hi, n = (float(v) for v in row[1:])
        except ValueError:
            raise SpectraError(f"{path}: line {line}: energies and events must be "
                               "numbers") from None
        if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi):
            raise SpectraError(f"{path}: line {line}: energy bin [{lo!r}, {hi!r}): accepted "
                               "0 < energy_low_J < energy_high_J (J)")
        if not (math.isfinite(n) and n >= 0.0):
            raise SpectraError(f"{path}: line {line}: events = {n!r}: accepted a number >= 0 "
                               "(events in simulated_time_s)")
        pairs.append(pair)
        low.append(lo)
        high.append(hi)
        events.append(n)
    if not pairs or sum(events) <= 0.0:
        raise SpectraError(f"{path}: no events: the table must hold at least one event")
    known = {"format", "version", "simulated_time_s", "ore_mass_kg", "ball_diameter_m",
             "energy_basis", "ore_coverage", "source"}
    return Spectra(time_s, ore, ball, basis, tuple(pairs), np.array(low), np.array(high),
                   np.array(events), coverage, str(meta.get("source", "")),
                   {k: v for k, v in meta.items() if k not in known})


# --------------------------------------------------------------------------- from a mill run
def from_mill_run(run_dir, load_material):
    """Spectra from a finished `scripts/ball_mill.py` run (its summary.json and
    collision_spectra.csv); `load_material`: name -> Material (yadebreak.load_material), for the
    material the summary names.

    The mill records stressing events of ore particles (one per particle and event, specific
    energy Ek'/mp absorbed, J/kg) for the feed size d0 only. Under the capture model (capture.py)
    a collision of the charge catches n_s = nbar / (1 - exp(-nbar)) particles of d0 on average
    when it catches any (nbar the expected number, Poisson), each taking the same specific energy.
    So each particle event is 1/n_s of a collision whose absorbed energy is n_s e m0 (m0 the mass
    of one particle of d0), and the collisions (counting those that catch nothing) are the
    particle events over nbar. The model, applied back to a charge of d0, then gives every
    particle of d0 the DEM's stressing rate and energy: the DEM's own spectrum at its feed size.
    """
    run_dir = Path(run_dir)
    try:
        summary = json.loads((run_dir / "summary.json").read_text())
        with open(run_dir / "collision_spectra.csv", newline="") as f:
            rows = list(csv.DictReader(f))
    except (OSError, json.JSONDecodeError) as exc:
        raise SpectraError(f"SPECTRA {run_dir}: needs a mill run's summary.json and "
                           f"collision_spectra.csv ({exc})") from None
    try:
        material = load_material(summary["material"])
        d0, ball, ore_mass, time_s = (float(summary[k]) for k in
                                      ("size", "ball_size", "initial_mass", "simulated_time"))
    except (KeyError, TypeError, ValueError) as exc:
        raise SpectraError(f"SPECTRA {run_dir}/summary.json: field {exc} missing or not "
                           "a number") from None
    if not rows:
        raise SpectraError(f"SPECTRA {run_dir}/collision_spectra.csv: no rows")
    m0 = material.density * math.pi / 6.0 * d0 ** 3
    pairs, low, high, events = [], [], [], []
    for kind in ("ball-ore", "ore-ore", "ore-liner"):
        capture = CaptureModel(material.density, ball, coverage=1.0)
        nbar = float(capture.expected_count(np.array([1.0]), np.array([d0]),
                                            plane=PAIR_GEOMETRY[kind] == "plane"))
        n_s = nbar / -math.expm1(-nbar)
        for r in rows:
            n = float(r[f"{kind}_per_s"]) * time_s / nbar
            if n <= 0.0:
                continue
            pairs.append(kind)
            low.append(float(r["energy_low_J_per_kg"]) * n_s * m0)
            high.append(float(r["energy_high_J_per_kg"]) * n_s * m0)
            events.append(n)
    return Spectra(time_s, ore_mass, ball, "absorbed", tuple(pairs), np.array(low),
                   np.array(high), np.array(events), 1.0, f"mill run {run_dir}",
                   {"feed_size_m": d0, "material": material.name,
                    "converted_from": "particle stressing events of the feed size"})


# --------------------------------------------------------------------------- synthetic spectra
def synthetic_spectra(ball_diameter, drum_diameter=0.3, drum_length=0.3, speed_fraction=0.7,
                      ball_filling=0.3, ore_mass=None, interstitial_filling=1.0,
                      drop_fraction=0.1, ball_density=7800.0, ore_density=2930.0, bins=40):
    """Ball-ball collision spectra of a mill from a simple documented rule (docs/grinding.md,
    Section 2.3), for comparing ball sizes without DEM:

    - power: Bond's equation (milling.bond_mill_power_per_ball_mass) times the ball mass, all of
      it spent in ball-ball collisions;
    - energies: exponential, mean drop_fraction * m_b g D (m_b one ball's mass, D the drum's
      diameter: a ball falling a fraction of the drum), so the collision rate is power / mean;
    - the ore fills `interstitial_filling` of the voids of the ball bed (packing 0.6).
    Sizes in m, densities kg/m3; energy_basis "collision".
    """
    volume = math.pi * 0.25 * drum_diameter ** 2 * drum_length
    ball_mass_total = ball_filling * volume * 0.6 * ball_density
    if ore_mass is None:
        ore_mass = interstitial_filling * ball_filling * volume * 0.4 * 0.6 * ore_density
    power = float(milling.bond_mill_power_per_ball_mass(drum_diameter, ball_filling,
                                                        speed_fraction)) * ball_mass_total
    m_ball = ball_density * math.pi / 6.0 * ball_diameter ** 3
    mean = drop_fraction * m_ball * milling.GRAVITY * drum_diameter
    rate = power / mean
    edges = mean * np.geomspace(1e-3, 20.0, bins + 1)
    per_bin = rate * -np.diff(np.exp(-edges / mean))
    time_s = 1.0
    return Spectra(time_s, float(ore_mass), float(ball_diameter), "collision",
                   ("ball-ball",) * bins, edges[:-1], edges[1:], per_bin * time_s,
                   min(1.0, interstitial_filling), "synthetic (docs/grinding.md, Section 2.3)",
                   {"drum_diameter_m": drum_diameter, "speed_fraction": speed_fraction,
                    "ball_filling": ball_filling, "power_W": power,
                    "mean_collision_energy_J": mean})


__all__ = ["FORMAT", "VERSION", "COLUMNS", "PAIR_GEOMETRY", "ENERGY_BASES", "Spectra",
           "SpectraError", "read_spectra", "write_spectra", "from_mill_run", "synthetic_spectra"]
