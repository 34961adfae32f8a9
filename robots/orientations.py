"""Old path of :mod:`robots.reach.orientations` (the reach family lives in ``robots/reach/``).

``pinarms.robots.orientations`` is the same module object as ``pinarms.robots.reach.orientations``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import orientations as _module

sys.modules[__name__] = _module
