"""Laboratory data files for calibration: CSV with a header row, the kind told from the columns.

Kinds and their columns (docs/calibration.md), SI or with the unit in the column's name:
- fracture: size, energy (one particle a row; optional `broken`, 0 = survived the energy given);
- t10: size, energy, t10;
- repeated: size, energy, impact, tested, broken;
- progeny: t10, n, passing.
Every value is checked as it is read: a bad one raises DataError naming the file, the line and the
column. Model layer: no YADE.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from yadebreak import model
from yadebreak.model.intervals import PARTICLE_SIZE, SPECIFIC_ENERGY, InputError

#: column name (lower case) -> (quantity, factor to the unit used here: mm, J/kg, %, J, kg)
COLUMNS = {
    "size_mm": ("size", 1.0), "size_m": ("size", 1e3), "size": ("size", 1e3),
    "energy_j_per_kg": ("energy", 1.0), "energy": ("energy", 1.0),
    "energy_j": ("energy_j", 1.0), "mass_kg": ("mass", 1.0), "mass_g": ("mass", 1e-3),
    "t10_percent": ("t10", 1.0), "t10": ("t10", 100.0),
    "passing_percent": ("passing", 1.0), "passing": ("passing", 100.0),
    "broken": ("broken", 1.0), "impact": ("impact", 1.0), "tested": ("tested", 1.0),
    "n": ("n", 1.0),
}
#: kind -> the quantities that make it (checked in this order: the first whose set is present)
KINDS = {
    "progeny": ("t10", "n", "passing"),
    "repeated": ("size", "energy", "impact", "tested", "broken"),
    "t10": ("size", "energy", "t10"),
    "fracture": ("size", "energy"),
}
ACCEPTED = ("fracture energies: size_mm,energy_J_per_kg[,broken]; t10: size_mm,energy_J_per_kg,"
            "t10_percent; repeated impacts: size_mm,energy_J_per_kg,impact,tested,broken; "
            "progeny: t10_percent,n,passing_percent")


class DataError(InputError):
    """A data file that cannot be used: the message names the file, the line and the column."""

    def __init__(self, path, line, column, message):
        self.path, self.line, self.column = str(path), line, column
        where = f"{self.path}" + (f", line {line}" if line else "") + \
            (f", column '{column}'" if column else "")
        super().__init__(f"{where}: {message}")


@dataclass(frozen=True)
class Table:
    """One data file: its kind and its columns (quantities in mm, J/kg, %), with each row's line."""
    path: str
    kind: str
    columns: dict
    lines: np.ndarray
    names: dict            # quantity -> the column's name as written in the file

    def __len__(self):
        return len(self.lines)

    def column_name(self, quantity):
        return self.names.get(quantity, quantity)

    def subset(self, rows):
        """The same table restricted to the rows `rows` (an index array): bootstrap resamples."""
        return Table(self.path, self.kind, {k: v[rows] for k, v in self.columns.items()},
                     self.lines[rows], self.names)


def read_table(path):
    """Read and check one CSV file; returns a Table. Raises DataError."""
    path = Path(path)
    try:
        text_lines = path.read_text(encoding="utf-8-sig").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(path, None, None, f"cannot be read ({exc})") from None
    rows = [(k + 1, r) for k, r in enumerate(csv.reader(text_lines))
            if r and not r[0].lstrip().startswith("#") and any(c.strip() for c in r)]
    if not rows:
        raise DataError(path, None, None, f"empty: a header row is needed ({ACCEPTED})")
    header_line, header = rows[0]
    quantities, names = {}, {}
    for k, name in enumerate(header):
        key = name.strip().lower()
        if key not in COLUMNS:
            raise DataError(path, header_line, name.strip(), "unknown column (accepted: "
                            f"{', '.join(COLUMNS)}; {ACCEPTED})")
        quantity, factor = COLUMNS[key]
        if quantity in quantities:
            raise DataError(path, header_line, name.strip(), f"a second column of {quantity}")
        quantities[quantity] = (k, factor)
        names[quantity] = name.strip()
    if "energy_j" in quantities:
        if "mass" not in quantities:
            raise DataError(path, header_line, names["energy_j"], "an energy in J needs a "
                            "mass column (mass_kg or mass_g) to give J/kg")
        if "energy" in quantities:
            raise DataError(path, header_line, names["energy_j"], "give energy_J_per_kg or "
                            "energy_J with the mass, not both")
    present = set(quantities) | ({"energy"} if "energy_j" in quantities else set())
    kind = next((k for k, need in KINDS.items() if set(need) <= present), None)
    if kind is None:
        raise DataError(path, header_line, None, f"columns {', '.join(header)} make no known "
                        f"kind of data (accepted: {ACCEPTED})")
    body = rows[1:]
    if not body:
        raise DataError(path, header_line + 1, None, "no data rows after the header")
    values = {q: np.empty(len(body)) for q in quantities}
    for i, (line, row) in enumerate(body):
        if len(row) != len(header):
            raise DataError(path, line, None, f"{len(row)} values for {len(header)} columns")
        for q, (k, factor) in quantities.items():
            cell = row[k].strip()
            try:
                v = float(cell)
            except ValueError:
                raise DataError(path, line, names[q], f"{cell!r} is not a number") from None
            if not np.isfinite(v):
                raise DataError(path, line, names[q], f"{cell!r}: must be a finite number")
            values[q][i] = v * factor
    lines = np.array([line for line, _ in body])
    if "energy_j" in values:
        values["energy"] = values.pop("energy_j") / np.where(values["mass"] > 0, values["mass"],
                                                               np.nan)
        names["energy"] = names["energy_j"]
    table = Table(str(path), kind, values, lines, names)
    _CHECKS[kind](table)
    return table


