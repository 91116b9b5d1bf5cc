"""The bonded agglomerate in YADE (issue 17): the single-bond tension test that calibrates E_B, a
bonded cantilever against Timoshenko's deflection, and a small agglomerate's impact against the
document's findings (the 4,104-sphere case: benchmarks/bench_agglomerate.py)."""
import argparse
import csv
import json
import math
import re

import numpy as np
import pytest

pytestmark = pytest.mark.yade


def _two_spheres(radius, distance, binder_changes, seed=1):
    """Two glass spheres `distance` apart along x bonded by one beam; sphere 0 fixed."""
    from yade import O, utils
    from yadebreak.model import bonds
    from yadebreak.engine.parts import bonds as bonded
    from yadebreak.scenes import agglomerate as scene_of_bonds
    mat = bonds.load_agglomerate_material("glass_epoxy")
    mat = mat.with_binder(**binder_changes)
    sphere_mat = O.materials.append(__import__("yade").wrapper.FrictMat(
        young=mat.spheres.young_modulus, poisson=mat.spheres.poisson_ratio,
        density=mat.spheres.density))
    ids = np.array([O.bodies.append(utils.sphere((0, 0, 0), radius, material=sphere_mat,
                                                 fixed=True)),
                    O.bodies.append(utils.sphere((distance, 0, 0), radius, material=sphere_mat))])
    O.engines = scene_of_bonds.bonded_engines(mat.spheres, gravity=0.0)
    watch, scale = bonded.attach_bonds(ids, np.array([[0, 1]]), np.array([distance]),
                                       np.array([radius, radius]), mat.binder,
                                       np.random.default_rng(seed))
    O.dt = 0.1 * scale
    return mat, ids, watch


def test_single_bond_tension_gives_E_B_and_breaks_at_its_strength(scene):
    """The document's calibration: a bond 12.5 mm long of radius 0.67 mm pulled at 0.03 m/s.
    The stress-strain slope is E_B; the bond breaks in tension within one step of reaching its
    own (drawn) tensile strength."""
    from yade import O
    from yadebreak.model import bonds
    length, radius = 12.5e-3, 1e-3
    mat, ids, watch = _two_spheres(radius, length, {"radius_multiplier": 0.67})
    area = math.pi * (0.67e-3) ** 2
    b = O.bodies[int(ids[1])]
    b.state.blockedDOFs = "xyzXYZ"
    b.state.vel = (0.03, 0, 0)
    phys = watch.net.physs[0]
    strain, stress = [], []
    while watch.broken_count() == 0 and O.iter < 200000:
        O.step()
        if watch.broken_count() == 0:
            strain.append((O.bodies[int(ids[1])].state.pos[0] - length) / length)
            stress.append(-phys.normalForce[0] / area)        # force on sphere 0 pulls it +x
    strain, stress = np.array(strain), np.array(stress)
    slope = np.polyfit(strain, stress, 1)[0]
    assert slope == pytest.approx(mat.binder.young_modulus, rel=1e-6)
    strength = watch.net.strengths[0][0]
    step_increment = mat.binder.young_modulus * 0.03 * O.dt / length
    assert watch.mode[0] == bonds.TENSION
    assert stress[-1] < strength <= stress[-1] + 2 * step_increment
    assert not O.interactions[int(ids[0]), int(ids[1])].isReal    # the bond's interaction went


def test_bonded_cantilever_deflects_as_timoshenko(scene):
    """Sphere 0 clamped, a transverse load P on sphere 1: at rest (dynamic relaxation) the tip's
    deflection is P L^3 / (3 E I) (1 + Phi / 4), its rotation P L^2 / (2 E I), and the larger end
    moment (at the clamp) P L."""
    from yade import O
    from yadebreak.model import bonds
    from yadebreak.engine.parts import bonds as bonded
    from yadebreak.scenes import agglomerate as scene_of_bonds
    length, radius = 2e-3, 0.8e-3
    mat, ids, watch = _two_spheres(radius, length, {"radius_multiplier": 0.5,
                                                    "tensile_strength": 1e5,
                                                    "shear_strength": 1e5,
                                                    "compressive_strength": 1e6})
    newton = next(e for e in O.engines if e.label == "newton")
    newton.damping = 0.3                       # YADE's non-viscous damping: relaxes to rest
    load = 1e-3                                 # N
    O.forces.setPermF(int(ids[1]), (0, load, 0))
    O.run(60000, True)
    rb = 0.5 * radius
    _, inertia, _ = bonds.section(rb)
    e = mat.binder.young_modulus
    phi = bonds.timoshenko_phi(rb, length, mat.binder.poisson_ratio)
    tip = O.bodies[int(ids[1])].state
    assert tip.pos[1] == pytest.approx(load * length**3 / (3 * e * inertia) * (1 + phi / 4),
                                       rel=2e-3)
    assert tip.ori.toRotationVector()[2] == pytest.approx(load * length**2 / (2 * e * inertia),
                                                          rel=2e-3)
    moment = bonded._end_moment(watch.net.geoms[0], watch.net.physs[0],
                                watch.net.lever_a[0], watch.net.lever_b[0])
    assert moment == pytest.approx(load * length, rel=2e-3)
    assert watch.broken_count() == 0


