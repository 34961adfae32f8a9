// pinarms page: title, colour bar, framing and the animation/cloud controls around a MeshCat
// scene. It reads the JSON that pinarms' build_scene stores on /meshcat/pinarms (property
// "pinarms_page"; keys documented in viz/page.py) and re-reads it when the scene is rebuilt.
(function () {
  "use strict";
  var PROPERTY = "pinarms_page";
  var shown = null;      // JSON text in use
  var framedAt = null;   // target the view was framed on (a rebuilt scene with another target re-frames)
  var ui = null;

  function root() {
    var m = window.viewer && window.viewer.scene_tree && window.viewer.scene_tree.children.meshcat;
    return m && m.children.pinarms;
  }

  function el(tag, attrs, parent) {
    var e = document.createElement(tag);
    Object.keys(attrs || {}).forEach(function (k) {
      if (k === "text") e.textContent = attrs[k]; else e.setAttribute(k, attrs[k]);
    });
    if (parent) parent.appendChild(e);
    return e;
  }

  function fmt(x) {
    if (x === 0) return "0";
    var a = Math.abs(x);
    return (a >= 0.01 && a < 1e4) ? String(Number(x.toPrecision(3))) : x.toExponential(2);
  }

  var CSS = [
    "#pinarms-page{position:absolute;left:0;top:0;width:100%;height:100%;pointer-events:none;",
    "font:13px/1.35 system-ui,-apple-system,'Segoe UI',Roboto,sans-serif;color:#1d2533}",
    "#pinarms-page .box{position:absolute;pointer-events:auto;background:rgba(255,255,255,.86);",
    "border-radius:6px;box-shadow:0 1px 4px rgba(0,0,0,.25);padding:8px 12px}",
    "#pinarms-title{left:12px;top:12px;max-width:46%}",
    "#pinarms-title h1{font-size:17px;margin:0 0 4px 0}",
    "#pinarms-title div{color:#4a5466;font-size:12px}",
    "#pinarms-colorbar{left:12px;bottom:12px;width:250px}",
    "#pinarms-colorbar .bar{height:14px;border-radius:2px;margin:4px 0 2px 0}",
    "#pinarms-colorbar .ticks{display:flex;justify-content:space-between;font-size:11px;color:#4a5466}",
    "#pinarms-controls{right:12px;bottom:12px;display:flex;gap:10px;align-items:center;white-space:nowrap}",
    "#pinarms-controls button{font:inherit;padding:3px 10px;cursor:pointer;min-width:78px}",
    "#pinarms-controls input[type=range]{width:180px}",
    "#pinarms-controls .time{font-variant-numeric:tabular-nums;min-width:92px}",
    "#pinarms-controls label{white-space:nowrap;cursor:pointer}"
  ].join("\n");

  function build() {
    var style = el("style", {text: CSS}, document.head);
    var pane = el("div", {id: "pinarms-page"}, document.body);
    var title = el("div", {id: "pinarms-title", "class": "box"}, pane);
    var bar = el("div", {id: "pinarms-colorbar", "class": "box"}, pane);
    var controls = el("div", {id: "pinarms-controls", "class": "box"}, pane);
    var play = el("button", {id: "pinarms-play", type: "button", title: "play / pause the animation"}, controls);
    var slider = el("input", {id: "pinarms-time", type: "range", min: "0", max: "1", step: "0.001", value: "0"}, controls);
    var time = el("span", {"class": "time"}, controls);
    var cloudLabel = el("label", {}, controls);
    var cloud = el("input", {id: "pinarms-cloud", type: "checkbox"}, cloudLabel);
    cloudLabel.appendChild(document.createTextNode(" workspace cloud"));
    play.addEventListener("click", function () {
      var a = window.viewer.animator;
      if (a.playing) a.pause(); else a.play();
    });
    slider.addEventListener("input", function () {
      var a = window.viewer.animator;
      if (a.playing) a.pause();
      a.play(); a.pause(); a.seek(parseFloat(slider.value));  // a seek shows nothing before the first play
      window.viewer.set_dirty();
    });
    cloud.addEventListener("change", function () { setClouds(cloud.checked); });
    return {style: style, pane: pane, title: title, bar: bar, controls: controls, play: play,
            slider: slider, time: time, cloud: cloud, cloudLabel: cloudLabel, info: null};
  }

  function setClouds(visible) {
    ui.info.clouds.forEach(function (path) {
      window.viewer.set_property(["meshcat"].concat(path.split("/")), "visible", visible);
    });
    window.viewer.set_dirty();
  }

  function frame(info) {
    var v = window.viewer, t = info.target, c = info.camera;
    // world (x, y, z), z up  ->  three.js camera frame (x, z, -y), y up
    v.controls.target.set(t[0], t[2], -t[1]);
    v.camera.position.set(c[0], c[2], -c[1]);
    v.controls.update();
    v.set_dirty();
    framedAt = JSON.stringify(t);
  }

  function apply(info) {
    if (!ui) ui = build();
    ui.info = info;
    document.title = info.title;
    ui.title.textContent = "";
    el("h1", {text: info.title}, ui.title);
    info.lines.forEach(function (line) { el("div", {text: line}, ui.title); });

    ui.bar.style.display = info.colorbar ? "" : "none";
    if (info.colorbar) {
      var cb = info.colorbar;
      ui.bar.textContent = "";
      el("div", {"class": "label", text: cb.label + (cb.unit ? " [" + cb.unit + "]" : "")}, ui.bar);
      var gradient = el("div", {"class": "bar"}, ui.bar);
      gradient.style.background = "linear-gradient(to right," + cb.colors.join(",") + ")";
      var ticks = el("div", {"class": "ticks"}, ui.bar);
      [cb.min, (cb.min + cb.max) / 2, cb.max].forEach(function (x) { el("span", {text: fmt(x)}, ticks); });
      el("div", {"class": "ticks", text: "low (near-singular) → high (dexterous)"}, ui.bar);
    }

    var duration = info.animation.duration;
    ui.play.style.display = ui.slider.style.display = ui.time.style.display = duration > 0 ? "" : "none";
    ui.slider.max = String(duration);
    ui.cloudLabel.style.display = info.clouds.length ? "" : "none";
    ui.cloud.checked = info.clouds_visible;
    ui.controls.style.display = (duration > 0 || info.clouds.length) ? "" : "none";
    if (framedAt !== JSON.stringify(info.target)) frame(info);
  }

  function tick() {
    var r = root();
    var text = r && r.object && r.object[PROPERTY];
    if (text && text !== shown) {
      shown = text;
      apply(JSON.parse(text));
    }
    if (ui && ui.info && ui.info.animation.duration > 0) {
      var a = window.viewer.animator;
      var now = a.actions.reduce(function (m, act) { return Math.max(m, act.time); }, 0);
      ui.play.textContent = a.playing ? "❚❚ pause" : "▶ play";
      if (document.activeElement !== ui.slider) ui.slider.value = String(now);
      ui.time.textContent = now.toFixed(2) + " / " + ui.info.animation.duration.toFixed(2) + " s";
    }
  }

  setInterval(tick, 100);
})();

