"""Closed forms of the linear batch population balance, against which the integration is
tested (docs/grinding.md, Section 5)."""
from __future__ import annotations

import numpy as np


def reid_batch(rates, matrix, initial, times):
    """Reid's (1965) solution of dm_i/dt = -S_i m_i + sum_{j<i} b_ij S_j m_j (classes ordered
    coarse to fine, distinct S_i): m_i(t) = sum_{j<=i} a_ij exp(-S_j t) with
    a_ij = sum_{k=j}^{i-1} b_ik S_k a_kj / (S_i - S_j) for j < i and a_ii = m_i(0) - sum_{j<i} a_ij.
    rates (n,) 1/s, matrix (n, n) with b_ij the fraction of class j's broken mass landing in i,
    initial (n,) kg, times (T,) s. Returns (T, n) masses."""
    s = np.asarray(rates, dtype=float)
    b = np.asarray(matrix, dtype=float)
    m0 = np.asarray(initial, dtype=float)
    n = len(s)
    a = np.zeros((n, n))
    for i in range(n):
        for j in range(i):
            a[i, j] = sum(b[i, k] * s[k] * a[k, j] for k in range(j, i)) / (s[i] - s[j])
        a[i, i] = m0[i] - a[i, :i].sum()
    return np.exp(-np.outer(np.asarray(times, dtype=float), s)) @ a.T


__all__ = ["reid_batch"]