def _args(out, **changes):
    values = dict(material="glass_epoxy", particles=250, speed=4.0, duration=2.5e-4,
                  radius_multiplier=0.0, time_step_fraction=0.2, check_period=1,
                  sample_interval=5e-6, vtk_interval=1e-4, seed=3, out=str(out))
    values.update(changes)
    return argparse.Namespace(**values)


def test_small_agglomerate_breaks_as_the_document_reports(scene, tmp_path):
    """A 250-sphere agglomerate (same sizes and packing density) at 4 m/s: bonds fail in tension
    far more than in shear and never in compression; the damage stays near the plane (no
    diametral fracture: one fragment keeps most of the mass); the time series, the log of
    broken bonds and the summary agree; broken bonds' spheres that touch again do so by
    Hertz-Mindlin, never by a bond."""
    from yade import O
    from yadebreak.jobs import agglomerate
    from yadebreak.model import bonds
    summary = agglomerate.run(_args(tmp_path), quiet=True)
    assert summary["end_reason"] == "finished"
    assert summary["particles"] == 250
    assert summary["bonds_broken_tension"] > 20
    assert summary["bonds_broken_tension"] > 5 * summary["bonds_broken_shear"]
    assert summary["bonds_broken_compression"] == 0
    found = summary["findings"]
    assert found["upper_half_damaged"] < 0.5 * found["damaged_fraction"]
    assert summary["fragments"]["largest_mass_fraction"] > 0.6
    assert summary["porosity"] == pytest.approx(
        1 - agglomerate.solid_fraction_of_document(
            bonds.load_agglomerate_material("glass_epoxy").spheres), abs=0.01)
    # the log, the series and the summary tell the same story
    with open(tmp_path / "bonds_broken.csv") as f:
        log = list(csv.DictReader(f))
    broken = summary["bonds_broken_tension"] + summary["bonds_broken_shear"]
    assert len(log) == broken
    with open(tmp_path / "timeseries.csv") as f:
        series = list(csv.DictReader(f))
    last = series[-1]
    assert int(last["broken_tension"]) == summary["bonds_broken_tension"]
    assert float(last["damage_ratio"]) == pytest.approx(summary["damage_ratio"], rel=1e-12)
    assert float(last["time_ms"]) == pytest.approx(0.25, abs=1e-3)
    assert all(float(r["time_ms"]) <= 0.25 + 1e-6 for r in log)
    # broken bonds: no bond physics left; spheres in contact again touch by Hertz-Mindlin
    watch = agglomerate_watch()
    touching = 0
    for row in np.flatnonzero(watch.mode):
        a, b = int(watch.net.a[row]), int(watch.net.b[row])
        if O.interactions.has(a, b) and O.interactions[a, b].isReal:
            assert type(O.interactions[a, b].phys).__name__ == "MindlinPhys"
            touching += 1
    assert touching > 0
    for f in ("summary.json", "agglomerate_impact.png", "damage_section.png",
              "paraview/spheres.pvd"):
        assert (tmp_path / f).exists()
    assert json.loads((tmp_path / "summary.json").read_text())["steps"] == O.iter


def agglomerate_watch():
    from yadebreak.engine.parts import bonds as bonded
    return bonded.watch_of()


def test_build_and_breakage_are_reproducible_from_the_seed(scene, tmp_path):
    from yadebreak.jobs import agglomerate
    first = agglomerate.run(_args(tmp_path / "a", particles=120, duration=1e-4), quiet=True)
    second = agglomerate.run(_args(tmp_path / "b", particles=120, duration=1e-4), quiet=True)
    assert (tmp_path / "a" / "bonds_broken.csv").read_text() == (
        tmp_path / "b" / "bonds_broken.csv").read_text()
    for key in ("bonds_initial", "bonds_broken_tension", "damage_ratio", "porosity"):
        assert first[key] == second[key]
    other = agglomerate.run(_args(tmp_path / "c", particles=120, duration=1e-4, seed=4),
                            quiet=True)
    assert other["porosity"] != first["porosity"]


