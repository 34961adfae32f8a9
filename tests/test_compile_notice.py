"""pinarms.compile_notice: a line on stderr while numba compiles for more than a set time (command line only)."""

from __future__ import annotations

import io
import subprocess
import sys

import pinarms.compiled  # noqa: F401  (numba imported: a notice attaches at once)
from numba import njit

from pinarms.compile_notice import CompileNotice


def _compile_something() -> None:
    """A fresh function compiled by numba (never cached): a compile of a fraction of a second."""
    def add(x, y):
        return x + y
    njit(add)(1.0, 2)


def test_a_compile_longer_than_the_threshold_draws_and_sums_up():
    stream = io.StringIO()
    with CompileNotice(stream=stream, after=0.0, interval=0.001) as notice:
        _compile_something()
    text = stream.getvalue()
    assert notice.seconds > 0.0
    assert "\r\x1b[2Kcompiling numba kernels on first use: " in text  # drawn while compiling
    assert text.endswith("(now in numba's cache; `pinarms warm` compiles them all once)\n")
    assert "compiled numba kernels on first use in " in text.splitlines()[-1]


def test_short_compiles_and_a_disabled_notice_draw_nothing():
    quiet, disabled = io.StringIO(), io.StringIO()
    with CompileNotice(stream=quiet, after=60.0, interval=0.001) as notice:
        _compile_something()
    assert quiet.getvalue() == "" and notice.seconds > 0.0
    with CompileNotice(stream=disabled, enabled=False, after=0.0, interval=0.001) as off:
        _compile_something()
    assert disabled.getvalue() == "" and off.seconds == 0.0


def test_a_notice_started_before_numba_is_imported_attaches_when_kernels_are():
    """The command line starts its notice before any numba import (a command that compiles nothing does
    not pay for importing numba); pinarms.compiled attaches it."""
    code = ("import io, sys\n"
            "from pinarms.compile_notice import CompileNotice\n"
            "stream = io.StringIO()\n"
            "with CompileNotice(stream=stream, after=0.0, interval=0.001) as notice:\n"
            "    assert 'numba' not in sys.modules\n"
            "    import pinarms.compiled\n"
            "    pinarms.compiled.njit(lambda x: x + 1)(1)\n"
            "print(notice.seconds > 0, 'compiled numba kernels on first use in' in stream.getvalue())\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["True", "True"]
