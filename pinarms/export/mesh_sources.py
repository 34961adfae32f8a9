"""Which files an export may copy, and under which name: meshes and their textures from the allowed folders only.

A received URDF or cell names its mesh files, and a COLLADA mesh names its texture images;
an export copies them into its folder. The sender chooses those names, so each is resolved
and checked before a byte is read:

- **allowed folders**: the description's own folder, the package folders the caller passes
  (``packages={"vendor": folder}``, ``--package vendor=FOLDER``) and, for a robot, the folders
  it was loaded with (``robot.package_dirs``); for a built-in arm or cell, pinarms' own model
  folders. A file named inside a received file never adds a folder.
- each reference is resolved as the loaders resolve it (``package://NAME/rel`` in package
  ``NAME``, or in ``package_dir/NAME/rel``; relative paths in the description's folder;
  ``file://`` and absolute paths as they are), then **every symbolic link and ``..``
  resolved**: the real file must lie inside an allowed folder (a link to ``/etc``, a
  ``package://a/../../x`` through a linked folder ``a``, ``../private/notes.txt`` are refused);
- it must be a regular file (no device, FIFO or socket) of at most :data:`MAX_COPY_BYTES`,
  with a mesh suffix (:data:`MESH_SUFFIXES`; a texture: :data:`TEXTURE_SUFFIXES`), on the
  reference and on the real file;
- its name in the export is made by pinarms from plain names (``A-Z a-z 0-9 _ . -``), never
  taken from the reference; a texture keeps its path relative to its COLLADA file (so the
  copied mesh still finds it) only when that path stays inside the export's ``meshes/``
  folder.

Anything else is :class:`~pinarms.export.errors.MeshNotAllowed` naming the reference; a file
that does not exist is :class:`~pinarms.export.errors.MeshNotFound`.
"""

from __future__ import annotations

import os
import posixpath
import re
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Mapping

from pinarms.files import safe_file_name

from pinarms.export.errors import MeshNotAllowed, MeshNotFound

__all__ = ["MESH_SUFFIXES", "TEXTURE_SUFFIXES", "MAX_COPY_BYTES", "MeshFolders", "MeshSource", "mesh_source",
           "collada_textures"]

#: Mesh files an export copies (what Pinocchio/coal and MuJoCo read).
MESH_SUFFIXES = (".stl", ".dae", ".obj", ".ply")
#: Texture images of a COLLADA mesh an export copies beside it.
TEXTURE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tga", ".bmp", ".tif", ".tiff")
#: Largest file an export copies [bytes] (the cell loader's mesh limit).
MAX_COPY_BYTES = 64 * 2**20

_HOW = ("if you trust the folder that holds it, pass it as a package: packages={NAME: FOLDER} "
        "(on the command line --package NAME=FOLDER)")


@dataclass(frozen=True)
class MeshFolders:
    """Where the meshes of one description may come from.

    Attributes:
        owner: how messages name the description (``robot 'arm'``, ``cell 'line'``).
        own: the description's folder (relative mesh paths), or ``None`` (a URDF without a file).
        packages: ``{NAME: folder}``: ``package://NAME/rel`` is ``folder/rel``.
        search: folders holding packages (``package://NAME/rel`` is ``folder/NAME/rel``), as
            Pinocchio's ``package_dirs``.
    """

    owner: str
    own: Path | None = None
    packages: Mapping[str, Path] = field(default_factory=dict)
    search: tuple[Path, ...] = ()

    def roots(self) -> list[tuple[str, Path]]:
        """``(label, real folder)`` of every allowed folder: named packages, search folders, the own folder."""
        out = [(name, Path(os.path.realpath(p))) for name, p in self.packages.items()]
        out += [("", Path(os.path.realpath(p))) for p in self.search]
        if self.own is not None:
            out.append(("", Path(os.path.realpath(self.own))))
        return out

    def candidates(self, reference: str) -> list[Path]:
        """The files ``reference`` may name, in the order the loaders try them."""
        if reference.startswith("package://"):
            name, _, rel = reference[len("package://"):].partition("/")
            if name in self.packages:
                return [Path(self.packages[name]) / rel]
            return [Path(d) / name / rel for d in self.search]
        if reference.startswith("file://"):
            return [Path(reference[len("file://"):])]
        if "://" in reference:
            raise MeshNotAllowed(f"{self.owner}: mesh {reference[:200]!r} uses a URL scheme other than package:// "
                                 "and file://; give a path or a package:// path")
        if os.path.isabs(reference):
            return [Path(reference)]
        return [] if self.own is None else [Path(self.own) / reference]

    def where(self) -> str:
        return ", ".join(str(r) for _, r in self.roots()) or "none"


@dataclass(frozen=True)
class MeshSource:
    """A checked file to copy: its real path and its path in the export (POSIX, from plain names)."""

    real: Path
    dest: str


