"""hausdorff.Mesh and read_mesh: points to a triangle surface, correctly
rounded, the same at every thread count and for every vertex dtype; bad
meshes raise with the face named."""
import math
import pathlib

import numpy as np
import pytest

import hausdorff

DATA = pathlib.Path(__file__).resolve().parents[2] / "data" / "orig"
SQUARE = hausdorff.Mesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]])


def test_distances_to_the_face_an_edge_and_a_corner():
    r = SQUARE.distances([[0.25, 0.5, 2.0], [3.0, 0.5, 0.0], [4.0, 5.0, 0.0], [0.5, 0.5, 0.0]])
    assert r.distances.tolist() == [2.0, 2.0, 5.0, 0.0]
    assert r.faces.tolist() == [1, 0, 0, 0]  # (0.5, 0.5) lies on both: the smaller index
    assert r.closest[2].tolist() == [1.0, 1.0, 0.0]
    assert (r.distance, r.i, r.face) == (5.0, 2, 0)
    assert np.allclose(r.barycentric.sum(axis=1), 1.0)


def test_the_distance_is_correctly_rounded():
    # sqrt(2) to the corner (1, 1, 0) of the square from (2, 2, 0)
    r = SQUARE.distances([[2.0, 2.0, 0.0]])
    assert r.distances[0] == math.sqrt(2.0)


def test_threads_and_vertex_dtypes_do_not_change_a_bit():
    mesh = hausdorff.read_mesh(DATA / "pinion.off")
    rng = np.random.default_rng(3)
    lo, hi = mesh.vertices.min(0), mesh.vertices.max(0)
    pts = lo - (hi - lo) + 3 * (hi - lo) * rng.random((2000, 3))
    one = mesh.distances(pts, threads=1)
    three = mesh.distances(pts, threads=3)
    assert np.array_equal(one.distances, three.distances) and np.array_equal(one.faces, three.faces)
    f32 = hausdorff.Mesh(mesh.vertices.astype(np.float32), mesh.faces.astype(np.int32))
    wide = hausdorff.Mesh(mesh.vertices.astype(np.float32).astype(np.float64), mesh.faces)
    assert np.array_equal(f32.distances(pts).distances, wide.distances(pts).distances)
    ints = hausdorff.Mesh(np.round(mesh.vertices * 100).astype(np.int64), mesh.faces)
    flts = hausdorff.Mesh(np.round(mesh.vertices * 100), mesh.faces)
    assert np.array_equal(ints.distances(pts).distances, flts.distances(pts).distances)


def test_read_mesh_merges_stl_corners():
    stl, obj = hausdorff.read_mesh(DATA / "Wuson.stl"), hausdorff.read_mesh(DATA / "WusonOBJ.obj")
    assert stl.vertices.shape == obj.vertices.shape == (2117, 3)
    assert stl.faces.shape == obj.faces.shape == (3732, 3)


def test_bad_meshes_raise_with_the_face_named():
    with pytest.raises(ValueError, match="triangle 1 refers to vertex 4"):
        hausdorff.Mesh(SQUARE.vertices, [[0, 1, 2], [0, 1, 4]]).distances([[0, 0, 1]])
    with pytest.raises(ValueError, match="face 0 refers to vertex -1"):
        hausdorff.Mesh(SQUARE.vertices, [[0, 1, -1]]).distances([[0, 0, 1]])
    with pytest.raises(ValueError, match="triangle 0, corner 1"):
        hausdorff.Mesh([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]], [[0, 1, 2]]).distances([[0, 0, 1]])
    with pytest.raises(ValueError, match="no triangles"):
        hausdorff.Mesh(SQUARE.vertices, np.zeros((0, 3), int)).distances([[0, 0, 1]])
    with pytest.raises(ValueError, match="faces must be an"):
        hausdorff.Mesh(SQUARE.vertices, [[0.5, 1, 2]]).distances([[0, 0, 1]])
    with pytest.raises(ValueError, match="has no faces"):
        hausdorff.read_mesh(pathlib.Path(__file__).resolve().parents[2] / "data" / "pinion_gear.ply")
