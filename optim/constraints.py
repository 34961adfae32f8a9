"""Old path of :mod:`optim.ga.constraints` (the family lives in ``optim/ga/``).

``pinarms.optim.constraints`` is the same module object as ``pinarms.optim.ga.constraints``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.ga import constraints as _module

sys.modules[__name__] = _module
