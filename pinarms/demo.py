"""The four-paper demo: each seed's study redone, compared number by number with the paper.

``run_demo(out_dir, quick=False)`` runs one study function per seed, each in its own module
under :mod:`pinarms.studies` (``seed000`` ... ``seed004``, ``cell``, ``line``, ``handoff``;
this module only lists them in :data:`STUDIES`). A study builds its
robot, redoes the paper's computation with pinarms and returns the rows of the
paper-vs-pinarms table (:class:`pinarms.report.Row`), a :class:`pinarms.viz.Session` and the
plots. The runner writes, into ``out_dir``::

    table.md, table.json       the paper-vs-pinarms table
    sessions/seed<k>.pinarms   one session per study (``pinarms view`` reopens it; cell.pinarms)
    html/seed<k>.html          the same scene as one standalone HTML page
    plots/seed<k>_*.png        joint curves, GA convergence, workspace views; cell_schedule.png,
                               cell_clearance.png

The ``cell`` study (docs/cells.md) plans the two SCARAs of ``mushroom_line`` on one belt and
the AUBO-i3's crate cycle in ``aubo_food_station``, its rows filed under seeds 000 and 001.
``quick`` uses fewer samples and GA generations (3 to 5 minutes on two cores once the kernels are
compiled, docs/first_use.md); the published numbers compared are the same. They all come from :mod:`pinarms.papers`; seed
002's via points (the paper prints none) are pinarms's representative path
:data:`pinarms.scenarios.GANTRY_PATH_AXIS_M`.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from pinarms.studies.cell import LINE_TASKS, study_cell  # noqa: F401  (old import path of LINE_TASKS)
from pinarms.studies.seed000 import study_000
from pinarms.studies.seed001 import study_001
from pinarms.studies.seed002 import BOUNDS_002_S, study_002  # noqa: F401  (old import path of BOUNDS_002_S)
from pinarms.studies.seed004 import study_004
from pinarms.studies.study import Study

from pinarms.report import Row, format_table, markdown_table

__all__ = ["Study", "DemoResult", "STUDIES", "run_demo", "study_000", "study_001", "study_002", "study_004",
           "study_cell", "study_line", "study_delta"]


@dataclass
class DemoResult:
    """All studies, the files written, and the table."""

    studies: list[Study]
    files: list[Path]
    out_dir: Path

    @property
    def rows(self) -> list[Row]:
        return [r for s in self.studies for r in s.rows]

    def table_text(self, width: int | None = None) -> str:
        """The table for a terminal (``width``: wrap to that many columns; None: one line per row)."""
        return format_table(self.rows, width=width)

    def as_dict(self) -> dict[str, Any]:
        return {
            "out_dir": str(self.out_dir),
            "rows": [r.as_dict() for r in self.rows],
            "studies": [{"key": s.key, "title": s.title, "seconds": round(s.seconds, 3)} for s in self.studies],
            "files": [str(p) for p in self.files],
        }


def study_line(quick: bool = False) -> Study:
    """The line study (:mod:`pinarms.studies.line`): arms, picks/min and miss rate on a belt."""
    from pinarms.studies.line import demo_study

    return demo_study(quick)


def study_delta(quick: bool = False) -> Study:
    """The delta study (:mod:`pinarms.studies.delta_cycle`): the standard pick cycle vs ABB's datasheet."""
    from pinarms.studies.delta_cycle import study_delta as _study

    return _study(quick)


def study_handoff(quick: bool = False) -> Study:
    """The hand-off study (:mod:`pinarms.studies.handoff`): MuJoCo re-check, SRDF, controller files."""
    from pinarms.studies.handoff import demo_study

    return demo_study(quick)


STUDIES: dict[str, Callable[[bool], Study]] = {
    "000": study_000,
    "001": study_001,
    "002": study_002,
    "004": study_004,
    "cell": study_cell,
    "line": study_line,
    "handoff": study_handoff,
    "delta": study_delta,
}


def run_demo(out_dir: str | Path = "demo-output", *, quick: bool = False, only: Any = None,
             progress: Callable[[str], None] | None = None) -> DemoResult:
    """Run the studies, write the table, sessions, HTML pages and plots into ``out_dir``.

    ``progress(label)`` is called as each study starts (``"seed 001: running the study"``)
    and ends (``"seed 001: done"``).
    """
    from pinarms import viz

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    keys = list(STUDIES) if not only else [k for k in STUDIES if k in set(only)]
    studies: list[Study] = []
    files: list[Path] = []
    for key in keys:
        if progress:
            progress(f"seed {key}: running the study")
        t0 = time.perf_counter()
        study = STUDIES[key](quick)
        study.seconds = time.perf_counter() - t0
        studies.append(study)
        if study.session is not None:
            (out / "sessions").mkdir(exist_ok=True)
            stem = f"seed{key}" if key.isdigit() else key
            path = out / "sessions" / f"{stem}.pinarms"
            study.session.save(path)
            files.append(path)
            (out / "html").mkdir(exist_ok=True)
            html = out / "html" / f"{stem}.html"
            viz.export_html(study.session, html)
            files.append(html)
        if study.plots:
            (out / "plots").mkdir(exist_ok=True)
            for name, write in study.plots.items():
                png = out / "plots" / f"{'seed' + key if key.isdigit() else key}_{name}.png"
                write(png)
                files.append(png)
        for name, write in study.exports.items():
            files += write(out / "export" / name)
        if progress:
            progress(f"seed {key}: done")
    result = DemoResult(studies, files, out)
    (out / "table.md").write_text("# paper vs pinarms\n\n" + markdown_table(result.rows) + "\n", encoding="utf-8")
    (out / "table.json").write_text(json.dumps(result.as_dict()["rows"], indent=2), encoding="utf-8")
    result.files[:0] = [out / "table.md", out / "table.json"]
    return result
