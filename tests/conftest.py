"""Suite-wide rules for the parallel run (``make test``: pytest-xdist, ``-n 2 --dist loadgroup``), and
the demo's quick studies shared by the files that check them.

Every test file is one xdist group, so a file's tests run in one worker, in order, and its
module- and session-scoped fixtures are built once per run (as ``--dist loadfile`` would);
a test that names its own ``@pytest.mark.xdist_group("...")`` joins that group instead
(tests in one group never run at the same time as each other). The longest groups are handed
out first (:data:`GROUP_SECONDS`, then those holding a test marked ``slow``), so that a long
file does not start last and leave the other worker idle at the end. The rules a new test follows to be parallel-safe are in
tests/README.md.
"""

from __future__ import annotations

from typing import Any, Callable

import distributed  # noqa: F401  (loads distributed's defaults into dask's config before any test overrides a
#                    key: a first import inside ``dask.config.set`` is undone with it, leaving later tests of the
#                    worker without any distributed setting)
import pytest

#: The group of the tests that use :func:`quick_study`: one worker builds each study once for all of them.
DEMO_STUDIES = "demo-studies"

#: CPU seconds (user + system, the test processes and their children) that the longest groups took in ``make test``
#: (2026-12, two workers): only their order matters. A group not listed starts after these when it has a test marked
#: ``slow`` (weight :data:`SLOW_SECONDS`), else in collection order at the end.
GROUP_SECONDS = {
    DEMO_STUDIES: 96.0,  # the demo's quick studies 000, 001 and 004, built once; `pinarms demo --quick` end to end
    "tests/foreign/test_foreign_arms.py": 76.0,  # one foreign arm's whole path
    "tests/optim/line/test_fixtures.py": 37.0,
    "tests/robots/test_xacro_expand.py": 30.0,
    "tests/optim/line/test_yaw_maps.py": 29.0,
    "tests/test_architecture_figures.py": 28.0,
    "tests/optim/layout/test_layout_search.py": 26.0,
    "tests/optim/line/test_task_maps.py": 20.0,
    "tests/optim/cycle/test_cell_screen.py": 20.0,
    "tests/optim/test_motion_transfer.py": 19.0,
    "tests/test_export_verify.py": 18.0,
    "tests/studies/test_handoff_plans.py": 18.0,
    "tests/cli/test_layout_search_cli.py": 16.0,
    "tests/fuzz/test_fuzz_api.py": 16.0,
    "tests/robots/cell/test_pair_tables.py": 15.0,
    "tests/robots/reach/test_reach_io.py": 14.0,
    "tests/test_packaging.py": 14.0,  # builds the wheel, installs it beside the namesakes in a fresh venv
    "tests/test_execution.py": 13.0,
    "tests/optim/cycle/test_cell_cycle.py": 12.0,
    "tests/robots/test_descriptions.py": 11.0,
    "tests/optim/line/test_tray_line.py": 11.0,
    "tests/optim/layout/test_layout_bound.py": 10.0,
}

#: The weight of an unlisted group that holds a test marked ``slow``.
SLOW_SECONDS = 5.0


def _group_of(item: pytest.Item) -> str:
    mark = item.get_closest_marker("xdist_group")
    if mark is None:
        return item.nodeid.split("::", 1)[0]
    return str(mark.args[0] if mark.args else mark.kwargs.get("name", "default"))


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook, which reads the groups
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if item.get_closest_marker("xdist_group") is None:
            item.add_marker(pytest.mark.xdist_group(_group_of(item)))
    # the longest groups first (stable: the collection order is kept among equals)
    slow = {_group_of(item) for item in items if item.get_closest_marker("slow") is not None}

    def weight(item: pytest.Item) -> float:
        group = _group_of(item)
        return GROUP_SECONDS.get(group, SLOW_SECONDS if group in slow else 0.0)

    items.sort(key=weight, reverse=True)


@pytest.fixture(scope="session")
def quick_study() -> Callable[[str], Any]:
    """``quick_study("001")`` is ``pinarms.demo.study_001(quick=True)``, built once per worker (about
    40 s for 001 on a loaded machine). Read-only: a test never changes the study it is given. A test
    that uses it is marked ``@pytest.mark.xdist_group(DEMO_STUDIES)`` so that one worker builds it."""
    from pinarms import demo

    built: dict[str, Any] = {}

    def get(key: str) -> Any:
        if key not in built:
            built[key] = getattr(demo, f"study_{key}")(quick=True)
        return built[key]

    return get
