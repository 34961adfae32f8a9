"""Hypothesis profiles of the fuzz suite.

``ci`` (the default): derandomised (the same examples every run, so CI never flakes) and
bounded so that the whole of tests/fuzz stays well under 60 s on two cores.
``explore``: random and ten times longer, to look for new failures locally
(``HYPOTHESIS_PROFILE=explore pytest tests/fuzz``); add what it finds as ``@example``
cases or to ``tests/fuzz/corpus/``.
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

_common = dict(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                                     HealthCheck.function_scoped_fixture],
               print_blob=True)
settings.register_profile("ci", derandomize=True, database=None, **_common)
settings.register_profile("explore", derandomize=False, **_common)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

