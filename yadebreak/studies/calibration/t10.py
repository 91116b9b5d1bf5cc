"""t10 against specific energy (drop weight or impact tests): A and b' of Eq. 7 (Tavares), or M,
the maximum t10 of Eq. 9.4 (Ab-T10), by least squares.

Tavares: t10 = A [1 - exp(-b' (Ek/mp) / E50b)] (Eq. 7), with the energy the particle absorbs,
e Ek/mp (e = 1/(1 + kp/ks), as in the fracture-energy fit), and E50b the median fracture energy of
the particles that break at it (model.median_fracture_energy_broken, from the fracture-energy
parameters: fitted from the same data set, or a base material's). Ab-T10: t10 = M P / 2, the mean
of Eq. 9.4 over the particles a single impact breaks (Material.t10_model). Intervals are
conditional on the fracture parameters (docs/calibration.md). Model layer: no YADE.
"""
from __future__ import annotations

import math

import numpy as np

from yadebreak import model
from yadebreak.studies.calibration.mle import Coord, least_squares, require

COORDS = [Coord("A", "%", "identity", 0.1, 100.0),
          Coord("b_prime", "-", "log", math.log(1e-5), math.log(10.0))]
COORD_M = Coord("t10_max", "%", "identity", 0.1, 100.0)


def e50b(table, fracture_params, device):
    """E50b (J/kg, absorbed) of every row, and the absorbed energies (J/kg)."""
    absorbed = device.share * table.columns["energy"]
    e50 = model.median_fracture_energy(table.columns["size"] * 1e-3, fracture_params["e_inf"],
                                       fracture_params["d0"] * 1e-3, fracture_params["phi"],
                                       device.k_particle, device.k_device)
    return model.median_fracture_energy_broken(absorbed, e50, fracture_params["sigma"],
                                               fracture_params["emax_ratio"]), absorbed


def fit_t10(table, fracture_params, device, intervals=True):
    """Fit A and b' (Eq. 7) to a t10 Table; returns the MLResult (extra: the rows' E50b)."""
    e50b_rows, absorbed = e50b(table, fracture_params, device)
    t10 = table.columns["t10"]
    ok = np.isfinite(e50b_rows)
    levels = len(set(zip(table.columns["size"][ok], table.columns["energy"][ok])))
    require(["A", "b_prime"], levels, "energy levels (size and energy)", table.path, 2)

    def residuals(x):
        return t10[ok] - model.t10_batch(absorbed[ok], e50b_rows[ok], x[0], math.exp(x[1]))

    ratio = absorbed[ok] / e50b_rows[ok]
    a0 = min(99.0, 1.2 * float(t10.max()))
    b0 = float(np.median(-np.log1p(-np.clip(t10[ok] / a0, 0, 0.95)) / ratio))
    result = least_squares(residuals, [a0, math.log(max(b0, 1e-4))], COORDS, intervals)
    result.extra.update({"e50b": e50b_rows, "absorbed": absorbed})
    return result


def fit_t10_max(table, ab_params, device, size_ref_mm, intervals=True):
    """Ab-T10: fit M to a t10 Table with S and e_min,ref given (t10 = M P / 2)."""
    p = ab_t10_break_probability(table, ab_params, device, size_ref_mm)
    t10 = table.columns["t10"]
    result = least_squares(lambda x: t10 - 0.5 * x[0] * p, [min(99.0, 2.0 * float(t10.max()))],
                           [COORD_M], intervals)
    result.extra.update({"probability": p})
    return result


def ab_t10_break_probability(table, ab_params, device, size_ref_mm):
    """Eq. 9.3 of the e_cum one loading leaves (Eq. 9.2): the share of particles one impact of each
    row's energy breaks."""
    size = table.columns["size"] * 1e-3
    e_min = model.ab_t10_min_energy(size, ab_params["e_min_ref"], size_ref_mm * 1e-3)
    e_cum = model.ab_t10_single_impact_cum(device.share * table.columns["energy"], e_min)
    return model.ab_t10_probability(e_cum, size, e_min, ab_params["selection"], size_ref_mm * 1e-3)
