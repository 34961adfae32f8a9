"""Old path of :mod:`optim.ga.adaptive` (the family lives in ``optim/ga/``).

``pinarms.optim.adaptive`` is the same module object as ``pinarms.optim.ga.adaptive``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.ga import adaptive as _module

sys.modules[__name__] = _module
