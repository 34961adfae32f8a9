"""Old path of :mod:`optim.timing.exact` (the family lives in ``optim/timing/``).

``pinarms.optim.exact`` is the same module object as ``pinarms.optim.timing.exact``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.timing import exact as _module

sys.modules[__name__] = _module
