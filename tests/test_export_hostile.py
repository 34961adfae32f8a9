"""Exports of received (hostile) descriptions stay in their folder and copy only allowed mesh files.

Each test builds the hostile URDF, cell or folder under ``tmp_path`` and checks that the
export writes nothing outside the output folder, copies nothing from outside the allowed
folders (the description's own folder and the packages the caller passes), and that the
folder it creates is the user's: the umask's permissions, a symbolic link to a folder
written through.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from pinarms import robots
from pinarms.cli import cli
from pinarms.export import MeshNotAllowed, export_cell, export_mjcf, export_urdf, mesh_references
from pinarms.robots.cell import load_cell
from pinarms.errors import InvalidInput

# an ASCII STL of one triangle (pinarms writes it as binary STL in a cell export)
STL = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\nendloop\nendfacet\nendsolid t\n"
SECRET = "private notes: not for the vendor\n"


def _arm(name: str, meshes: tuple[str, ...] = ()) -> str:
    """A one-joint arm URDF named ``name`` whose link ``l1`` shows ``meshes`` (and collides as a box)."""
    visuals = "".join(f'<visual><geometry><mesh filename="{m}"/></geometry></visual>' for m in meshes)
    return (f'<robot name="{name}"><link name="base"/><link name="l1">{visuals}'
            '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>'
            '<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>'
            '<origin xyz="0 0 0.2"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')


def _cell(name: str, mesh: str = "") -> str:
    """A cell URDF named ``name``: one arm on a world frame, a table fixture (a mesh when ``mesh``)."""
    shape = f'<mesh filename="{mesh}"/>' if mesh else '<box size="1 1 0.05"/>'
    return (f'<robot name="{name}"><link name="world"/>'
            '<link name="arm_base_link"/><joint name="arm_mount" type="fixed"><parent link="world"/>'
            '<child link="arm_base_link"/></joint>'
            '<link name="arm_l1"><collision><geometry><box size="0.05 0.05 0.3"/></geometry>'
            '<origin xyz="0 0 0.15"/></collision></link>'
            '<joint name="arm_j1" type="revolute"><parent link="arm_base_link"/><child link="arm_l1"/>'
            '<origin xyz="0 0 1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
            f'<link name="table"><collision><geometry>{shape}</geometry></collision></link>'
            '<joint name="table_mount" type="fixed"><parent link="world"/><child link="table"/></joint></robot>')


def _files(folder: Path) -> set[str]:
    """Every entry under ``folder`` (links not followed), relative, POSIX."""
    out = set()
    for dirpath, dirnames, filenames in os.walk(folder):
        for entry in dirnames + filenames:
            out.add((Path(dirpath) / entry).relative_to(folder).as_posix())
    return out


@pytest.fixture
def received(tmp_path):
    """``tmp_path/recv``: where a received description lives (its own folder)."""
    folder = tmp_path / "recv"
    folder.mkdir()
    return folder


def _export(*args: str):
    return CliRunner().invoke(cli, ["urdf", "export", *args])


# --------------------------------------------------------------------------- names (item 2)
@pytest.mark.parametrize("flags", [[], ["--mjcf"], ["--srdf"]])
def test_a_robot_name_never_leaves_the_output_folder(tmp_path, received, flags):
    (received / "recv.urdf").write_text(_arm("../other/evil"))
    (tmp_path / "other").mkdir()  # out/../other/evil.urdf was written when this folder existed
    before = _files(tmp_path)
    run = _export(str(received / "recv.urdf"), str(tmp_path / "out"), *flags, "--json")
    assert run.exit_code == 0, run.output
    added = _files(tmp_path) - before
    assert added and all(p.startswith("out/") or p == "out" for p in added), added
    assert _files(tmp_path / "other") == set()
    doc = json.loads(run.output)
    written = doc["mjcf"] if flags == ["--mjcf"] else doc["urdf"]
    assert Path(written).parent == tmp_path / "out" and Path(written).name in ("_other_evil.urdf", "_other_evil.xml")
    assert Path(written).is_file()


def test_an_absolute_robot_name_writes_inside_the_output_folder(tmp_path, received):
    target = tmp_path / "elsewhere" / "evil"
    target.parent.mkdir()
    (received / "recv.urdf").write_text(_arm(str(target)))
    result = export_urdf(robots.from_urdf(received / "recv.urdf"), tmp_path / "out")
    assert _files(tmp_path / "elsewhere") == set()
    assert result.urdf.parent == tmp_path / "out" and result.urdf.is_file()
    assert not result.urdf.name.startswith(".")


def test_a_cell_name_never_leaves_the_output_folder(tmp_path, received):
    (received / "cell.urdf").write_text(_cell("../../evil_cell"))
    cell = load_cell(str(received / "cell.urdf"))
    before = _files(tmp_path)
    out = export_cell(cell, tmp_path / "o" / "out", mjcf=True)
    added = _files(tmp_path) - before
    assert all(p == "o" or p.startswith("o/out") for p in added), added
    assert {out.urdf.name, out.srdf.name, out.mjcf.name} == {"_evil_cell.urdf", "_evil_cell.srdf", "_evil_cell.xml"}


def test_a_xacro_cell_name_never_leaves_the_output_folder(tmp_path, received):
    text = _cell("${'../' + 'evil_xacro'}").replace("<robot ", '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" ')
    (received / "cell.urdf.xacro").write_text(text)
    (tmp_path / "o").mkdir()
    before = _files(tmp_path)
    run = _export(str(received / "cell.urdf.xacro"), str(tmp_path / "o" / "out"), "--cell", "--srdf", "--json")
    assert run.exit_code == 0, run.output
    assert all(p.startswith("o/out") for p in _files(tmp_path) - before), _files(tmp_path) - before
    assert Path(json.loads(run.output)["srdf"]) == tmp_path / "o" / "out" / "_evil_xacro.srdf"


# --------------------------------------------------------------------------- meshes (items 3, 4)
def test_a_package_path_through_a_symlinked_folder_is_refused(tmp_path, received):
    deep = tmp_path / "d1" / "d2" / "d3"
    deep.mkdir(parents=True)
    (received / "a").symlink_to(deep, target_is_directory=True)
    (tmp_path / "planted.stl").write_text(STL)  # what the sender wants copied (received/a/../../../planted.stl)
    (received / "recv.urdf").write_text(_arm("arm", ("package://a/../../../planted.stl",)))
    robot = robots.from_urdf(received / "recv.urdf")
    before = _files(tmp_path)
    with pytest.raises(MeshNotAllowed, match="outside the folders") as info:
        export_urdf(robot, tmp_path / "x" / "out")
    assert "package://a/../../../planted.stl" in str(info.value)
    assert _files(tmp_path) - before <= {"x"}


def test_a_collada_texture_that_climbs_out_is_refused(tmp_path, received):
    deep = received / "a" / "b" / "c" / "d"
    deep.mkdir(parents=True)
    (deep / "part.dae").write_text(  # five levels up: tmp_path/evil.png, and from the copied mesh: tmp_path/o1/o2
        '<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">'
        '<library_images><image id="t"><init_from>../../../../../evil.png</init_from></image></library_images>'
        '</COLLADA>')
    (tmp_path / "evil.png").write_bytes(b"\x89PNG\r\n\x1a\n" + b"x" * 16)
    (received / "recv.urdf").write_text(_arm("arm", ("a/b/c/d/part.dae",)))
    robot = robots.from_urdf(received / "recv.urdf")
    (tmp_path / "o1" / "o2").mkdir(parents=True)
    before = _files(tmp_path)
    with pytest.raises(MeshNotAllowed, match="evil.png"):
        export_urdf(robot, tmp_path / "o1" / "o2" / "out")
    assert _files(tmp_path) == before


def test_a_collada_texture_inside_the_folder_is_copied_beside_its_mesh(tmp_path, received):
    (received / "visual").mkdir()
    (received / "textures").mkdir()
    (received / "visual" / "part.dae").write_text(
        '<COLLADA><library_images><image id="t"><init_from>../textures/skin.png</init_from></image>'
        '</library_images></COLLADA>')
    (received / "textures" / "skin.png").write_bytes(b"\x89PNG\r\n\x1a\nskin")
    (received / "recv.urdf").write_text(_arm("arm", ("visual/part.dae",)))
    result = export_urdf(robots.from_urdf(received / "recv.urdf"), tmp_path / "out")
    (ref,) = mesh_references(result.urdf.read_text())
    mesh = result.folder / ref
    assert mesh.is_file() and (mesh.parent / "../textures/skin.png").resolve().read_bytes().endswith(b"skin")
    assert all((result.folder / m).resolve().is_relative_to(result.folder.resolve()) for m in result.meshes)


@pytest.mark.parametrize("kind", ["absolute", "file_url", "relative_up"])
def test_a_private_file_is_never_copied(tmp_path, received, kind):
    private = tmp_path / "private"
    private.mkdir()
    (private / "notes.txt").write_text(SECRET)
    (private / "part.stl").write_text(STL)
    mesh = {"absolute": str(private / "part.stl"), "file_url": f"file://{private / 'notes.txt'}",
            "relative_up": "../private/notes.txt"}[kind]
    (received / "recv.urdf").write_text(_arm("arm", (mesh,)))
    run = _export(str(received / "recv.urdf"), str(tmp_path / "out"))
    assert run.exit_code == 1, run.output
    assert run.output.startswith("Error: ") and len(run.output.strip().splitlines()) == 1, run.output
    assert not (tmp_path / "out").exists()
    assert all(SECRET not in p.read_text(errors="replace") for p in tmp_path.rglob("*") if p.is_file()
               and p.parent != private)


def test_a_mesh_that_is_not_a_mesh_file_is_refused_even_inside_the_folder(tmp_path, received):
    (received / "notes.txt").write_text(SECRET)
    (received / "recv.urdf").write_text(_arm("arm", ("notes.txt",)))
    with pytest.raises(MeshNotAllowed, match=r"\.stl"):
        export_urdf(robots.from_urdf(received / "recv.urdf"), tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_a_package_folder_the_user_passes_is_allowed(tmp_path, received):
    vendor = tmp_path / "vendor"
    (vendor / "meshes").mkdir(parents=True)
    (vendor / "meshes" / "link.stl").write_text(STL)
    (received / "recv.urdf").write_text(_arm("arm", ("package://vendor/meshes/link.stl",)))
    refused = _export(str(received / "recv.urdf"), str(tmp_path / "refused"))
    assert refused.exit_code == 1 and "--package" in refused.output, refused.output
    run = _export(str(received / "recv.urdf"), str(tmp_path / "out"), "--package", f"vendor={vendor}", "--json")
    assert run.exit_code == 0, run.output
    assert json.loads(run.output)["meshes"] == ["meshes/vendor/meshes/link.stl"]
    assert (tmp_path / "out" / "meshes" / "vendor" / "meshes" / "link.stl").read_text() == STL


def test_a_cell_mesh_swapped_for_a_link_after_loading_is_refused(tmp_path, received):
    """The cell loader checks meshes; the export checks again what it copies, at the time it copies."""
    private = tmp_path / "private"
    private.mkdir()
    (private / "secret.stl").write_text(STL)
    (received / "table.stl").write_text(STL)
    (received / "cell.urdf").write_text(_cell("c", "table.stl"))
    cell = load_cell(str(received / "cell.urdf"))
    (received / "table.stl").unlink()
    (received / "table.stl").symlink_to(private / "secret.stl")
    with pytest.raises(MeshNotAllowed, match="table.stl"):
        export_cell(cell, tmp_path / "out", mjcf=False)
    assert not (tmp_path / "out").exists()


# --------------------------------------------------------------------------- the output folder (item 12)
@pytest.fixture
def umask_022():
    old = os.umask(0o022)
    try:
        yield
    finally:
        os.umask(old)


def test_export_folders_follow_the_umask(tmp_path, umask_022):
    urdf = export_urdf("aubo_i3", tmp_path / "u")
    cell = export_cell("aubo_food_station", tmp_path / "c", mjcf=False)
    mjcf = export_mjcf("aubo_i3", tmp_path / "m")
    for result in (urdf, cell, mjcf):
        assert (result.folder.stat().st_mode & 0o777) == 0o755, oct(result.folder.stat().st_mode)
        for p in result.folder.rglob("*"):
            assert (p.stat().st_mode & 0o777) == (0o755 if p.is_dir() else 0o644), (p, oct(p.stat().st_mode))


@pytest.mark.parametrize("full", [False, True])
def test_a_symlinked_output_folder_is_written_through(tmp_path, full):
    real = tmp_path / "real"
    real.mkdir()
    if full:
        (real / "old.txt").write_text("old")
    link = tmp_path / "link"
    link.symlink_to(real, target_is_directory=True)
    result = export_urdf("aubo_i3", link, overwrite=full)
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert (real / "aubo_i3.urdf").is_file() and not (real / "old.txt").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]  # no .link.*.old, no .real.*.partial
    assert result.urdf.is_file()


def test_a_symlinked_output_folder_keeps_its_files_without_overwrite(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (real / "mine.txt").write_text("mine")
    (tmp_path / "link").symlink_to(real, target_is_directory=True)
    with pytest.raises(InvalidInput, match="not empty"):
        export_urdf("aubo_i3", tmp_path / "link")
    assert (real / "mine.txt").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]


def test_a_link_to_nothing_as_output_folder_is_refused(tmp_path):
    (tmp_path / "link").symlink_to(tmp_path / "missing", target_is_directory=True)
    with pytest.raises(InvalidInput, match="does not exist"):
        export_urdf("aubo_i3", tmp_path / "link")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link"]


def test_a_link_inside_the_allowed_folder_is_followed_and_copied(tmp_path, received):
    (received / "parts").mkdir()
    (received / "parts" / "link1.stl").write_text(STL)
    (received / "same.stl").symlink_to(received / "parts" / "link1.stl")
    (received / "recv.urdf").write_text(_arm("arm", ("same.stl",)))
    result = export_urdf(robots.from_urdf(received / "recv.urdf"), tmp_path / "out")
    assert result.meshes == ("meshes/parts/link1.stl",)
    copy = result.folder / result.meshes[0]
    assert not copy.is_symlink() and copy.read_text() == STL
