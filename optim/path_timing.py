"""Old path of :mod:`optim.topp.path_timing` (the family lives in ``optim/topp/``).

``pinarms.optim.path_timing`` is the same module object as ``pinarms.optim.topp.path_timing``, so every
name (private ones included) keeps working.
"""

import sys

from pinarms.optim.topp import path_timing as _module

sys.modules[__name__] = _module
