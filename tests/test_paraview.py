"""The bed impact's ParaView series (issue 16): .pvd indexes and .vtp frames, read with xml.etree
as ParaView would read them (no ParaView needed) (YADE)."""
import argparse
import xml.etree.ElementTree as ET

import numpy as np
import pytest

pytestmark = pytest.mark.yade

INTERVAL = 1e-4                 # s of simulated time: about 11 frames in this 1.1 ms run
SPHERE_ARRAYS = {"id": 1, "radius": 1, "velocity": 3, "fracture_energy": 1, "damage": 1,
                 "class": 1, "generation": 1}


def _args(out, **changes):
    # 7 particles, 0.9 J: 4 breakages within 1.1 ms of simulated time, about 1.5 s
    values = dict(material="copper_ore", size=5.5e-3, rings=1, layers=1, energy=0.9, speed=0.0,
                  seed=5, time_step_fraction=0.05, dmin=0.0, global_damping="material",
                  dummies="ledger", read_period="fast", max_time=0.02, out=str(out),
                  vtk_interval=INTERVAL)
    values.update(changes)
    return argparse.Namespace(**values)


def read_pvd(path):
    """[(timestep, file)] of a .pvd collection."""
    return [(float(d.get("timestep")), d.get("file"))
            for d in ET.parse(path).getroot().iter("DataSet")]


def read_vtp(path):
    """(number of points, points (n, 3), {array name: values (n, components)}, cells {tag:
    (connectivity, offsets)}) of an ASCII .vtp file."""
    piece = ET.parse(path).getroot().find("PolyData/Piece")
    n = int(piece.get("NumberOfPoints"))

    def values(array):
        data = np.array((array.text or "").split(), dtype=float)
        return data.reshape(-1, int(array.get("NumberOfComponents", "1")))

    points = values(piece.find("Points/DataArray"))
    arrays = {a.get("Name"): values(a) for where in ("PointData", "CellData")
              for a in piece.findall(f"{where}/DataArray")}
    cells = {tag: tuple(values(a).ravel().astype(int) for a in piece.findall(f"{tag}/DataArray"))
             for tag in ("Verts", "Polys") if piece.find(tag) is not None}
    return n, points, arrays, cells


@pytest.fixture(scope="module")
def bed_run(tmp_path_factory):
    """One tiny bed impact with a frame every INTERVAL (the YADE scene reset before and after)."""
    from yade import O
    from yadebreak.jobs import bed
    from yadebreak import engine
    out = tmp_path_factory.mktemp("bed")
    engine.forget()
    O.reset()
    brk, summary = bed.run(_args(out), quiet=True)
    final_spheres = sorted(b.id for b in O.bodies if b is not None and hasattr(b.shape, "radius"))
    engine.forget()
    O.reset()
    return out, brk, summary, final_spheres


def test_frames_at_start_every_interval_and_at_the_end(bed_run):
    out, _, summary, _ = bed_run
    folder = out / "paraview"
    frames = read_pvd(folder / "spheres.pvd")
    times = [t for t, _ in frames]
    assert times[0] == 0.0 and times[-1] == pytest.approx(summary["simulated_time"], rel=1e-12)
    assert all(b > a for a, b in zip(times, times[1:]))
    # one frame per interval (checked every 100-400 steps) plus the start and the end
    assert summary["simulated_time"] / INTERVAL <= len(frames) <= summary["simulated_time"] / INTERVAL + 2
    assert len({f for _, f in frames}) == len(frames)
    assert all((folder / f).exists() for _, f in frames)
    # no stray frame files
    assert sorted(p.name for p in folder.glob("spheres_*.vtp")) == sorted(f for _, f in frames)
    assert [t for t, _ in read_pvd(folder / "surfaces.pvd")] == times


def test_every_sphere_with_its_state(bed_run):
    out, brk, summary, final_spheres = bed_run
    frames = read_pvd(out / "paraview" / "spheres.pvd")
    counts = []
    for _, name in frames:
        n, points, arrays, cells = read_vtp(out / "paraview" / name)
        assert points.shape == (n, 3) and np.all(np.isfinite(points))
        assert {k: v.shape for k, v in arrays.items()} == {k: (n, c) for k, c in SPHERE_ARRAYS.items()}
        connectivity, offsets = cells["Verts"]         # one vertex cell per sphere
        assert list(connectivity) == list(range(n)) and list(offsets) == list(range(1, n + 1))
        ids = arrays["id"].ravel()
        assert len(set(ids)) == n
        assert np.all(np.isfinite(arrays["velocity"]))
        classes = arrays["class"].ravel()
        assert set(classes) <= {0, 1, 2, 3}           # broken bodies (4) are gone from the scene
        assert list(classes).count(0) == 1            # the ball, a sphere yadebreak does not track
        assert arrays["radius"][classes == 0][0, 0] == pytest.approx(0.044)
        # breakable and unbreakable fragments have one (J/kg); the ball and dummies do not (-1)
        has_energy = (classes == 1) | (classes == 2)
        assert np.all(arrays["fracture_energy"][has_energy] > 0)
        assert np.all(arrays["fracture_energy"][~has_energy] == -1.0)
        assert np.all((arrays["damage"] >= 0) & (arrays["damage"] < 1))
        counts.append(n)
    assert counts[0] == 8                             # 7 particles and the ball
    # the last frame is the scene at the end, with the controller's state
    n, _, arrays, _ = read_vtp(out / "paraview" / frames[-1][1])
    assert sorted(arrays["id"].ravel().astype(int)) == final_spheres
    for i, cls, gen, energy in zip(arrays["id"].ravel().astype(int), arrays["class"].ravel(),
                                   arrays["generation"].ravel(), arrays["fracture_energy"].ravel()):
        row = brk.bodies.get(i)
        if row is not None:
            assert ("none", "breakable", "unbreakable", "dummy").index(row.kind) == cls
            assert row.generation == gen
            if row.kind in ("breakable", "unbreakable"):
                assert energy == pytest.approx(row.fracture_energy, rel=1e-9)
    # breakage shows: fragments replace their parents between frames
    assert summary["breakage_events"] > 0
    assert len(set(counts)) > 1 and arrays["generation"].max() >= 1


