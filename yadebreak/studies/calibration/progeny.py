"""Progeny size distributions: the Eq. 10 table (alpha_n, beta_n for each t_n) by least squares.

Each n is fitted on its own: passing_n(t10) = 100 I_(t10/100)(alpha_n, beta_n) (model.t_n) against
the measured passing at the t10 values given, with ln alpha and ln beta as coordinates and
Student-t profile intervals. Model layer: no YADE.
"""
from __future__ import annotations

import math


from yadebreak import model
from yadebreak.studies.calibration.mle import Coord, least_squares


def coords(n):
    return [Coord(f"alpha_{n:g}", "-", "log", math.log(1e-3), math.log(100.0)),
            Coord(f"beta_{n:g}", "-", "log", math.log(1e-3), math.log(500.0))]


def fit_progeny(table, intervals=True):
    """{n: MLResult} for every n present in a progeny Table."""
    c = table.columns
    out = {}
    for n in model.N_VALUES:
        rows = c["n"] == n
        if not rows.any():
            continue
        t10, passing = c["t10"][rows], c["passing"][rows]

        def residuals(x, t10=t10, passing=passing):
            return passing - model.t_n(t10, math.exp(x[0]), math.exp(x[1]))

        # start from the paper's Table 1 average, which every material lies near
        a0, b0 = model.TABLE1_BETA_PARAMS[n]
        out[n] = least_squares(residuals, [math.log(a0), math.log(b0)], coords(n), intervals)
    return out