// Reachability maps (page key "reachability", see viz/page.py): one panel per map with the
// index colour bar and a slice control over its voxel layers (hidden at first, so that the voxels
// never hide the robot; then all / up to / only this layer; moving the slider shows that layer).
(function () {
  "use strict";
  var PROPERTY = "pinarms_page";
  var shown = null;
  var pane = null;

  function el(tag, attrs, parent) {
    var e = document.createElement(tag);
    Object.keys(attrs || {}).forEach(function (k) {
      if (k === "text") e.textContent = attrs[k]; else e.setAttribute(k, attrs[k]);
    });
    if (parent) parent.appendChild(e);
    return e;
  }

  function panel(m, i, bottom) {
    var box = el("div", {id: "pinarms-reach-" + i, "class": "pinarms-reach"}, pane);
    box.style.cssText = "position:absolute;right:12px;pointer-events:auto;background:rgba(255,255,255,.86);" +
      "border-radius:6px;box-shadow:0 1px 4px rgba(0,0,0,.25);padding:8px 12px;width:300px;bottom:" + bottom + "px";
    el("div", {"class": "label", text: m.label + ": " + m.name}, box).style.fontWeight = "600";
    el("div", {"class": "description", text: m.description}, box).style.cssText = "font-size:11px;color:#4a5466";
    var bar = el("div", {"class": "pinarms-colorbar"}, box);
    bar.style.cssText = "height:14px;border-radius:2px;margin:4px 0 2px 0;background:linear-gradient(to right," +
      m.colors.join(",") + ")";
    var ticks = el("div", {}, box);
    ticks.style.cssText = "display:flex;justify-content:space-between;font-size:11px;color:#4a5466";
    ["0", "0.5", "1"].forEach(function (t) { el("span", {text: t}, ticks); });
    var row = el("div", {}, box);
    row.style.cssText = "display:flex;gap:6px;align-items:center;margin-top:4px";
    var mode = el("select", {"class": "pinarms-slice-mode"}, row);
    [["none", "hidden"], ["all", "all layers"], ["below", "layers up to"], ["only", "this layer only"]].forEach(function (o) {
      el("option", {value: o[0], text: o[1]}, mode);
    });
    var n = m.layers.length;
    var slider = el("input", {"class": "pinarms-slice", type: "range", min: "0", max: String(n - 1), step: "1",
                              value: String(n - 1)}, row);
    slider.style.width = "120px";
    var label = el("span", {"class": "pinarms-slice-label"}, box);
    label.style.cssText = "font-size:11px;font-variant-numeric:tabular-nums";
    function apply() {
      var k = parseInt(slider.value, 10);
      label.textContent = "z = " + m.layers[k].z_mm + " mm (base frame)";
      m.layers.forEach(function (layer, j) {
        var visible = mode.value !== "none" && (mode.value === "all" || (mode.value === "below" ? j <= k : j === k));
        window.viewer.set_property(["meshcat"].concat(layer.path.split("/")), "visible", visible);
      });
      window.viewer.set_dirty();
    }
    slider.addEventListener("input", function () { if (mode.value === "none") { mode.value = "only"; } apply(); });
    mode.addEventListener("change", apply);
    label.textContent = "z = " + m.layers[n - 1].z_mm + " mm (base frame)";
    return box;
  }

  function tick() {
    var m = window.viewer && window.viewer.scene_tree && window.viewer.scene_tree.children.meshcat;
    var r = m && m.children.pinarms;
    var text = r && r.object && r.object[PROPERTY];
    if (!text || text === shown) return;
    shown = text;
    var info = JSON.parse(text);
    if (pane) pane.remove();
    pane = null;
    var maps = info.reachability || [];
    if (!maps.length) return;
    pane = el("div", {id: "pinarms-reach"}, document.body);
    pane.style.cssText = "position:absolute;left:0;top:0;width:100%;height:100%;pointer-events:none;" +
      "font:13px/1.35 system-ui,-apple-system,'Segoe UI',Roboto,sans-serif;color:#1d2533";
    var bottom = (info.animation && info.animation.duration > 0) || (info.clouds && info.clouds.length) ? 64 : 12;
    maps.forEach(function (map, i) { bottom += panel(map, i, bottom).offsetHeight + 8; });
  }

  setInterval(tick, 100);
})();
