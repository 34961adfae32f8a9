"""The distance tables of pairs close in the chain (robots.cell.pair_tables): every bound below coal's exact
distance on 2 000 seeded random joint values per table, the compiled lookup equal to the numpy one, the
cover with tables never clearing a state the exact check finds closer than the margin, the per-pair and
whole-state screens and the excess agreeing, and the disk cache checked."""

from __future__ import annotations

from pathlib import Path

import coal
import numpy as np
import pytest
from pinarms.optim.motion import MotionChecker, load_scene
from pinarms.robots.cell import pair_tables as pt
from pinarms.robots.cell.cover_kernel import _fk, table_low
from pinarms.robots.cell.cover import link_cover, pair_arrays

N = 2000


@pytest.fixture(scope="module")
def ur5():
    cell = load_scene("ur5_table_box")
    cover = link_cover(cell)
    return cell, cover


def _frames(cover, q):
    nj = cover.fk[0].shape[0]
    R, p = np.empty((nj, 3, 3)), np.empty((nj, 3))
    _fk(np.ascontiguousarray(q, dtype=float), *cover.fk, R, p)
    return R, p


def _angles(cell, tables, t, Q):
    bp = cell._placements
    out = np.zeros((Q.shape[0], 2))
    for i, j in enumerate(tables.joint[t]):
        if j >= 0:
            out[:, i] = bp.scale[j] * Q[:, bp.index[j]] + bp.offset[j]
    return out


def test_the_ur5_pairs_close_in_the_chain_get_tables(ur5):
    cell, cover = ur5
    names = [o.name for o in cell.collision_model.geometryObjects]
    got = {frozenset((names[a], names[b])) for a, b in zip(cover.tables.pair_a, cover.tables.pair_b)}
    for a, b in (("forearm", "wrist_2"), ("wrist_1", "wrist_3"), ("base", "upper_arm")):
        assert frozenset((f"ur5_{a}_link_0", f"ur5_{b}_link_0")) in got
    # three joints apart, or a fixture (a table would be built again for every base placement): no table
    assert frozenset(("ur5_forearm_link_0", "ur5_wrist_3_link_0")) not in got
    assert frozenset(("ur5_upper_arm_link_0", "table_0")) not in got
    assert cover.tables.low.size == cover.tables.child.size > 0


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["ur5_table_box", "ur5_shelf"])
def test_every_table_bound_stays_below_coal_on_random_joint_values(scene):
    """On the shelf the UR5 stands on a pedestal: its tables, built for the table's placement, serve it too."""
    cell = load_scene(scene)
    cover = link_cover(cell)
    tables = cover.tables
    objs = cell.collision_model.geometryObjects
    rng = np.random.default_rng(11)
    Q = rng.uniform(-np.pi, np.pi, (N, cell.lower.size))
    req = coal.DistanceRequest()
    positive = 0
    for t in range(tables.pair_a.size):
        a, b = int(tables.pair_a[t]), int(tables.pair_b[t])
        bound = tables.bound(t, _angles(cell, tables, t, Q))
        for i, q in enumerate(Q):
            R, p = _frames(cover, q)
            if i < 200:
                assert table_low(R, tables.arrays(), t) == bound[i]  # the compiled lookup finds the same cell
            T = []
            for g in (a, b):
                o, j = objs[g], int(objs[g].parentJoint)
                T.append(coal.Transform3s(R[j] @ o.placement.rotation, R[j] @ o.placement.translation + p[j]))
            d = coal.distance(objs[a].geometry, T[0], objs[b].geometry, T[1], req, coal.DistanceResult())
            assert bound[i] <= max(d, 0.0) + 1e-9, (objs[a].name, objs[b].name, q, bound[i], d)
        positive += int((bound > 0.0).sum())
    assert positive > N  # the tables prove something


@pytest.fixture(scope="module")
def near_contact(ur5):
    """Seeded random UR5 states (many near contact: the UR5's own links are a few mm apart) and the checker."""
    cell, _ = ur5
    ch = MotionChecker(cell, ["ur5"])
    return ch, ch.full(cell.random_q(1000, seed=5)[:, ch.cols])


