"""A ParaView time series of a YADE scene: the bodies of each shape that can break (engine/shapes/)
with yadebreak's state, walls and facets.

    frames = ParaviewSeries("out/run/paraview", brk, interval=2e-4)   # writes the first frame
    while running:
        coupling.run_steps(100)
        frames()                 # a frame whenever `interval` seconds of simulated time have passed
    frames.close()               # the last frame

Files (XML VTK in ASCII, so any XML parser reads them; docs/outputs.md lists every array):
  spheres.pvd, spheres_NNNN.vtp    one frame per file: a point with a vertex cell per sphere and
                                   its id, radius, velocity, fracture_energy, damage, class and
                                   generation (the ball is a sphere of class 0)
  polyhedra.pvd, polyhedra_NNNN.vtp   in scenes with polyhedra, from the first frame that has
                                   one: each polyhedron's faces as polygons, each face with its
                                   body's id, volume, velocity, fracture_energy, damage, class
                                   and generation (any other shape: <its plural>.pvd, as its
                                   Shape.frame draws it)
  surfaces.pvd, surfaces_NNNN.vtp  walls as square patches sized to the bed, facets as triangles;
                                   a new file only when they change (the bed's holder goes at the
                                   first touch), earlier frames name the same file
The .pvd indexes are rewritten after every frame, so a run that dies leaves a readable series.
Coupling layer: imports yade.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from yadebreak.scenes import view
from yadebreak.engine.shapes import SHAPES
from yadebreak.engine.state import NONE
from yadebreak.jobs.lifecycle import write_atomic

#: frames over a run's planned simulated time when no interval is given (bed.run: max_time / 20)
DEFAULT_FRAMES = 20
#: fracture_energy written for bodies that cannot break (ParaView's ASCII reader takes no inf/nan)
NO_FRACTURE_ENERGY = -1.0
#: margin of a wall's patch beyond the spheres it was sized to
WALL_MARGIN = 1.2


def series(folder, brk, interval, resume=False, **options):
    """A ParaviewSeries into `folder` every `interval` s of simulated time, or, for interval 0,
    a stand-in that writes nothing."""
    if interval < 0 or not math.isfinite(interval):
        raise ValueError(f"ParaView frame interval {interval!r}: accepted >= 0 s (0: no frames)")
    if interval == 0:
        return NoSeries()
    return ParaviewSeries(folder, brk, interval, resume=resume, **options)


class NoSeries:
    """What series() returns for interval 0: the same calls, nothing written."""

    def __call__(self):
        return False

    def close(self):
        pass


class ParaviewSeries:
    """Frames of the scene into `folder`, at start, every `interval` s of simulated time (checked
    at each call) and at close(). `brk` is the yadebreak controller (None: every sphere class 0).
    resume=True continues a series that a checkpointed run left: frames after the present
    simulated time are dropped, later ones appended. wall_patch: (centre (m, 3), half side (m))
    of the walls' square patches (walls are infinite planes); default: around yadebreak's spheres
    at the first frame. sphere_arrays: callable(ids) -> [(name, values, VTK type)], the spheres'
    own arrays in place of the controller's (the bonded agglomerate: damage ratio, fragment)."""

    def __init__(self, folder, brk, interval, resume=False, wall_patch=None, sphere_arrays=None):
        if not interval > 0:
            raise ValueError(f"ParaView frame interval {interval!r}: accepted > 0 s")
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.brk = brk
        self.interval = float(interval)
        self._wall_patch = wall_patch     # (centre, half side), or None until the first frame
        self._sphere_arrays = sphere_arrays
        self._surfaces = None             # ((points, polygons, ids), file) last written
        self.frames = []                  # (time, surfaces file)
        self.shape_frames = {}            # shape plural -> [(time, its file)], from its first
        if resume:
            self._keep_frames_until(view.now())
        else:
            self._remove_files(0)
        if not self.frames:
            self.write_frame()

    def __call__(self):
        """Write a frame if the next due time (see _next_due) has come; True if one was written."""
        if view.now() < self._next_due():
            return False
        self.write_frame()
        return True

    def close(self):
        """The last frame (unless one was written at this time). The .pvd indexes are complete
        after every frame: nothing else is left to close."""
        if not self.frames or self.frames[-1][0] < view.now():
            self.write_frame()

    def _next_due(self):
        """Frames fall due at start + k interval, k counted from the start of the series (not from
        the last frame, which a chunk of steps may have taken past its due time)."""
        start, last = self.frames[0][0], self.frames[-1][0]
        return start + (math.floor((last - start) / self.interval + 1e-9) + 1) * self.interval

    def write_frame(self):
        k, now = len(self.frames), float(view.now())
        for shape in SHAPES.values():
            self._shape_frame(shape, k, now)
        self.frames.append((now, self._surfaces_file()))
        write_atomic(self.folder / "surfaces.pvd", _pvd(self.frames))

    def _shape_frame(self, shape, k, now):
        """Frame k of one shape's bodies (Shape.frame: one pass over YADE's bodies, the rest in
        numpy), from the first frame on or from the first that has one (paraview_from_start)."""
        found = shape.frame(view.bodies())
        if found is None:
            return
        series = self.shape_frames.setdefault(shape.plural, [])
        if not len(found.ids) and not series and not shape.paraview_from_start:
            return
        name = f"{shape.plural}_{k:04d}.vtp"
        arrays = [("id", found.ids, "Int64"), *found.arrays, ("velocity", found.vel, "Float64")]
        if shape.paraview_from_start and self._sphere_arrays is not None:
            arrays += self._sphere_arrays(found.ids)
        else:
            columns = self._body_columns(found.ids)
            arrays += [("fracture_energy", columns["fracture_energy"], "Float64"),
                       ("damage", columns["damage"], "Float64"),
                       ("class", columns["class"], "Int32"),
                       ("generation", columns["generation"], "Int32")]
        if found.faces is None:
            text = _polydata(found.points, arrays, "PointData")
        else:
            text = _polydata(found.points, [(n, np.asarray(v)[found.owner], t)
                                            for n, v, t in arrays], "CellData", found.faces)
        write_atomic(self.folder / name, text)
        series.append((now, name))
        write_atomic(self.folder / f"{shape.plural}.pvd", _pvd(series))

    def _body_columns(self, ids):
        """fracture_energy, damage, class and generation of bodies `ids` from the controller's
        body table (class 0 and no fracture energy for bodies it does not know: the ball)."""
        n = len(ids)
        out = {"fracture_energy": np.full(n, NO_FRACTURE_ENERGY), "damage": np.zeros(n),
               "class": np.full(n, NONE, np.int32), "generation": np.zeros(n, np.int32)}
        if self.brk is None or n == 0:
            return out
        c = self.brk.bodies.columns
        inside = ids < len(c["kind"])     # the table grows with the ids it knows; rows beyond: none
        rows = ids[inside]
        energy = c["fracture_energy"][rows]
        out["fracture_energy"][inside] = np.where(np.isfinite(energy), energy, NO_FRACTURE_ENERGY)
        out["damage"][inside] = c["damage"][rows]
        out["class"][inside] = c["kind"][rows]
        out["generation"][inside] = c["generation"][rows]
        return out

    # -- walls and facets ----------------------------------------------------------------------
    def _surfaces_file(self):
        """The file of the walls and facets as they are now: the last one if nothing changed."""
        points, polys, ids = geometry = self._surface_geometry()
        if self._surfaces is not None:
            (last_points, last_polys, last_ids), name = self._surfaces
            if (last_polys == polys and np.array_equal(last_ids, ids)
                    and np.array_equal(last_points, points)):
                return name
        name = f"surfaces_{len({s for _, s in self.frames}):04d}.vtp"
        write_atomic(self.folder / name, _surfaces_vtp(geometry))
        self._surfaces = (geometry, name)
        return name

    def _surface_geometry(self):
        """(points (n, 3), polygons as lists of point indices, body id of each polygon)."""
        points, polys, ids = [], [], []
        for surface in view.surfaces():
            corners = surface.corners if surface.corners is not None else \
                self._wall_corners(surface.axis, surface.offset)
            polys.append(list(range(len(points), len(points) + len(corners))))
            points += [tuple(p) for p in corners]
            ids.append(surface.id)
        return (np.array(points, float).reshape(-1, 3), polys, np.array(ids, np.int64))

    def _wall_corners(self, axis, offset):
        """A wall's square patch (see wall_patch), in its plane (normal `axis`, at `offset`)."""
        u, v = [a for a in range(3) if a != axis]
        if self._wall_patch is None:
            self._wall_patch = self._patch_size()
        centre, half = self._wall_patch
        corners = []
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            p = np.array(centre, float)
            p[axis] = offset
            p[u] += su * half
            p[v] += sv * half
            corners.append(p)
        return corners

    def _patch_size(self):
        """(centre (3,), half side) of the walls' patches: the bounding box of yadebreak's spheres
        (all spheres if it knows none) with a margin."""
        ids, pos, _, radius = view.spheres()
        if not len(ids):
            return np.zeros(3), 1.0
        known = self._body_columns(ids)["class"] != NONE
        if known.any():
            pos, radius = pos[known], radius[known]
        low, high = (pos - radius[:, None]).min(axis=0), (pos + radius[:, None]).max(axis=0)
        return 0.5 * (low + high), WALL_MARGIN * 0.5 * float((high - low).max())

    # -- resuming ------------------------------------------------------------------------------
    def _keep_frames_until(self, now):
        """Reload the frames of an interrupted run written up to `now` (s); remove later ones."""
        self.frames = [(t, f) for t, f in _read_pvd(self.folder / "surfaces.pvd") if t <= now]
        for shape in SHAPES.values():
            kept = [(t, f) for t, f in _read_pvd(self.folder / f"{shape.plural}.pvd") if t <= now]
            if kept:
                self.shape_frames[shape.plural] = kept
        self._remove_files(len(self.frames), {f for _, f in self.frames})
        if self.frames:                   # surfaces unchanged since: that file goes on
            last = self.folder / self.frames[-1][1]
            geometry = self._surface_geometry()
            if last.is_file() and last.read_text() == _surfaces_vtp(geometry):
                self._surfaces = (geometry, last.name)

    def _remove_files(self, first_kept_out, surfaces_kept=()):
        """Frame files of an earlier run not in this series: each shape's frame k for k >=
        first_kept_out and surface files not kept (an older, longer run would otherwise leave
        stray frames)."""
        for shape in SHAPES.values():
            for path in self.folder.glob(f"{shape.plural}_*.vtp"):
                if int(path.stem.split("_")[1]) >= first_kept_out:
                    path.unlink()
            if first_kept_out == 0 and not shape.paraview_from_start:
                (self.folder / f"{shape.plural}.pvd").unlink(missing_ok=True)
        for path in self.folder.glob("surfaces_*.vtp"):
            if path.name not in surfaces_kept:
                path.unlink()


