"""Option groups of the command line: a frozen dataclass whose fields are options of a command.

A command that takes many flags takes them in a few groups, each one object: the decorator
:func:`option_group` adds the group's options to the command (flags, defaults and help as the
group declares them, or as the command words them) and hands the command one object of the
group, built (and so checked, in its ``__post_init__``) from the values the user typed::

    @cli.command("cycle")
    @option_group(TimingFlags, "timing", vmax={"help": "Joint speed limit(s) ..."})
    def cycle_cmd(robot, timing: TimingFlags, ...) -> None:
        timing.limits(np.ones(arm.nq))   # (vmax, amax, jmax) in SI, one value or one per joint

The flags stay the user's: a group changes the command's signature, never its command line.
A group's checks raise :class:`~pinarms.errors.InvalidInput` naming the flag, one ``Error:`` line.

The groups shared by several commands are here: :class:`TimingFlags` (the trajectory kind,
joint limits and the optimiser of ``cycle``, ``layout-search``, ``plan`` and ``optimize``),
:class:`LoadFlags` (payload and torque limits of ``cycle`` and ``optimize``), :class:`UnitFlags`
(``--mm`` and ``--deg``) and :class:`OutputFlags` (``--session``, ``--plot`` and ``--json``).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from typing import Any, Callable, ClassVar, Mapping

import click
import numpy as np

from pinarms.cli._common import floats, si_limit

__all__ = ["Flag", "flag", "option_group", "TimingFlags", "LoadFlags", "UnitFlags", "OutputFlags", "JSON_FLAG"]


@dataclass(frozen=True)
class Flag:
    """One option of a group: click's declarations (``"--session", "session_path"``) and attributes."""

    decls: tuple[str, ...]
    attrs: Mapping[str, Any]

    @property
    def name(self) -> str:
        """The option's Python name (click's rule: the second declaration, else the longest flag)."""
        return str(click.Option(list(self.decls), **self.attrs).name)


def flag(*decls: str, **attrs: object) -> Flag:
    """A :class:`Flag` written as :func:`click.option` is."""
    return Flag(tuple(decls), dict(attrs))


#: ``--json``, as every command has it.
JSON_FLAG = flag("--json", "as_json", is_flag=True, help="Print one JSON document instead of text.")


def option_group(group: type, name: str, *, only: tuple[str, ...] | None = None,
                 **changes: Mapping[str, object]) -> Callable[[Callable[..., object]], Callable[..., object]]:
    """Add the options of ``group`` (a frozen dataclass with ``FLAGS``) to a command; pass it one ``group``.

    ``only`` keeps some of the group's options (the other fields take their defaults);
    ``changes`` maps a field to the attributes the command words its own way
    (``vmax={"help": ...}``, ``kind={"default": "3-5-3"}``). The command's parameter ``name``
    receives ``group(**values)``.
    """
    flags = {f.name: f for f in group.FLAGS}
    fields = {f.name for f in dataclasses.fields(group)}
    unknown = sorted(set(flags) - fields) + sorted(set(changes) - set(flags)) + sorted(set(only or ()) - set(flags))
    if unknown:
        raise TypeError(f"option_group({group.__name__}): no field or flag {unknown}")
    used = [flags[n] for n in (only or tuple(flags))]
    options = [click.option(*f.decls, **{**f.attrs, **changes.get(f.name, {})}) for f in used]
    names = tuple(f.name for f in used)

    def decorate(command: Callable[..., object]) -> Callable[..., object]:
        @functools.wraps(command)
        def run(*args: object, **values: object) -> object:
            mine = {n: values.pop(n) for n in names}
            return command(*args, **values, **{name: group(**mine)})

        for option in reversed(options):
            run = option(run)
        return run

    return decorate


