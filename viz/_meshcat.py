"""MeshCat imports, without the DeprecationWarning meshcat 0.3.2 triggers in pyzmq on import."""

from __future__ import annotations

import warnings

with warnings.catch_warnings():
    warnings.simplefilter("ignore", DeprecationWarning)
    import meshcat
    import meshcat.animation
    import meshcat.geometry as mg
    import meshcat.transformations
    from meshcat.visualizer import ViewerWindow
    from pinocchio.visualize import MeshcatVisualizer

__all__ = ["meshcat", "mg", "ViewerWindow", "MeshcatVisualizer"]