def _numbers(values, integer):
    flat = np.asarray(values).ravel().tolist()
    return " ".join(map(str, flat)) if integer else " ".join(f"{x:.10g}" for x in flat)


def _data_array(name, values, vtk_type):
    values = np.asarray(values)
    components = values.shape[1] if values.ndim == 2 else 1
    name_attr = f' Name="{name}"' if name else ""
    return (f'<DataArray type="{vtk_type}"{name_attr} NumberOfComponents="{components}" '
            f'format="ascii">{_numbers(values, vtk_type.startswith("Int"))}</DataArray>\n')


def _cells(tag, connectivity, offsets):
    return (f"<{tag}>\n" + _data_array("connectivity", connectivity, "Int64")
            + _data_array("offsets", offsets, "Int64") + f"</{tag}>\n")


def _polydata(points, arrays, where, polys=None):
    """A .vtp document: the points, each a vertex cell (polys None) or the polygons `polys`
    (lists of point indices), and `arrays` [(name, values, VTK type)] as PointData or CellData."""
    n = len(points)
    if polys is None:
        cells, n_verts, n_polys = _cells("Verts", np.arange(n), np.arange(1, n + 1)), n, 0
    else:
        connectivity = np.array([i for poly in polys for i in poly], np.int64)
        offsets = np.cumsum([len(poly) for poly in polys], dtype=np.int64)
        cells, n_verts, n_polys = _cells("Polys", connectivity, offsets), 0, len(polys)
    vectors = next((name for name, values, _ in arrays if np.ndim(values) == 2), None)
    data = "".join(_data_array(name, values, vtk_type) for name, values, vtk_type in arrays)
    return ('<?xml version="1.0"?>\n<VTKFile type="PolyData" version="1.0" '
            'byte_order="LittleEndian" header_type="UInt64">\n<PolyData>\n'
            f'<Piece NumberOfPoints="{n}" NumberOfVerts="{n_verts}" NumberOfLines="0" '
            f'NumberOfStrips="0" NumberOfPolys="{n_polys}">\n'
            f'<{where}' + (f' Vectors="{vectors}"' if vectors else "") + f'>\n{data}</{where}>\n'
            f'<Points>\n{_data_array("", points, "Float64")}</Points>\n{cells}'
            '</Piece>\n</PolyData>\n</VTKFile>\n')


def _surfaces_vtp(geometry):
    points, polys, ids = geometry
    return _polydata(points, [("id", ids, "Int64")], "CellData", polys)


def _pvd(frames):
    """The collection index: one DataSet per frame, timestep in seconds of simulated time."""
    entries = "".join(f'<DataSet timestep="{t!r}" group="" part="0" file="{name}"/>\n'
                      for t, name in frames)
    return ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" '
            f'byte_order="LittleEndian">\n<Collection>\n{entries}</Collection>\n</VTKFile>\n')


def _read_pvd(path):
    """[(timestep, file)] of a .pvd, [] if there is none."""
    if not Path(path).exists():
        return []
    return [(float(d.get("timestep")), d.get("file"))
            for d in ET.parse(path).getroot().iter("DataSet")]