def test_anvil_is_a_square_under_the_bed(bed_run):
    out, _, _, _ = bed_run
    surfaces = {f for _, f in read_pvd(out / "paraview" / "surfaces.pvd")}
    assert len(surfaces) == 1                         # nothing moved: one file for every frame
    n, points, arrays, cells = read_vtp(out / "paraview" / surfaces.pop())
    connectivity, offsets = cells["Polys"]
    assert n == 4 and list(connectivity) == [0, 1, 2, 3] and list(offsets) == [4]
    assert list(arrays["id"].ravel()) == [0]          # the anvil, body 0
    assert np.all(points[:, 2] == 0.0)
    half = np.abs(points[:, :2]).max()
    assert np.all(np.isclose(np.abs(points[:, :2]), half))
    assert half > 1.5 * 5.5e-3                        # beyond the ring's particles' edges


def test_interval_zero_writes_no_series_and_a_bad_one_is_refused(scene, tmp_path):
    from yadebreak.jobs import paraview
    frames = paraview.series(tmp_path / "none", None, 0.0)
    frames()
    frames.close()
    assert not (tmp_path / "none").exists()
    with pytest.raises(ValueError, match=">= 0 s"):
        paraview.series(tmp_path / "bad", None, -1.0)



def test_polyhedra_are_written_face_by_face_with_their_bodies_fields(scene, tmp_path):
    """A scene with a rotated 10 mm cube and a tetrahedron: polyhedra_0000.vtp holds their 6 + 4
    faces over 8 + 4 points; the points of each body are where YADE has its vertices (their hull
    has the body's volume and its centroid at the body's position) and every face carries its
    body's id, volume and velocity; a sphere scene writes no polyhedra file."""
    from yade import Quaternion, polyhedra_utils, wrapper
    from yadebreak.jobs import paraview
    from yadebreak.model.cells import convex_polyhedron
    O = scene
    mat = wrapper.PolyhedraMat(young=1e9, poisson=0.25, density=2700.0)
    O.materials.append(mat)
    side = 0.01
    cube = polyhedra_utils.polyhedra(mat, v=[(x, y, z) for x in (0, side) for y in (0, side)
                                             for z in (0, side)])
    cube.state.ori = Quaternion((1.0, 2.0, 3.0), 0.7)
    cube.state.vel = (1.0, -2.0, 0.5)
    tetra = polyhedra_utils.polyhedra(mat, v=[(0.02, 0, 0), (0.03, 0, 0), (0.02, 0.01, 0),
                                              (0.02, 0, 0.01)])
    ids = [O.bodies.append(cube), O.bodies.append(tetra)]
    paraview.ParaviewSeries(tmp_path / "poly", None, 1e-3)
    piece = ET.parse(tmp_path / "poly" / "polyhedra_0000.vtp").getroot().find(".//Piece")
    assert (piece.get("NumberOfPolys"), piece.get("NumberOfPoints")) == ("10", "12")
    points = np.array(piece.find("Points/DataArray").text.split(), float).reshape(-1, 3)
    cells = {a.get("Name"): np.array(a.text.split(), float) for a in piece.find("CellData")}
    connectivity = np.array(piece.find("Polys/DataArray[@Name='connectivity']").text.split(), int)
    offsets = np.array(piece.find("Polys/DataArray[@Name='offsets']").text.split(), int)
    faces = np.split(connectivity, offsets[:-1])
    for bid in ids:
        body = O.bodies[bid]
        own = np.unique(np.concatenate([f for f, owner in zip(faces, cells["id"]) if owner == bid]))
        hull = convex_polyhedron(points[own])
        assert hull.volume == pytest.approx(body.shape.GetVolume(), rel=1e-9)
        assert np.allclose(hull.centroid, tuple(body.state.pos), rtol=0, atol=1e-12)
        mine = cells["id"] == bid
        assert np.all(cells["volume"][mine] == pytest.approx(body.shape.GetVolume(), rel=1e-9))
        velocity = cells["velocity"].reshape(-1, 3)[mine]
        assert np.allclose(velocity, tuple(body.state.vel))
    assert read_pvd(tmp_path / "poly" / "polyhedra.pvd") == [(0.0, "polyhedra_0000.vtp")]
    O.reset()
    paraview.ParaviewSeries(tmp_path / "spheres_only", None, 1e-3)
    assert not list((tmp_path / "spheres_only").glob("polyhedra*"))
