"""The mesh covers cached on disk (robots.cell.mesh_cover_cache): a second build reads the file and gives the
same arrays; a file whose cover does not hold its mesh (a sphere or a cylinder shrunk, a cylinder naming a
missing sphere), of the wrong shapes or types, or truncated, is refused and built again — never used
(docs/files.md: caches cannot change a verdict)."""

from __future__ import annotations

import numpy as np
import pytest

from pinarms.robots.cell import mesh_cover, mesh_cover_cache
from pinarms.robots.cell.mesh_cover_cache import cached_mesh_parts, holds_mesh

COUNT = 16
EDGE = 0.03  # m: pieces cut coarser than the cells' (fewer pieces, a quicker build; the same code)
NAMES = ("centres", "radii", "a", "b", "rad", "sphere", "owner")


def _link_mesh() -> tuple[np.ndarray, np.ndarray]:
    """A closed link 0.3 m long: a tube of radius 40 mm with a housing of 60 mm at one end (seeded jitter)."""
    n, rings = 24, 13
    z = np.linspace(0.0, 0.3, rings)
    r = np.where(z < 0.08, 0.06, 0.04)
    phi = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    V = np.column_stack([np.outer(r, np.cos(phi)).ravel(), np.outer(r, np.sin(phi)).ravel(), np.repeat(z, n)])
    V += np.random.default_rng(7).normal(0.0, 1e-3, V.shape)
    T = []
    for i in range(rings - 1):
        for j in range(n):
            a, b, c, d = i * n + j, i * n + (j + 1) % n, (i + 1) * n + j, (i + 1) * n + (j + 1) % n
            T += [(a, b, d), (a, d, c)]
    V = np.vstack([V, [[0.0, 0.0, 0.0], [0.0, 0.0, 0.3]]])
    bottom, top = len(V) - 2, len(V) - 1
    T += [(bottom, (j + 1) % n, j) for j in range(n)]
    T += [(top, (rings - 1) * n + j, (rings - 1) * n + (j + 1) % n) for j in range(n)]
    return V, np.array(T, dtype=np.int64)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty cache folder, every build written, and a count of the builds (the real one each time)."""
    monkeypatch.setenv("PINARMS_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(mesh_cover_cache, "MIN_SECONDS", 0.0)
    builds = []
    real = mesh_cover.mesh_parts_owned

    def counted(*args, **kw):
        builds.append(1)
        return real(*args, **kw)

    monkeypatch.setattr(mesh_cover, "mesh_parts_owned", counted)
    return tmp_path / "mesh_covers", builds


def _file(folder):
    files = list(folder.glob("*.npz"))
    assert len(files) == 1
    return files[0]


def _assert_same(got, want):
    assert len(got) == len(want) == 6
    for g, w in zip(got, want):
        assert g.dtype == w.dtype
        np.testing.assert_array_equal(g, w)


def test_a_second_build_reads_the_file_and_gives_the_same_arrays(cache):
    folder, builds = cache
    V, T = _link_mesh()
    first = cached_mesh_parts(V, T, COUNT, EDGE)
    assert len(builds) == 1 and _file(folder).stat().st_size > 0
    second = cached_mesh_parts(V, T, COUNT, EDGE)
    assert len(builds) == 1  # read, not built
    _assert_same(second, first)
    _assert_same(first, mesh_cover.mesh_parts(V, T, COUNT, EDGE))
    assert holds_mesh(mesh_cover.mesh_parts_owned(V, T, COUNT, EDGE), V, T, COUNT, EDGE)


def test_another_mesh_or_count_is_another_file(cache):
    folder, builds = cache
    V, T = _link_mesh()
    cached_mesh_parts(V, T, COUNT, EDGE)
    cached_mesh_parts(V * 1.01, T, COUNT, EDGE)
    cached_mesh_parts(V, T, COUNT - 4, EDGE)
    assert len(builds) == 3 and len(list(folder.glob("*.npz"))) == 3


def _shrink_sphere(cover):
    centres, radii, *rest = cover
    radii = radii.copy()
    radii[int(np.argmax(radii))] *= 0.9  # the mesh pokes out of it
    return (centres, radii, *rest)


def _shrink_cylinder(cover):
    *head, rad, sphere, owner = cover
    rad = rad.copy()
    rad[int(np.argmax(rad))] *= 0.95
    return (*head, rad, sphere, owner)


def _move_sphere(cover):
    centres, *rest = cover
    centres = centres.copy()
    centres[0, 0] += 0.01
    return (centres, *rest)


def _wrong_sphere_index(cover):
    *head, sphere, owner = cover
    sphere = sphere.copy()
    sphere[0] = len(cover[1])
    return (*head, sphere, owner)


def _drop_a_cylinder(cover):
    centres, radii, a, b, rad, sphere, owner = cover
    return centres, radii, a[:-1], b[:-1], rad[:-1], sphere[:-1], owner  # its pieces name no cylinder


def _wrong_owner(cover):
    *head, owner = cover
    owner = owner.copy()
    owner[owner == 0] = len(cover[4]) - 1  # the first cylinder's pieces said to lie in the last one
    return (*head, owner)


def _short_owner(cover):
    *head, owner = cover
    return (*head, owner[:-1])


def _wrong_shape(cover):
    centres, *rest = cover
    return (centres[:, :2], *rest)


def _wrong_type(cover):
    *head, sphere, owner = cover
    return (*head, sphere.astype(np.float64), owner)


def _not_finite(cover):
    centres, radii, *rest = cover
    radii = radii.copy()
    radii[0] = np.inf
    return (centres, radii, *rest)


@pytest.mark.parametrize("poison", [_shrink_sphere, _shrink_cylinder, _move_sphere, _wrong_sphere_index,
                                    _drop_a_cylinder, _wrong_shape, _wrong_type, _not_finite, _wrong_owner,
                                    _short_owner])
def test_a_poisoned_file_is_refused_and_built_again(cache, poison):
    folder, builds = cache
    V, T = _link_mesh()
    good = cached_mesh_parts(V, T, COUNT, EDGE)
    path = _file(folder)
    with np.load(path) as z:
        stored = tuple(np.array(z[k]) for k in NAMES)
    assert holds_mesh(stored, V, T, COUNT, EDGE)
    bad = poison(stored)
    assert not holds_mesh(bad, V, T, COUNT, EDGE)
    np.savez(path, **dict(zip(NAMES, bad)))
    got = cached_mesh_parts(V, T, COUNT, EDGE)
    assert len(builds) == 2  # refused: built again
    _assert_same(got, good)
    _assert_same(cached_mesh_parts(V, T, COUNT, EDGE), good)  # and overwritten with the good cover
    assert len(builds) == 2


def test_a_truncated_or_foreign_file_is_refused_and_built_again(cache):
    folder, builds = cache
    V, T = _link_mesh()
    good = cached_mesh_parts(V, T, COUNT, EDGE)
    path = _file(folder)
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    _assert_same(cached_mesh_parts(V, T, COUNT, EDGE), good)
    assert len(builds) == 2
    path.write_bytes(b"not an archive")
    _assert_same(cached_mesh_parts(V, T, COUNT, EDGE), good)
    assert len(builds) == 3


def test_a_cover_of_more_spheres_than_asked_or_of_other_pieces_is_refused():
    V, T = _link_mesh()
    cover = mesh_cover.mesh_parts_owned(V, T, COUNT, EDGE)
    assert holds_mesh(cover, V, T, COUNT, EDGE)
    assert not holds_mesh(cover, V, T, len(cover[1]) - 1, EDGE)
    assert not holds_mesh(cover, V, T, COUNT, EDGE / 2)  # other pieces: the owners do not fit
    assert not holds_mesh(cover[:6], V, T, COUNT, EDGE)


def test_a_mesh_is_read_once_per_object_and_again_when_its_vertices_change():
    """mesh_arrays keeps a coal mesh's arrays (a Python call per triangle): the same arrays for the same
    object, read-only; another object or changed vertices read again."""
    import coal

    from pinarms.robots.cell.mesh_cover import mesh_arrays

    V, T = _link_mesh()

    def model(V):
        m = coal.BVHModelOBBRSS()
        m.beginModel(len(T), len(V))
        m.addVertices(V)
        m.addTriangles(T)
        m.endModel()
        return m

    geo = model(V)
    first = mesh_arrays(geo)
    np.testing.assert_array_equal(first[0], V)
    np.testing.assert_array_equal(first[1], T)
    assert mesh_arrays(geo)[1] is first[1]  # kept
    holder = coal.CollisionObject(geo)
    assert mesh_arrays(holder.collisionGeometry())[1] is first[1]  # another Python wrapper of the same mesh
    with pytest.raises(ValueError):
        first[0][0, 0] = 1.0  # read-only: a caller cannot change the kept copy
    geo.beginReplaceModel()
    geo.replaceVertex(V[0] + 0.01)
    for v in V[1:]:
        geo.replaceVertex(v)
    geo.endReplaceModel(True, True)
    moved = mesh_arrays(geo)
    np.testing.assert_array_equal(moved[0][0], V[0] + 0.01)
    other = mesh_arrays(model(V * 2.0))
    np.testing.assert_array_equal(other[0], V * 2.0)
