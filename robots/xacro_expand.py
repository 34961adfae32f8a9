"""Expand a user's xacro file into URDF text, behind a wall (time, memory, files).

A xacro file is a program: its ``${...}`` expressions are Python, ``load_yaml`` reads
files, ``<xacro:include>`` pulls in any XML file, ``$(env ...)`` reads the environment.
A cell or arm description received from someone else must not be able to read the
machine's files or hang it, so :func:`expand_xacro` runs xacro in a child process with:

- **time**: a wall-clock timeout and a CPU-time limit (:attr:`XacroLimits.timeout_s`);
- **memory**: an address-space limit (:attr:`XacroLimits.memory_bytes`) and a cap on the
  size of the URDF text (:attr:`XacroLimits.output_bytes`);
- **a sandbox**: the child reads no file of the request itself (this process serves each
  one after checking it, :mod:`pinarms.robots._xacro_child`) and, before asking for the
  first, walls itself in (:mod:`pinarms.robots._sandbox`): Linux Landlock (it can write,
  create or remove nothing, execute no program, read only the interpreter's folders), no
  capability, ``no_new_privs``, and a seccomp filter (no network, no metadata change, no
  control of other processes); it gets an empty environment and may not start processes.
  Without Landlock a root child drops to the user ``nobody``; :attr:`XacroResult.wall`
  lists the steps taken;
- **files**: the input, its includes and ``load_yaml`` files must lie (symbolic links
  resolved) inside the file's own folder or a package folder the caller names;
  ``$(find PKG)`` resolves only those packages (``pinarms`` is always given: the folder
  of the built-in arms' macros, so a cell can ``<xacro:include
  filename="$(find pinarms)/scara_mushroom.xacro"/>``);
- **expressions**: ``${...}`` is evaluated by the whitelist of
  :mod:`pinarms.robots.xacro_eval`, never by Python's ``eval``: literals, property names,
  arithmetic, comparisons, ``and`` / ``or`` / ``not``, ``a if c else b``, subscripts of
  lists and dicts, and calls of a fixed set of math functions (``radians``, ``sin``, ...,
  ``xacro.arg``, ``xacro.tokenize``, ``load_yaml``); anything else is
  :class:`~pinarms.errors.XacroForbidden` naming the construct, and numbers or
  strings beyond the size bounds are :class:`~pinarms.errors.XacroLimitExceeded`
  at once. ``$(env)``, ``$(optenv)``, ``$(eval)`` and ``$(cwd)`` are refused.

Everything else of xacro works as documented by ROS: properties, macros with default and
block parameters, ``xacro:if``/``unless``, ``xacro:arg`` with defaults, includes with
namespaces. Errors are named: :class:`~pinarms.errors.XacroForbidden` (the wall),
:class:`~pinarms.errors.XacroLimitExceeded` (time, memory, size),
:class:`~pinarms.errors.XacroFileNotFound` (the file, an included file or a yaml
file does not exist; also a :class:`~pinarms.errors.CellNotFound`),
:class:`~pinarms.errors.XacroArgError` (an argument the file does not declare, or
a non-number for an argument whose default is a number) and
:class:`~pinarms.errors.XacroError` (xacro itself fails: unknown macro, undefined
property, malformed XML: the message names the file, included or not, and the line).
See docs/files.md.
"""

from __future__ import annotations

import math
import os
import signal
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from pinarms.files import check_regular

from pinarms.robots._xacro_child import WorkerFailed, WorkerOutputTooLarge, WorkerTimeout, run_worker
from pinarms.errors import (
    InvalidInput,
    MissingMesh,
    XacroArgError,
    XacroError,
    XacroFileNotFound,
    XacroForbidden,
    XacroLimitExceeded,
)

__all__ = ["XacroLimits", "XacroResult", "expand_xacro", "BUILTIN_PACKAGE", "parse_xacro_args", "mesh_path", "check_mesh_files"]

#: ``$(find pinarms)``: the folder of the built-in arms' xacro macros.
BUILTIN_PACKAGE = ("pinarms", Path(__file__).resolve().parent / "xacro")


