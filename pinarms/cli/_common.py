"""Shared plumbing of the ``pinarms`` command line: the command group, error handling,
JSON output, number parsing, unit scales and session saving (one place for every command group).
"""

from __future__ import annotations

import dataclasses
import json
import math
import sys
from pathlib import Path
from typing import Any, Iterable

import click
import numpy as np

from pinarms import robots
from pinarms.errors import InvalidInput, PinarmsError
from pinarms.robots.robot import Robot

__all__ = ["cli", "main", "json_option", "skipped_pair_lines", "package_map", "PinarmsCommand", "name_the_flag", "NUMBERS", "PinarmsGroup", "one_line", "jsonable", "emit", "fmt",
           "show_progress", "progress_bar", "terminal_width", "load_robot", "floats", "si_limit", "vectors_from_args",
           "joint_scale_at", "new_session", "save_session", "scheduler_option", "scheduler_value", "quiet_dask"]

# numbers may be negative: "-0.5" must reach the command as a value, not as an option
NUMBERS = {"ignore_unknown_options": True}


def one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


#: Set this variable (to anything) to see the Python traceback of an unexpected error.
DEBUG_VARIABLE = "PINARMS_TRACEBACK"


def name_the_flag(text: str, params: list[click.Parameter]) -> str:
    """``text`` with its first word, when it is the Python name of one of ``params``' options
    (``amax must be ...``), replaced by the option's flag (``--amax must be ...``): the library
    names its parameters, the command line must name the flag that fixes the error."""
    head, sep, rest = text.partition(" ")
    for p in params:
        if isinstance(p, click.Option) and p.name == head and p.opts:
            return max(p.opts, key=len) + sep + rest
    return text