def test_the_scalar_screen_never_misses_a_bond_near_its_strength(scene, tmp_path):
    """BondWatch computes exact end moments only where a scalar upper bound reaches 80 % of a
    strength: mid-impact, the exact stresses of every intact bond give the same counts and the
    same failing bonds."""
    from yadebreak.jobs import agglomerate
    from yadebreak.model import bonds
    from yadebreak.engine.parts import bonds as bonded
    from yadebreak.scenes import agglomerate as scene_of_bonds
    from yade import O
    agglomerate.run(_args(tmp_path, particles=200, duration=2e-5), quiet=True)
    watch = agglomerate_watch()
    for _ in range(3000):                                   # on to a step with bonds near failure
        if watch.above[0] > 2:
            break
        O.step()
    tensile, shear, compressive = watch._stresses()
    net, alive = watch.net, watch.alive
    exact = np.array([bonded._end_moment(net.geoms[r], net.physs[r], net.lever_a[r],
                                         net.lever_b[r]) for r in alive])
    depth = np.array([net.geoms[r].penetrationDepth for r in alive])
    axial = -net.stiffness.axial[alive] * (depth - net.unp[alive])
    t, s, c = bonds.bond_stresses(axial, [net.physs[r].shearForce.norm() for r in alive], exact,
                                  [net.physs[r].moment_twist.norm() for r in alive],
                                  net.radius[alive])
    st, sc = net.strengths[0][alive], net.strengths[2][alive]
    level = bonded.WATCH_LEVEL
    assert np.count_nonzero(t >= level * st) > 0          # mid-impact: some bonds near failure
    np.testing.assert_array_equal(tensile >= level * st, t >= level * st)
    np.testing.assert_array_equal(compressive >= level * sc, c >= level * sc)
    near = t >= level * st
    np.testing.assert_allclose(tensile[near], t[near], rtol=1e-12)
    assert np.all(tensile >= t - 1e-9 * st)                 # elsewhere an upper bound
    assert math.isfinite(float(np.max(shear)))


def _rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def test_a_killed_run_resumes_to_the_same_bonds_broken_without_duplicate_lines(scene, tmp_path):
    """Checkpoints, a kill after bonds broke past the last checkpoint (their lines written), and
    --resume: bonds_broken.csv (each bond once), timeseries.csv and the summary (but for wall
    times) are the uninterrupted run's to the last digit: checkpoints are written where every run
    renews its contacts as a load would (scene_of_bonds.renew_contacts)."""
    from yade import O
    from yadebreak.jobs import agglomerate
    from yadebreak.engine.parts import bonds as bonded
    from yadebreak.engine.parts import protocol
    from yadebreak.scenes import agglomerate as scene_of_bonds
    from yadebreak.jobs.lifecycle import RunFinished, ScriptError
    small = dict(particles=120, duration=1.5e-4)     # 89 of 431 bonds break, by 0.1 ms
    whole = agglomerate.run(_args(tmp_path / "whole", checkpoint_every=-1.0, **small), quiet=True)
    cut = tmp_path / "cut"
    died = _args(cut, checkpoint_every=0.0, stop_after=4e-5, **small)   # at every renewal
    assert agglomerate.run(died, quiet=True) is None
    assert not (cut / "summary.json").exists()
    O.reset()
    saved, _ = scene_of_bonds.load_checkpoint(cut / "checkpoint.yade.gz")
    at_checkpoint = saved.watch.broken_count()
    assert 0 < at_checkpoint < len(_rows(cut / "bonds_broken.csv"))
    # goes on without checkpoints and dies again: more lines past the checkpoint
    O.reset()
    protocol.forget()                  # as in a new process
    again = _args(cut, checkpoint_every=-1.0, stop_after=7e-5, resume=True, **small)
    assert agglomerate.run(again, quiet=True) is None
    assert len(_rows(cut / "bonds_broken.csv")) > at_checkpoint
    with pytest.raises(ScriptError, match=r"other values of \['speed'\]"):
        agglomerate.run(_args(cut, speed=5.0, resume=True, **small), quiet=True)
    O.reset()
    protocol.forget()
    resumed = agglomerate.run(_args(cut, checkpoint_every=-1.0, resume=True, **small),
                              quiet=True)
    assert whole["bonds_broken_tension"] > at_checkpoint
    for name in ("bonds_broken.csv", "timeseries.csv"):
        assert (cut / name).read_text() == (tmp_path / "whole" / name).read_text(), name
    log = _rows(cut / "bonds_broken.csv")
    assert len({r["bond"] for r in log}) == len(log) == whole["bonds_broken_tension"]
    cost = [d.pop("cost") for d in (resumed, whole)]
    assert resumed == whole
    for key in ("checks", "bonds_read"):
        assert cost[0][key] == cost[1][key]
    assert not (cut / "checkpoint.yade.gz").exists()
    with pytest.raises(RunFinished):                   # finished: nothing to do, nothing rewritten
        agglomerate.run(_args(cut, resume=True, **small), quiet=True)


