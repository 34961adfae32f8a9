"""Old path of :mod:`optim.ga.engine` (the family lives in ``optim/ga/``).

``pinarms.optim.engine`` is the same module object as ``pinarms.optim.ga.engine``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.ga import engine as _module

sys.modules[__name__] = _module