def _bad(table, rows, quantity, message):
    """Raise DataError at the first row of the boolean mask `rows`, if any."""
    rows = np.asarray(rows)
    if rows.any():
        i = int(np.argmax(rows))
        value = table.columns[quantity][i] if quantity in table.columns else None
        shown = f"{value:g}: " if value is not None and np.isfinite(value) else ""
        raise DataError(table.path, int(table.lines[i]), table.column_name(quantity),
                        shown + message)


def _check_positive(table, quantity, unit):
    _bad(table, ~(table.columns[quantity] > 0), quantity, f"must be > 0 ({unit})")


def _check_common(table):
    if "mass" in table.columns:
        _check_positive(table, "mass", "kg")
    _check_positive(table, "size", "mm")
    _check_positive(table, "energy", "J/kg")
    within(table, "size", PARTICLE_SIZE.scaled(1e-3), "mm")
    within(table, "energy", SPECIFIC_ENERGY, "J/kg")


def within(table, quantity, interval, unit, why=""):
    """Every value of `quantity` in `interval` (its unit `unit`), or DataError at the first."""
    values = table.columns[quantity]
    _bad(table, ~np.array([v in interval for v in values], bool), quantity,
         f"must be {interval} ({unit}){why}")


def _check_fracture(table):
    _check_common(table)
    if "broken" in table.columns:
        b = table.columns["broken"]
        _bad(table, (b != 0) & (b != 1), "broken", "must be 1 (broke at this energy) or 0 (did "
             "not break up to this energy: censored)")
    broken = table.columns.get("broken", np.ones(len(table)))
    for size in np.unique(table.columns["size"]):
        rows = table.columns["size"] == size
        if not (broken[rows] == 1).any():
            _bad(table, rows, "size", "this size class has no broken particle: nothing to fit "
                 "(an empty class)")


def _check_t10(table):
    _check_common(table)
    t = table.columns["t10"]
    _bad(table, ~((t > 0) & (t < 100)), "t10", "must be in (0, 100) %")


def _check_repeated(table):
    _check_common(table)
    c = table.columns
    for q in ("impact", "tested", "broken"):
        _bad(table, (c[q] != np.round(c[q])) | (c[q] < 0), q, "must be a whole number >= 0")
    _bad(table, c["impact"] < 1, "impact", "impact numbers start at 1")
    _bad(table, c["tested"] < 1, "tested", "must be >= 1 (particles tested at this impact)")
    _bad(table, c["broken"] > c["tested"], "broken", "more broken than tested")
    for key in sorted(set(zip(c["size"], c["energy"]))):
        rows = np.flatnonzero((c["size"] == key[0]) & (c["energy"] == key[1]))
        order = rows[np.argsort(c["impact"][rows], kind="stable")]
        impacts = c["impact"][order]
        mask = np.zeros(len(table), bool)
        if not np.array_equal(impacts, np.arange(1, len(order) + 1)):
            k = int(np.argmax(impacts != np.arange(1, len(order) + 1)))
            mask[order[k]] = True
            _bad(table, mask, "impact", f"the impacts of {key[0]:g} mm at {key[1]:g} J/kg must "
                 "be numbered 1, 2, 3, ... once each")
        survivors = c["tested"][order][:-1] - c["broken"][order][:-1]
        worse = c["tested"][order][1:] > survivors
        if worse.any():
            mask[order[1:][worse][0]] = True
            _bad(table, mask, "tested", "more tested than survived the impact before")


def _check_progeny(table):
    c = table.columns
    _bad(table, ~((c["t10"] > 0) & (c["t10"] < 100)), "t10", "must be in (0, 100) %")
    _bad(table, ~((c["passing"] >= 0) & (c["passing"] <= 100)), "passing",
         "must be in [0, 100] %")
    known = np.isin(c["n"], model.N_VALUES)
    _bad(table, ~known, "n", "not one of Eq. 10's n: " + ", ".join(f"{n:g}" for n in
                                                                   model.N_VALUES))
    for t10 in np.unique(c["t10"]):
        rows = np.flatnonzero(c["t10"] == t10)
        order = rows[np.argsort(c["n"][rows], kind="stable")]
        mask = np.zeros(len(table), bool)
        dup = np.diff(c["n"][order]) == 0
        rising = np.diff(c["passing"][order]) > 0
        for bad, what in ((dup, "a second row for this n at this t10"),
                          (rising, "sizes out of order: passing 1/n of the size must not grow "
                           "with n (a finer sieve passes less)")):
            if bad.any():
                mask[order[1:][bad][0]] = True
                _bad(table, mask, "n" if what.startswith("a second") else "passing", what)
    for n in model.N_VALUES:
        if 0 < np.count_nonzero(c["n"] == n) < 3:
            _bad(table, c["n"] == n, "n", "fewer than 3 t10 values for this n: alpha and beta "
                 "(Eq. 10) need at least 3")


_CHECKS = {"fracture": _check_fracture, "t10": _check_t10, "repeated": _check_repeated,
           "progeny": _check_progeny}


def read_tables(paths):
    """Read every file; returns {kind: [Table, ...]}."""
    out = {}
    for p in paths:
        table = read_table(p)
        out.setdefault(table.kind, []).append(table)
    return out


def concat(tables):
    """One Table of several of the same kind (their rows keep their own file and line)."""
    if len(tables) == 1:
        return tables[0]
    cols = {q: np.concatenate([t.columns[q] for t in tables]) for q in tables[0].columns
            if all(q in t.columns for t in tables)}
    return Table(" + ".join(t.path for t in tables), tables[0].kind, cols,
                 np.concatenate([t.lines for t in tables]), tables[0].names)
