"""Helpers of the session tests: a small URDF robot, and reading or rewriting a saved session's members."""

from __future__ import annotations

import io
import json
import zipfile

import numpy as np

LEVER_URDF = """<robot name="lever">
  <link name="base_link"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
  <link name="arm"><visual><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.04 0.04"/></geometry></visual></link>
  <link name="tcp"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="arm"/><axis xyz="0 0 1"/>
    <origin xyz="0 0 0.1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="tool" type="fixed"><parent link="arm"/><child link="tcp"/><origin xyz="0.4 0 0"/></joint>
</robot>"""


def rewrite(src, dst, *, drop=(), replace=None):
    """Copy the session zip ``src`` to ``dst`` without the ``drop`` members and with ``replace`` {member: bytes}."""
    replace = replace or {}
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for item in zin.infolist():
            if item.filename in drop:
                continue
            zout.writestr(item.filename, replace.get(item.filename, zin.read(item.filename)))
    return dst


def document(path):
    with zipfile.ZipFile(path) as zf:
        return json.loads(zf.read("session.json"))


def npy_bytes(arr):
    buf = io.BytesIO()
    np.save(buf, arr)
    return buf.getvalue()
