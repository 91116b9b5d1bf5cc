"""`python3 -m yadebreak verify --quick 1` (yadebreak/runs/verify.py): the paper's Section 4.1
subset runs, writes its report and plots, its probabilities sit within the binomial 3 sigma of
the model for those very cases, and global damping makes the progeny no coarser than the
tolerance below (the paper's finer progeny is not reproduced: docs/high_energy.md)."""
import json

import pytest

from yadebreak.runs import verify

pytestmark = pytest.mark.yade

#: Fig. 19's check, as a share of t10 without damping. The paper found its damping made the
#: progeny finer; here it makes it coarser, and the quick run bounds by how much at its energy.
#: Measured (docs/high_energy.md, "Global damping"; 29 mm copper ore, 16 particles, seed 3,
#: 2 % RT): t10 2.18 -> 2.16 % at 300 J/kg, 7.11 -> 6.17 % at 1000 J/kg (-13 %), 13.78 -> 9.34 %
#: at 3000 J/kg (-32 %); the quick run's 2 particles at 1000 J/kg: 4.25 -> 3.95 % (-7 %). 20 %
#: at 1000 J/kg is the 16-particle effect with room for the scatter of 2 particles; it fails if
#: the damping reaches the parents (which also lowers the broken fraction) or doubles its effect.
DAMPING_TOLERANCE = 0.20


def test_the_energies_of_figs_8_10_give_the_model_probabilities_asked():
    mat, steel = verify.paper_material("copper_ore"), verify.load_material("steel")
    energies = verify.probability_energies(mat, 5.5e-3, (0.2, 0.5, 0.8), steel)
    p = mat.breakage_probability(energies, 5.5e-3, partner=steel)
    assert p == pytest.approx([0.2, 0.5, 0.8], abs=0.02)      # energies rounded to 2 digits


def test_quick_verify_writes_its_report_and_meets_its_checks(scene, tmp_path):
    out = tmp_path / "verify"
    assert verify.main(["--quick", "1", "--out", str(out)]) == 0
    for name in ("report.md", "results.json", "fig08_probability.png", "fig16_t10.png",
                 "fig19_damping.png"):
        assert (out / name).stat().st_size > 0, name
    report = (out / "report.md").read_text()
    assert "Settings: 5.5 mm on steel" in report and "Emax/E50 4" in report
    figures = {f["name"]: f for f in json.loads((out / "results.json").read_text())["figures"]}
    probability = figures["Figs. 8-10: breakage probability against energy"]
    runs = json.loads((out / "results.json").read_text())["runs"]
    for r in runs:
        if r["size"] == 5.5e-3:     # each point against the model for that very case
            sigma = (r["model_probability"] * (1 - r["model_probability"]) / r["particles"]) ** 0.5
            assert abs(r["broken_fraction"] - r["model_probability"]) <= 3 * sigma, r
            assert r["options"]["time_step_fraction"] == 0.05
    assert len(probability["checks"]) == 3 and all(c["ok"] for c in probability["checks"])
    damping = figures["Fig. 19: global damping"]["checks"]
    assert [c["damping"] for c in damping] == [0.3]
    for c in damping:
        assert c["difference"] >= -DAMPING_TOLERANCE * c["t10_0"], c
    assert all(r["scenes_at_step_limit"] == 0 for r in runs)


def test_a_run_waits_for_the_fragments_still_flying_towards_the_plate(scene):
    """29 mm copper ore at 1000 J/kg, seed 3: the quiet rule alone stopped the run at 121 us with
    a fragment thrown from the parent's top still heading down at 33 m/s (1 breakage; 4 after
    20,000 more steps). With wait_for_arrivals nothing heading down faster than 10 % of the
    impact speed is left in flight, and the cascade is not cut."""
    from yadebreak import scenes
    from yadebreak.scenes import impacts
    speed = 2000.0 ** 0.5
    options = dict(seed=3, time_step_fraction=0.02, read_period="every_step", emax_ratio=4.0,
                   global_damping=0.0)
    brk, ids = scenes.impact_scene("copper_ore", 29e-3, speeds=[speed], **options)
    scenes.run_until_rebound(ids, brk=brk, wait_for_arrivals=True)
    assert impacts._all_away(0.1 * speed) or impacts._latest_arrival(0.1 * speed) < 1e-5
    assert len(brk.breakage_events) >= 4