def test_the_cover_with_tables_never_clears_a_state_closer_than_the_margin(ur5, near_contact):
    _, cover = ur5
    ch, Q = near_contact
    pairs = cover.prepare(*pair_arrays(ch.pairs))
    proven = cover.screen(Q, pairs, ch.pair_margin)
    collides = ch.coal_collides(Q, "margin")
    assert collides.sum() > 100 and proven.sum() > 100  # both kinds well represented
    assert not np.any(proven & collides)
    # the per-pair screen: a pair it proves is farther than its margin (coal, pair by pair)
    per_pair = cover.pair_screen(Q, pairs, ch.pair_margin)
    np.testing.assert_array_equal(per_pair.all(axis=1), proven)
    # the excess: positive exactly where the screen proves (lower bounds of the same distances)
    excess = cover.excess(Q, pairs, ch.pair_margin)
    assert np.all(excess[proven] > 0.0) and not np.any(excess[~proven] > 0.0)


def test_tables_only_raise_the_excess(ur5, near_contact):
    _, cover = ur5
    ch, Q = near_contact
    from dataclasses import replace

    bare = replace(cover, tables=pt.no_tables())
    pairs = cover.prepare(*pair_arrays(ch.pairs))
    bare_pairs = bare.prepare(*pair_arrays(ch.pairs))
    assert np.all(bare_pairs.table == -1) and np.any(pairs.table >= 0)
    with_t = cover.excess(Q[:500], pairs, ch.pair_margin)
    without = bare.excess(Q[:500], bare_pairs, ch.pair_margin)
    assert np.all(with_t >= without - 1e-12)
    assert np.mean(with_t > 0) > np.mean(without > 0) + 0.2  # the UR5's close pairs: most clear states now proven


def test_the_disk_cache_round_trips_and_rejects_a_bad_file(ur5, tmp_path, monkeypatch):
    cell, _ = ur5
    monkeypatch.setenv("PINARMS_CACHE_DIR", str(tmp_path))
    objs = cell.collision_model.geometryObjects
    names = [o.name for o in objs]
    a, b = names.index("ur5_wrist_1_link_0"), names.index("ur5_ee_link_0")
    (found,) = [f for f in pt.table_paths(cell, [(a, b)])]
    table = pt.build_table(cell, *found)
    key = "0" * 64
    pt._save(key, table)
    got = pt._load(key)
    for k in pt._FIELDS:
        np.testing.assert_array_equal(got[k], table[k])
    bad = dict(table, child=np.full_like(table["child"], 0))  # children pointing backwards
    pt._save(key, bad)
    assert pt._load(key) is None
    (tmp_path / "pair_tables" / f"{key}.npz").write_bytes(b"not an npz")
    assert pt._load(key) is None


