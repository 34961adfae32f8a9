"""Peers measured beside pinarms: the Robotics Toolbox for Python when it is installed.

The toolbox is optional (``pip install roboticstoolbox-python``, best in its own
environment with pinarms installed too); without it the benchmarks say so and still run.
The arm is loaded from the same URDF text pinarms uses (visual and collision elements
dropped: they do not change the kinematics and their mesh paths need ROS packages).
"""

from __future__ import annotations

import io
import xml.etree.ElementTree as ET

FAIRNESS = (
    "Fairness note: the Robotics Toolbox's ik_LM tests its tol (default 1e-6) against 1/2 |e|^2, so its own "
    "success flag accepts errors up to 1.4 mm; here it runs with tol = 5e-13 (|e| <= 1e-6) and every answer of "
    "both tools is judged by the same check: FK within 1e-6 m and 1e-6 rad of the target and within the joint "
    "limits (checked here, not by either solver). pinarms solves to 1e-10."
)


def rtb_version() -> str | None:
    try:
        import roboticstoolbox
    except Exception:  # noqa: BLE001 - absent or broken install: the benchmark runs without it
        return None
    return getattr(roboticstoolbox, "__version__", "?")


def rtb_ets(robot):
    """The toolbox's ETS from the robot's base to its tcp frame, or ``None`` when the toolbox is absent."""
    if rtb_version() is None:
        return None
    import roboticstoolbox as rtb
    from roboticstoolbox.models.URDF.URDFRobot import URDF_file

    root = ET.fromstring(robot.urdf_text)
    for link in root.findall("link"):
        for tag in ("visual", "collision"):
            for el in link.findall(tag):
                link.remove(el)
    elinks, name, _ = URDF_file(io.StringIO(ET.tostring(root, encoding="unicode")))
    arm = rtb.Robot(elinks, name=name)
    return arm.ets(end=robot.model.frames[robot.frame_id("tcp")].name)


def absent_line() -> str:
    return ("Robotics Toolbox for Python: not installed here (pip install roboticstoolbox-python, e.g. in a separate "
            "virtualenv with pinarms); its columns are left out")
