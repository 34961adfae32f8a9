"""Old path of :mod:`optim.timing.reference` (the family lives in ``optim/timing/``).

``pinarms.optim.reference`` is the same module object as ``pinarms.optim.timing.reference``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.timing import reference as _module

sys.modules[__name__] = _module
