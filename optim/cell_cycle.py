"""Old path of :mod:`optim.cycle.in_cell` (the cycle family lives in ``optim/cycle/``).

``pinarms.optim.cell_cycle`` is the same module object as ``pinarms.optim.cycle.in_cell``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.cycle import in_cell as _module

sys.modules[__name__] = _module
