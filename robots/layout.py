"""Old path of :mod:`robots.reach.layout` (the reach family lives in ``robots/reach/``).

``pinarms.robots.layout`` is the same module object as ``pinarms.robots.reach.layout``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import layout as _module

sys.modules[__name__] = _module
