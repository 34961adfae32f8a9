"""Old path of :mod:`optim.cycle.straight` (the cycle family lives in ``optim/cycle/``).

``pinarms.optim.straight_approach`` is the same module object as ``pinarms.optim.cycle.straight``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.cycle import straight as _module

sys.modules[__name__] = _module
