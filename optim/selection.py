"""Old path of :mod:`optim.ga.selection` (the family lives in ``optim/ga/``).

``pinarms.optim.selection`` is the same module object as ``pinarms.optim.ga.selection``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.ga import selection as _module

sys.modules[__name__] = _module
