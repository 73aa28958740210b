// kneeform's 3D view: the part with the composite painted on it (WebGL 2,
// no library). The data block's layout is documented in view3d.rs.
(function () {
  "use strict";
  var root = document.getElementById("view3d");
  var canvas = root.querySelector("canvas");
  var status = root.querySelector(".view3d-status");
  var readout = root.querySelector(".view3d-pick");
  var d = JSON.parse(document.getElementById("view3d-data").textContent);

  function unavailable(why) {
    root.setAttribute("data-state", "unavailable");
    canvas.style.display = "none";
    status.textContent = "No interactive 3D view: " + why + " The pictures above show the same colours.";
  }
  function bytes(b64) {
    var s = atob(b64), a = new Uint8Array(s.length);
    for (var i = 0; i < s.length; i++) a[i] = s.charCodeAt(i);
    return a;
  }
  function bitmap(b64) {
    return createImageBitmap(new Blob([bytes(b64)], { type: "image/png" }),
      { colorSpaceConversion: "none", premultiplyAlpha: "none" });
  }

  var gl = canvas.getContext("webgl2", { antialias: true, preserveDrawingBuffer: true });
  if (!gl) { unavailable("this browser has no WebGL 2."); return; }
  var maxTexture = gl.getParameter(gl.MAX_TEXTURE_SIZE);
  if (d.size[0] > maxTexture || d.size[1] > maxTexture) {
    unavailable("the grid (" + d.size[0] + " x " + d.size[1] + " nodes) is larger than this GPU's textures (" + maxTexture + ").");
    return;
  }

  var positions = new Float32Array(bytes(d.positions).buffer);
  var indices = new Uint32Array(bytes(d.indices).buffer);

  var vs = "#version 300 es\n" +
    "in vec3 p; uniform mat4 mvp; out vec3 vp;\n" +
    "void main() { vp = p; gl_Position = mvp * vec4(p, 1.0); }\n";
  var fs = "#version 300 es\nprecision highp float; precision highp int;\n" +
    "in vec3 vp; out vec4 colour;\n" +
    "uniform vec3 centre; uniform mat3 toGrid; uniform float pitch; uniform ivec2 origin; uniform ivec2 size;\n" +
    "uniform vec2 depthRange; uniform float depthTol; uniform vec3 light; uniform int rampLen;\n" +
    "uniform sampler2D nodes; uniform sampler2D ramp;\n" +
    "void main() {\n" +
    "  vec3 n = normalize(cross(dFdx(vp), dFdy(vp)));\n" +
    "  float shade = 0.3 + 0.7 * abs(dot(n, light));\n" +
    "  vec3 c = vec3(0.78) * shade;\n" +
    "  vec3 g = toGrid * (vp + centre);\n" +
    "  ivec2 ij = ivec2(floor(g.x / pitch + 0.5), floor(g.z / pitch + 0.5)) - origin;\n" +
    "  if (all(greaterThanEqual(ij, ivec2(0))) && all(lessThan(ij, size))) {\n" +
    "    vec4 t = texelFetch(nodes, ij, 0);\n" +
    "    int count = int(t.r * 255.0 + 0.5);\n" +
    "    float q = floor(t.g * 255.0 + 0.5) * 256.0 + floor(t.b * 255.0 + 0.5);\n" +
    "    float depth = depthRange.x + q / 65535.0 * (depthRange.y - depthRange.x);\n" +
    "    if (count > 0 && abs(g.y - depth) <= depthTol) {\n" +
    "      c = texelFetch(ramp, ivec2(min(count, rampLen) - 1, 0), 0).rgb * (0.6 + 0.4 * shade);\n" +
    "    }\n" +
    "  }\n" +
    "  colour = vec4(c, 1.0);\n" +
    "}\n";
  var markVs = "#version 300 es\nuniform mat4 mvp; uniform vec3 at;\n" +
    "void main() { gl_Position = mvp * vec4(at, 1.0); gl_Position.z -= 0.01 * gl_Position.w; gl_PointSize = 11.0; }\n";
  var markFs = "#version 300 es\nprecision highp float; out vec4 colour;\n" +
    "void main() { vec2 r = gl_PointCoord - 0.5; if (dot(r, r) > 0.25 || dot(r, r) < 0.06) discard; colour = vec4(1.0, 0.0, 1.0, 1.0); }\n";

  function program(vsText, fsText) {
    function shader(type, text) {
      var s = gl.createShader(type);
      gl.shaderSource(s, text);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      return s;
    }
    var p = gl.createProgram();
    gl.attachShader(p, shader(gl.VERTEX_SHADER, vsText));
    gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fsText));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    return p;
  }
  var prog, mark;
  try {
    prog = program(vs, fs);
    mark = program(markVs, markFs);
  } catch (e) {
    unavailable("the shaders did not compile (" + e.message + ").");
    return;
  }

  var vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  var vbo = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, vbo);
  gl.bufferData(gl.ARRAY_BUFFER, positions, gl.STATIC_DRAW);
  var loc = gl.getAttribLocation(prog, "p");
  gl.enableVertexAttribArray(loc);
  gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
  var ibo = gl.createBuffer();
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibo);
  gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
  gl.bindVertexArray(null);

  function texture(unit, width, height, source) {
    var t = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE);
    gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
    gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    if (source instanceof Uint8Array) {
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, width, height, 0, gl.RGBA, gl.UNSIGNED_BYTE, source);
    } else {
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, source);
    }
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    return t;
  }
  var rampBytes = bytes(d.ramp);
  var rampLen = rampBytes.length / 4;
  texture(1, rampLen, 1, rampBytes);

  // The camera orbits the part's centre: azimuth and elevation of the eye,
  // distance in radii; z is up.
  var start = (function () {
    var v = d.view, l = Math.hypot(v[0], v[1], v[2]);
    var e = [-v[0] / l, -v[1] / l, -v[2] / l];
    return { az: Math.atan2(e[1], e[0]), el: Math.asin(e[2]), dist: 2.4 };
  })();
  var cam = { az: start.az, el: start.el, dist: start.dist, target: [0, 0, 0] };
  var fov = 35 * Math.PI / 180;

  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function norm(a) { var l = Math.hypot(a[0], a[1], a[2]); return [a[0] / l, a[1] / l, a[2] / l]; }
  function basis() {
    var r = d.radius * cam.dist;
    var t = cam.target;
    var eye = [t[0] + r * Math.cos(cam.el) * Math.cos(cam.az), t[1] + r * Math.cos(cam.el) * Math.sin(cam.az), t[2] + r * Math.sin(cam.el)];
    var f = norm(sub(t, eye));
    var right = norm(cross(f, [0, 0, 1]));
    var up = cross(right, f);
    return { eye: eye, f: f, right: right, up: up };
  }
  function mvp() {
    var b = basis(), aspect = canvas.width / canvas.height;
    var near = Math.max(d.radius * (cam.dist - 2.5), d.radius * 0.005), far = d.radius * (cam.dist + 2.5);
    var t = 1 / Math.tan(fov / 2);
    var view = [b.right[0], b.up[0], -b.f[0], 0, b.right[1], b.up[1], -b.f[1], 0, b.right[2], b.up[2], -b.f[2], 0,
      -dot(b.right, b.eye), -dot(b.up, b.eye), dot(b.f, b.eye), 1];
    var proj = [t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (far + near) / (near - far), -1, 0, 0, 2 * far * near / (near - far), 0];
    var m = new Float32Array(16);
    for (var c = 0; c < 4; c++) for (var r = 0; r < 4; r++) {
      var s = 0;
      for (var k = 0; k < 4; k++) s += proj[k * 4 + r] * view[c * 4 + k];
      m[c * 4 + r] = s;
    }
    return m;
  }

  // The overlay: a 2D canvas over the WebGL one (pointer events pass
  // through), redrawn with every frame: the vehicle axes, the colour
  // legend, a scale bar and the largest zones' ids.
  var wrap = document.createElement("div");
  wrap.style.position = "relative";
  wrap.style.display = "inline-block";
  wrap.style.maxWidth = "100%";
  canvas.parentNode.insertBefore(wrap, canvas);
  wrap.appendChild(canvas);
  var overlay = document.createElement("canvas");
  overlay.width = canvas.width;
  overlay.height = canvas.height;
  overlay.className = "view3d-overlay";
  overlay.style.cssText = "position:absolute;left:1px;top:1px;width:calc(100% - 2px);height:calc(100% - 2px);pointer-events:none;";
  wrap.appendChild(overlay);
  var ctx2d = overlay.getContext("2d");
  var zonesOf = null;
  function project(m, p) {
    // Canvas pixels of the point p (offsets from the centre), or null
    // behind the eye.
    var x = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
    var y = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
    var w = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
    if (w <= 0) return null;
    return [(x / w + 1) / 2 * overlay.width, (1 - y / w) / 2 * overlay.height];
  }
  function niceLength(mm) {
    var e = Math.pow(10, Math.floor(Math.log10(mm))), f = mm / e;
    return (f >= 5 ? 5 : f >= 2 ? 2 : 1) * e;
  }
  function drawOverlay(m, b) {
    var c = ctx2d, W = overlay.width, H = overlay.height;
    c.clearRect(0, 0, W, H);
    c.font = "13px sans-serif";
    c.lineWidth = 2;
    // The vehicle axes, from the bottom-left corner.
    var o = [60, H - 60], axes = [["x", [1, 0, 0], "#c0392b"], ["y", [0, 1, 0], "#1e8449"], ["z", [0, 0, 1], "#2471a3"]];
    axes.forEach(function (a) {
      var v = a[1], sx = dot(v, b.right), sy = dot(v, b.up);
      var e = [o[0] + 40 * sx, o[1] - 40 * sy];
      c.strokeStyle = a[2]; c.fillStyle = a[2];
      c.beginPath(); c.moveTo(o[0], o[1]); c.lineTo(e[0], e[1]); c.stroke();
      c.fillText(a[0], e[0] + 4 * Math.sign(sx || 1), e[1] - 4 * Math.sign(sy || 1));
    });
    c.fillStyle = "#333";
    c.fillText("vehicle axes (front -x, z up)", 12, H - 10);
    // The legend: one swatch per count of the ramp.
    var n = rampLen, top = 14, left = W - 150, sw = Math.min(14, Math.max(2, Math.floor(180 / n)));
    c.fillStyle = "rgba(255,255,255,0.85)";
    c.fillRect(left - 8, top - 4, 150, n * sw + 44);
    c.fillStyle = "#333";
    c.fillText("angles struck", left, top + 10);
    for (var k = 0; k < n; k++) {
      c.fillStyle = "rgb(" + rampBytes[4 * k] + "," + rampBytes[4 * k + 1] + "," + rampBytes[4 * k + 2] + ")";
      c.fillRect(left, top + 18 + (n - 1 - k) * sw, 24, sw);
    }
    c.fillStyle = "#333";
    c.fillText(String(n), left + 30, top + 28);
    c.fillText("1", left + 30, top + 18 + n * sw);
    c.fillStyle = "rgb(199,199,199)";
    c.fillRect(left, top + 22 + n * sw, 24, 10);
    c.fillStyle = "#333";
    c.fillText("none", left + 30, top + 32 + n * sw);
    // The scale bar: mm per pixel at the depth of the view's centre.
    var mmPerPx = 2 * d.radius * cam.dist * Math.tan(fov / 2) / H;
    var len = niceLength(mmPerPx * 140), px = len / mmPerPx;
    c.strokeStyle = "#333"; c.fillStyle = "#333";
    c.beginPath(); c.moveTo(W - 30 - px, H - 24); c.lineTo(W - 30, H - 24);
    c.moveTo(W - 30 - px, H - 30); c.lineTo(W - 30 - px, H - 18);
    c.moveTo(W - 30, H - 30); c.lineTo(W - 30, H - 18); c.stroke();
    c.textAlign = "right";
    c.fillText(len + " mm (at the view's centre)", W - 30, H - 34);
    c.textAlign = "left";
    // The largest zones' ids at their centroids, largest first; a label
    // that would cover one already drawn is left out (a pick names it).
    var placed = [];
    (d.zones || []).forEach(function (z) {
      var p = project(m, [z.at[0] - d.centre[0], z.at[1] - d.centre[1], z.at[2] - d.centre[2]]);
      if (!p || p[0] < 0 || p[1] < 0 || p[0] > W || p[1] > H) return;
      var label = "zone " + z.id;
      var w = c.measureText(label).width + 8;
      if (placed.some(function (q) { return Math.abs(q[0] - p[0]) < (q[2] + w) / 2 && Math.abs(q[1] - p[1]) < 18; })) return;
      placed.push([p[0], p[1], w]);
      c.fillStyle = "rgba(255,255,255,0.85)";
      c.fillRect(p[0] - w / 2, p[1] - 9, w, 18);
      c.strokeStyle = "#333"; c.lineWidth = 1;
      c.strokeRect(p[0] - w / 2, p[1] - 9, w, 18);
      c.fillStyle = "#000";
      c.fillText(label, p[0] - w / 2 + 4, p[1] + 5);
      c.lineWidth = 2;
    });
  }

  var picked = null, first = true, pending = false;
  function draw() {
    pending = false;
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(1, 1, 1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    var m = mvp(), b = basis();
    gl.useProgram(prog);
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "mvp"), false, m);
    gl.uniform3fv(gl.getUniformLocation(prog, "centre"), d.centre);
    // GLSL's mat3 is column-major; to_grid is written by rows.
    gl.uniformMatrix3fv(gl.getUniformLocation(prog, "toGrid"), true, d.to_grid);
    gl.uniform1f(gl.getUniformLocation(prog, "pitch"), d.pitch);
    gl.uniform2iv(gl.getUniformLocation(prog, "origin"), d.origin);
    gl.uniform2iv(gl.getUniformLocation(prog, "size"), d.size);
    gl.uniform2fv(gl.getUniformLocation(prog, "depthRange"), d.depth_range);
    gl.uniform1f(gl.getUniformLocation(prog, "depthTol"), d.depth_tol);
    gl.uniform3fv(gl.getUniformLocation(prog, "light"), norm([-b.f[0] + 0.3 * b.up[0], -b.f[1] + 0.3 * b.up[1], -b.f[2] + 0.3 * b.up[2]]));
    gl.uniform1i(gl.getUniformLocation(prog, "rampLen"), rampLen);
    gl.uniform1i(gl.getUniformLocation(prog, "nodes"), 0);
    gl.uniform1i(gl.getUniformLocation(prog, "ramp"), 1);
    gl.bindVertexArray(vao);
    gl.drawElements(gl.TRIANGLES, indices.length, gl.UNSIGNED_INT, 0);
    gl.bindVertexArray(null);
    if (picked) {
      gl.useProgram(mark);
      gl.uniformMatrix4fv(gl.getUniformLocation(mark, "mvp"), false, m);
      gl.uniform3fv(gl.getUniformLocation(mark, "at"), picked);
      gl.drawArrays(gl.POINTS, 0, 1);
    }
    drawOverlay(m, b);
    if (first) {
      first = false;
      root.setAttribute("data-overlay", "axes legend scale-bar zones:" + (d.zones || []).length);
      var px = new Uint8Array(canvas.width * canvas.height * 4), part = 0, coloured = 0;
      gl.readPixels(0, 0, canvas.width, canvas.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
      for (var i = 0; i < px.length; i += 4) {
        var hi = Math.max(px[i], px[i + 1], px[i + 2]), lo = Math.min(px[i], px[i + 1], px[i + 2]);
        if (lo < 250) part++;
        if (hi - lo > 40) coloured++;
      }
      root.setAttribute("data-part-pixels", part);
      root.setAttribute("data-coloured-pixels", coloured);
      root.setAttribute("data-state", "drawn");
      status.textContent = "Interactive 3D view (" + d.triangles + " triangles" +
        (d.simplified ? ", simplified from " + d.simplified.original_triangles + ": the face towards the knee-form every " + d.simplified.pitch + " mm" : "") +
        ", grid " + d.size[0] + " x " + d.size[1] + " nodes).";
      if (d.simplified) root.setAttribute("data-simplified", d.simplified.original_triangles);
    }
  }
  function redraw() { if (!pending) { pending = true; requestAnimationFrame(draw); } }

  // The angles that strike node k, from the masks' pixels.
  var masks = null;
  function anglesAt(k) {
    if (!masks) return null;
    var out = [];
    for (var a = 0; a < d.angles.length; a++) {
      var b = a >> 3, p = (k * d.mask_words + Math.floor(b / 3)) * 4 + b % 3;
      if (masks[p] >> (a & 7) & 1) out.push(d.angles[a]);
    }
    return out;
  }
  function runs(list) {
    // Consecutive angles of the run's list as "first to last".
    var parts = [], i = 0;
    while (i < list.length) {
      var j = i, at = d.angles.indexOf(list[i]);
      while (j + 1 < list.length && d.angles.indexOf(list[j + 1]) === at + (j + 1 - i)) j++;
      parts.push(j > i + 1 ? list[i] + " to " + list[j] : list.slice(i, j + 1).join(", "));
      i = j + 1;
    }
    return parts.join(", ");
  }
  function fmt(v) { var s = v.toFixed(2); return s === "-0.00" ? "0.00" : s; }
  function pick(cx, cy) {
    var rect = canvas.getBoundingClientRect();
    var x = 2 * (cx - rect.left) / rect.width - 1, y = 1 - 2 * (cy - rect.top) / rect.height;
    var b = basis(), t = Math.tan(fov / 2), aspect = canvas.width / canvas.height;
    var dir = norm([0, 1, 2].map(function (a) { return b.f[a] + x * t * aspect * b.right[a] + y * t * b.up[a]; }));
    var best = Infinity;
    for (var i = 0; i < indices.length; i += 3) {
      var p0 = indices[i] * 3, p1 = indices[i + 1] * 3, p2 = indices[i + 2] * 3;
      var v0 = [positions[p0], positions[p0 + 1], positions[p0 + 2]];
      var e1 = sub([positions[p1], positions[p1 + 1], positions[p1 + 2]], v0);
      var e2 = sub([positions[p2], positions[p2 + 1], positions[p2 + 2]], v0);
      var h = cross(dir, e2), det = dot(e1, h);
      if (Math.abs(det) < 1e-12) continue;
      var s = sub(b.eye, v0), u = dot(s, h) / det;
      if (u < 0 || u > 1) continue;
      var q = cross(s, e1), v = dot(dir, q) / det;
      if (v < 0 || u + v > 1) continue;
      var dist = dot(e2, q) / det;
      if (dist > 0 && dist < best) best = dist;
    }
    if (best === Infinity) { picked = null; readout.textContent = "No part under the pointer."; redraw(); return; }
    picked = [0, 1, 2].map(function (a) { return b.eye[a] + best * dir[a]; });
    var w = picked.map(function (c, a) { return c + d.centre[a]; });
    var m = d.to_grid;
    var g = [0, 1, 2].map(function (r) { return m[3 * r] * w[0] + m[3 * r + 1] * w[1] + m[3 * r + 2] * w[2]; });
    var i = Math.floor(g[0] / d.pitch + 0.5) - d.origin[0], j = Math.floor(g[2] / d.pitch + 0.5) - d.origin[1];
    var text = "x = " + fmt(w[0]) + ", y = " + fmt(w[1]) + ", z = " + fmt(w[2]) + " mm (vehicle frame" + (d.frame ? ", after --frame" : "") + ")";
    if (i < 0 || j < 0 || i >= d.size[0] || j >= d.size[1]) {
      text += "; outside the grid.";
    } else {
      text += "; nearest node i = " + i + ", j = " + j;
      if (zonesOf) {
        var q = (j * d.size[0] + i) * 4, zone = zonesOf[q] * 65536 + zonesOf[q + 1] * 256 + zonesOf[q + 2];
        text += zone > 0 ? " in zone " + zone + " (zones.csv)" : " in no struck zone";
      }
      var list = anglesAt(j * d.size[0] + i);
      if (list === null) text += " (this run's composite.csv has no angle sets).";
      else if (list.length === 0) text += ": struck at no angle.";
      else text += ": struck at " + list.length + " of " + d.angles.length + " angles (" + runs(list) + " degrees), if the point lies on the node's surface (within " + d.depth_tol + " mm of its depth).";
    }
    readout.textContent = text;
    redraw();
  }

  var drag = null;
  canvas.addEventListener("pointerdown", function (e) {
    drag = { x: e.clientX, y: e.clientY, moved: 0, pan: e.shiftKey || e.button === 2 };
    try { canvas.setPointerCapture(e.pointerId); } catch (err) { /* a synthetic pointer */ }
  });
  canvas.addEventListener("pointermove", function (e) {
    if (!drag) return;
    var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.moved += Math.abs(dx) + Math.abs(dy);
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) {
      // The target moves with the pointer, in the screen's plane.
      var b = basis(), k = 2 * d.radius * cam.dist * Math.tan(fov / 2) / canvas.getBoundingClientRect().height;
      cam.target = [0, 1, 2].map(function (a) { return cam.target[a] - k * (dx * b.right[a] - dy * b.up[a]); });
    } else {
      cam.az -= dx * 0.008;
      cam.el = Math.max(-1.5, Math.min(1.5, cam.el + dy * 0.008));
    }
    redraw();
  });
  canvas.addEventListener("pointerup", function (e) {
    if (drag && drag.moved < 4) pick(e.clientX, e.clientY);
    drag = null;
  });
  canvas.addEventListener("contextmenu", function (e) { e.preventDefault(); });
  canvas.addEventListener("wheel", function (e) {
    e.preventDefault();
    cam.dist = Math.max(0.05, Math.min(20, cam.dist * Math.exp(e.deltaY * 0.001)));
    redraw();
  }, { passive: false });
  canvas.addEventListener("dblclick", function () {
    cam.az = start.az; cam.el = start.el; cam.dist = start.dist; cam.target = [0, 0, 0];
    redraw();
  });

  function pixels(img) {
    var c = document.createElement("canvas");
    c.width = img.width; c.height = img.height;
    var ctx = c.getContext("2d");
    ctx.drawImage(img, 0, 0);
    return ctx.getImageData(0, 0, img.width, img.height, { colorSpace: "srgb" }).data;
  }
  var loads = [bitmap(d.nodes_png).then(function (img) { texture(0, d.size[0], d.size[1], img); })];
  loads.push(bitmap(d.zones_png).then(function (img) { zonesOf = pixels(img); }));
  if (d.masks_png) {
    loads.push(bitmap(d.masks_png).then(function (img) { masks = pixels(img); }));
  }
  Promise.all(loads).then(draw, function (e) { unavailable("its data did not load (" + e + ")."); });
})();
