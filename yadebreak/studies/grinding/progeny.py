"""Where a broken particle's mass goes in the population balance (population.py): its t10 (Eq. 8
at e_j / E, or Eq. 9 at the threshold) and its progeny over the classes below and the fines (Eq.
10), or a given breakage matrix in place of Eqs. 8-10."""
from __future__ import annotations

import numpy as np

from yadebreak import model
from yadebreak.studies.grinding.grid import split_linear


class Progeny:
    """The fate of broken mass for `material` over `classes` (classes.SizeClasses).

    t10_at: "collision" takes a breakage's t10 from Eq. 8 at e_j / E, "threshold" Eq. 9's t10_min.
    matrix: None, or the (classes + 1, classes) fractions of a class's broken mass (column)
    going to each class and the fines (row), replacing Eqs. 8-10. Without a matrix, `table`
    (n, G, n + 1) holds the fractions of a broken particle of class i at each t10 of `t10_grid`
    (101 values from Eq. 9's t10_min to A: a breakage has e >= E) landing in each class l >= i
    and the fines: Eq. 10 at the sieves over the parent's representative size."""

    def __init__(self, material, classes, t10_at="collision", matrix=None, error=ValueError):
        self.criterion, self.t10_at = material.criterion, t10_at
        self.n = classes.count
        self.matrix = None if matrix is None else self._checked(matrix, error)
        self.t10_grid = np.linspace(material.t10_min, material.params.A, 101)
        if self.matrix is None:
            self.table = self._table(material.beta_params, classes)

    def _table(self, beta_params, classes):
        n, sizes, sieves = self.n, classes.sizes, classes.sieves
        table = np.zeros((n, len(self.t10_grid), n + 1))
        for i in range(n):
            passing = model.progeny_passing(self.t10_grid, beta_params,
                                            sieves[i:] / sizes[i]) / 100.0   # (G, n+1-i)
            passing[:, 0] = 1.0
            table[:, :, i:n][i] = passing[:, :-1] - passing[:, 1:]
            table[i, :, n] = passing[:, -1]
        return table

    def _checked(self, matrix, error):
        matrix = np.asarray(matrix, dtype=float)
        if (matrix.shape != (self.n + 1, self.n) or np.any(matrix < 0)
                or not np.allclose(matrix.sum(axis=0), 1.0, rtol=0, atol=1e-12)
                or np.any(np.triu(matrix[:self.n], 1) > 0)):
            raise error(f"breakage_matrix: needs shape ({self.n + 1}, {self.n}), "
                        "non-negative columns summing to 1, nothing above the parent")
        return matrix

    def t10(self, log_ratio):
        """t10 (%) of breakages at mean ln(e_j / E) `log_ratio`: Eq. 8 at the ratio (at least 1),
        or Eq. 9's t10_min for t10_at="threshold"."""
        return self.t10_at_ratio(np.exp(np.maximum(log_ratio, 0.0)))

    def t10_at_ratio(self, ratio):
        """t10 (%) of breakages at e_j / E = `ratio` (>= 1), by t10_at."""
        if self.t10_at == "threshold":
            return np.full(np.shape(ratio), self.criterion.t10_min)
        return self.criterion.t10(ratio)

    def weights(self, broken, t10):
        """Broken mass per class (n, J, K) at t10 (%) on the t10 grid: (n, G)."""
        g = len(self.t10_grid)
        lo, hi = self.t10_grid[0], self.t10_grid[-1]
        return split_linear((t10 - lo) / (hi - lo) * (g - 1), broken, g).reshape(self.n, g)

    def spread(self, weights):
        """Mass per class (n, G) on the t10 grid spread by Eq. 10: (n, n + 1), from class i
        to class l and the fines."""
        return np.einsum("ig,igl->il", weights, self.table)

    def retained(self, i, t10):
        """Share of a broken particle of class i (t10 %) that stays in class i: its progeny
        coarser than the class's lower sieve (Eq. 10, from the table)."""
        if self.matrix is not None:
            return np.full(np.shape(t10), self.matrix[i, i])
        return np.interp(t10, self.t10_grid, self.table[i, :, i])
