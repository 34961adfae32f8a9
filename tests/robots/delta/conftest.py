"""The shipped delta, loaded once for the delta tests (read-only)."""

from __future__ import annotations

import pytest

from pinarms.robots.delta import load_delta


@pytest.fixture(scope="session")
def delta():
    return load_delta("delta_flexpicker")
