"""Old path of :mod:`optim.ga.problem` (the family lives in ``optim/ga/``).

``pinarms.optim.problem`` is the same module object as ``pinarms.optim.ga.problem``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.ga import problem as _module

sys.modules[__name__] = _module
