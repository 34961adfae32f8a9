"""Old path of :mod:`robots.reach.workspace_stream` (the reach family lives in ``robots/reach/``).

``pinarms.robots.workspace_stream`` is the same module object as ``pinarms.robots.reach.workspace_stream``, so every
name (private ones included) keeps working.
"""

import sys

from .reach import workspace_stream as _module

sys.modules[__name__] = _module
