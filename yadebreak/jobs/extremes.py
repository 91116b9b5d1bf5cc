"""The stability matrix: scenes at the extremes of every input, and what each must satisfy.

Each case builds a small scene, runs it to its end, and measures: no NaN or infinity in any body
or event; total mass (spheres plus ledger) conserved to 1e-9; no fragment leaving faster than its
parent's rigid velocity field (|v| + 2 |w| r, recorded per event); no kinetic energy created (no
gravity in these scenes: the contact law only stores and dissipates); and the run ending. Used by
scripts/extremes.py (the full matrix, a table) and tests/test_extremes.py (a fast subset).
YADE is reached through the scenes (scenes/extremes.py, scenes/view.py).
"""
from __future__ import annotations

import csv
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from yadebreak import engine, scenes
from yadebreak.engine import attach
from yadebreak.scenes import extremes as extreme_scenes, view
from yadebreak.criteria import load_material
from yadebreak.jobs import skeleton
from yadebreak.jobs.lifecycle import progress
from yadebreak.options.flags import fail

SIZE = 5.5e-3


@dataclass
class Case:
    name: str
    build: object                         # callable(n) -> (controller, ids of the bodies fired)
    n: int = 20                           # particles in the full matrix
    n_fast: int = 4                       # particles in the test subset
    max_steps: int = 200000
    expect: dict = field(default_factory=dict)   # e.g. {"min_breakages_one_step": 100}


def _material(name="limestone", **changes):
    """The material `name` with some of its criterion's parameters changed (SI)."""
    mat = load_material(name)
    return mat.with_params(**changes) if changes else mat


def _impact(size=SIZE, speed=20.0, material=None, **options):
    def build(n):
        return scenes.impact_scene(material or _material(), size, [speed] * n, seed=4,
                                   dummies="ledger", **options)
    return build


def _set_fracture_energy(brk, ids, energy):
    """Give the bodies `ids` one fracture energy (J/kg), so that they break together."""
    for i in ids:
        brk.bodies[i].fracture_energy = brk.bodies[i].fracture_energy_initial = energy


def _all_break_at_once(n):
    """n identical particles hit the plate in the same step with one low fracture energy: they
    all break in that step (fragments kept unbreakable, dmin = the size, to keep the run short)."""
    brk, ids = scenes.impact_scene(_material(), SIZE, [30.0] * n, seed=4, dummies="ledger",
                                   dmin=SIZE)
    _set_fracture_energy(brk, ids, 50.0)
    return brk, ids


def _break_now(ratio, size=SIZE):
    """Particles resting on the plate broken at once (t10' from Eq. 8 at `ratio`: 1 gives the
    primary t10' of Eq. 9, 1e6 gives A)."""
    def build(n):
        brk, ids = scenes.impact_scene(_material(), size, [0.0] * n, seed=4, gap_fraction=0.0,
                                       dummies="ledger")
        for i in ids:
            brk.break_body(i, ratio=ratio, direction=(0.0, 0.0, -1.0))
        return brk, ids
    return build




def _head_on(n):
    """Pairs of touching, identical particles (same fracture energy) fired at each other: both
    break in the same step, each touching the other."""
    ore = _material()
    ids = extreme_scenes.head_on_pairs(ore, SIZE, n, speed=15.0)
    brk = attach({"ore": ore}, seed=4, dummies="ledger")
    _set_fracture_energy(brk, ids, 30.0)
    return brk, ids


def _in_facet_corner(n):
    """Particles resting in a corner of a wall and two facets (a floor and a side) broken at once:
    fragments placed against a wall and facets."""
    ore = _material()
    ids = extreme_scenes.in_facet_corner(ore, SIZE, n)
    brk = attach({"ore": ore}, seed=4, dummies="ledger")
    engine.run_steps(1)                          # contacts exist before the breakage
    for i in ids:
        brk.break_body(i, ratio=3.0, direction=(0.0, 0.0, -1.0))
    return brk, ids