@dataclass(frozen=True)
class XacroLimits:
    """Bounds of one expansion.

    Attributes:
        timeout_s: wall-clock time [s] (also the CPU-time limit, rounded up).
        memory_bytes: address space of the expanding process [bytes].
        output_bytes: largest URDF text accepted [bytes].
    """

    timeout_s: float = 20.0
    memory_bytes: int = 768 * 2**20
    output_bytes: int = 64 * 2**20

    def __post_init__(self) -> None:
        for name in ("timeout_s", "memory_bytes", "output_bytes"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
                raise InvalidInput(f"XacroLimits.{name} must be a finite positive number, got {value!r}")


@dataclass(frozen=True)
class XacroResult:
    """What :func:`expand_xacro` produced.

    Attributes:
        urdf_text: the URDF (pretty-printed XML, with the given header comments).
        files: every file read (the input, includes, yaml), resolved paths, sorted.
        args: the ``xacro:arg`` values used (declared defaults, overridden by the caller's).
        declared: the file's ``xacro:arg`` declarations and their defaults.
        wall: the sandbox the expansion ran in, e.g. ``"landlock (ABI 7), no capabilities,
            seccomp"`` (first part ``"landlock (ABI n)"``, ``"user nobody (no Landlock)"`` or
            ``"resource limits only"``).
    """

    urdf_text: str
    files: tuple[str, ...]
    args: Mapping[str, str] = field(default_factory=dict)
    declared: Mapping[str, str] = field(default_factory=dict)
    wall: str = ""


def _as_number(text: str) -> float | None:
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def _arg_text(name: str, value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        if not math.isfinite(float(value)):
            raise XacroArgError(f"xacro argument {name!r} must be finite, got {value!r}")
        return repr(float(value)) if isinstance(value, float) else str(int(value))
    if hasattr(value, "item") and callable(value.item):  # numpy scalar
        return _arg_text(name, value.item())
    if isinstance(value, str):
        return value
    raise XacroArgError(f"xacro argument {name!r} must be a number or a string, got {type(value).__name__}")


def parse_xacro_args(items: list[str] | tuple[str, ...]) -> dict[str, str]:
    """``["k=v", ...]`` (command-line ``--arg k=v``) → ``{"k": "v"}``; :class:`XacroArgError` otherwise."""
    out: dict[str, str] = {}
    for item in items:
        name, sep, value = str(item).partition("=")
        if not sep or not name.strip():
            raise XacroArgError(f"xacro argument must be written NAME=VALUE, got {item!r}")
        out[name.strip()] = value.strip()
    return out


def _limit_resources(limits: XacroLimits):
    def apply() -> None:  # runs in the child between fork and exec
        import resource

        cpu = int(math.ceil(limits.timeout_s)) + 1
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu))
        resource.setrlimit(resource.RLIMIT_AS, (int(limits.memory_bytes), int(limits.memory_bytes)))
        resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        try:
            resource.setrlimit(resource.RLIMIT_NPROC, (0, 0))
        except (ValueError, OSError):  # pragma: no cover - some kernels refuse 0
            pass

    return apply


def expand_xacro(
    path: str | os.PathLike,
    args: Mapping[str, str | float] | None = None,
    *,
    packages: Mapping[str, str | os.PathLike] | None = None,
    header: tuple[str, ...] | list[str] = (),
    limits: XacroLimits | None = None,
) -> XacroResult:
    """Expand the xacro file ``path`` into URDF text behind the wall of the module doc.

    Args:
        path: the ``.xacro`` file.
        args: values of the file's ``xacro:arg`` declarations (numbers or strings). An
            argument whose declared default is a number must be given a number.
        packages: ``{name: folder}`` for ``$(find name)``; the folders may be read too.
            ``pinarms`` (the built-in macros) is always available.
        header: comment lines put at the top of the URDF, replacing xacro's banner (which
            holds the file's absolute path).
        limits: time, memory and size bounds (default :class:`XacroLimits`).

    Raises:
        XacroForbidden: the file reads outside its folders (also by an include pattern),
            declares a DOCTYPE, or uses a refused construct.
        XacroLimitExceeded: time, memory or output size exceeded (the output is read only
            up to ``limits.output_bytes``).
        XacroArgError: an argument the file does not declare, or a non-number for a
            numeric one.
        XacroFileNotFound: the file, a file it includes or a yaml file it loads is missing.
        XacroError: xacro fails (unknown macro, undefined property, malformed XML of the
            file or of an included file: the message names that file and the line; root
            element not ``<robot>``).
    """
    limits = limits if limits is not None else XacroLimits()
    if not isinstance(limits, XacroLimits):
        raise InvalidInput(f"limits must be a XacroLimits, got {type(limits).__name__}")
    check_regular(path, "xacro file", error=XacroError, missing=XacroFileNotFound)  # a FIFO would block the child
    path = Path(path)
    given = {str(k): _arg_text(str(k), v) for k, v in (args or {}).items()}
    pkgs = {BUILTIN_PACKAGE[0]: str(BUILTIN_PACKAGE[1])}
    for name, folder in (packages or {}).items():
        folder = Path(folder)
        if not folder.is_dir():
            raise XacroError(f"package {name!r}: folder {str(folder)!r} does not exist")
        pkgs[str(name)] = str(folder.resolve())
    roots = [str(path.resolve().parent), *pkgs.values()]
    request = {"path": str(path.resolve()), "args": given, "roots": roots, "packages": pkgs, "header": list(header)}
    try:
        answer, files = run_worker(request, cwd=str(path.resolve().parent), timeout_s=limits.timeout_s,
                                   output_bytes=int(limits.output_bytes), preexec=_limit_resources(limits))
    except WorkerTimeout:
        raise XacroLimitExceeded(
            f"xacro on {str(path)!r} did not finish within {limits.timeout_s:g} s "
            "(an expression or macro that never ends?); pinarms stopped it"
        ) from None
    except WorkerOutputTooLarge:
        raise XacroLimitExceeded(
            f"xacro on {str(path)!r} produced more than the {limits.output_bytes / 2**20:g} MiB allowed; "
            "pinarms stopped it there"
        ) from None
    except WorkerFailed as exc:
        status, text = exc.args
        if "MemoryError" in text or status == -signal.SIGKILL:
            raise XacroLimitExceeded(
                f"xacro on {str(path)!r} needed more than {limits.memory_bytes / 2**20:g} MiB of memory; pinarms stopped it"
            ) from None
        if status == -signal.SIGXCPU:
            raise XacroLimitExceeded(
                f"xacro on {str(path)!r} used more than {limits.timeout_s:g} s of CPU; pinarms stopped it") from None
        last = " ".join(text.strip().splitlines()[-1:]) or f"exit status {status}"
        raise XacroError(f"xacro on {str(path)!r} failed: {last}") from None
    declared = {k: v for k, v in answer.get("declared", {}).items()}
    _check_numeric_args(path, given, declared)
    if not answer["ok"]:
        kind, message = answer["kind"], answer["message"]
        if kind == "memory":
            raise XacroLimitExceeded(
                f"xacro on {str(path)!r} needed more than {limits.memory_bytes / 2**20:g} MiB of memory; pinarms stopped it"
            )
        cls = {"forbidden": XacroForbidden, "args": XacroArgError, "limit": XacroLimitExceeded,
               "not_found": XacroFileNotFound}.get(kind, XacroError)
        raise cls(f"xacro on {str(path)!r}: {message}")
    used = {k: given.get(k, v) for k, v in declared.items()}
    return XacroResult(answer["urdf"], tuple(files), used, declared, answer.get("wall", ""))


