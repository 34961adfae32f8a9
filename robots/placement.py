"""Old path of :mod:`robots.reach.placement` (the reach family lives in ``robots/reach/``).

``pinarms.robots.placement`` is the same module object as ``pinarms.robots.reach.placement``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import placement as _module

sys.modules[__name__] = _module
