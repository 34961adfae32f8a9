"""Old path of :mod:`robots.reach.reach_io` (the reach family lives in ``robots/reach/``).

``pinarms.robots.reach_io`` is the same module object as ``pinarms.robots.reach.reach_io``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import reach_io as _module

sys.modules[__name__] = _module