def _check_numeric_args(path: Path, given: dict[str, str], declared: dict[str, str | None]) -> None:
    for name, value in given.items():
        default = declared.get(name)
        if default is not None and _as_number(default) is not None and _as_number(value) is None:
            raise XacroArgError(
                f"xacro argument {name!r} of {str(path)!r} must be a number (its default is {default}), got {value!r}"
            )


def mesh_path(filename: str, base_dir: str | os.PathLike, packages: Mapping[str, str | os.PathLike] | None = None) -> Path:
    """The file a URDF ``<mesh filename>`` names, checked to lie in the allowed folders.

    ``package://PKG/rel`` resolves in ``packages[PKG]``; ``file://`` and absolute paths are
    taken as they are; a relative path resolves against ``base_dir`` (the description's
    folder). Allowed folders: ``base_dir`` and the package folders (symbolic links resolved).

    Raises:
        XacroForbidden: the file lies outside the allowed folders, or names an unknown package.
        MissingMesh: the file does not exist.
    """
    pkgs = {BUILTIN_PACKAGE[0]: Path(BUILTIN_PACKAGE[1]), **{str(k): Path(v) for k, v in (packages or {}).items()}}
    base = Path(base_dir).resolve()
    text = str(filename).strip()
    if text.startswith("package://"):
        pkg, _, rel = text[len("package://"):].partition("/")
        if pkg not in pkgs:
            raise XacroForbidden(
                f"mesh {text!r}: package {pkg!r} is not among the packages given ({', '.join(sorted(pkgs))}); "
                f"pass packages={{{pkg!r}: folder}} (on the command line --package {pkg}=FOLDER)"
            )
        target = pkgs[pkg] / rel
    elif text.startswith("file://"):
        target = Path(text[len("file://"):])
    else:
        target = Path(text) if os.path.isabs(text) else base / text
    real = Path(os.path.realpath(target))
    roots = [base, *(Path(os.path.realpath(p)) for p in pkgs.values())]
    if not any(real == r or r in real.parents for r in roots):
        raise XacroForbidden(
            f"mesh {text!r} lies outside the folders the description may read "
            f"({', '.join(str(r) for r in roots)})"
        )
    if not real.is_file():
        raise MissingMesh(f"mesh file {text!r} does not exist (looked for {str(target)!r})")
    return real


def check_mesh_files(
    urdf_text: str, source: str | os.PathLike, packages: Mapping[str, str | os.PathLike] | None = None
) -> list[str]:
    """Check every ``<mesh filename>`` of ``urdf_text`` with :func:`mesh_path`.

    Args:
        source: the description file (its folder resolves relative paths).

    Returns:
        The package folders (``pinarms`` first, then ``packages``), for ``package_dirs``.
    """
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(urdf_text)
    except ET.ParseError as exc:
        raise XacroError(f"{str(source)!r} did not expand to well-formed XML: {exc}") from exc
    base = Path(source).resolve().parent
    for mesh in root.iter("mesh"):
        mesh_path(mesh.get("filename", ""), base, packages)
    return [str(BUILTIN_PACKAGE[1]), *(str(Path(v).resolve()) for v in (packages or {}).values())]
