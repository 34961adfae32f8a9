"""viz.robot_drawing: package:// meshes found in the folders given, by either convention, never outside them."""

from __future__ import annotations

from pinarms.viz.robot_drawing import resolved_package_meshes


def test_package_meshes_resolve_by_either_folder_convention_and_stay_inside(tmp_path):
    (tmp_path / "share" / "vendor" / "meshes").mkdir(parents=True)
    (tmp_path / "share" / "vendor" / "meshes" / "a.stl").write_text("solid a\nendsolid a\n")
    (tmp_path / "mine" / "meshes").mkdir(parents=True)
    (tmp_path / "mine" / "meshes" / "b.stl").write_text("solid b\nendsolid b\n")
    (tmp_path / "secret.stl").write_text("solid s\nendsolid s\n")
    text = ('<robot><mesh filename="package://vendor/meshes/a.stl"/><mesh filename=\'package://own/meshes/b.stl\'/>'
            '<mesh filename="package://own/../secret.stl"/><mesh filename="package://gone/c.stl"/></robot>')
    out = resolved_package_meshes(text, (str(tmp_path / "share"), str(tmp_path / "mine")))
    assert f'filename="{tmp_path / "share" / "vendor" / "meshes" / "a.stl"}"' in out  # <dir>/NAME/rel (Pinocchio)
    assert f"filename='{tmp_path / 'mine' / 'meshes' / 'b.stl'}'" in out  # <dir>/rel (the package folder itself)
    assert 'filename="package://own/../secret.stl"' in out and str(tmp_path / "secret.stl") not in out
    assert 'filename="package://gone/c.stl"' in out  # found nowhere: left for Pinocchio to report