def _check_suffix(name: str, suffixes: tuple[str, ...], owner: str, what: str, reference: str) -> None:
    if PurePosixPath(name).suffix.lower() not in suffixes:
        raise MeshNotAllowed(f"{owner}: {what} {reference[:200]!r} is not a {what} file by its suffix "
                             f"({' '.join(suffixes)}); only those are copied")


def _inside(real: Path, folders: MeshFolders) -> tuple[str, Path] | None:
    """The first allowed folder holding ``real`` (label, folder), or ``None``."""
    return next(((label, root) for label, root in folders.roots() if real.is_relative_to(root)), None)


def _real_file(candidate: Path, folders: MeshFolders, what: str, reference: str) -> tuple[Path, str, Path]:
    """``candidate`` resolved, inside an allowed folder, a regular file: (real path, label, folder)."""
    real = Path(os.path.realpath(candidate))
    holder = _inside(real, folders)
    if holder is None:
        raise MeshNotAllowed(f"{folders.owner}: {what} {reference[:200]!r} resolves to {str(real)!r}, outside the "
                             f"folders an export may copy from ({folders.where()}); {_HOW}")
    if not real.is_file():
        raise MeshNotAllowed(f"{folders.owner}: {what} {reference[:200]!r} resolves to {str(real)!r}, "
                             "which is not a regular file")
    return real, holder[0], holder[1]


def mesh_source(reference: str, folders: MeshFolders) -> MeshSource:
    """The checked file a ``<mesh filename>`` names and its path in the export (``meshes/...``; module doc).

    Raises:
        MeshNotAllowed: outside the allowed folders, not a mesh suffix, not a regular file, another URL scheme.
        MeshNotFound: no candidate exists.
    """
    reference = str(reference).strip()
    _check_suffix(reference, MESH_SUFFIXES, folders.owner, "mesh", reference)
    candidates = folders.candidates(reference)
    found = next((c for c in candidates if os.path.lexists(c)), None)
    if found is None:
        hint = (f"; pass the folder of package {reference[len('package://'):].partition('/')[0]!r}: "
                "packages={NAME: FOLDER} (--package NAME=FOLDER)") if reference.startswith("package://") else ""
        raise MeshNotFound(f"{folders.owner}: mesh {reference[:200]!r} cannot be found (looked at "
                           f"{', '.join(str(c) for c in candidates) or 'nothing'}){hint}")
    real, label, root = _real_file(found, folders, "mesh", reference)
    _check_suffix(real.name, MESH_SUFFIXES, folders.owner, "mesh", reference)
    parts = [label] if label else []
    parts += list(real.relative_to(root).parts)
    stem = [safe_file_name(p, "part") for p in parts[:-1]]
    name = safe_file_name(PurePosixPath(parts[-1]).stem, "mesh") + real.suffix.lower()
    return MeshSource(real, "/".join(["meshes", *stem, name]))


_IMAGE_RE = re.compile(r"<init_from>\s*([^<\s]+)\s*</init_from>")


def collada_textures(mesh: MeshSource, folders: MeshFolders, max_bytes: int = MAX_COPY_BYTES) -> list[MeshSource]:
    """The texture images a COLLADA (``.dae``) mesh names by relative path, checked like meshes.

    A texture lands at its path relative to the copied mesh (``mesh.dest``), which must stay
    inside ``meshes/``; URLs and absolute paths are not copied (the mesh then shows without them),
    nor are images that do not exist.

    Raises:
        MeshNotAllowed: a texture outside the allowed folders, or whose place beside the copied
            mesh would leave the export's ``meshes/`` folder.
    """
    if mesh.real.suffix.lower() != ".dae" or mesh.real.stat().st_size > max_bytes:
        return []
    text = mesh.real.read_text(encoding="utf-8", errors="replace")
    out = []
    for ref in dict.fromkeys(_IMAGE_RE.findall(text)):
        if "://" in ref or ref.startswith(("/", "#")) or PurePosixPath(ref).suffix.lower() not in TEXTURE_SUFFIXES:
            continue
        candidate = mesh.real.parent / ref
        if not os.path.lexists(candidate):
            continue
        what = f"texture of mesh {mesh.real.name!r}:"
        real, _, _ = _real_file(candidate, folders, "texture", ref)
        _check_suffix(real.name, TEXTURE_SUFFIXES, folders.owner, "texture", ref)
        dest = posixpath.normpath(posixpath.join(posixpath.dirname(mesh.dest), ref))
        parts = dest.split("/")
        if parts[0] != "meshes" or len(parts) < 2 or any(p.startswith(".") or not p for p in parts):
            raise MeshNotAllowed(f"{folders.owner}: {what} {ref[:200]!r} would land at {dest!r}, outside the "
                                 "export's meshes/ folder; keep textures beside or below their mesh")
        out.append(MeshSource(real, dest))
    return out
