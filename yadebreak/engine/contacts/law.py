"""The physics of one contact under YADE's Hertz-Mindlin law (Eqs. 15-16): the work a contact does
while its overlap grows, and what each of its two bodies counts of it (Eq. 4). Written once on
operators that Python floats and numpy arrays share, so both read paths (each.py, arrays.py) give
the same numbers to the last bit."""
from __future__ import annotations

import math

import numpy as np

from yadebreak import model


class HertzMindlinWork:
    """Eqs. 15-16 for YADE's Law2_ScGeom_MindlinPhys_Mindlin: the normal work while the overlap
    grows, with F = kno delta^1.5 + dashpot.

    The Hertz part is exact between two reads, 0.4 kno (d1^2.5 - d0^2.5); the dashpot part
    (total force minus kno d^1.5) by the trapezoidal rule, except from first touch, where
    Mindlin's dashpot grows like delta^(1/4) at a nearly constant rate: over k steps its work is
    (0.8 - 0.3 / k^2) F d (the trapezoid's 0.5 over one step, which is what YADE's leapfrog makes
    of it, 0.8 over many). Pairs whose kno varies (zeroed artificial overlaps) take the trapezoid
    on their total force.

    Each formula is written once, with operators that numpy arrays and Python floats share (the
    same operations in the same order: the same numbers to the last bit on either), and both
    read paths of ContactReader call it."""

    @staticmethod
    def first_touch_factor(interval):
        return 0.8 - 0.3 / interval ** 2

    @staticmethod
    def trapezoid(d0, f0, delta, force):
        """Work (J) of a force going from f0 to `force` (N) as the displacement goes d0 -> delta
        (m): the dashpot of zeroed pairs, and the shear work (Eq. 16)."""
        return 0.5 * (f0 + force) * (delta - d0)

    @staticmethod
    def from_overlap(d0, f0, kno, delta, force, sqrt):
        """Work (J) from overlap d0 > 0 (force f0) up to delta (> d0): the Hertz part exact, the
        dashpot part (force minus kno d^1.5) by the trapezoid. `sqrt`: math.sqrt on floats,
        np.sqrt on arrays."""
        el0 = kno * d0 * sqrt(d0)
        el1 = kno * delta * sqrt(delta)
        return 0.4 * (el1 * delta - el0 * d0) + 0.5 * (f0 - el0 + force - el1) * (delta - d0)

    @staticmethod
    def from_first_touch(kno, delta, force, first_touch, sqrt):
        """Work (J) from first touch up to delta: the Hertz part exact, the dashpot's
        first_touch F d (see first_touch_factor)."""
        el1 = kno * delta * sqrt(delta)
        return 0.4 * el1 * delta + first_touch * (force - el1) * delta

    @classmethod
    def loading(cls, d0, f0, kno, delta, force, first_touch):
        """Work (J) of a Hertz contact from overlap d0 (force f0) up to delta (> d0), over
        arrays of contacts (ContactReader._read_each calls from_overlap and from_first_touch on
        floats itself: a call less per contact)."""
        touching = d0 > 0.0
        if touching.all():                      # the usual case: one formula, no np.where
            return cls.from_overlap(d0, f0, kno, delta, force, np.sqrt)
        d0c = np.maximum(d0, 0.0)               # equal to d0 where the formula is taken
        return np.where(touching, cls.from_overlap(d0c, f0, kno, delta, force, np.sqrt),
                        cls.from_first_touch(kno, delta, force, first_touch, np.sqrt))

    @staticmethod
    def peaked(d0, delta, overlap_before, time_before, time_read):
        """The overlap fell since the last read (d0 at time_read) after rising from the read
        before (overlap_before at time_before): it peaked in between (floats or arrays)."""
        return (delta < d0) & (overlap_before < d0) & (time_read > time_before)

    @classmethod
    def past_peak(cls, d0, f0, kno, overlap_before, time_before, time_read, now, delta):
        """Work (J) of a contact that peaked between two reads (peaked()), up to the peak of
        the parabola through its last three overlaps (model.parabolic_peak); None when that
        peak is not above d0. Floats: a few contacts per impact, at sparse reads only."""
        peak = model.parabolic_peak(time_before, overlap_before, time_read, d0, now, delta)
        return cls.to_peak(d0, f0, kno, peak) if peak > d0 else None

    @staticmethod
    def to_peak(d0, f0, kno, peak):
        """Work (J) of a Hertz contact from d0 up to `peak` (> d0), where the overlap peaked
        between two reads (sparse reads; the peak from model.parabolic_peak)."""
        el0 = kno * d0 * math.sqrt(d0)
        return 0.4 * kno * (peak ** 2.5 - d0 ** 2.5) + 0.5 * (f0 - el0) * (peak - d0)

    @staticmethod
    def stored(kno, delta):
        """Elastic energy (J) held in a Hertz contact: 0.4 kno delta^2.5."""
        return 0.4 * kno * delta ** 2.5


def total_work(work, shear_work, cs):
    """A contact's counted work (J): normal work plus cs times its shear work (floats or
    arrays)."""
    return work + cs * shear_work if cs > 0.0 else work


def own_share(total, offset, share, emin):
    """One body's side of a contact: whether the work done since its offset (J) counts (at least
    emin), and its share (Eq. 4) of that work (J); floats or arrays."""
    own = total - offset
    return own >= emin, share * own