# --------------------------------------------------------------------------- shared groups
@dataclass(frozen=True)
class TimingFlags:
    """How a move is timed: the trajectory ``kind``, the joint limits as typed (one value or one per
    joint, SI) and the optimiser (``method``, ``seed``)."""

    kind: str = "multi-quintic"
    vmax: str | None = None
    amax: str | None = None
    jmax: str | None = None
    method: str = "exact"
    seed: int = 0

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--kind", type=click.Choice(["multi-quintic", "quintic-bspline", "3-5-3"]), default="multi-quintic",
             show_default=True),
        flag("--vmax", default=None, help="Joint speed limit(s) [rad/s or m/s], one or per joint (default: the URDF's)."),
        flag("--amax", default=None, help="Acceleration limit(s) [rad/s² or m/s²]."),
        flag("--jmax", default=None, help="Jerk limit(s) [rad/s³ or m/s³]."),
        flag("--method", type=click.Choice(["exact", "ga"]), default="exact", show_default=True),
        flag("--seed", default=0, show_default=True, type=int, help="Random seed of the optimiser."),
    )

    def __post_init__(self) -> None:
        for what in ("vmax", "amax", "jmax"):
            text = getattr(self, what)
            if text is not None:
                floats(text, f"--{what}")  # a slip in the numbers: said before anything loads

    def limits(self, scale: float | np.ndarray) -> tuple[Any, Any, Any]:
        """``(vmax, amax, jmax)`` in SI (``None`` where not given): each value times ``scale`` (one per joint
        checks the count: one value or one per joint)."""
        return (si_limit(self.vmax, "--vmax", scale), si_limit(self.amax, "--amax", scale),
                si_limit(self.jmax, "--jmax", scale))


@dataclass(frozen=True)
class LoadFlags:
    """What the gripper carries (``payload``, e.g. ``3kg``) and the joint torque limits (``torque``: the
    URDF's efforts; ``torque_max``: given, one or per joint)."""

    payload: str | None = None
    torque: bool = False
    torque_max: str | None = None

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--payload", default=None, help="Mass at the tcp, e.g. 3kg or 800g: also limits joint torques."),
        flag("--torque", "torque", is_flag=True, help="Also limit joint torques to the URDF's efforts."),
        flag("--torque-max", default=None, help="Joint torque limit(s) [N·m, or N for prismatic joints], one or per joint."),
    )

    def __post_init__(self) -> None:
        if self.torque_max is not None:
            floats(self.torque_max, "--torque-max")

    @property
    def asked(self) -> bool:
        """Whether any of the three flags was given."""
        return self.payload is not None or self.torque or self.torque_max is not None

    @property
    def kg(self) -> float | None:
        """The payload [kg] (``None`` without ``--payload``)."""
        from pinarms.units import mass_kg

        return None if self.payload is None else mass_kg(self.payload)

    def torque_limits(self, nq: int) -> np.ndarray | float | bool:
        """The torque limits: ``--torque-max`` per joint, else ``True`` (the URDF's) when a payload or
        ``--torque`` asks for them, else ``False``."""
        given = si_limit(self.torque_max, "--torque-max", np.ones(nq))
        if given is not None:
            return given
        return self.payload is not None or self.torque


@dataclass(frozen=True)
class UnitFlags:
    """The user's units: lengths in millimetres (``mm``), angles in degrees (``deg``); SI otherwise."""

    mm: bool = False
    deg: bool = False

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--mm", is_flag=True, help="Lengths in millimetres."),
        flag("--deg", is_flag=True, help="Angles in degrees."),
    )

    @property
    def length(self) -> float:
        """Metres per length unit typed (1e-3 with ``--mm``)."""
        return 1e-3 if self.mm else 1.0

    @property
    def angle(self) -> float:
        """Radians per angle unit typed (pi / 180 with ``--deg``)."""
        return np.pi / 180.0 if self.deg else 1.0

    @property
    def length_unit(self) -> str:
        """``"mm"`` or ``"m"``."""
        return "mm" if self.mm else "m"


@dataclass(frozen=True)
class OutputFlags:
    """Where a command writes besides its text: a session file, a plot, and JSON instead of text."""

    session_path: str | None = None
    plot_path: str | None = None
    as_json: bool = False

    FLAGS: ClassVar[tuple[Flag, ...]] = (
        flag("--session", "session_path", default=None, type=click.Path(dir_okay=False),
             help="Save the result into a session file."),
        flag("--plot", "plot_path", default=None, type=click.Path(dir_okay=False), help="Write a plot (.png or .svg)."),
        JSON_FLAG,
    )
