"""Old path of :mod:`robots.reach.reachability` (the reach family lives in ``robots/reach/``).

``pinarms.robots.reachability`` is the same module object as ``pinarms.robots.reach.reachability``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import reachability as _module

sys.modules[__name__] = _module
