"""Helpers shared by the description tests: Pinocchio/yourdfpy models of the committed URDFs."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
import pinocchio as pin
import yourdfpy

from pinarms.robots.urdf_build import URDF_DIR


def urdf_file(name: str) -> Path:
    return URDF_DIR / f"{name}.urdf"


@lru_cache(maxsize=None)
def pin_model(name: str) -> pin.Model:
    return pin.buildModelFromUrdf(str(urdf_file(name)), mimic=True)


@lru_cache(maxsize=None)
def yourdf_model(name: str) -> yourdfpy.URDF:
    return yourdfpy.URDF.load(str(urdf_file(name)), load_meshes=False, build_collision_scene_graph=False)


def independent_joint_names(model: pin.Model) -> list[str]:
    """Names of the joints that own a configuration coordinate, in q order."""
    joints = [
        (model.joints[j].idx_q, model.names[j])
        for j in range(1, model.njoints)
        if "Mimic" not in model.joints[j].shortname()
    ]
    return [name for _, name in sorted(joints)]


def random_q(model: pin.Model, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(model.lowerPositionLimit, model.upperPositionLimit, size=(n, model.nq))


def pin_frame(model: pin.Model, q: np.ndarray, frame: str) -> np.ndarray:
    """T_base←frame (4x4) by Pinocchio for one configuration."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.asarray(q, dtype=float))
    return data.oMf[model.getFrameId(frame)].homogeneous.copy()
