"""The standalone page's reachability panel: a colour bar and a slice slider over the voxel layers.

:func:`inject_overlay` adds, before ``</body>`` of MeshCat's static page, a fixed panel per
reachability map (``id="pinarms-reach-<i>"``) with

- a colour bar (a CSS gradient through the index colormap, 0 to 1) and its label,
- a slider over the horizontal layers (``input[type=range]``, one step per layer, its height in
  mm shown) and a choice: all layers, the layers up to the slider's height, or that layer only.

The slider sets the ``visible`` property of the layers' scene objects with MeshCat's own
``set_property`` command (:mod:`viz.reach_scene` draws one object per layer). Text is put in
the page with ``textContent`` and the data as JSON with ``</`` escaped, so map names cannot
inject markup.
"""

from __future__ import annotations

import json
from typing import Any

import matplotlib
import numpy as np

from .reach_scene import INDEX_COLORMAP

__all__ = ["inject_overlay", "overlay_html"]


def _gradient(colormap: str = INDEX_COLORMAP, stops: int = 11) -> str:
    cmap = matplotlib.colormaps[colormap]
    parts = []
    for x in np.linspace(0.0, 1.0, stops):
        r, g, b = (int(round(255 * c)) for c in cmap(x)[:3])
        parts.append(f"rgb({r},{g},{b}) {x * 100:.0f}%")
    return "linear-gradient(to top, " + ", ".join(parts) + ")"


_SCRIPT = r"""
(function () {
  const maps = %DATA%;
  function build() {
    if (typeof viewer === "undefined") { setTimeout(build, 100); return; }
    maps.forEach(function (m, i) {
      const panel = document.createElement("div");
      panel.id = "pinarms-reach-" + i;
      panel.style.cssText = "position:fixed;left:12px;bottom:" + (12 + 150 * i) + "px;z-index:10;" +
        "background:rgba(255,255,255,0.92);border:1px solid #999;border-radius:6px;padding:8px;" +
        "font:12px sans-serif;color:#222;display:flex;gap:10px;align-items:stretch;max-width:420px";
      const bar = document.createElement("div");
      bar.className = "pinarms-colorbar";
      bar.style.cssText = "width:16px;min-height:110px;border:1px solid #555;background:%GRADIENT%";
      const scale = document.createElement("div");
      scale.style.cssText = "display:flex;flex-direction:column;justify-content:space-between";
      ["1.0", "0.5", "0.0"].forEach(function (t) { const s = document.createElement("span"); s.textContent = t; scale.appendChild(s); });
      const body = document.createElement("div");
      const title = document.createElement("div");
      title.style.fontWeight = "bold";
      title.textContent = "reachability index: " + m.name;
      const desc = document.createElement("div");
      desc.textContent = m.description;
      desc.style.cssText = "margin:2px 0 6px 0;color:#555";
      const mode = document.createElement("select");
      mode.className = "pinarms-slice-mode";
      [["all", "all layers"], ["below", "layers up to"], ["only", "this layer only"]].forEach(function (o) {
        const opt = document.createElement("option"); opt.value = o[0]; opt.textContent = o[1]; mode.appendChild(opt);
      });
      const slider = document.createElement("input");
      slider.type = "range"; slider.min = 0; slider.max = m.layers.length - 1; slider.step = 1;
      slider.value = m.layers.length - 1; slider.className = "pinarms-slice";
      slider.style.width = "160px";
      const label = document.createElement("span");
      label.className = "pinarms-slice-label";
      function apply() {
        const k = parseInt(slider.value, 10);
        label.textContent = "z = " + m.layers[k].z_mm + " mm (base frame)";
        m.layers.forEach(function (layer, j) {
          const show = mode.value === "all" || (mode.value === "below" ? j <= k : j === k);
          viewer.handle_command({type: "set_property", path: layer.path, property: "visible", value: show});
        });
      }
      slider.addEventListener("input", apply);
      mode.addEventListener("change", apply);
      const row = document.createElement("div");
      row.appendChild(mode); row.appendChild(slider);
      body.appendChild(title); body.appendChild(desc); body.appendChild(row); body.appendChild(label);
      panel.appendChild(bar); panel.appendChild(scale); panel.appendChild(body);
      document.body.appendChild(panel);
      label.textContent = "z = " + m.layers[m.layers.length - 1].z_mm + " mm (base frame)";
    });
  }
  build();
})();
"""


def overlay_html(session: Any, paths: dict[str, list[str]]) -> str:
    """The panel markup for ``session``'s reachability maps drawn at ``paths`` (empty string if none)."""
    maps = []
    for name, scene_paths in paths.items():
        rec = session.reachability[name]
        layers = [p for p in scene_paths if "/layers/" in p]
        maps.append({
            "name": name,
            "description": rec.description,
            "layers": [{"path": "/meshcat/" + p, "z_mm": int(p.rsplit("/z", 1)[1][:-2])} for p in layers],
        })
    if not maps:
        return ""
    data = json.dumps(maps).replace("</", "<\\/")
    script = _SCRIPT.replace("%DATA%", data).replace("%GRADIENT%", _gradient())
    return f'<script id="pinarms-reachability">{script}</script>\n'


def inject_overlay(html: str, session: Any, paths: dict[str, list[str]]) -> str:
    """``html`` with the reachability panel inserted before its last ``</body>`` (unchanged if no map)."""
    snippet = overlay_html(session, paths)
    if not snippet:
        return html
    at = html.rfind("</body>")
    return html[:at] + snippet + html[at:] if at >= 0 else html + snippet
