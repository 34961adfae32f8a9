"""Old path of :mod:`optim.ga.mutation` (the family lives in ``optim/ga/``).

``pinarms.optim.mutation`` is the same module object as ``pinarms.optim.ga.mutation``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.ga import mutation as _module

sys.modules[__name__] = _module
