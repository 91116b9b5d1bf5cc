"""The fracture-energy grid of the population balance (population.py): per size class, cells
uniform in ln E holding the class's mass, the fresh distribution's share in each (Eqs. 1-3 from
the material's criterion), and Eq. 6's weakening tabulated once. SI units: m, J/kg."""
from __future__ import annotations

import math

import numpy as np

from yadebreak import model


class FractureGrid:
    """ln E cells per class of `sizes` (m), from 1e-3 of the 0.01 % quantile of the fresh
    distribution (room for damage) up to its 1 - 1e-7 quantile; `fresh` (n, K) the fresh
    distribution's mass fraction in each cell (rows sum to 1)."""

    def __init__(self, criterion, sizes, cells):
        self.n, self.cells = len(sizes), int(cells)
        lo = np.log(1e-3 * criterion.ppf(1e-4, sizes))
        hi = np.log(criterion.ppf(1.0 - 1e-7, sizes))
        self.width = (hi - lo) / (self.cells - 1)                           # (n,)
        self.log_e = lo[:, None] + self.width[:, None] * np.arange(self.cells)   # (n, K)
        edges = self.log_e[:, 1:] - 0.5 * self.width[:, None]
        cdf = criterion.cdf(np.exp(edges), sizes[:, None])
        cdf = np.concatenate([np.zeros((self.n, 1)), cdf, np.ones((self.n, 1))], axis=1)
        self.fresh = np.diff(cdf, axis=1)

    def deposit(self, keep, keep_at, moved, moved_at):
        """Masses `keep` (n, K) at ln E `keep_at` and `moved` (n, J, K) at `moved_at` put back
        on each class's grid (clipped to its ends)."""
        out = np.zeros(self.n * self.cells)
        for m, at in ((keep, keep_at), (moved, moved_at)):
            shape = (self.n,) + (1,) * (at.ndim - 1)
            pos = (at - self.log_e[:, 0].reshape(shape)) / self.width.reshape(shape)
            out += split_linear(pos, m, self.cells)
        return out.reshape(self.n, self.cells)


class DamageTable:
    """ln(1 - D) of Eq. 6 against ln r for the material's gamma, tabulated once (the Newton solve
    per cell and step would cost most of a step); zero everywhere when `on` is False."""

    def __init__(self, gamma, on=True):
        self.on = on
        x = np.linspace(math.log(1e-10), math.log(30.0), 4001)   # ln(-ln(1 - r))
        r = -np.expm1(-np.exp(x))
        d = np.minimum(model.damage(r, gamma), 1.0 - 1e-15)
        self._log_r = np.log(r)
        self._log_keep = np.log1p(-d)

    def log_keep(self, log_ratio):
        """ln(1 - D(r)) (Eq. 6) for ln r < 0, from the table; 0 without damage."""
        if not self.on:
            return np.zeros_like(log_ratio)
        return np.interp(log_ratio, self._log_r, self._log_keep, left=0.0,
                         right=self._log_keep[-1])


def split_linear(pos, mass, count):
    """Masses (first axis: class) at fractional grid positions `pos` (same shape, clipped to
    [0, count - 1]) split between the two nearest of `count` nodes per class, linearly: each
    mass and its mean position are kept. Returns the flat (classes * count) totals."""
    pos = np.clip(pos, 0.0, count - 1.0)
    k0 = np.minimum(np.floor(pos).astype(int), count - 2)
    frac = pos - k0
    rows = mass.shape[0]
    idx = ((np.arange(rows) * count).reshape((rows,) + (1,) * (pos.ndim - 1)) + k0).ravel()
    out = np.bincount(idx, weights=(mass * (1.0 - frac)).ravel(), minlength=rows * count)
    return out + np.bincount(idx + 1, weights=(mass * frac).ravel(), minlength=rows * count)