def test_the_cache_lives_in_the_users_cache_folder_keyed_by_the_code_that_built_it(ur5, tmp_path, monkeypatch):
    """Issue 35 item 5: not in the package folder, and a change to the builder's code gives other names."""
    cell, _ = ur5
    package = Path(pt.__file__).resolve().parent
    monkeypatch.delenv("PINARMS_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert pt._path("0" * 64) == tmp_path / "xdg" / "pinarms" / "pair_tables" / f"{'0' * 64}.npz"
    monkeypatch.setenv("PINARMS_CACHE_DIR", str(tmp_path / "own"))
    assert pt._path("0" * 64).parent == tmp_path / "own" / "pair_tables"
    assert package not in pt._path("0" * 64).parents
    names = [o.name for o in cell.collision_model.geometryObjects]
    (found,) = pt.table_paths(cell, [(names.index("ur5_wrist_1_link_0"), names.index("ur5_ee_link_0"))])
    key = pt._key(cell, *found)
    edited = tmp_path / "_table_build.py"
    edited.write_text(Path(pt._CODE[1]).read_text(encoding="utf-8") + "\n# edited\n", encoding="utf-8")
    monkeypatch.setattr(pt, "_CODE", (pt._CODE[0], edited, pt._CODE[2]))
    assert pt._key(cell, *found) != key


@pytest.mark.slow
def test_a_poisoned_cache_is_rebuilt_and_the_verdict_is_unchanged(ur5, near_contact, tmp_path, monkeypatch):
    """Issue 35 item 5: every stored bound raised to 5 m (a stale or planted file under the right name) is
    refused by the value check, for each of the UR5's tables; planted, it is built again, equal to the clean
    one, and the cover proves exactly the states it proved before. (With the value check off, the same planted
    tables let the cover prove 15 of 659 colliding states of this sample clear.)"""
    from dataclasses import replace

    cell, cover = ur5
    ch, Q = near_contact
    monkeypatch.setenv("PINARMS_CACHE_DIR", str(tmp_path))
    own = [(p.index_a, p.index_b) for p in cell.pairs if p.kind == "self"]
    bare = replace(cover, tables=pt.no_tables())
    found = [f for f in pt.table_paths(cell, own) if frozenset(f[:2]) in
             {frozenset((int(a), int(b))) for a, b in zip(cover.tables.pair_a, cover.tables.pair_b)}]
    assert len(found) == cover.tables.pair_a.size >= 3
    clean = {pt._key(cell, *f): pt._MEMORY[pt._key(cell, *f)] for f in found}
    for f in found:
        key = pt._key(cell, *f)
        poison = dict(clean[key], low=np.full_like(clean[key]["low"], 5.0))
        assert not pt._trusted(cell, *f, poison) and pt._trusted(cell, *f, clean[key])
    # the smallest table planted poisoned (rebuilt: one build, to keep the test short), the others clean
    planted = min(clean, key=lambda k: clean[k]["child"].size)
    for key, table in clean.items():
        pt._save(key, dict(table, low=np.full_like(table["low"], 5.0)) if key == planted else table)
    assert pt._load(planted) is not None  # structurally sound: only its values give it away
    monkeypatch.setattr(pt, "_MEMORY", {})
    tables = pt.pair_tables(cell, own, bare)
    np.testing.assert_array_equal(tables.low, cover.tables.low)
    pairs = cover.prepare(*pair_arrays(ch.pairs))
    again = replace(cover, tables=tables)
    np.testing.assert_array_equal(again.screen(Q, again.prepare(*pair_arrays(ch.pairs)), ch.pair_margin),
                                  cover.screen(Q, pairs, ch.pair_margin))
    np.testing.assert_array_equal(pt._load(planted)["low"], clean[planted]["low"])  # overwritten by the rebuild


@pytest.mark.slow
def test_a_table_of_the_aubo_food_station_stays_below_coal():
    """Another arm with a mesh: the AUBO-i3's upper arm against the food station's hopper (a fixed mesh)."""
    from pinarms.robots import load_cell

    cell = load_cell("aubo_food_station")
    objs = cell.collision_model.geometryObjects
    found = pt.table_paths(cell, [(p.index_a, p.index_b) for p in cell.pairs])
    assert [(objs[a].name, objs[b].name) for a, b, _, _ in found] == [("aubo_upperArm_Link_2", "hopper_0")]
    a, b, side_a, side_b = found[0]
    tables = pt.assemble(cell, found, [pt.build_table(cell, a, b, side_a, side_b)])
    Q = cell.random_q(N, seed=12)
    bound = tables.bound(0, _angles(cell, tables, 0, Q))
    Rg, pg = cell.geometry_placements(Q)
    req = coal.DistanceRequest()
    d = np.array([coal.distance(objs[a].geometry, coal.Transform3s(Rg[i, a], pg[i, a]), objs[b].geometry,
                                coal.Transform3s(Rg[i, b], pg[i, b]), req, coal.DistanceResult()) for i in range(N)])
    assert np.all(bound <= np.maximum(d, 0.0) + 1e-9)
    assert np.mean(bound > 0.0) > 0.5


def test_the_cache_reader_skips_a_fifo_a_large_file_and_a_pickle(tmp_path, monkeypatch):
    import os

    from pinarms.robots.cell import disk_cache

    fifo = tmp_path / "fifo.npz"
    os.mkfifo(fifo)
    assert disk_cache.read_arrays(fifo, ["low"]) is None  # returns at once: no writer is waited for
    disk_cache.write_arrays(tmp_path / "sub" / "ok.npz", {"low": np.arange(3.0)})
    assert (tmp_path / "sub").stat().st_mode & 0o777 == 0o700
    np.testing.assert_array_equal(disk_cache.read_arrays(tmp_path / "sub" / "ok.npz", ["low"])["low"], np.arange(3.0))
    np.savez(tmp_path / "pickled.npz", low=np.array([{"a": 1}], dtype=object))
    assert disk_cache.read_arrays(tmp_path / "pickled.npz", ["low"]) is None
    monkeypatch.setattr(disk_cache, "MAX_FILE_BYTES", 10)
    assert disk_cache.read_arrays(tmp_path / "sub" / "ok.npz", ["low"]) is None
