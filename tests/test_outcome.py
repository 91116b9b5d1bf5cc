"""attach(outcome=...) and kappa="batch": what a breakage makes (docs/model.md, "The outcome of a
breakage").

'paper' breaks at the threshold and spreads the dummies' fines by Eqs. 11-12; 'model' breaks at
the stressing event's peak (t10' of Eq. 8 at its whole energy) and spreads the fines by Eq. 10,
so that the family set's product is Eq. 10 at its t10'. With kappa = 1 a single impact's t10 is
then Eq. 8's mean over the particles that break (above Eq. 7 by up to exp(sigma^2/2), the gap the
paper's kappa closes); kappa="batch" takes at each breakage the kappa of that definition, and the
mean is Eq. 7."""
import dataclasses
import math

import numpy as np
import pytest

from yadebreak import model
from yadebreak.model import equations, families
from yadebreak.criteria import load_material
from yadebreak.options.table import AttachError, Config

PAPER_MATERIALS = ("copper_ore", "granulite", "limestone")
SIEVES = np.array([0.1, 0.15, 0.05, 1 / 25, 1 / 50, 1 / 75, 0.005])   # 1/10, and below 0.210


def _paper(name):
    """The material as the paper's single-particle runs take it (Emax/E50 = 4)."""
    return load_material(name).with_params(emax_ratio=4.0)


def _e50(mat, size):
    return float(mat.criterion.median_fracture_energy(size))


# -- the options --------------------------------------------------------------------------------
def test_the_outcome_sets_the_break_and_the_fines_and_refuses_what_contradicts_it():
    paper, peak = Config.from_options(), Config.from_options(outcome="model")
    assert (paper.criteria.break_at, paper.fines) == ("threshold", "gaudin_schuhmann")
    assert (peak.criteria.break_at, peak.fines) == ("peak", "eq10")
    assert Config.from_options(outcome="paper", break_at="peak").fines == "gaudin_schuhmann"
    for bad, named in (({"break_at": "threshold"}, "break_at = 'threshold'"),
                       ({"t10_energy": "e50b"}, "t10_energy = 'e50b'")):
        with pytest.raises(AttachError, match=named) as err:
            Config.from_options(outcome="model", **bad)
        assert "\n" not in str(err.value) and "outcome='model'" in str(err.value)
    with pytest.raises(AttachError, match="outcome = 'exact': accepted 'paper' or 'model'"):
        Config.from_options(outcome="exact")
    # saved with a scene and read back: the same config
    assert Config.from_options(**peak.as_options()) == peak
    assert Config.from_options(kappa="batch").criteria.kappa == "batch"
    with pytest.raises(AttachError, match="kappa = 'late'"):
        Config.from_options(kappa="late")


def test_every_job_takes_the_outcome_on_its_command_line():
    from yadebreak.jobs import options as job_options
    for job in ("single_impact", "drop_weight", "bed_impact", "ball_mill"):
        args = job_options.read(job, None, ["--outcome", "model"])
        assert job_options.attach_options(job, args)["outcome"] == "model", job


# -- the model ----------------------------------------------------------------------------------
def test_eq8s_mean_over_the_broken_is_that_of_drawn_particles():
    """t10_mean_broken (quadrature over the broken particles' fracture energies) against the mean
    of Eq. 8 over 200,000 drawn particles of which those below the energy break: within four
    standard errors of that sample mean."""
    rng = np.random.default_rng(11)
    for name, energy in (("copper_ore", 300.0), ("granulite", 1000.0), ("limestone", 150.0)):
        mat = _paper(name)
        e50 = _e50(mat, 0.029)
        drawn = model.sample_fracture_energy(rng, e50, mat.params.sigma, 4.0, size=200_000)
        broken = drawn[drawn < energy]
        t10 = model.t10(energy / broken, mat.params.A, mat.params.b_prime)
        error = t10.std() / math.sqrt(len(t10))
        mean = model.t10_mean_broken(energy, e50, mat.params.sigma, 4.0, mat.params.A, mat.params.b_prime)
        assert abs(mean - t10.mean()) < 4 * error, name


def test_the_batch_kappa_makes_eq8s_mean_eq7_within_the_papers_range():
    """kappa_of_batch: Eq. 8's mean over the broken at that kappa is Eq. 7 (to the root's
    tolerance); where t10 is far below A its value lies in the paper's 0.95 .. exp(sigma^2/2),
    and at kappa = 1 the mean exceeds Eq. 7 (the lognormal's mean of 1/E)."""
    steel = load_material("steel")
    for name in PAPER_MATERIALS:
        mat = _paper(name)
        e50 = _e50(mat, 0.029)
        for energy in (150.0, 300.0, 1000.0, 3000.0):
            x = float(mat.absorbed(energy, steel))
            eq7 = float(mat.t10_model(energy, 0.029, steel))
            kappa = model.kappa_of_batch(x, e50, mat.params.sigma, 4.0, mat.params.A, mat.params.b_prime)
            assert model.t10_mean_broken(x, e50, mat.params.sigma, 4.0, mat.params.A, mat.params.b_prime,
                                         kappa) == pytest.approx(eq7, rel=1e-9)
            if eq7 < 0.25 * mat.params.A:
                assert 0.95 <= kappa <= math.exp(mat.params.sigma ** 2 / 2), (name, energy, kappa)
                assert model.t10_mean_broken(x, e50, mat.params.sigma, 4.0, mat.params.A, mat.params.b_prime) > eq7
    assert math.isnan(model.kappa_of_batch(0.0, 300.0, 0.8, 4.0, 60.0, 0.03))


