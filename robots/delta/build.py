"""Generate the shipped deltas' URDF (the open tree) and closures file from their xacro sources.

Command line::

    python -m pinarms.robots.delta.build           # regenerate urdf/<delta>.urdf and .closures.xml
    python -m pinarms.robots.delta.build --check   # exit status 1 and list the stale files
"""

from __future__ import annotations

import sys
from pathlib import Path

from pinarms.robots.urdf_build import build_file, write_atomic
from pinarms.robots.delta.closures import closures_to_xml
from pinarms.robots.delta.family import family_closures
from pinarms.robots.delta.shipped import delta_info, delta_names

__all__ = ["build_delta", "build_deltas", "stale_deltas"]


def build_delta(name: str) -> dict[Path, str]:
    """The files of shipped delta ``name``: ``{urdf path: URDF text, closures path: closures text}``."""
    entry = delta_info(name)
    label = f"robots/delta/xacro/{entry.xacro_path.name}"
    urdf = build_file(entry.xacro_path, source_label=label)
    closures = closures_to_xml(family_closures(name), comment=f"Loop closures of {name} (generated from {label} "
                               "by `python -m pinarms.robots.delta.build`): each forearm's lower ball joint on "
                               "the platform. Pinocchio builds its constraint models from them.")
    return {entry.urdf_path: urdf, entry.closures_path: closures}


def build_deltas() -> list[Path]:
    """Write every shipped delta's files (all built before any is written, each atomically)."""
    files = {p: t for name in delta_names() for p, t in build_delta(name).items()}
    for path, text in files.items():
        write_atomic(path, text)
    return list(files)


def stale_deltas() -> list[str]:
    """Names of the committed delta files that differ from a fresh build."""
    out = []
    for name in delta_names():
        for path, text in build_delta(name).items():
            if not path.is_file() or path.read_text(encoding="utf-8") != text:
                out.append(path.name)
    return out


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv == ["--check"]:
        stale = stale_deltas()
        for name in stale:
            print(f"stale: {name}")
        return 1 if stale else 0
    for path in build_deltas():
        print(f"wrote {path.name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
