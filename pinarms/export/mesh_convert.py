"""COLLADA collision meshes as OBJ for MuJoCo, which reads STL, OBJ and MSH meshes but not COLLADA.

MuJoCo refuses a model whose collision geometry is a ``.dae`` file ("no decoder found for
mesh file"). The MJCF export converts each such mesh once, with trimesh (a dependency of
yourdfpy) reading COLLADA through pycollada (pinarms' ``mujoco`` extra), into an OBJ file
beside it (``<stem>_collada.obj``: vertices and faces only, 12 decimals, so to 1e-12 m; MuJoCo
then keeps them as float32, 1e-7 m at a metre), and points the compiled model at it. The vertices are the
COLLADA file's, as coal reads them for pinarms' own checks (node transforms applied by both;
the tests compare MuJoCo's mesh with coal's).
"""

from __future__ import annotations

import io
import xml.etree.ElementTree as ET
from pathlib import PurePosixPath

from pinarms.robots.errors import ModelError

__all__ = ["collada_to_obj", "collada_collision_meshes", "converted_name", "OBJ_DIGITS"]

#: Decimals of the vertex coordinates written [m]: 1e-12 m.
OBJ_DIGITS = 12


def collada_collision_meshes(urdf_text: str) -> list[str]:
    """The distinct ``.dae`` files of ``<collision>`` elements of a URDF, in document order."""
    root = ET.fromstring(urdf_text)
    found: dict[str, None] = {}
    for collision in root.iter("collision"):
        for mesh in collision.iter("mesh"):
            name = mesh.get("filename", "")
            if name.lower().endswith(".dae"):
                found.setdefault(name, None)
    return list(found)


def converted_name(mesh: str) -> str:
    """Where the OBJ of the COLLADA mesh ``mesh`` (a POSIX path in the export) goes: ``<stem>_collada.obj`` beside it."""
    path = PurePosixPath(mesh)
    return str(path.with_name(f"{path.stem}_collada.obj"))


def collada_to_obj(data: bytes, name: str) -> bytes:
    """The COLLADA mesh ``data`` (every triangle of its scene, node transforms applied) as OBJ text (vertices, faces).

    Raises:
        ModelError: pycollada is missing, or the file holds no triangles or cannot be read;
            the message says what to do.
    """
    try:
        import collada  # noqa: F401  (trimesh reads COLLADA through it)
        import trimesh
    except ImportError as exc:
        raise ModelError(f"MuJoCo cannot read the COLLADA collision mesh {name}, and converting it needs "
                         "pycollada: pip install pycollada (or pip install 'pinarms[mujoco]'), or give an STL or "
                         "OBJ collision mesh") from exc
    try:
        mesh = trimesh.load(io.BytesIO(data), file_type="dae", force="mesh", process=False)
    except Exception as exc:  # trimesh and pycollada raise many kinds
        raise ModelError(f"cannot convert the COLLADA collision mesh {name} for MuJoCo ({type(exc).__name__}: "
                         f"{' '.join(str(exc).split())[:200]}); give an STL or OBJ collision mesh") from exc
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise ModelError(f"the COLLADA collision mesh {name} holds no triangles; give an STL or OBJ collision mesh")
    from trimesh.exchange.obj import export_obj

    text = export_obj(mesh, include_normals=False, include_color=False, include_texture=False, write_texture=False,
                      digits=OBJ_DIGITS, header=None)
    return text.encode("ascii")
