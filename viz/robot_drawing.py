"""One robot's visual geometry in a MeshCat scene: drawn, posed, bounded and animated.

The geometry is Pinocchio's visual model of the robot's URDF, drawn under
``<root>/robots/<key>/visuals/<geometry>`` by Pinocchio's ``MeshcatVisualizer`` and placed
at the robot's ``base_to_world``. Frames and units: metres, the robot's base frame unless
said otherwise.
"""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path
from typing import Sequence, TYPE_CHECKING

import numpy as np
import pinocchio as pin

from pinarms.viz._meshcat import MeshcatVisualizer, meshcat
from pinarms.viz.errors import ViewerError

if TYPE_CHECKING:
    from pinarms.robots.robot import Robot

__all__ = ["RobotDrawing", "resolved_package_meshes"]

_PACKAGE_MESH = re.compile(r'(filename\s*=\s*)(["\'])(?:package|model)://([^/"\']+)/([^"\']+)\2')


def resolved_package_meshes(urdf_text: str, package_dirs: Sequence[str]) -> str:
    """``urdf_text`` with each ``package://NAME/rel`` mesh found in ``package_dirs`` given as its absolute path.

    A package folder is found either way a caller may list it: as the folder that holds
    ``NAME/`` (Pinocchio's convention, ``<dir>/NAME/rel``) or as the package folder itself
    (``--package NAME=FOLDER``: ``<dir>/rel``, the convention of :mod:`pinarms.viz.mesh_paths`). Only
    files inside those folders are named; a mesh found nowhere is left for Pinocchio to report.
    """
    roots = [Path(d) for d in package_dirs if d]

    def resolve(match: re.Match) -> str:
        name, rel = match.group(3), match.group(4)
        if ".." in Path(rel).parts:
            return match.group(0)
        for root in roots:
            for cand in (root / name / rel, root / rel):
                real = Path(os.path.realpath(cand))
                if real.is_file() and real.is_relative_to(Path(os.path.realpath(root))):
                    return f"{match.group(1)}{match.group(2)}{real}{match.group(2)}"
        return match.group(0)

    return _PACKAGE_MESH.sub(resolve, urdf_text)


class RobotDrawing:
    """One robot's visual geometry in the scene, driven by Pinocchio's MeshcatVisualizer."""

    def __init__(self, vis: meshcat.Visualizer, robot: Robot, key: str, base_to_world: np.ndarray,
                 package_dirs: Sequence[str], root: str = "pinarms") -> None:
        self.robot = robot
        self.root = f"{root}/robots/{key}"
        try:
            visual_model = pin.buildGeomFromUrdfString(
                robot.model, resolved_package_meshes(robot.urdf_text, package_dirs), pin.GeometryType.VISUAL,
                package_dirs=list(package_dirs)
            )
        except Exception as exc:  # Pinocchio raises ValueError/RuntimeError for missing meshes
            raise ViewerError(
                f"cannot build the visual geometry of robot {key!r}: {exc}; if its meshes moved, "
                "pass package_dirs=... to viz.load_session (on the command line --package-dir FOLDER)"
            ) from exc
        self.pv = MeshcatVisualizer(robot.model, None, visual_model)
        self.pv.initViewer(viewer=vis)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # unsupported geometry is skipped, not fatal
            self.pv.loadViewerModel(rootNodeName=self.root)
        vis[self.root].set_transform(base_to_world)
        self.geometry_paths = [self.pv.getViewerNodeName(g, pin.GeometryType.VISUAL)
                               for g in visual_model.geometryObjects]

    def display(self, q: np.ndarray) -> None:
        """Show configuration ``q (nq,)``."""
        self.pv.display(self.robot.q_to_pinocchio(q))

    def extent(self, qs: np.ndarray) -> np.ndarray:
        """Corners of the visual geometries' boxes at each row of ``qs (F, nq)``, ``(8kF, 3)`` in the base frame [m].

        A geometry whose box is unknown contributes its origin. The displayed pose is untouched.
        """
        model, gmodel = self.pv.model, self.pv.visual_model
        data, gdata = model.createData(), gmodel.createData()
        signs = np.array(np.meshgrid([0, 1], [0, 1], [0, 1])).reshape(3, -1).T
        local = []
        for g in gmodel.geometryObjects:
            try:
                g.geometry.computeLocalAABB()
                lo, hi = np.asarray(g.geometry.aabb_local.min_), np.asarray(g.geometry.aabb_local.max_)
                local.append((lo + signs * (hi - lo)) * np.asarray(g.meshScale))
            except Exception:  # noqa: BLE001 - a geometry coal cannot bound: its origin only
                local.append(np.zeros((1, 3)))
        corners = [np.zeros((1, 3))]
        for qp in np.atleast_2d(self.robot.q_to_pinocchio(qs)):
            pin.forwardKinematics(model, data, qp)
            pin.updateGeometryPlacements(model, data, gmodel, gdata)
            corners += [box @ M.rotation.T + M.translation for box, M in zip(local, gdata.oMg)]
        return np.vstack(corners)

    def record(self, anim: meshcat.animation.Animation, vis: meshcat.Visualizer, qs: np.ndarray) -> None:
        """Add one key frame per row of ``qs (F, nq)`` to ``anim`` (rigid poses: tracks hold position + rotation)."""
        model, data = self.pv.model, self.pv.data
        gmodel, gdata = self.pv.visual_model, self.pv.visual_data
        qp = self.robot.q_to_pinocchio(qs)
        ids = [gmodel.getGeometryId(g.name) for g in gmodel.geometryObjects]
        for i in range(qp.shape[0]):
            pin.forwardKinematics(model, data, qp[i])
            pin.updateGeometryPlacements(model, data, gmodel, gdata)
            with anim.at_frame(vis, i) as frame:
                for path, gid in zip(self.geometry_paths, ids):
                    frame[path].set_transform(gdata.oMg[gid].homogeneous)
