"""Meshes of URDFs embedded in session files stay inside the folders the caller allows."""

from __future__ import annotations

import os
import re

import pytest

from pinarms import robots
from pinarms import viz
from pinarms.viz import SessionFormatError

from session_files import LEVER_URDF, document


MESH_URDF = LEVER_URDF.replace('<box size="0.1 0.1 0.1"/>', '<mesh filename="{}"/>')


@pytest.mark.parametrize("filename, ok", [
    ("package://lever/meshes/base.stl", True),
    ("meshes/base.stl", True),                               # relative: resolved against the package dirs
    ("{pkg}/lever/meshes/base.stl", True),                   # absolute, inside a package dir
    ("file://{pkg}/lever/meshes/base.stl", True),
    ("package://lever/meshes/missing.stl", True),            # missing: left to the viewer
    ("package://lever/../../../etc/passwd.stl", False),      # '..'
    ("/etc/hosts.stl", False),                               # absolute, outside
    ("file:///etc/hosts.stl", False),
    ("http://example.com/base.stl", False),                  # other schemes
    ("package://lever/escape.stl", False),                   # a symbolic link out of the package dir
    ("package://lever/meshes/base.txt", False),              # not a mesh file
    ("package://lever/fifo.stl", False),                     # not a regular file
])
def test_embedded_urdf_meshes_stay_inside_the_allowed_folders(tmp_path, filename, ok):
    study = tmp_path / "study"
    pkg = study / "pkg"
    (pkg / "lever" / "meshes").mkdir(parents=True)
    (pkg / "lever" / "meshes" / "base.stl").write_bytes(b"solid x\nendsolid x\n")
    (pkg / "lever" / "meshes" / "base.txt").write_text("x")
    outside = tmp_path / "secret.stl"
    outside.write_text("secret")
    os.symlink(outside, pkg / "lever" / "escape.stl")
    os.mkfifo(pkg / "lever" / "fifo.stl")
    urdf = MESH_URDF.format(filename.format(pkg=pkg))
    robot = robots.from_urdf_text(urdf, package_dirs=(str(pkg),))
    s = viz.Session(robot, key="lever")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    # beside its package folder (inside the session's own folder), or elsewhere with the folder passed
    for back in (viz.load_session(s.save(study / "m.pinarms")),
                 viz.load_session(s.save(elsewhere / "m.pinarms"), package_dirs=[str(pkg)])):
        assert back.robots["lever"].source == "urdf"
        if ok:
            rob = back.robot("lever")
            assert rob.nq == 1 and str(pkg) in rob.package_dirs
        else:
            with pytest.raises(SessionFormatError, match="mesh"):
                back.robot("lever")
    # elsewhere without it: the folder the file names is never used by itself, and the message says what to pass
    far = viz.load_session(elsewhere / "m.pinarms")
    with pytest.raises(SessionFormatError, match="mesh") as info:
        far.robot("lever")
    if ok:
        assert "--package-dir" in str(info.value) and "package_dirs=" in str(info.value)


SECRET_STL = b"solid secret_part\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n" \
             b"endfacet\nendsolid secret_part\n"


@pytest.mark.parametrize("form", ["absolute", "package_named"])
def test_a_session_cannot_allow_folders_by_itself(tmp_path, form):
    """Issue 29 item 2: package_dirs ["/"] in session.json and a mesh in another folder: refused, no page written."""
    from click.testing import CliRunner

    from pinarms.cli import cli

    other = tmp_path / "other"
    other.mkdir()
    secret = other / "secret_part.stl"
    secret.write_bytes(SECRET_STL)
    study = tmp_path / "study"
    study.mkdir()
    mesh = f"package://{other}/secret_part.stl" if form == "absolute" else f"package:/{other}/secret_part.stl"
    robot = robots.from_urdf_text(MESH_URDF.format(mesh), package_dirs=("/",))
    path = viz.Session(robot, key="lever").save(study / "s.pinarms")
    assert document(path)["robots"][0]["package_dirs"] == ["/"]
    page = study / "page.html"
    with pytest.raises(SessionFormatError, match=re.escape(repr(mesh))) as info:
        viz.export_html(viz.load_session(path), page)
    assert "package_dirs=" in str(info.value) and "--package-dir" in str(info.value)
    assert not page.exists() and not list(study.glob("*.part"))
    result = CliRunner().invoke(cli, ["export-html", str(path), str(page)])
    assert result.exit_code != 0 and "Traceback" not in result.output
    lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error:") and "secret_part.stl" in lines[0], result.stderr
    assert not page.exists()
    if form == "absolute":  # the caller may allow the folder: then the mesh is read from it (and only then)
        assert viz.load_session(path, package_dirs=[str(other)]).robot("lever").nq == 1
