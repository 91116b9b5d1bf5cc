"""Size classes on the root-2 sieve series and the feed's mass in each (docs/grinding.md,
Section 1). Sizes in metres, masses in kg."""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from yadebreak.model import milling


class FeedError(ValueError):
    """A feed that the classes cannot hold (one line naming the option or file)."""


@dataclass(frozen=True)
class SizeClasses:
    """Classes between consecutive sieves (m, strictly descending): class k holds sizes in
    (sieves[k + 1], sieves[k]]. Mass below sieves[-1] is the fines, kept as one mass."""

    sieves: np.ndarray

    @property
    def count(self):
        return len(self.sieves) - 1

    @property
    def sizes(self):
        """Representative size of each class (m): the geometric mean of its sieves."""
        return np.sqrt(self.sieves[:-1] * self.sieves[1:])

    @property
    def fines_size(self):
        """Size (m) standing for the fines where a size is needed (capture): one class below."""
        return self.sieves[-1] ** 2 / self.sizes[-1]


def root2_classes(top_size, count):
    """`count` classes on the root-2 series below the sieve `top_size` (m)."""
    return SizeClasses(milling.size_classes(top_size, count))


def read_psd_csv(path):
    """A feed size distribution from a CSV with columns size_mm, passing_percent: (sizes m,
    passing %), sizes ascending. Raises FeedError (one line) on anything else."""
    path = Path(path)
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as exc:
        raise FeedError(f"--feed {path}: cannot be read ({exc.strerror})") from None
    if not rows or not {"size_mm", "passing_percent"} <= set(rows[0]):
        raise FeedError(f"--feed {path}: needs the columns size_mm,passing_percent")
    try:
        size = np.array([float(r["size_mm"]) for r in rows]) * 1e-3
        passing = np.array([float(r["passing_percent"]) for r in rows])
    except (TypeError, ValueError):
        raise FeedError(f"--feed {path}: size_mm and passing_percent must be numbers") from None
    order = np.argsort(size)
    size, passing = size[order], passing[order]
    if np.any(size <= 0) or np.any(np.diff(size) <= 0):
        raise FeedError(f"--feed {path}: size_mm must be positive and all different")
    if np.any(passing < 0) or np.any(passing > 100) or np.any(np.diff(passing) < 0):
        raise FeedError(f"--feed {path}: passing_percent must rise with size within 0-100 %")
    if passing[-1] != 100.0:
        raise FeedError(f"--feed {path}: passing_percent at the largest size is {passing[-1]:g}, "
                        "must be 100 (the top size of the feed)")
    return size, passing


def feed_top_sieve(feed):
    """The top sieve (m) for a feed: a single size d (m) is the geometric mean of its class,
    top = d 2^(1/4); a distribution's top is its smallest size passing 100 %."""
    if np.ndim(feed) == 0:
        return float(feed) * 2.0 ** 0.25
    size, passing = feed
    return float(size[np.argmax(passing >= 100.0)])


def feed_masses(classes, feed, total_mass):
    """(mass per class, fines mass) in kg for `total_mass` kg of feed: a single size (m) goes
    whole into its class; a distribution (sizes m ascending, passing %) is split by its passing
    at the sieves, interpolated linearly in passing against ln size (0 below its finest size)."""
    sieves = classes.sieves
    if np.ndim(feed) == 0:
        d = float(feed)
        if not sieves[-1] < d <= sieves[0]:
            raise FeedError(f"--feed = {1e3 * d:g} mm: outside the classes "
                            f"({1e3 * sieves[-1]:.4g}, {1e3 * sieves[0]:.4g}] mm")
        masses = milling.mass_in_classes([d], [total_mass], sieves)
        return masses, 0.0
    size, passing = feed
    at = np.interp(np.log(sieves), np.log(size), passing, left=0.0, right=100.0)
    if at[0] < 100.0:
        raise FeedError(f"--feed: {at[0]:.4g} % passes the top sieve {1e3 * sieves[0]:.4g} mm; "
                        "accepted 100 % (the feed's top size at or below it)")
    fractions = -np.diff(at) / 100.0
    return total_mass * fractions, total_mass * at[-1] / 100.0


def class_label(size_m):
    """A sieve size for tables and plots: mm, four significant digits."""
    return f"{1e3 * size_m:.4g}"


__all__ = ["SizeClasses", "FeedError", "root2_classes", "read_psd_csv", "feed_top_sieve",
           "feed_masses", "class_label"]
