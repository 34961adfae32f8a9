"""Old path of :mod:`robots.reach._reach_child` (the reach family lives in ``robots/reach/``).

``pinarms.robots._reach_child`` is the same module object as ``pinarms.robots.reach._reach_child``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import _reach_child as _module

sys.modules[__name__] = _module
