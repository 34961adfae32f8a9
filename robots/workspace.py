"""Old path of :mod:`robots.reach.workspace` (the reach family lives in ``robots/reach/``).

``pinarms.robots.workspace`` is the same module object as ``pinarms.robots.reach.workspace``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import workspace as _module

sys.modules[__name__] = _module