def cases():
    ab = load_material("ab_t10_ore")
    return [
        Case("impact 0.01 m/s", _impact(speed=0.01), n=5, n_fast=1),
        Case("impact 150 m/s", _impact(speed=150.0), n=10, n_fast=1),
        Case("size 0.1 mm at 150 m/s", _impact(size=1e-4, speed=150.0)),
        Case("size 0.1 mm, broken at 10 x E", _break_now(10.0, size=1e-4), n=10, n_fast=2),
        Case("size 200 mm at 10 m/s", _impact(size=0.2, speed=10.0), n=5, n_fast=1),
        Case("Emax/E50 = 1.001", _impact(material=_material(emax_ratio=1.001))),
        Case("Emax/E50 = 1e4", _impact(material=_material(emax_ratio=1e4))),
        Case("sigma = 0.01", _impact(material=_material(sigma=0.01))),
        Case("sigma = 3", _impact(material=_material(sigma=3.0))),
        Case("gamma = 0.5", _impact(speed=8.0, material=_material(gamma=0.5))),
        Case("gamma = 50", _impact(speed=8.0, material=_material(gamma=50.0))),
        Case("t10' at its minimum (Eq. 9)", _break_now(1.0)),
        Case("t10' at A", _break_now(1e6)),
        Case("time step 0.5 % of T_R", _impact(time_step_fraction=0.005), n=5, n_fast=1),
        Case("time step 40 % of T_R", _impact(time_step_fraction=0.4)),
        Case("hundreds of breakages in one step", _all_break_at_once, n=300, n_fast=100,
             expect={"min_breakages_one_step": 100}),
        Case("fragments against a wall and facets", _in_facet_corner, n=10, n_fast=3),
        Case("neighbours breaking in the same step", _head_on, n=10, n_fast=2,
             expect={"min_breakages_one_step": 2}),
        Case("Ab-T10, S x 1e-3", _impact(speed=40.0, material=ab.with_params(
            selection=ab.params.selection * 1e-3))),
        Case("Ab-T10, S x 1e3, e_min = 0", _impact(speed=5.0, material=ab.with_params(
            selection=ab.params.selection * 1e3, e_min_ref=0.0))),
    ]


def _kinetic(brk):
    return view.moving_kinetic_energy() + brk.ledger.kinetic_energy()   # ledger fines carry
    #                                                                     their momentum


def run_case(case, fast=False):
    """Build, run to the end (every fired body or its fragments away and free) and measure."""
    engine.forget()
    t0 = time.time()
    n = case.n_fast if fast else case.n
    brk, ids = case.build(n)
    # as the scene starts; where parents were broken at rest, their fragments' (which the
    # replacement must keep at zero, the rigid field of a body at rest)
    kinetic_before = _kinetic(brk)
    mass_before = brk.total_mass()
    steps = scenes.run_until_rebound(ids, max_steps=case.max_steps)
    # then on until no collision is left: nothing touches, or the kinetic energy no longer changes
    # over 500 steps (fragments flying apart, or clusters moving or resting as one)
    ended = False
    last = _kinetic(brk)
    while steps < case.max_steps:
        engine.run_steps(500)
        steps += 500
        now = _kinetic(brk)
        if view.real_contacts() == 0 or abs(now - last) <= 1e-6 * last + 1e-15:
            ended = True
            break
        last = now
    kinetic_after = _kinetic(brk)
    breakages = brk.breakage_events
    per_step = {}
    for e in breakages:
        per_step[e["iter"]] = per_step.get(e["iter"], 0) + 1
    finite_events = all(np.isfinite(e["specific_energy"]) and np.isfinite(e["fracture_energy"])
                        and np.isfinite(e.get("t10", 0.0)) for e in brk.events)
    result = {
        "case": case.name, "particles": n, "steps": steps, "ended": bool(ended),
        "breakages": len(breakages), "max_breakages_one_step": max(per_step.values(), default=0),
        "finite": bool(view.all_finite() and finite_events),
        "mass_error": abs(brk.total_mass() - mass_before) / mass_before,
        "fragment_speed_excess": max((e.get("fragment_speed_excess", -math.inf)
                                      for e in breakages), default=-math.inf),
        "kinetic_before": kinetic_before, "kinetic_after": kinetic_after,
        "warnings": sorted(brk.warned), "wall_s": time.time() - t0}
    result["ok"] = bool(
        result["finite"] and result["ended"] and result["mass_error"] <= 1e-9
        and result["fragment_speed_excess"] <= 1e-9
        and kinetic_after <= kinetic_before * (1 + 1e-6) + 1e-9
        and result["max_breakages_one_step"] >= case.expect.get("min_breakages_one_step", 0))
    brk.close()
    return result


