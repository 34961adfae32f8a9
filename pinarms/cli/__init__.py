"""The ``pinarms`` command line: one module per command group, the shared plumbing in ``_common``.

Every command prints a short human-readable report, or with ``--json`` one JSON document
on stdout. Units are SI (m, rad, s) unless ``--deg`` / ``--mm`` ask for degrees and
millimetres at the edge (:mod:`pinarms.units` converts). A user mistake (unknown robot,
malformed numbers, unreachable target, infeasible limits, missing file) ends with one line
``Error: ...`` on stderr and a non-zero exit status, never a Python traceback.

Exit status: 0 success, 1 a pinarms error (bad value, unreachable, infeasible, ...),
2 a command-line usage error (unknown option, missing argument).

A new command group is a new module here that decorates its commands with
``@cli.command`` (or ``@cli.group``) from :mod:`._common`, imported below.
"""

from __future__ import annotations

from pinarms.cli import (  # noqa: F401  (each module registers its commands on ``cli``)
    belt_commands,
    cell_commands,
    cycle_commands,
    demo_command,
    layout_commands,
    line_commands,
    motion_commands,
    reach_commands,
    robot_commands,
    session_commands,
    trajectory_commands,
    urdf_commands,
    verify_commands,
    warm_command,
    workspace_commands,
)
from pinarms.cli._common import cli, main
from pinarms.cli.via_points import read_via_file

__all__ = ["cli", "main", "read_via_file"]
