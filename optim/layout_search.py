"""Old path of :mod:`optim.layout.search` (the layout search lives in ``optim/layout/``).

``pinarms.optim.layout_search`` is the same module object as ``pinarms.optim.layout.search``,
so every name keeps working.
"""

import sys

from pinarms.optim.layout import search as _module

sys.modules[__name__] = _module
