"""What criteria decide for the bodies of one read, and every material's criterion on its bodies
at once (judge_all, called by engine/judging.py)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Judgement:
    """What a criterion decided for the bodies read now (arrays aligned with the ids given).

    breaks: breaks now. level, threshold: the criterion's variable and the value at which the body
    breaks (J/kg). rising: the body's loading grew since the last read, by `rise` (J/kg, what a
    read schedule extrapolates). jump: the rise of the criterion's variable since the last read,
    for the warning that a read came late."""

    breaks: np.ndarray
    level: np.ndarray
    threshold: np.ndarray
    rising: np.ndarray
    rise: np.ndarray
    jump: np.ndarray
    order: np.ndarray | None = None       # judge_all: each body's criterion.order (None:
    #                                       one criterion judged them all)


def judge_all(criterion_of, table, ids, active, ek, specific):
    """Every material's criterion on its active bodies among `ids` (vectorised per material);
    criterion_of[m] is the criterion of material index m; `active` a mask of `ids`, None for all.
    Returns a Judgement over all `ids` (inactive rows: no breakage, not rising) with `order`,
    the criteria's settling order (None: one criterion judged every body)."""
    n = len(ids)
    if len(criterion_of) == 1 and (active is None or active.all()):     # no grouping
        return criterion_of[0].judge(table, ids, ek, specific)
    if active is None:
        active = np.ones(n, bool)
    out = Judgement(breaks=np.zeros(n, bool), level=np.zeros(n), threshold=np.ones(n),
                    rising=np.zeros(n, bool), rise=np.zeros(n), jump=np.zeros(n),
                    order=np.zeros(n, np.int8))
    materials = table.columns["material"][ids]
    for m in np.unique(materials[active]).tolist():
        rows = np.nonzero(active & (materials == m))[0]
        crit = criterion_of[m]
        j = crit.judge(table, ids[rows], ek[rows], specific[rows])
        for name in ("breaks", "level", "threshold", "rising", "rise", "jump"):
            getattr(out, name)[rows] = getattr(j, name)
        out.order[rows] = crit.order
    return out
