"""Exceptions of pinarms, re-exported from the floor module :mod:`pinarms.errors`.

The hierarchy moved down to ``pinarms/errors.py`` so that the floor (execution layer,
atomic files, units) imports nothing above it; ``from pinarms.robots.errors import ...``
keeps working and names the same classes.
"""

from __future__ import annotations

from pinarms.errors import *  # noqa: F401,F403
from pinarms.errors import __all__, _rebuild_execution_error  # noqa: F401
