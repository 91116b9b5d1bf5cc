"""What the engine remembers, as plain numbers: per-body state in numpy columns keyed by body id,
the event log and the fines ledger, with to_dict / from_dict for saving with the scene. No yade
import.

Classes of a body (`kind`): model/kinds.py, shared with the criteria.
"""
from __future__ import annotations

import json
import math
import os
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

import numpy as np

from yadebreak.model.kinds import BREAKABLE, BROKEN, DUMMY, KINDS, NONE, UNBREAKABLE  # noqa: F401

#: format of to_dict(); from_dict refuses others with a clear message
FORMAT_VERSION = 2


class Breakable(NamedTuple):
    """A breakable body found in the scene at attach: a sphere or a convex polyhedron."""
    id: int
    label: str            # its YADE material's label
    mass: float           # kg
    radius: float         # m: a sphere's; half a polyhedron's sieve size


#: the columns of every body table: column -> (dtype, value of a new row); energies J/kg,
#: event_max J, sizes m, mass kg. A criterion adds its own (Criterion.columns).
SHARED_COLUMNS = {
    "kind": (np.int8, NONE),
    "material": (np.int16, -1),            # index into BodyTable.labels
    "mass": (np.float64, 0.0),
    "radius": (np.float64, 0.0),
    "fracture_energy": (np.float64, math.inf),          # now, after damage (Tavares: E of Eq. 5)
    "fracture_energy_initial": (np.float64, math.inf),
    "damage": (np.float64, 0.0),                         # 1 - E / E_initial (Ab-T10: e_cum / E)
    "specific_energy": (np.float64, 0.0),                # Ek'/m at the last read
    "event_max": (np.float64, 0.0),                      # largest Ek' of the open event (J)
    "carried": (np.float64, 0.0),       # Ek' (J) a fragment took over from its parent's contacts
    "event_partner": (np.int64, -1),    # the body across the contact that brought most of it
    "cracked": (np.int8, 0),            # break_at="peak": passed its threshold, breaks at the peak
    "t10": (np.float64, math.nan),      # unbreakable: first would-be t10'; dummy: its event's
    "parent_size": (np.float64, math.nan),               # dummy: the parent's diameter
    "generation": (np.int32, 0),
    "pause_until": (np.int64, -1),      # no energy counted before this iteration (fresh fragments)
}


def assembled_columns(criteria):
    """The columns of a body table whose bodies these criteria judge: the shared ones and each
    criterion's own (a name two criteria declare must mean the same column)."""
    columns = dict(SHARED_COLUMNS)
    for criterion in criteria:
        for name, spec in criterion.columns.items():
            if columns.setdefault(name, spec) != spec:
                raise ValueError(f"body-table column {name!r}: {type(criterion).__name__} "
                                 f"declares {spec}, another part {columns[name]}")
    return columns


class BodyTable:
    """Per-body state in numpy columns indexed by body id (grown as bodies appear).

    `table[i]` is a BodyRow: a live view of body i's row (read and write by field name).
    It iterates like a dict {id: row} over the bodies yadebreak knows. `spec`: its columns,
    {name: (dtype, value of a new row)} (assembled_columns; default: the shared ones).
    """

    def __init__(self, labels=(), spec=None):
        self.labels = list(labels)            # material labels; `material` holds their index
        self.spec = dict(SHARED_COLUMNS if spec is None else spec)
        self.size = 0
        self.columns = {name: np.empty(0, dtype) for name, (dtype, _) in self.spec.items()}
        self.known = {}                       # id -> None, in the order bodies were adopted

    def _grow(self, top):
        if top < self.size:
            return
        size = max(top + 1, 2 * self.size, 64)
        for name, (dtype, fill) in self.spec.items():
            column = np.full(size, fill, dtype)
            column[:self.size] = self.columns[name][:self.size]
            self.columns[name] = column
        self.size = size

    def add(self, ids, kind, material, mass, radius, **values):
        """New rows for bodies `ids` (arrays or scalars broadcast), other fields at their
        defaults or from `values`."""
        ids = np.atleast_1d(np.asarray(ids, dtype=np.int64))
        if len(ids) == 0:
            return
        self._grow(int(ids.max()))
        c = self.columns
        for name, (_, fill) in self.spec.items():
            c[name][ids] = fill
        c["kind"][ids] = kind
        c["material"][ids] = self.labels.index(material) if isinstance(material, str) else material
        c["mass"][ids] = mass
        c["radius"][ids] = radius
        for name, value in values.items():
            c[name][ids] = value
        self.known.update(dict.fromkeys(ids.tolist()))

    def kind_of(self, i):
        return KINDS[self.columns["kind"][i]] if i in self.known else "none"

    def label_of(self, i):
        return self.labels[self.columns["material"][i]]

    # -- a dict of rows ----------------------------------------------------------------------
    def __contains__(self, i):
        return i in self.known

    def __len__(self):
        return len(self.known)

    def __iter__(self):
        return iter(self.known)

    def __getitem__(self, i):
        if i not in self.known:
            raise KeyError(i)
        return BodyRow(self, i)

    def get(self, i, default=None):
        return BodyRow(self, i) if i in self.known else default

    def items(self):
        return ((i, BodyRow(self, i)) for i in self.known)

    def values(self):
        return (BodyRow(self, i) for i in self.known)

    def ids(self):
        return np.fromiter(self.known, np.int64, len(self.known))

    # -- saving --------------------------------------------------------------------------------
    def to_dict(self):
        ids = self.ids()
        return {"labels": self.labels, "ids": ids.tolist(),
                "columns": {name: _listed(self.columns[name][ids]) for name in self.spec}}

    @classmethod
    def from_dict(cls, data, spec=None):
        """The table saved by to_dict, with the columns `spec` (see BodyTable): a saved column
        it lacks is not read, one it has that was not saved starts at its new-row value."""
        table = cls(data["labels"], spec)
        ids = np.asarray(data["ids"], dtype=np.int64)
        if len(ids):
            table._grow(int(ids.max()))
            for name, (dtype, _) in table.spec.items():
                if name not in data["columns"]:      # a column added since the state was saved
                    continue                          # (_grow filled it with its new-row value)
                table.columns[name][ids] = np.asarray(data["columns"][name], dtype=float).astype(dtype)
            table.known = dict.fromkeys(ids.tolist())
        return table