def test_a_damaged_checkpoint_is_refused_in_one_line(scene, tmp_path):
    from yadebreak.jobs import agglomerate
    from yadebreak.jobs.lifecycle import ScriptError
    (tmp_path / "checkpoint.yade.gz").write_bytes(b"\x1f\x8b\x08garbage")
    with pytest.raises(ScriptError, match=r"checkpoint.yade.gz is damaged .*start the run over "
                                          r"with --overwrite 1, or choose another --out$"):
        agglomerate.run(_args(tmp_path, resume=True), quiet=True)
    assert not (tmp_path / "summary.json").exists()


def test_a_time_step_that_cannot_finish_is_refused_before_the_run(scene, tmp_path):
    """--time-step-fraction 1e-18 makes the run need ~1e21 steps, beyond YADE's 64-bit step
    counter; 1e-300 a time step whose square (in the rolling stiffness) is no float: both refused
    in one line before a step is taken."""
    from yade import O
    from yadebreak.jobs import agglomerate
    from yadebreak.engine import AttachError
    for fraction, steps in ((1e-18, r"needs \d\.\d+e\+2\d steps "),
                            (1e-300, r"needs \d\.\d+e\+30\d steps ")):
        with pytest.raises(AttachError) as info:
            agglomerate.run(_args(tmp_path, particles=60, time_step_fraction=fraction), quiet=True)
        message = str(info.value)
        assert message.startswith(f"time_step_fraction = {fraction:g}: the time step ")
        assert re.search(steps, message) and "glass_epoxy.toml" in message
        assert message.endswith("accepted a time step >= 1e-150 s and at most 9.22e+18 steps "
                                "(YADE's step counter)")
        assert "\n" not in message and O.iter == 0


def test_a_bonded_scene_loads_with_its_watch_and_a_plain_save_is_refused(scene, tmp_path):
    """O.save does not store the BondWatch: save_checkpoint keeps it in O.tags, and after
    a plain O.load of that file the first step restores it (the same bonds, modes, strengths and
    counts, and the run goes on breaking bonds); a scene O.saved later, whose stored state is
    stale, is refused at its first step rather than run with the wrong bonds."""
    from yade import O
    from yadebreak.jobs import agglomerate
    from yadebreak.engine.parts import bonds as bonded
    from yadebreak.engine.parts import protocol
    from yadebreak.scenes import agglomerate as scene_of_bonds
    material, packing = agglomerate.build(_args(tmp_path, particles=60))
    O.reset()
    built = scene_of_bonds.agglomerate_scene(material, packing, seed=3)
    while built.watch.broken_count() < 3:
        O.step()
    before = built.watch
    saved_mode, saved_checks = before.mode.copy(), before.checks
    scene_of_bonds.save_checkpoint(tmp_path / "c.yade.gz", built, {"any": 1})
    O.run(20, True)
    O.save(str(tmp_path / "plain.yade.gz"))               # the tags still hold the earlier state
    protocol.forget()
    O.load(str(tmp_path / "c.yade.gz"))
    O.step()
    watch = bonded.watch_of()
    assert watch is not before
    assert watch.checks == saved_checks + 1                   # the step after the load: checked
    assert np.all(watch.mode[saved_mode != 0] == saved_mode[saved_mode != 0])
    assert watch.broken_count() >= np.count_nonzero(saved_mode) >= 3
    for a, b in zip(watch.net.strengths, before.net.strengths):
        np.testing.assert_array_equal(a, b)
    assert watch.touch_time == before.touch_time
    O.load(str(tmp_path / "plain.yade.gz"))
    with pytest.raises(RuntimeError, match=r"stored at step \d+ and the scene is at step \d+"):
        O.step()
