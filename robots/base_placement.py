"""Old path of :mod:`robots.reach.base_placement` (the reach family lives in ``robots/reach/``).

``pinarms.robots.base_placement`` is the same module object as ``pinarms.robots.reach.base_placement``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import base_placement as _module

sys.modules[__name__] = _module
