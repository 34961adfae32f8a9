"""Old path of :mod:`robots.reach._reach_worker` (the reach family lives in ``robots/reach/``).

``pinarms.robots._reach_worker`` is the same module object as ``pinarms.robots.reach._reach_worker``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import _reach_worker as _module

sys.modules[__name__] = _module