def _listed(values):
    """A column as a JSON-able list (inf and nan as strings JSON keeps)."""
    return [v if math.isfinite(v) else str(v) for v in values.tolist()]


class BodyRow:
    """A live view of one body's row: `row.fracture_energy = 1e3` writes the column."""

    __slots__ = ("_table", "id")

    def __init__(self, table, i):
        object.__setattr__(self, "_table", table)
        object.__setattr__(self, "id", i)

    def __getattr__(self, name):
        table = self._table
        if name == "kind":
            return KINDS[table.columns["kind"][self.id]]
        if name == "material":
            return table.label_of(self.id)
        try:
            return table.columns[name][self.id].item()
        except KeyError:
            raise AttributeError(name) from None

    def __setattr__(self, name, value):
        table = self._table
        if name == "kind":
            value = KINDS.index(value)
        elif name == "material":
            value = table.labels.index(value)
        elif name not in table.columns:
            raise AttributeError(name)
        table.columns[name][self.id] = value

    def as_dict(self):
        return {name: getattr(self, name) for name in self._table.spec}

    def __repr__(self):
        return f"BodyRow({self.id}, {self.as_dict()})"


class EventLog:
    """Every breakage and damage event, in memory and, when a path is given, appended to a
    JSON-lines file and flushed with the read that made it (held): a run that dies leaves its
    events."""

    #: while coupling.engine.run_steps steps the scene, a list: a write that fails (a full disk)
    #: is put there for run_steps to raise after the step, outside YADE's loop (an error raised
    #: inside a PyRunner comes out with YADE's traceback printed); the event stays in memory
    deferred = None

    def __init__(self, path=None, events=()):
        self.path = None if path is None else Path(path)
        self.events = list(events)
        self._file = None
        self._held = None                       # the lines of the events held (held())

    def start(self):
        """Begin a new log file (attach)."""
        if self.path is not None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.path.write_text("")

    def rewrite(self):
        """Make the file hold exactly the events in memory (after a restore)."""
        if self.path is not None:
            tmp = self.path.with_suffix(".tmp")
            try:
                tmp.write_text("".join(json.dumps(e) + "\n" for e in self.events))
                tmp.replace(self.path)
            finally:                                # a full disk leaves no half file
                tmp.unlink(missing_ok=True)

    @contextmanager
    def held(self):
        """The events recorded in the block are in memory at once and go to the file in one
        write and flush when it ends, even by an error: a read of a collisional cloud closes
        dozens of stressing events, and a write and a flush each cost more than the event."""
        if self.path is None or self._held is not None:
            yield
            return
        self._held = []
        try:
            yield
        finally:
            lines, self._held = self._held, None
            if lines:
                self._write("".join(lines))

    def record(self, event):
        self.events.append(event)
        if self.path is not None:
            line = json.dumps(event) + "\n"
            if self._held is not None:
                self._held.append(line)
            else:
                self._write(line)

    def _write(self, text):
        """Append whole lines `text` to the file; a write that fails leaves the file as it was."""
        whole = None
        try:
            if self._file is None:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                self._file = open(self.path, "a", buffering=1)
            whole = self._file.tell()
            self._file.write(text)
            self._file.flush()
        except OSError as exc:
            self._cut(whole)
            if EventLog.deferred is None:
                raise
            EventLog.deferred.append(exc)

    def _cut(self, size):
        """After a failed write: the file closed and cut back to its whole lines (`size` bytes;
        cutting needs no space on a full disk), so that it never ends in half an event."""
        file, self._file = self._file, None
        if file is None:
            return
        try:
            file.close()                 # flushes what is buffered: fails again on a full disk
        except OSError:
            pass
        if size is not None:
            try:
                os.truncate(self.path, size)
            except OSError:
                pass

    def close(self):
        if self._file is not None:
            self._file.close()
            self._file = None