def _family_set_passing(fset, beta_params, fines):
    """Probability-weighted passing (%) of a family set at SIEVES (relative to the parent)."""
    return sum(p * families.family_passing(counts, fset.t10, beta_params, SIEVES, fines)
               for counts, p in zip(fset.counts, fset.probabilities))


@pytest.mark.parametrize("name", PAPER_MATERIALS)
def test_family_sets_with_the_fines_spread_by_eq10_give_eq10_at_a_tenth_and_below(name):
    """Every family set of the material's table, its dummies spread by Eq. 10 (outcome
    'model'): the product is Eq. 10 within 1 % at 1/10 and at every sieve below the dummy
    size. The paper's Eqs. 11-12 miss it by more than 10 % somewhere (limestone: about half of
    t10' near primary breakage; copper ore and granulite: 1.1-1.25 times)."""
    mat = load_material(name)
    table = families.table_for(mat)
    worst_paper = 0.0
    for fset in table.sets:
        eq10 = model.progeny_passing(fset.t10, mat.beta_params, SIEVES)
        spread = _family_set_passing(fset, mat.beta_params, "eq10")
        assert spread == pytest.approx(eq10, rel=0.01), fset.t10
        paper = _family_set_passing(fset, mat.beta_params, "gaudin_schuhmann")
        worst_paper = max(worst_paper, abs(paper[0] / eq10[0] - 1.0))
    assert worst_paper > 0.10


# -- in YADE ------------------------------------------------------------------------------------
def _impacts(name, energy, particles, **options):
    """Single impacts of 29 mm particles on steel, 4 a scene (independently seeded scenes), at
    the paper's single-particle settings and 2 % of the Rayleigh time: the ImpactTally."""
    from yadebreak import scenes
    tally, brk = scenes.single_impacts(name, 0.029, float(np.sqrt(2 * energy)), particles, 4, 3,
                                       time_step_fraction=0.02, read_period="every_step",
                                       emax_ratio=4.0, **options)
    return tally, brk


@pytest.mark.yade
def test_a_model_breakage_takes_eq8_at_the_events_peak_with_the_batch_kappa(scene):
    """outcome='model', kappa='batch': each breakage carries Eq. 8 at its own ratio with the
    kappa of model.kappa_of_batch at its specific energy and size (to rounding), at the peak
    (its specific energy Eq. 4's share of the impact, within the dashpot's and the reads' 3 %),
    and the controller spreads the fines by Eq. 10."""
    gr, steel = _paper("granulite"), load_material("steel")
    share = gr.energy_partition(steel) * 300.0
    tally, brk = _impacts("granulite", 300.0, 4, outcome="model", kappa="batch")
    assert len(tally.broken) == 4 and brk.config.fines == "eq10"
    for e in tally.broken:
        kappa = model.kappa_of_batch(e["specific_energy"], _e50(gr, 2 * e["radius"]), gr.params.sigma,
                                     4.0, gr.params.A, gr.params.b_prime)
        assert e["kappa"] == pytest.approx(kappa, rel=1e-9)
        assert e["t10"] == pytest.approx(float(model.t10(e["ratio"], gr.params.A, gr.params.b_prime, kappa)),
                                         rel=1e-9)
        assert e["specific_energy"] == pytest.approx(share, rel=0.03)


@pytest.mark.yade
@pytest.mark.parametrize("kappa", [1.0, "batch"])
def test_single_impacts_give_the_models_t10_for_that_very_case(scene, kappa):
    """Granulite, 29 mm, 300 J/kg on steel (97 % break), 128 particles in 32 scenes, outcome
    'model': t10 within 10 % plus two standard errors (from the scatter between scenes) of the
    model's value for that case: Eq. 8's mean over the particles that break at kappa 1 (Eq. 7
    times 1.32 here), Eq. 7 itself with the batch kappa. Eq. 8's mean at kappa 1 lies outside
    the batch kappa's bound (1.16 points from Eq. 7 against 0.76 allowed at seed 3), so the
    test tells the two readings apart."""
    from yadebreak.analysis import reports
    gr, steel = _paper("granulite"), load_material("steel")
    x = float(gr.absorbed(300.0, steel))
    eq7 = float(gr.t10_model(300.0, 0.029, steel))
    mean_eq8 = model.t10_mean_broken(x, _e50(gr, 0.029), gr.params.sigma, 4.0, gr.params.A, gr.params.b_prime)
    expected, other = (eq7, mean_eq8) if kappa == "batch" else (mean_eq8, eq7)
    tally, _ = _impacts("granulite", 300.0, 128, outcome="model", kappa=kappa)
    result = reports.breakage_result_of(tally, gr, 300.0, steel)
    t10, se = result["t10_simulated"], result["t10_standard_error"]
    bound = 0.10 * expected + 2 * se
    assert len(tally.broken) >= 120
    assert abs(t10 - expected) <= bound, (t10, se, expected)
    if kappa == "batch":
        assert abs(other - expected) > bound, (other, bound)
