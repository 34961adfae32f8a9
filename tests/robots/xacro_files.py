"""Shared by the xacro tests: a user file's head, a secret that must never be read, a SCARA on a pedestal."""

from __future__ import annotations

from pathlib import Path

HEAD = '<?xml version="1.0"?>\n<robot name="user_arm" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
SECRET = "pinarms-secret-7f3a"

SCARA_ON_PEDESTAL = HEAD + """
  <xacro:arg name="height" default="0.75"/>
  <xacro:arg name="prefix" default="cell_"/>
  <xacro:include filename="$(find pinarms)/scara_mushroom.xacro"/>
  <xacro:pinarms_materials/>
  <link name="floor"/>
  <xacro:scara_mushroom prefix="$(arg prefix)" parent="floor" xyz="0.1 0 $(arg height)" rpy="0 0 ${pi / 2}"/>
</robot>
"""


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text)
    return path