class FinesLedger:
    """Dummy fines kept outside the DEM (dummies="ledger"): per entry its mass (kg), the parent's
    diameter (m), the event's t10' (%), material label and momentum (kg m/s)."""

    def __init__(self, entries=()):
        self.entries = [dict(e) for e in entries]

    def add(self, mass, parent_size, t10, material, momentum):
        self.entries.append({"mass": float(mass), "parent_size": float(parent_size),
                             "t10": float(t10), "material": material,
                             "momentum": [float(p) for p in momentum]})

    def __len__(self):
        return len(self.entries)

    def __iter__(self):
        return iter(self.entries)

    def total_mass(self):
        return sum(e["mass"] for e in self.entries)

    def kinetic_energy(self):
        """Kinetic energy (J) the fines carry: |p|^2 / 2m summed."""
        return sum(0.5 * sum(p * p for p in e["momentum"]) / e["mass"] for e in self.entries)

    def to_list(self):
        return [dict(e) for e in self.entries]


def check_format(data):
    """Refuse saved state of another format version, saying which."""
    version = data.get("format_version", 1)
    if version != FORMAT_VERSION:
        raise ValueError(f"saved yadebreak state has format version {version}; this yadebreak "
                         f"reads version {FORMAT_VERSION}: run the scene again from its start")


def _forgets_mask(name):
    """set's method `name`, after which the mask is built anew when next asked."""
    method = getattr(set, name)

    def changed(self, *args):
        result = method(self, *args)
        self._mask = None
        return result
    changed.__name__ = name
    return changed


class TrackedBodies(set):
    """The ids of the bodies the engine reads: a set that also keeps them as a mask by id, in
    step with every change (a numpy read asks for it each read; built from the set it would
    cost about 20 ns per body, 160 us a read at 8,000 bodies)."""

    def __init__(self, ids=()):
        super().__init__(ids)
        self._mask = None

    def add(self, i):
        set.add(self, i)
        mask = self._mask
        if mask is not None:
            if 0 <= i < len(mask):
                mask[i] = True
            else:
                self._mask = None

    def discard(self, i):
        set.discard(self, i)
        mask = self._mask
        if mask is not None and 0 <= i < len(mask):
            mask[i] = False

    def __reduce__(self):                    # a copy builds its own mask
        return TrackedBodies, (list(self),)

    def mask(self, n):
        """Which of the ids 0 .. n-1 are tracked (a read-only view)."""
        mask = self._mask
        if mask is None or len(mask) < n:
            ids = np.fromiter(self, np.int64, len(self))
            mask = np.zeros(max(n, int(ids.max()) + 1 if len(ids) else 0), bool)
            mask[ids] = True
            self._mask = mask
        view = mask[:n]
        view.flags.writeable = False
        return view


# every other change of the set: the mask is built anew when next asked
for _name in ("remove", "pop", "clear", "update", "difference_update", "intersection_update",
              "symmetric_difference_update", "__ior__", "__iand__", "__isub__", "__ixor__"):
    setattr(TrackedBodies, _name, _forgets_mask(_name))
del _name


class EngineState:
    """Everything an engine knows about its bodies, as plain numbers: the body table, which
    bodies are tracked (breakable, or unbreakable awaiting their t10') and which have an open
    stressing event, the event log, the fines ledger, the random stream, the top size (m) and
    the warnings given."""

    def __init__(self, labels, seed, event_log=None, columns=None):
        self.table = BodyTable(labels, columns)
        self.tracked = TrackedBodies()
        self.open_events = set()
        self.log = EventLog(event_log)
        self.ledger = FinesLedger()
        self.rng = np.random.default_rng(seed)
        self.top_size = 0.0
        self.warned = set()

    def total_mass(self):
        """Mass (kg) of every body known, fragments and ledger fines included, broken parents
        excluded (summed in the order bodies appeared)."""
        ids = self.table.ids()
        keep = self.table.columns["kind"][ids] != BROKEN
        return float(sum(self.table.columns["mass"][ids][keep].tolist()) + self.ledger.total_mass())

    def to_dict(self):
        return {"format_version": FORMAT_VERSION, "table": self.table.to_dict(),
                "tracked": sorted(self.tracked), "events": self.log.events,
                "ledger": self.ledger.to_list(), "rng": self.rng.bit_generator.state,
                "top_size": self.top_size, "warned": sorted(self.warned)}

    @classmethod
    def from_dict(cls, data, event_log=None, columns=None):
        """The state saved by to_dict; `columns`: its body table's (assembled_columns)."""
        check_format(data)
        self = cls(data["table"]["labels"], 0, event_log)
        self.table = BodyTable.from_dict(data["table"], columns)
        self.tracked = TrackedBodies(data["tracked"])
        # open events are those with an energy recorded (built in id order, as at any restore)
        event_max = self.table.columns["event_max"]
        self.open_events = {i for i in data["tracked"] if event_max[i] > 0.0}
        self.log = EventLog(event_log, data["events"])
        self.ledger = FinesLedger(data["ledger"])
        self.rng.bit_generator.state = data["rng"]
        self.top_size = data["top_size"]
        self.warned = set(data["warned"])
        return self
