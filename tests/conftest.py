"""Suite-wide collection rules for the parallel run (``make test``: pytest-xdist, ``-n 2 --dist loadgroup``).

Every test file is one xdist group, so a file's tests run in one worker, in order, and its
module- and session-scoped fixtures are built once per run (as ``--dist loadfile`` would);
a test that names its own ``@pytest.mark.xdist_group("...")`` joins that group instead
(tests in one group never run at the same time as each other). Files holding tests marked
``slow`` are handed out first, so that a long file does not start last and leave one
worker idle at the end. The rules a new test follows to be parallel-safe are in
tests/README.md.
"""

from __future__ import annotations

import pytest


def _file_of(item: pytest.Item) -> str:
    return item.nodeid.split("::", 1)[0]


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook, which reads the groups
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if item.get_closest_marker("xdist_group") is None:
            item.add_marker(pytest.mark.xdist_group(_file_of(item)))
    # slow files first (stable: the collection order is kept within each of the two parts)
    slow_files = {_file_of(item) for item in items if item.get_closest_marker("slow") is not None}
    items.sort(key=lambda item: _file_of(item) not in slow_files)
