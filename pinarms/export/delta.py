"""A delta robot for other tools: its URDF (the open tree), its loop-closures file, and MJCF with equality constraints.

MuJoCo reads the URDF (every link kept as a body: ``fusestatic="false"``); each loop closure
becomes an ``<equality><connect site1=... site2=.../>`` between two sites at the closure's
frames, as stiff as the time step allows. MuJoCo writes numbers with six significant digits;
the bodies' positions and orientations are written back at full precision from the URDF's
joint origins, so the MJCF's kinematics equal pinarms' (the closures hold within 1e-12 m).
"""

from __future__ import annotations

import os
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from pinarms.files import publish_folder
from pinarms.robots.delta import DeltaRobot, closures_to_xml, load_delta
from pinarms.errors import InvalidInput, ModelError

from pinarms.export.urdf_files import check_export_folder

__all__ = ["ExportedDelta", "delta_mjcf_text", "export_delta", "closure_site"]


@dataclass(frozen=True)
class ExportedDelta:
    """The files of an exported delta."""

    folder: Path
    urdf: Path
    closures: Path
    mjcf: Path


def closure_site(frame: str) -> str:
    """Name of the MJCF site at a closure's frame (bodies keep the frame's name)."""
    return f"{frame}_site"


def _full_precision_poses(root: ET.Element, urdf_text: str) -> None:
    """Set every body's ``pos``/``quat`` from its URDF joint origin (MuJoCo saves 6 digits)."""
    for joint in ET.fromstring(urdf_text).iter("joint"):
        origin = joint.find("origin")
        body = root.find(f".//body[@name='{joint.find('child').get('link')}']")
        if body is None:  # pragma: no cover - fusestatic="false" keeps every link
            raise ModelError(f"MuJoCo dropped the body of URDF link {joint.find('child').get('link')!r}")
        xyz = np.array([float(v) for v in (origin.get("xyz", "0 0 0") if origin is not None else "0 0 0").split()])
        rpy = np.array([float(v) for v in (origin.get("rpy", "0 0 0") if origin is not None else "0 0 0").split()])
        quat = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs()            # x, y, z, w
        body.set("pos", " ".join(repr(float(v)) for v in xyz))
        body.set("quat", " ".join(repr(float(v)) for v in (quat[3], quat[0], quat[1], quat[2])))


def delta_mjcf_text(delta: DeltaRobot) -> str:
    """The MJCF of ``delta``: its tree, a site at each closure frame, one ``connect`` equality per closure,
    and its payloads (:meth:`~pinarms.robots.delta.DeltaRobot.with_payload`) as bodies under the tcp.

    Raises:
        ModelError: ``mujoco`` is not installed, or MuJoCo refuses the model.
    """
    try:
        import mujoco
    except ImportError as exc:
        raise ModelError("the MJCF export needs MuJoCo's Python package: pip install mujoco") from exc
    if not delta.urdf_text:
        raise InvalidInput(f"delta {delta.name!r} carries no URDF text; load it with load_delta or delta_from_files")
    head, end, tail = delta.urdf_text.rpartition("</robot>")
    extension = '<mujoco><compiler fusestatic="false" discardvisual="false"/></mujoco>'
    with tempfile.TemporaryDirectory() as tmp:
        try:
            model = mujoco.MjModel.from_xml_string(f"{head}{extension}\n{end}{tail}")
            mujoco.mj_saveLastXML(os.path.join(tmp, "delta.xml"), model)
        except Exception as exc:  # MuJoCo raises ValueError with its own message
            raise ModelError(f"MuJoCo refuses delta {delta.name!r}: {' '.join(str(exc).split())}") from exc
        root = ET.parse(os.path.join(tmp, "delta.xml")).getroot()
    _full_precision_poses(root, delta.urdf_text)
    tcp = root.find(".//body[@name='tcp']")
    for k, (mass, offset) in enumerate(delta.payloads):   # delta.with_payload: point masses at the tcp
        body = ET.SubElement(tcp, "body", {"name": f"payload{k + 1}", "pos": " ".join(repr(v) for v in offset)})
        ET.SubElement(body, "inertial", {"pos": "0 0 0", "mass": repr(mass), "diaginertia": "1e-12 1e-12 1e-12"})
    equality = root.find("equality")
    if equality is None:
        equality = ET.SubElement(root, "equality")
    step = float(model.opt.timestep)
    for c in delta.closures.closures:
        if c.kind != "point":
            raise ModelError(f"closure {c.name!r} of {delta.name!r} is a {c.kind!r}; the MJCF export writes ball joints")
        for frame in (c.frame1, c.frame2):
            body = root.find(f".//body[@name='{frame}']")
            if body is None:  # pragma: no cover - every frame of the family is a link
                raise ModelError(f"closure frame {frame!r} is not a link of {delta.name!r}")
            ET.SubElement(body, "site", {"name": closure_site(frame), "size": "0.005", "rgba": "0.85 0.15 0.15 1"})
        ET.SubElement(equality, "connect", {"name": c.name, "site1": closure_site(c.frame1),
                                            "site2": closure_site(c.frame2), "solref": f"{2.0 * step:g} 1",
                                            "solimp": "0.99 0.999 0.001"})
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"


def export_delta(delta_or_name: DeltaRobot | str, out_dir: str | os.PathLike, *, overwrite: bool = False
                 ) -> ExportedDelta:
    """Write ``<name>.urdf``, ``<name>.closures.xml`` and ``<name>.xml`` (MJCF) into ``out_dir`` (all or nothing).

    Raises:
        InvalidInput: ``out_dir`` is a file, or not empty (without ``overwrite``).
        ModelError: MuJoCo is missing or refuses the model.
    """
    delta = load_delta(delta_or_name) if isinstance(delta_or_name, str) else delta_or_name
    if not isinstance(delta, DeltaRobot):
        raise InvalidInput(f"export_delta takes a DeltaRobot or a shipped delta's name, got {delta_or_name!r}")
    out = check_export_folder(out_dir, overwrite)
    mjcf = delta_mjcf_text(delta)
    names = {"urdf": f"{delta.name}.urdf", "closures": f"{delta.name}.closures.xml", "mjcf": f"{delta.name}.xml"}

    def fill(tmp: Path) -> None:
        (tmp / names["urdf"]).write_text(delta.urdf_text, encoding="utf-8")
        (tmp / names["closures"]).write_text(closures_to_xml(delta.closures), encoding="utf-8")
        (tmp / names["mjcf"]).write_text(mjcf, encoding="utf-8")

    publish_folder(out, fill)
    return ExportedDelta(out, *(out / names[k] for k in ("urdf", "closures", "mjcf")))
