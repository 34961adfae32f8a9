"""Meshes MuJoCo cannot read, converted on export: COLLADA collision meshes as OBJ, ASCII STL as binary STL.

MuJoCo reads binary STL, OBJ and MSH meshes only. An ASCII STL file is written as binary STL
(:func:`binary_stl`: the cell export's copies, and beside the arm's as ``<stem>_binary.stl``).

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
import struct
import xml.etree.ElementTree as ET
from pathlib import Path, PurePosixPath
from typing import Callable, Iterator

from pinarms.files import path_inside
from pinarms.errors import ModelError

from pinarms.export.errors import MeshNotFound

__all__ = ["collada_to_obj", "binary_stl", "is_ascii_stl", "mujoco_conversions", "OBJ_DIGITS"]

#: Decimals of the vertex coordinates written [m]: 1e-12 m.
OBJ_DIGITS = 12


def is_ascii_stl(head: bytes) -> bool:
    """Whether a file starting with ``head`` (its first 4 kB suffice) is an ASCII STL file."""
    return head[:512].lstrip().lower().startswith(b"solid") and b"facet" in head[:4096].lower()


def _with_name(mesh: str, tail: str) -> str:
    path = PurePosixPath(mesh)
    return str(path.with_name(f"{path.stem}{tail}"))


def mujoco_conversions(urdf_text: str, folder: Path) -> Iterator[tuple[str, str, Callable[[bytes], bytes]]]:
    """``(mesh, converted mesh, conversion)`` for each mesh of a URDF in ``folder`` that MuJoCo cannot read.

    The COLLADA meshes of ``<collision>`` elements (``<stem>_collada.obj``; COLLADA visuals are
    discarded) and the ASCII STL meshes (``<stem>_binary.stl``), each once, in document order.
    """
    root = ET.fromstring(urdf_text)
    stl = dict.fromkeys(e.get("filename", "") for e in root.iter("mesh") if e.get("filename", "").lower().endswith(".stl"))
    for name in stl:
        with open(path_inside(folder, name), "rb") as f:
            ascii_stl = is_ascii_stl(f.read(4096))
        if ascii_stl:
            yield name, _with_name(name, "_binary.stl"), lambda data, n=name: binary_stl(data, n)
    dae = dict.fromkeys(e.get("filename", "") for c in root.iter("collision") for e in c.iter("mesh")
                        if e.get("filename", "").lower().endswith(".dae"))
    for name in dae:
        yield name, _with_name(name, "_collada.obj"), lambda data, n=name: collada_to_obj(data, n)


def binary_stl(data: bytes, name: str) -> bytes:
    """An ASCII STL file as binary STL (MuJoCo reads binary STL only); binary STL as it is."""
    if not is_ascii_stl(data):
        return data
    words = data.decode("ascii", errors="replace").split()
    facets = []
    try:
        for i, w in enumerate(words):
            if w == "normal":
                normal = [float(v) for v in words[i + 1 : i + 4]]
            elif w == "vertex":
                facets.append((normal, [float(v) for v in words[i + 1 : i + 4]]))
    except (ValueError, UnboundLocalError) as exc:
        raise MeshNotFound(f"mesh {name} is not a readable ASCII STL file ({exc})") from exc
    if not facets or len(facets) % 3:
        raise MeshNotFound(f"mesh {name} is not a readable ASCII STL file (vertices not in triangles)")
    out = bytearray(b"binary STL written by pinarms".ljust(80, b" "))
    out += struct.pack("<I", len(facets) // 3)
    for k in range(0, len(facets), 3):
        out += struct.pack("<3f", *facets[k][0])
        for _, vertex in facets[k : k + 3]:
            out += struct.pack("<3f", *vertex)
        out += b"\x00\x00"
    return bytes(out)


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
