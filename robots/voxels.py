"""Old path of :mod:`robots.reach.voxels` (the reach family lives in ``robots/reach/``).

``pinarms.robots.voxels`` is the same module object as ``pinarms.robots.reach.voxels``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import voxels as _module

sys.modules[__name__] = _module