def run(args):
    """The matrix (args.only: the cases whose name holds it; args.fast: the test suite's particle
    counts): a table on stdout, and extremes.md, extremes.csv and extremes.json in args.out (of
    the cases done, if the run fails). Returns the exit status: 1 if any case fails. A
    skeleton.Units job of one case per unit, not resumable: a case takes seconds and the matrix is
    run whole."""
    chosen = {case.name: case for case in cases() if not args.only or args.only in case.name}
    if not chosen:
        fail(f"--only = {args.only}: no case's name holds it; the cases: "
             + "; ".join(case.name for case in cases()))
    out = Path(args.out)
    start, rows = time.time(), []

    def compute(k, name):
        r = run_case(chosen[name], fast=args.fast)
        progress(f"{name}: {'ok' if r['ok'] else 'FAILED'}, {r['breakages']} breakages, "
                 f"{r['steps']} steps, {r['wall_s']:.1f} s")
        return None, r

    def write(done, end_reason, end_message):
        rows[:] = done
        if done:
            _write_tables(out, done)

    skeleton.run(skeleton.Units(args, list(chosen), compute, write, resumable=False))
    print(_table(rows))
    failed = [r["case"] for r in rows if not r["ok"]]
    progress(f"{len(rows) - len(failed)} of {len(rows)} cases ok in {time.time() - start:.0f} s; "
             f"wrote {out / 'extremes.md'}" + (f"; FAILED: {failed}" if failed else ""))
    return 1 if failed else 0


def _write_tables(out, rows):
    """extremes.md, extremes.csv and extremes.json of `rows`."""
    (out / "extremes.md").write_text(_table(rows) + "\n")
    with open(out / "extremes.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        for r in rows:
            writer.writerow({k: (";".join(v) if isinstance(v, list) else v) for k, v in r.items()})
    (out / "extremes.json").write_text(json.dumps(rows, indent=2))


def _table(rows):
    """The results as a Markdown table, a row per case."""
    lines = ["| case | particles | breakages | most in one step | steps | ended | finite | mass "
             "error | fragment speed margin (m/s) | kinetic energy before, after (J) | warnings "
             "| wall (s) | ok |", "|" + "---|" * 13]
    for r in rows:
        margin = ("-" if r["fragment_speed_excess"] == float("-inf")
                  else f"{r['fragment_speed_excess']:.1e}")
        lines.append(f"| {r['case']} | {r['particles']} | {r['breakages']} "
                     f"| {r['max_breakages_one_step']} | {r['steps']} "
                     f"| {'yes' if r['ended'] else 'NO'} | {'yes' if r['finite'] else 'NO'} "
                     f"| {r['mass_error']:.1e} | {margin} "
                     f"| {r['kinetic_before']:.3g}, {r['kinetic_after']:.3g} "
                     f"| {', '.join(r['warnings']) or '-'} "
                     f"| {r['wall_s']:.1f} | {'yes' if r['ok'] else 'NO'} |")
    return "\n".join(lines)
