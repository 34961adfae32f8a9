"""Files given by path are read only when they are regular files, and only up to a size bound.

A FIFO once blocked ``--arrivals``, ``plan --file`` and ``fk x.urdf`` forever, and a ``.urdf``
linked to ``/dev/zero`` was read without end by ``fk`` and ``urdf export`` (issue 35, item 8).
Every case here must end with a named error within a few seconds: a watchdog turns a hang
into a failure instead of a stuck test.
"""

import contextlib
import os
import signal
import time

import pytest
from click.testing import CliRunner

from pinarms.cli import cli
from pinarms.errors import InvalidInput, ModelError
from pinarms.files import check_regular, open_regular, read_bounded, read_bounded_text

LIMIT_S = 5.0


@contextlib.contextmanager
def watchdog(seconds: float = 10.0):
    """Raise TimeoutError in this thread when the block takes longer than ``seconds`` (a blocked open too)."""

    def alarm(signum, frame):
        raise TimeoutError(f"still blocked after {seconds} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    t0 = time.perf_counter()
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert time.perf_counter() - t0 < LIMIT_S


@pytest.fixture
def fifo(tmp_path):
    def make(name: str):
        p = tmp_path / name
        os.mkfifo(p)
        return p
    return make


@pytest.fixture
def zero_link(tmp_path):
    def make(name: str):
        p = tmp_path / name
        os.symlink("/dev/zero", p)
        return p
    return make


def test_a_fifo_is_refused_without_blocking(fifo):
    p = fifo("pipe.txt")
    with watchdog(), pytest.raises(InvalidInput, match=r"'.*pipe.txt' is not a regular file \(a FIFO\)"):
        read_bounded(p, 1024, "test file")
    with watchdog(), pytest.raises(ModelError, match="a FIFO"):
        check_regular(p, "test file", error=ModelError)


def test_a_device_a_folder_and_a_nul_byte_are_refused(tmp_path, zero_link):
    with watchdog(), pytest.raises(InvalidInput, match="a character device"):
        read_bounded(zero_link("zero.bin"), 1024, "test file")
    with pytest.raises(InvalidInput, match="a folder"):
        read_bounded(tmp_path, 1024, "test file")
    with pytest.raises(InvalidInput, match="cannot read test file"):
        read_bounded("a\x00b", 1024, "test file")
    with pytest.raises(ModelError, match="does not exist"):
        read_bounded(tmp_path / "none", 1024, "test file", error=ModelError)


def test_the_size_bound_and_the_text(tmp_path):
    p = tmp_path / "f.txt"
    p.write_bytes(b"\xef\xbb\xbfabc")
    assert read_bounded(p, 6) == b"\xef\xbb\xbfabc" and read_bounded_text(p, 6) == "abc"
    with pytest.raises(InvalidInput, match="is 6 bytes; the limit is 5 bytes"):
        read_bounded(p, 5)
    p.write_bytes(b"\xff\xfe")
    with pytest.raises(InvalidInput, match=r"not UTF-8 text \(byte 0\)"):
        read_bounded_text(p, 6)
    with open_regular(p) as fh:  # blocking again for the caller
        assert fh.read() == b"\xff\xfe"


def _cli(args):
    with watchdog():
        r = CliRunner().invoke(cli, args)
    assert r.exit_code == 1, (r.output, r.exception)
    assert r.output.startswith("Error: ") and r.output.count("\n") == 1 and "Traceback" not in r.output
    return r.output


def test_fk_and_urdf_export_refuse_a_fifo_and_dev_zero(fifo, zero_link, tmp_path):
    for p in (fifo("arm.urdf"), zero_link("zero.urdf")):
        out = _cli(["fk", str(p), "0", "0", "0"])
        assert "not a regular file" in out and p.name in out
        out = _cli(["urdf", "export", str(p), str(tmp_path / "out")])
        assert "not a regular file" in out and not (tmp_path / "out").exists()


def test_plan_file_and_arrivals_refuse_a_fifo(fifo):
    out = _cli(["plan", "--file", str(fifo("via.json"))])
    assert "via-point file" in out and "a FIFO" in out
    out = _cli(["belt", "run", "--arms", "1", "--arrivals", str(fifo("arrivals.csv"))])
    assert "arrivals file" in out and "a FIFO" in out


def test_cell_xacro_session_and_trajectory_files_refuse_a_fifo(fifo):
    from pinarms.export import read_trajectory_csv, read_trajectory_yaml
    from pinarms.robots import expand_xacro
    from pinarms.robots.cell import load_cell
    from pinarms.viz import load_session

    cases = [
        (lambda: load_cell(str(fifo("cell.urdf"))), ModelError),
        (lambda: expand_xacro(fifo("arm.urdf.xacro")), ModelError),
        (lambda: load_session(fifo("s.pinarms")), InvalidInput),
        (lambda: read_trajectory_yaml(fifo("t.yaml")), InvalidInput),
        (lambda: read_trajectory_csv(fifo("t.csv")), InvalidInput),
    ]
    for call, error in cases:
        with watchdog(), pytest.raises(error, match="not a regular file"):
            call()
