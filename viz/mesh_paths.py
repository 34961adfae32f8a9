"""Meshes of a URDF embedded in a session file: every one read must lie inside the folders the caller allows.

A session file is hostile until checked, and a URDF it embeds names mesh files that the
viewer reads. :func:`check_mesh_paths` resolves each mesh as Pinocchio would and refuses
the URDF when one may lie outside the allowed folders (symbolic links followed), uses a URL
scheme other than ``package://``, ``model://`` or ``file://``, is not a mesh file or not a
regular file, or when the URDF declares a DOCTYPE or entities.
"""

from __future__ import annotations

import os
import re
from pathlib import Path, PurePosixPath
from typing import Any

from pinarms.viz.errors import SessionFormatError

__all__ = ["check_mesh_paths", "MESH_SUFFIXES"]

MESH_SUFFIXES = (".stl", ".dae", ".obj", ".ply", ".glb", ".gltf", ".3ds", ".fbx")

_HOW = ("if you trust that folder, pass it: viz.load_session(path, package_dirs=[...]) or "
        "--package-dir FOLDER on the command line")


def check_mesh_paths(urdf_text: str, package_dirs: tuple[str, ...], source: str, *,
                     recorded: tuple[str, ...] = ()) -> tuple[str, ...]:
    """Refuse an embedded URDF whose meshes may lie outside the allowed folders ``package_dirs``.

    ``package_dirs`` are the folders the *caller* allows (:func:`pinarms.viz.load_session` passes the
    session file's own folder and its ``package_dirs`` argument); folders named inside the
    file (``recorded``, the ``package_dirs`` of ``session.json``) never widen them.
    Pinocchio resolves ``package://p`` (and ``model://p``) and relative paths ``p`` against
    each allowed folder, and uses absolute paths and ``file://`` URLs as they are. Each must
    name a mesh file (``.stl``, ``.dae``, ...) that lies, symbolic links followed, inside
    one of the allowed folders: ``..`` escapes, absolute paths elsewhere, other URL schemes
    and non-regular files (devices, FIFOs) are refused. A package-relative mesh found in no
    allowed folder is refused when the file names folders of its own that were not passed
    (the message says which to pass); otherwise it is left to the viewer (which reports it).
    Recorded folders that lie inside an allowed folder (links followed) are searched too.

    Returns:
        The folders to resolve meshes against: the recorded ones inside the allowed folders,
        then the allowed folders.

    Raises:
        SessionFormatError: naming the robot and the mesh path, and what to pass instead.
    """
    root = _parse_urdf(urdf_text, source)
    roots = [Path(d).resolve() for d in package_dirs if isinstance(d, str) and d]
    bases, unlisted = _search_folders(roots, recorded)
    for mesh in root.iter("mesh"):
        _check_mesh(mesh.get("filename", ""), source, roots, bases, unlisted)
    return tuple(str(b) for b in bases)


def _parse_urdf(urdf_text: str, source: str) -> Any:
    """The URDF's XML root; a DOCTYPE, entities or malformed XML raise SessionFormatError."""
    import xml.etree.ElementTree as ET

    if re.search(r"<!\s*(DOCTYPE|ENTITY)", urdf_text, re.IGNORECASE):
        raise SessionFormatError(f"{source}: the URDF declares a DOCTYPE or entities; entity expansion is refused")
    try:
        return ET.fromstring(urdf_text)
    except ET.ParseError as exc:
        raise SessionFormatError(f"{source}: the embedded URDF is not well-formed XML ({exc})") from None


def _search_folders(roots: list[Path], recorded: tuple[str, ...]) -> tuple[list[Path], list[str]]:
    """The folders to search (recorded ones inside ``roots``, then ``roots``) and the recorded ones left out."""
    inside, unlisted = [], []
    for d in recorded:
        try:
            real = Path(d).resolve() if isinstance(d, str) and os.path.isabs(d) else None
        except (ValueError, OSError):  # a NUL byte, a path too long: never a folder to search
            real = None
        if real is not None and any(real.is_relative_to(b) for b in roots):
            inside.append(real)
        elif isinstance(d, str) and d:
            unlisted.append(d)
    return list(dict.fromkeys(inside + roots)), unlisted


def _check_mesh(name: str, source: str, roots: list[Path], bases: list[Path], unlisted: list[str]) -> None:
    """Refuse the mesh ``name`` unless each file it may resolve to lies inside ``roots`` and is a regular file."""
    where = f"the allowed folders {[str(b) for b in roots]}" if roots else "the allowed folders (none)"
    shown = repr(name[:200])
    scheme, sep, rest = name.partition("://")
    if not sep:
        scheme, rest = "", name
    if scheme not in ("", "package", "model", "file"):
        raise SessionFormatError(f"{source}: mesh {shown} uses the URL scheme {scheme!r}; only package://, "
                                 f"model://, file:// and plain paths are read")
    rel = PurePosixPath(rest)
    if rel.suffix.lower() not in MESH_SUFFIXES:
        raise SessionFormatError(f"{source}: mesh {shown} is not a mesh file ({', '.join(MESH_SUFFIXES)})")
    absolute = scheme == "file" or rel.is_absolute()
    if absolute:
        if not rel.is_absolute():
            raise SessionFormatError(f"{source}: mesh {shown} is a file:// URL without an absolute path")
        if not any(Path(rest).resolve().is_relative_to(b) for b in roots):
            raise SessionFormatError(f"{source}: mesh {shown} lies outside {where}; {_HOW}")
        candidates = [Path(rest)]
    else:
        if ".." in rel.parts or not rel.parts:
            raise SessionFormatError(f"{source}: mesh {shown} leaves its package folder ('..')")
        # Pinocchio tries <dir>/<path>; some versions also <dir>/<path without its package name>
        tails = [rel.parts] + ([rel.parts[1:]] if scheme and len(rel.parts) > 1 else [])
        candidates = [base.joinpath(*tail) for base in bases for tail in tails]
    found = False
    for cand in candidates:
        if not os.path.lexists(cand):
            continue
        found = True
        real = cand.resolve()
        if not any(real.is_relative_to(base) for base in roots):
            raise SessionFormatError(f"{source}: mesh {shown} resolves to {str(real)!r}, outside {where}; {_HOW}")
        if not real.is_file():
            raise SessionFormatError(f"{source}: mesh {shown} resolves to {str(real)!r}, which is not a "
                                     f"regular file")
    if not found and not absolute and unlisted:
        raise SessionFormatError(
            f"{source}: mesh {shown} is in none of {where}; the session file names the folder(s) "
            f"{[d[:200] for d in unlisted[:5]]}, which a session cannot allow by itself: {_HOW}")
