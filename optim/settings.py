"""Old path of :mod:`optim.ga.settings` (the family lives in ``optim/ga/``).

``pinarms.optim.settings`` is the same module object as ``pinarms.optim.ga.settings``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.ga import settings as _module

sys.modules[__name__] = _module