class PinarmsCommand(click.Command):
    """A command whose pinarms errors name its flags (:func:`name_the_flag`); one ``Error:`` line."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except PinarmsError as exc:
            raise click.ClickException(name_the_flag(one_line(exc), self.params)) from None


class PinarmsGroup(click.Group):
    """A click group that turns every error into one line ``Error: ...`` (exit status 1).

    pinarms errors print their message; a missing or unreadable file, a file that is not
    UTF-8 text and running out of memory say so; anything else is an unexpected error,
    named by its type (``PINARMS_TRACEBACK=1`` shows its traceback). Python warnings (NumPy's
    overflow or division warnings) raised by a command that fails are dropped, the ``Error:``
    line says what went wrong; after a command that succeeds each distinct one is a
    ``Warning: ...`` line on stderr. An unknown option that names an existing file says how
    to give it (``./--c.toml`` or ``-- --c.toml``). Its commands are :class:`PinarmsCommand`.
    """

    command_class = PinarmsCommand

    def invoke(self, ctx: click.Context) -> Any:
        import warnings

        if ctx.parent is not None:  # a nested group: the outermost one catches and reports
            return self._invoke(ctx)
        with warnings.catch_warnings(record=True) as caught:  # the filters in force decide what is recorded
            result = self._invoke(ctx)  # on an error, its one Error: line is all the user sees
        for text in dict.fromkeys(f"{w.category.__name__}: {' '.join(str(w.message).split())}" for w in caught):
            click.echo(f"Warning: {text}", err=True)  # one line each, without Python's source lines
        return result

    def _invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except click.NoSuchOption as exc:
            import os

            if exc.option_name and os.path.exists(exc.option_name):
                exc.message = (f"{exc.message.rstrip('.')}; to name the file {exc.option_name!r}, write "
                               f"./{exc.option_name} or put -- before it")
            raise
        except (click.ClickException, click.exceptions.Exit, click.exceptions.Abort):
            raise
        except PinarmsError as exc:
            raise click.ClickException(one_line(exc)) from None
        except FileNotFoundError as exc:
            raise click.ClickException(f"file not found: {exc.filename or one_line(exc)}") from None
        except OSError as exc:
            where = f"{exc.filename}: " if exc.filename else ""
            raise click.ClickException(f"{where}{exc.strerror or one_line(exc)}") from None
        except UnicodeDecodeError as exc:
            raise click.ClickException(f"a file is not UTF-8 text ({one_line(exc)}): save it as UTF-8") from None
        except MemoryError:
            raise click.ClickException("out of memory: lower the counts or sizes asked for") from None
        except Exception as exc:
            import os

            if os.environ.get(DEBUG_VARIABLE):
                raise
            raise click.ClickException(
                f"unexpected {type(exc).__name__}: {one_line(exc)} (a bug in pinarms: set {DEBUG_VARIABLE}=1 "
                "to see where, and report it)") from None


def jsonable(obj: Any) -> Any:
    """Plain JSON types for numpy arrays/scalars, dataclasses, paths and dict-like results."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, Path):
        return str(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    for method in ("as_dict", "to_dict"):
        if callable(getattr(obj, method, None)):
            return jsonable(getattr(obj, method)())
    if hasattr(obj, "_asdict"):
        return jsonable(obj._asdict())
    return obj if isinstance(obj, (str, int, type(None))) else str(obj)


def emit(as_json: bool, data: dict, lines: Iterable[str]) -> None:
    if as_json:
        click.echo(json.dumps(jsonable(data), indent=2))
    else:
        for line in lines:
            click.echo(line)


def fmt(values: Any, digits: int = 6) -> str:
    arr = np.atleast_1d(np.asarray(values, dtype=float))
    return "  ".join(f"{v:.{digits}g}" for v in arr)


def show_progress(as_json: bool) -> bool:
    """Progress bars only for a person at a terminal, never in machine-readable output."""
    from pinarms.progress import wanted

    return wanted(as_json, sys.stderr)


def progress_bar(label: str, total: int | None, as_json: bool):
    """A :class:`pinarms.progress.ProgressBar` on stderr, drawn only when :func:`show_progress` says so."""
    from pinarms.progress import ProgressBar

    return ProgressBar(label, total, enabled=show_progress(as_json), stream=sys.stderr)


def terminal_width() -> int | None:
    """Columns of the terminal stdout writes to (``COLUMNS`` if set); ``None`` for a pipe or a file."""
    import os
    import shutil

    if not (sys.stdout.isatty() or os.environ.get("COLUMNS")):
        return None
    return max(40, shutil.get_terminal_size().columns)


def load_robot(name: str) -> Robot:
    """A registry name, or the path of any ``.urdf`` file."""
    if name.lower().endswith(".urdf"):
        return robots.from_urdf(name)
    return robots.load(name)


def floats(text: str, what: str) -> np.ndarray:
    """``"1, 2,3"`` → array; a clear usage error otherwise."""
    parts = [p for p in text.replace(";", ",").split(",") if p.strip()]
    try:
        values = np.array([float(p) for p in parts], dtype=float)
    except ValueError:
        raise click.BadParameter(f"{what} must be comma-separated numbers, got {text!r}") from None
    if values.size == 0:
        raise click.BadParameter(f"{what} is empty")
    if not np.all(np.isfinite(values)):
        raise click.BadParameter(f"{what} holds a non-finite value: {text!r}")
    return values


def si_limit(text: str | None, what: str, scale: float | np.ndarray) -> np.ndarray | float | None:
    """A limit option in user units → SI: one value for every joint, or one per joint."""
    if text is None:
        return None
    values = floats(text, what)
    per_joint = np.asarray(scale, dtype=float)
    if per_joint.ndim and values.size not in (1, per_joint.size):
        raise InvalidInput(f"{what} takes one value or one per joint ({per_joint.size}), got {values.size}")
    values = values * per_joint
    return float(values[0]) if values.size == 1 else values


def vectors_from_args(values: tuple[float, ...]) -> np.ndarray:
    return np.asarray(values, dtype=float)


def joint_scale_at(scale: float | np.ndarray, joint: int) -> float:
    """The scale of one joint (a scalar scale applies to every joint)."""
    arr = np.asarray(scale, dtype=float)
    return float(arr[joint]) if arr.ndim else float(arr)


@click.group(cls=PinarmsGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="pinarms", prog_name="pinarms")
def cli() -> None:
    """pinarms: model, plan and time-optimise food/agricultural handling arms (on Pinocchio).

    Units are SI (m, rad, s); --deg and --mm convert at the command line.
    Every command takes --json for machine-readable output.
    """


def main() -> None:
    """Console-script entry point (``pinarms``): a line on stderr while numba compiles kernels for over 2 s."""
    import sys

    from pinarms.compile_notice import CompileNotice
    from pinarms.progress import wanted

    with CompileNotice(enabled=wanted("--json" in sys.argv[1:])):
        cli(prog_name="pinarms")


json_option = click.option("--json", "as_json", is_flag=True, help="Print one JSON document instead of text.")

#: Where a sweep runs (pinarms.execution): none = here, serially; the standard
#: DASK_SCHEDULER_ADDRESS variable is read when the option is not given.
def quiet_dask() -> None:
    """Silence Dask's own logging for a command-line run: its errors reach the user as one ``Error:`` line.

    Worker processes started here read ``DASK_LOGGING__DISTRIBUTED`` from the environment
    (unless the user set it); this process's Dask loggers are set to CRITICAL.
    """
    import logging
    import os

    os.environ.setdefault("DASK_LOGGING__DISTRIBUTED", "critical")
    import distributed  # noqa: F401  (it configures its loggers on import: set them afterwards)

    names = [n for n in list(logging.root.manager.loggerDict) if n.split(".")[0] in ("distributed", "tornado")]
    for name in ("distributed", "tornado", *names):
        logging.getLogger(name).setLevel(logging.CRITICAL)


def scheduler_value(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    """Check ``--scheduler`` at once (its form, not the cluster) and quiet Dask when one is used."""
    if value is None or not value.strip() or value.strip() == "serial":
        return None if value is None or not value.strip() else value
    from pinarms.execution import describe_scheduler

    describe_scheduler(value)  # InvalidInput naming a malformed address: one Error line
    quiet_dask()
    return value


scheduler_option = click.option(
    "--scheduler", default=None, envvar="DASK_SCHEDULER_ADDRESS", show_envvar=True, metavar="ADDRESS",
    callback=scheduler_value,
    help="Run the work on Dask: tcp://HOST:8786 (a running `dask scheduler`), or 'processes' / 'processes:N' "
         "(local worker processes). Default: serially here, or DASK_SCHEDULER_ADDRESS when it is set.")


def new_session(robot: Robot | str | None, title: str):
    """A :class:`pinarms.viz.Session` for ``robot`` (built-in name or any URDF)."""
    from pinarms import viz

    return viz.Session(robot=robot, title=title)


def save_session(session: Any, path: str, data: dict, lines: list[str]) -> None:
    """Write ``session`` to ``path`` and report it in the command's JSON ``data`` and text ``lines``."""
    session.save(path)
    data["session"] = path
    lines.append(f"session written: {path}")


def skipped_pair_lines(allowed: Any, k: float, lu: str) -> list[str]:
    """One line per reason: the pairs of links never checked for it (``out of reach`` and ``constant``: with the
    smallest proven bound, checked again at a clearance above it), each pair of links once."""
    by_reason: dict[str, dict[tuple[str, str], float]] = {}
    for a in allowed:
        bodies = by_reason.setdefault(str(a.reason), {})
        key = (a.body_a, a.body_b) if (a.body_b, a.body_a) not in bodies else (a.body_b, a.body_a)
        bodies[key] = min(bodies.get(key, np.inf), a.distance_bound)
    lines = []
    for reason in sorted(by_reason):
        pairs = by_reason[reason]
        if reason in ("out of reach", "constant"):
            text = ", ".join(f"{a} – {b} (>= {d * k:.4g} {lu})" for (a, b), d in sorted(pairs.items(), key=lambda x: x[1]))
            lines.append(f"skipped while proven farther than the clearance ({reason}): {text}")
        else:
            notes = {(a.body_a, a.body_b): a.note for a in allowed if a.note}
            text = ", ".join(f"{a} – {b}" + (f" ({notes[(a, b)]})" if notes.get((a, b)) else "") for a, b in pairs)
            lines.append(f"skipped ({reason}): {text}")
    return lines


def package_map(packages: tuple[str, ...]) -> dict[str, str]:
    """``--package NAME=FOLDER`` values as ``{NAME: FOLDER}``."""
    pkgs = {}
    for item in packages:
        name, sep, folder = item.partition("=")
        if not sep or not name.strip() or not folder.strip():
            raise click.BadParameter(f"--package must be NAME=FOLDER, got {item!r}")
        pkgs[name.strip()] = folder.strip()
    return pkgs
