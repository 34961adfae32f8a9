"""Old path of :mod:`optim.ga.crossover` (the family lives in ``optim/ga/``).

``pinarms.optim.crossover`` is the same module object as ``pinarms.optim.ga.crossover``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.ga import crossover as _module

sys.modules[__name__] = _module
