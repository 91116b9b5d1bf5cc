"""studies/verify/readings.py: the seeds of a Fig. 16 point pooled by the particles broken, and
the target (t10 within 15 % of Eq. 7 where Eq. 7 is at most 20 %, the passing within 20 % at
every sieve where Eq. 10 passes more than 1 %)."""
import math

import pytest

from yadebreak.studies.verify import readings


def _run(seed, broken, t10, se, passing, model=(0.5, 5.0, 50.0), t10_model=4.0):
    return {"seeds": [seed], "particles": 8, "broken_fraction": broken / 8, "t10_simulated": t10,
            "t10_standard_error": se, "t10_model": t10_model, "breakage_events_all_generations": 3,
            "relative_sizes": [0.01, 0.1, 0.5], "progeny_passing_simulated": list(passing),
            "progeny_passing_model": list(model)}


def test_seeds_pool_by_the_particles_broken_and_their_standard_errors_add_in_quadrature():
    p = readings.pool([_run(3, 2, 3.0, 0.4, (1, 4, 40)), _run(4, 6, 5.0, 0.2, (1, 6, 60)),
                       _run(5, 0, None, None, (0, 0, 0))])
    assert p["broken"] == 8 and p["particles"] == 24
    assert p["t10"] == pytest.approx((2 * 3.0 + 6 * 5.0) / 8)
    assert p["t10_se"] == pytest.approx(math.hypot(2 * 0.4, 6 * 0.2) / 8)
    assert p["passing"] == pytest.approx([1.0, 5.5, 55.0])


def test_the_target_reads_t10_and_every_sieve_where_eq10_passes_more_than_one_percent():
    # the finest sieve (Eq. 10 at 0.5 %) does not count, however far off
    met = readings.judge(readings.pool([_run(3, 8, 4.4, 0.1, (5.0, 5.9, 40.5))]))
    assert met["t10_met"] and met["passing_met"]
    assert met["worst"] == pytest.approx(-0.19) and met["worst_size"] == 0.5
    short = readings.judge(readings.pool([_run(3, 8, 3.3, 0.1, (0.5, 5.0, 50.0))]))
    assert not short["t10_met"] and short["passing_met"]
    above = readings.pool([_run(3, 8, 30.0, 1.0, (1, 5, 50), t10_model=25.0)])
    assert readings.judge(above) is None
