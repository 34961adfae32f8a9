"""Old path of :mod:`optim.timing.time_jerk` (the family lives in ``optim/timing/``).

``pinarms.optim.time_jerk`` is the same module object as ``pinarms.optim.timing.time_jerk``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.timing import time_jerk as _module

sys.modules[__name__] = _module
