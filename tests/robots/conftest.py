"""Fixtures shared by the robots tests."""

from __future__ import annotations

import sys

import pytest


@pytest.fixture
def fast_switching():
    """Threads switch every microsecond (instead of 5 ms) while the test runs: races show up."""
    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    try:
        yield
    finally:
        sys.setswitchinterval(old)
