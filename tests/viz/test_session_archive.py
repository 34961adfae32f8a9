"""The bounded reader of session archives: damaged files, forged zips and bombs, limits."""

from __future__ import annotations

import io
import json
import struct
import subprocess
import sys
import textwrap
import zipfile
import zlib

import numpy as np
import pytest

from pinarms import robots
from pinarms import viz
from pinarms.errors import InvalidInput
from pinarms.viz import SessionFormatError

from session_files import document, npy_bytes, rewrite


def test_truncated_file(saved, tmp_path):
    data = saved.read_bytes()
    for cut in (len(data) // 2, len(data) - 10, 30):
        bad = tmp_path / f"cut{cut}.pinarms"
        bad.write_bytes(data[:cut])
        with pytest.raises(SessionFormatError, match="not a zip archive, or truncated"):
            viz.load_session(bad)


def test_garbage_and_empty_files(tmp_path):
    bad = tmp_path / "garbage.pinarms"
    bad.write_bytes(np.random.default_rng(0).bytes(5000))
    with pytest.raises(SessionFormatError, match="not a zip"):
        viz.load_session(bad)
    empty = tmp_path / "empty.pinarms"
    empty.write_bytes(b"")
    with pytest.raises(SessionFormatError):
        viz.load_session(empty)
    with pytest.raises(InvalidInput, match="does not exist"):
        viz.load_session(tmp_path / "missing.pinarms")


def test_corrupt_member_bytes(saved, tmp_path):
    data = bytearray(saved.read_bytes())
    with zipfile.ZipFile(saved) as zf:
        info = zf.getinfo("session.json")
    start = info.header_offset + 30 + len(info.filename) + len(info.extra)
    data[start + 5 : start + 25] = bytes(20)  # damage the compressed session.json in place
    bad = tmp_path / "crc.pinarms"
    bad.write_bytes(bytes(data))
    with pytest.raises(SessionFormatError, match="session.json"):
        viz.load_session(bad)


def test_missing_members(saved, tmp_path):
    with pytest.raises(SessionFormatError, match="'session.json' is missing"):
        viz.load_session(rewrite(saved, tmp_path / "a.pinarms", drop={"session.json"}))
    member = document(saved)["trajectories"][0]["q"]["member"]
    with pytest.raises(SessionFormatError, match=f"{member}' is missing"):
        viz.load_session(rewrite(saved, tmp_path / "b.pinarms", drop={member}))
    with pytest.raises(SessionFormatError, match="robots/1.urdf' is missing"):
        viz.load_session(rewrite(saved, tmp_path / "c.pinarms", drop={"robots/1.urdf"}))


def test_wrong_array_shape_and_dtype(saved, tmp_path):
    doc = document(saved)
    q_ref = doc["trajectories"][0]["q"]
    n, nq = q_ref["shape"]
    # a q of 5 columns for a 6-joint robot, consistently declared in the index
    doc["trajectories"][0]["q"]["shape"] = [n, nq - 1]
    bad = rewrite(saved, tmp_path / "shape.pinarms", replace={
        "session.json": json.dumps(doc).encode(), q_ref["member"]: npy_bytes(np.zeros((n, nq - 1)))})
    with pytest.raises(SessionFormatError, match=rf"shape \({n}, {nq - 1}\), expected \({n}, {nq}\)"):
        viz.load_session(bad)
    # array disagrees with the index
    bad = rewrite(saved, tmp_path / "index.pinarms", replace={q_ref["member"]: npy_bytes(np.zeros((n + 1, nq)))})
    with pytest.raises(SessionFormatError, match="but session.json says"):
        viz.load_session(bad)
    # integer array
    bad = rewrite(saved, tmp_path / "dtype.pinarms", replace={q_ref["member"]: npy_bytes(np.zeros((n, nq), dtype=np.int64))})
    with pytest.raises(SessionFormatError, match="dtype int64, expected float64"):
        viz.load_session(bad)
    # a pickled object array is refused, never unpickled
    obj = np.empty(2, dtype=object)
    obj[:] = [{"a": 1}, None]
    buf = io.BytesIO()
    np.save(buf, obj, allow_pickle=True)
    padded = buf.getvalue() + bytes(n * nq * 8)  # the zip entry's size is then what the index's shape needs
    bad = rewrite(saved, tmp_path / "pickle.pinarms", replace={q_ref["member"]: padded})
    with pytest.raises(SessionFormatError, match="object array: pickled data is never loaded"):
        viz.load_session(bad)
    bad = rewrite(saved, tmp_path / "pickle2.pinarms", replace={q_ref["member"]: buf.getvalue()})
    with pytest.raises(SessionFormatError, match=r"holds \d+ bytes in the zip directory, but session.json's shape"):
        viz.load_session(bad)
    # NaN
    nan = np.zeros((n, nq))
    nan[1, 2] = np.nan
    bad = rewrite(saved, tmp_path / "nan.pinarms", replace={q_ref["member"]: npy_bytes(nan)})
    with pytest.raises(SessionFormatError, match="NaN"):
        viz.load_session(bad)


# A zip built byte by byte, so that a test can forge what zipfile would refuse to write:
# a raw deflate stream of 2 GiB of zeros (about 2 MB), a directory that lies about sizes,
# duplicate names, unknown compression methods.
_ZEROS_1M = bytes(1 << 20)


def _deflate(prefix: bytes, n_zeros: int, *, with_crc: bool = True) -> tuple[bytes, int]:
    """Raw deflate of ``prefix + bytes(n_zeros)`` and its CRC-32, without ever holding the zeros.

    After a full flush the compressor's state is reset, so every following 1 MiB block of
    zeros compresses to the same bytes: compress one, repeat it.
    """
    c = zlib.compressobj(9, zlib.DEFLATED, -15)
    out = [c.compress(prefix) + c.flush(zlib.Z_FULL_FLUSH)]
    crc = zlib.crc32(prefix)
    full, rest = divmod(n_zeros, 1 << 20)
    if full:
        block = c.compress(_ZEROS_1M) + c.flush(zlib.Z_FULL_FLUSH)
        again = c.compress(_ZEROS_1M) + c.flush(zlib.Z_FULL_FLUSH)
        assert block == again  # the trick holds
        out.append(block * full)
        if with_crc:
            big = bytes(16 << 20)
            n16, n1 = divmod(full, 16)
            for _ in range(n16):
                crc = zlib.crc32(big, crc)
            for _ in range(n1):
                crc = zlib.crc32(_ZEROS_1M, crc)
    out.append(c.compress(bytes(rest)) + c.flush())
    if with_crc:
        crc = zlib.crc32(bytes(rest), crc)
    return b"".join(out), crc


def _raw_zip(entries) -> bytes:
    """A zip of ``entries`` = [(name, method, raw bytes, crc, uncompressed size[, central size])].

    The optional sixth value is the size written to the central directory (a lie, when it differs).
    """
    local, central = [], []
    offset = 0
    for e in entries:
        name, method, raw, crc, size = e[:5]
        dir_size = e[5] if len(e) > 5 else size
        nb = name.encode("utf-8")
        hdr = struct.pack("<4s5H3L2H", b"PK\x03\x04", 20, 0x800, method, 0, 0x21, crc, len(raw), dir_size, len(nb), 0)
        local.append(hdr + nb + raw)
        central.append(struct.pack("<4s6H3L5H2L", b"PK\x01\x02", 20, 20, 0x800, method, 0, 0x21, crc, len(raw),
                                   dir_size, len(nb), 0, 0, 0, 0, 0, offset) + nb)
        offset += len(hdr) + len(nb) + len(raw)
    cd = b"".join(central)
    eocd = struct.pack("<4s4H2LH", b"PK\x05\x06", 0, 0, len(entries), len(entries), len(cd), offset, 0)
    return b"".join(local) + cd + eocd


def _entries_of(path, skip=()):
    """Members of a saved session as raw deflate entries (to rebuild it with _raw_zip)."""
    out = []
    with zipfile.ZipFile(path) as zf:
        for info in zf.infolist():
            if info.filename in skip:
                continue
            data = zf.read(info.filename)
            c = zlib.compressobj(6, zlib.DEFLATED, -15)
            out.append((info.filename, 8, c.compress(data) + c.flush(), zlib.crc32(data), len(data)))
    return out


def _npy_header(shape, descr="<f8") -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": descr, "fortran_order": False, "shape": tuple(shape)})
    return buf.getvalue()


@pytest.fixture(scope="module")
def cloud_session(tmp_path_factory):
    """A UR5 session with a 100-point workspace cloud (the member the bombs replace)."""
    ur5 = robots.load("ur5")
    s = viz.Session(ur5, title="bomb base")
    q = ur5.random_q(100, seed=4)
    s.add_workspace("cloud", points=ur5.position(q), manipulability=ur5.manipulability(q))
    return s.save(tmp_path_factory.mktemp("bomb") / "base.pinarms")


def test_raw_zip_builder_makes_files_zipfile_inflates(cloud_session, tmp_path):
    """The forged-zip helpers are sound: a small bomb (8 MiB of zeros) is a valid zip, CRC included."""
    doc = document(cloud_session)
    member = doc["workspaces"][0]["points"]["member"]
    n = (8 << 20) // 24
    hdr = _npy_header((n, 3))
    raw, crc = _deflate(hdr, 24 * n)
    doc["workspaces"][0]["points"]["shape"] = [n, 3]
    doc["workspaces"][0]["manipulability"]["shape"] = [n]
    js = json.dumps(doc).encode()
    c = zlib.compressobj(6, zlib.DEFLATED, -15)
    entries = _entries_of(cloud_session, skip={member, "session.json"})
    entries += [("session.json", 8, c.compress(js) + c.flush(), zlib.crc32(js), len(js)),
                (member, 8, raw, crc, len(hdr) + 24 * n)]
    path = tmp_path / "small_bomb.pinarms"
    path.write_bytes(_raw_zip(entries))
    assert path.stat().st_size < 20_000  # 8 MiB of zeros in under 20 kB
    with zipfile.ZipFile(path) as zf:
        assert zf.testzip() is None  # every CRC right
        data = zf.read(member)
    arr = np.load(io.BytesIO(data))
    assert arr.shape == (n, 3) and not arr.any()
    # the manipulability member still has 100 values: refused by size before any array is read
    with pytest.raises(SessionFormatError, match=r"manipulability.npy' holds 928 bytes in the zip directory"):
        viz.load_session(path)


@pytest.fixture(scope="module")
def bombs(cloud_session, tmp_path_factory):
    """Session files whose points member inflates to 2 GiB of zeros, lying in different places."""
    folder = tmp_path_factory.mktemp("bombs")
    doc = document(cloud_session)
    member = doc["workspaces"][0]["points"]["member"]
    n_big = ((2 << 30) - 128) // 24  # header (128 bytes) + data = 2 GiB
    hdr_big = _npy_header((n_big, 3))
    raw, crc = _deflate(hdr_big, 24 * n_big)
    size_big = len(hdr_big) + 24 * n_big
    assert size_big == 2 << 30
    base = _entries_of(cloud_session, skip={member, "session.json"})

    def build(name, index_rows, entry):
        d = json.loads(json.dumps(doc))
        d["workspaces"][0]["points"]["shape"] = [index_rows, 3]
        d["workspaces"][0]["manipulability"]["shape"] = [index_rows]
        js = json.dumps(d).encode()
        c = zlib.compressobj(6, zlib.DEFLATED, -15)
        path = folder / name
        path.write_bytes(_raw_zip(base + [("session.json", 8, c.compress(js) + c.flush(), zlib.crc32(js), len(js)),
                                          entry]))
        return path

    small = len(_npy_header((100, 3))) + 2400
    return {
        # everything agrees: a 2 GiB array, honestly declared
        "honest": build("honest.pinarms", n_big, (member, 8, raw, crc, size_big)),
        # session.json says 100 points; the zip directory and the .npy header say 2 GiB
        "index_small": build("index_small.pinarms", 100, (member, 8, raw, crc, size_big)),
        # index and zip directory say 100 points (2,528 bytes); the deflate stream holds 2 GiB
        "directory_lies": build("directory_lies.pinarms", 100, (member, 8, raw, crc, small)),
        # the same with the CRC of the first 2,528 bytes: zipfile's own check passes
        "crc_lies": build("crc_lies.pinarms", 100,
                          (member, 8, raw, zlib.crc32(hdr_big + bytes(small - len(hdr_big))), small)),
        # the local header says 2 GiB, the central directory 2,528 bytes
        "central_lies": build("central_lies.pinarms", 100, (member, 8, raw, crc, size_big, small)),
    }


_MEASURE = textwrap.dedent("""
    import json, resource, sys, time, tracemalloc
    from pinarms.viz import load_session  # loaded here, not inside the timed read (the package loads lazily)
    out = []
    for path in sys.argv[1:]:
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        tracemalloc.start()
        t = time.perf_counter()
        try:
            load_session(path)
            err = None
        except Exception as exc:
            err = [type(exc).__name__, str(exc)]
        dt = time.perf_counter() - t
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        out.append({"path": path, "s": dt, "peak_mb": peak / 2**20, "rss_growth_mb": (rss - before) / 1024,
                    "rss_mb": rss / 1024, "error": err})
    print(json.dumps(out))
""")


def test_zip_bombs_are_refused_fast_with_little_memory(bombs):
    """Issue 16: a 2 MB file inflating to 2 GiB of zeros is refused in < 1 s with < 200 MB peak memory.

    Measured in a fresh process (peak RSS by getrusage before/after, Python and NumPy
    allocations by tracemalloc); the old loader reached 4.1 GB and 21 s on such a file.
    """
    for path in bombs.values():
        assert path.stat().st_size < 2_300_000  # 2 GiB of zeros in about 2.1 MB
    proc = subprocess.run([sys.executable, "-c", _MEASURE, *map(str, bombs.values())],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    results = {r["path"].rsplit("/", 1)[1].split(".")[0]: r for r in json.loads(proc.stdout)}
    print(json.dumps({k: {m: round(v, 4) for m, v in r.items() if m in ("s", "peak_mb", "rss_growth_mb")} for k, r in results.items()}))
    expected = {
        "honest": r"points.npy' declares shape \(89478480, 3\) \(2,147,483,520 bytes\), more than the 536,870,912 allowed",
        "index_small": r"points.npy' holds 2,147,483,648 bytes in the zip directory, but session.json's shape \(100, 3\) needs 2,400",
        "directory_lies": r"points.npy' is corrupt \(Bad CRC-32",
        "crc_lies": r"points.npy' has shape \(89478480, 3\), but session.json says \(100, 3\)",
        "central_lies": r"points.npy' (has shape \(89478480, 3\), but session.json says \(100, 3\)|is corrupt)",
    }
    import re as _re

    for name, r in results.items():
        assert r["error"] is not None and r["error"][0] == "SessionFormatError", (name, r)
        assert _re.search(expected[name], r["error"][1]), (name, r["error"][1])
        assert r["s"] < 1.0, (name, r)
        assert r["peak_mb"] < 200 and r["rss_growth_mb"] < 200, (name, r)


def test_limits_refuse_big_sessions_and_say_how_to_raise_them(saved):
    doc = document(saved)
    q = doc["trajectories"][0]["q"]
    with pytest.raises(SessionFormatError, match=r"more than the 4,000 allowed for one array \(limit max_array_bytes\)"):
        viz.load_session(saved, limits=viz.SessionLimits(max_array_bytes=4000))
    with pytest.raises(SessionFormatError, match=r"add up to more than 10,000 bytes .*raise it with load_session"):
        viz.load_session(saved, limits=viz.SessionLimits(max_total_bytes=10_000))
    with pytest.raises(SessionFormatError, match="max_text_bytes"):
        viz.load_session(saved, limits=viz.SessionLimits(max_text_bytes=100))
    with pytest.raises(SessionFormatError, match="session.json.*more than the 1,000 allowed"):
        viz.load_session(saved, limits=viz.SessionLimits(max_json_bytes=1000))
    with pytest.raises(SessionFormatError, match="nests deeper than 3 levels"):
        viz.load_session(saved, limits=viz.SessionLimits(max_json_depth=3))
    with pytest.raises(SessionFormatError, match="max_members"):
        viz.load_session(saved, limits=viz.SessionLimits(max_members=5))
    assert q["shape"][0] * q["shape"][1] * 8 > 4000  # the first refusal is about this array, not a smaller one
    ok = viz.load_session(saved, limits=viz.SessionLimits(max_total_bytes=200_000, max_array_bytes=50_000))
    assert ok.trajectories.keys() == {"P1-P4 quintic", "raw"}
    with pytest.raises(InvalidInput, match="positive integer"):
        viz.SessionLimits(max_total_bytes=0)
    with pytest.raises(InvalidInput, match="SessionLimits"):
        viz.load_session(saved, limits={"max_total_bytes": 1})
