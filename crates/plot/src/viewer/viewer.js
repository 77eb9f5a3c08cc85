// brtf's 3D view of a fit: the measured samples as points over the
// projected hemisphere (height = value), the fitted model as a translucent
// surface, and model ÷ data as colour. Plain WebGL2, no library, no
// network. The data block beside this script is written by brtf-plot
// (crates/plot/src/viewer): per incidence, base64 of packed arrays.
(function () {
  'use strict';
  var script = document.currentScript;
  var root = script ? script.parentElement : null;
  if (!root || root.dataset.started) {
    var waiting = document.querySelectorAll('.brtf-view:not([data-started])');
    root = waiting.length ? waiting[0] : null;
  }
  if (!root) return;
  root.dataset.started = '1';
  var payload = JSON.parse(root.querySelector('.bv-data').textContent);
  var incidences = payload.incidences;
  var controls = root.querySelector('.bv-controls');
  var canvas = root.querySelector('.bv-canvas');
  var tip = root.querySelector('.bv-tip');
  var legend = root.querySelector('.bv-legend');
  var status = root.querySelector('.bv-status');
  var TOP = 65534, NONE = 65535;
  var MODES = [['data', 'data'], ['model', 'model'], ['residual', 'model ÷ data']];
  var state = { incidence: 0, mode: 0, log: true, points: true, surface: true, removed: true, surfaceOf: 0 };
  var view = { yaw: -2.2, pitch: 0.62, dist: 3.4, pan: [0, 0, 0.2] };
  var HEIGHT = 0.9;
  var hook = { draws: 0, ready: false, error: null };
  root.brtfView = hook;

  if (!incidences.length) {
    status.textContent = 'No incidence with data to show.';
    return;
  }

  // --- controls -----------------------------------------------------------
  var uid = root.id || 'bv';
  function el(tag, attrs, text) {
    var e = document.createElement(tag);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    return e;
  }
  function labelled(input, text) {
    var l = el('label');
    l.appendChild(input);
    l.appendChild(document.createTextNode(' ' + text));
    return l;
  }
  if (incidences.length > 1) {
    var pick = el('select', { 'class': 'bv-incidence', 'aria-label': 'incidence' });
    incidences.forEach(function (inc, k) { pick.appendChild(el('option', { value: k }, inc.label)); });
    pick.addEventListener('change', function () { select(+pick.value); });
    var l = el('label', {}, 'incidence ');
    l.appendChild(pick);
    controls.appendChild(l);
  }
  var modes = el('fieldset', { 'class': 'bv-modes' });
  modes.appendChild(el('legend', {}, 'show'));
  MODES.forEach(function (m, k) {
    var r = el('input', { type: 'radio', name: uid + '-mode', value: m[0] });
    if (k === 0) r.checked = true;
    r.addEventListener('change', function () { state.mode = k; changed(); });
    modes.appendChild(labelled(r, m[1]));
  });
  controls.appendChild(modes);
  function toggle(key, text, cls) {
    var c = el('input', { type: 'checkbox', 'class': cls });
    c.checked = state[key];
    c.addEventListener('change', function () { state[key] = c.checked; changed(); });
    controls.appendChild(labelled(c, text));
  }
  toggle('log', 'log height', 'bv-log');
  toggle('points', 'points', 'bv-points');
  toggle('surface', 'model surface', 'bv-surface');
  toggle('removed', 'removed samples', 'bv-removed');
  var surfacePick = null;
  if (incidences[0].surfaces.length > 1) {
    surfacePick = el('select', { 'class': 'bv-surface-of', 'aria-label': 'surface of' });
    incidences[0].surfaces.forEach(function (s, k) { surfacePick.appendChild(el('option', { value: k }, s.label)); });
    surfacePick.addEventListener('change', function () { state.surfaceOf = +surfacePick.value; loadSurface(); changed(); });
    var sl = el('label', {}, 'surface of ');
    sl.appendChild(surfacePick);
    controls.appendChild(sl);
  }
  var reset = el('button', { type: 'button', 'class': 'bv-reset' }, 'reset view');
  reset.addEventListener('click', function () {
    view = { yaw: -2.2, pitch: 0.62, dist: 3.4, pan: [0, 0, 0.2] };
    requestDraw();
  });
  controls.appendChild(reset);

  var gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true });
  if (!gl) {
    var box = el('div', { 'class': 'bv-nogl' },
      'This browser offers no WebGL2, which the 3D view needs. The maps and cuts below show the same comparison.');
    canvas.replaceWith(box);
    legend.hidden = true;
    hook.ready = true;
    hook.error = 'no webgl2';
    return;
  }

  // --- shaders ------------------------------------------------------------
  var COMMON = [
    'uniform vec4 u_scale;', // lo, hi (log10 of the code range), bottom of the log height, ln(ratio)
    'uniform bool u_log;',
    'float lval(float a) { float c = floor(a * 65535.0 + 0.5); if (c < 0.5) return -1e30;',
    '  return u_scale.x + (c - 1.0) / 65533.0 * (u_scale.y - u_scale.x); }',
    'float height(float lv) { if (lv < -1e29) return 0.0;',
    '  if (u_log) return clamp((lv - u_scale.z) / (u_scale.y - u_scale.z), 0.0, 1.0);',
    '  return pow(10.0, lv - u_scale.y); }'
  ].join('\n');
  var POINT_VS = ['#version 300 es', 'precision highp float;', COMMON,
    'in float a_x; in float a_y; in float a_data; in float a_model; in float a_flag;',
    'uniform mat4 u_mvp; uniform int u_mode; uniform float u_floor; uniform float u_size;',
    'uniform bool u_removed; uniform float u_height; uniform vec3 u_rdbu[11];',
    'out vec4 v_colour;',
    'vec3 ramp(float t) {',
    '  vec3 c0 = vec3(0.267, 0.005, 0.329), c1 = vec3(0.231, 0.322, 0.545), c2 = vec3(0.129, 0.569, 0.549);',
    '  vec3 c3 = vec3(0.369, 0.788, 0.384), c4 = vec3(0.992, 0.906, 0.145);',
    '  float x = clamp(t, 0.0, 1.0) * 4.0;',
    '  if (x < 1.0) return mix(c0, c1, x); if (x < 2.0) return mix(c1, c2, x - 1.0);',
    '  if (x < 3.0) return mix(c2, c3, x - 2.0); return mix(c3, c4, x - 3.0); }',
    'vec3 diverge(float t) { float x = (clamp(t, -1.0, 1.0) + 1.0) * 5.0; int i = int(min(floor(x), 9.0));',
    '  return mix(u_rdbu[i], u_rdbu[i + 1], x - float(i)); }',
    'void main() {',
    '  bool back = a_flag >= 128.0; float gate = back ? a_flag - 128.0 : a_flag;',
    '  bool removed = gate > 0.5;',
    '  if (removed && !u_removed) { gl_Position = vec4(2.0, 2.0, 2.0, 1.0); gl_PointSize = 1.0; v_colour = vec4(0.0); return; }',
    '  float ld = lval(a_data), lm = lval(a_model);',
    '  float shown = u_mode == 1 ? lm : ld;',
    '  float h = height(shown) * u_height;',
    '  gl_Position = u_mvp * vec4(a_x * 2.0 - 1.0, a_y * 2.0 - 1.0, back ? -h : h, 1.0);',
    '  gl_PointSize = removed ? max(1.0, u_size * 0.7) : u_size;',
    '  if (removed) { v_colour = vec4(0.62, 0.62, 0.62, 1.0); return; }',
    '  if (u_mode == 2) {',
    '    float d = ld < -1e29 ? 0.0 : pow(10.0, ld); float m = lm < -1e29 ? 0.0 : pow(10.0, lm);',
    '    v_colour = vec4(diverge(log((m + u_floor) / (d + u_floor)) / u_scale.w), 1.0);',
    '  } else {',
    '    float t = shown < -1e29 ? 0.0 : clamp((shown - u_scale.z) / (u_scale.y - u_scale.z), 0.0, 1.0);',
    '    v_colour = vec4(ramp(t), 1.0);',
    '  } }'].join('\n');
  // Round points when they are large enough to show it; small ones stay
  // square (a discard per fragment halves a software renderer's speed).
  var POINT_FS = ['#version 300 es', 'precision mediump float;', 'in vec4 v_colour; out vec4 o;',
    'uniform bool u_round;',
    'void main() { if (u_round) { vec2 p = gl_PointCoord * 2.0 - 1.0; if (dot(p, p) > 1.0) discard; }',
    '  o = v_colour; }'].join('\n');
  var SURF_VS = ['#version 300 es', 'precision highp float;', COMMON,
    'in vec2 a_uv; in float a_code;',
    'uniform mat4 u_mvp; uniform float u_sign; uniform float u_height;',
    'out vec3 v_pos; out float v_h;',
    'void main() { float h = height(lval(a_code)); v_h = h;',
    '  v_pos = vec3(a_uv, u_sign * h * u_height); gl_Position = u_mvp * vec4(v_pos, 1.0); }'].join('\n');
  var SURF_FS = ['#version 300 es', 'precision mediump float;', 'in vec3 v_pos; in float v_h; out vec4 o;',
    'void main() { vec3 n = normalize(cross(dFdx(v_pos), dFdy(v_pos)));',
    '  float light = 0.55 + 0.45 * abs(dot(n, normalize(vec3(0.4, -0.5, 0.8))));',
    '  vec3 c = mix(vec3(0.66, 0.69, 0.74), vec3(0.33, 0.38, 0.48), v_h);',
    '  o = vec4(c * light, 0.3); }'].join('\n');
  var LINE_VS = ['#version 300 es', 'in vec3 a_pos; uniform mat4 u_mvp;',
    'void main() { gl_Position = u_mvp * vec4(a_pos, 1.0); }'].join('\n');
  var LINE_FS = ['#version 300 es', 'precision mediump float;', 'uniform vec4 u_colour; out vec4 o;',
    'void main() { o = u_colour; }'].join('\n');

  function program(vs, fs) {
    function shader(type, text) {
      var s = gl.createShader(type);
      gl.shaderSource(s, text);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error('brtf view shader: ' + gl.getShaderInfoLog(s));
      return s;
    }
    var p = gl.createProgram();
    gl.attachShader(p, shader(gl.VERTEX_SHADER, vs));
    gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fs));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error('brtf view program: ' + gl.getProgramInfoLog(p));
    var u = {};
    var n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
    for (var k = 0; k < n; k++) {
      var name = gl.getActiveUniform(p, k).name.replace('[0]', '');
      u[name] = gl.getUniformLocation(p, name);
    }
    return { p: p, u: u, a: function (name) { return gl.getAttribLocation(p, name); } };
  }
  var points = program(POINT_VS, POINT_FS);
  var surf = program(SURF_VS, SURF_FS);
  var lines = program(LINE_VS, LINE_FS);
  var rdbu = new Float32Array([].concat.apply([], payload.rdbu.map(function (c) {
    return [c[0] / 255, c[1] / 255, c[2] / 255];
  })));

  // --- data ---------------------------------------------------------------
  function bytesOf(b64) {
    var text = atob(b64);
    var out = new Uint8Array(text.length);
    for (var k = 0; k < text.length; k++) out[k] = text.charCodeAt(k);
    return out;
  }
  var current = null; // the shown incidence's decoded arrays and GL objects
  function load(k) {
    var inc = incidences[k];
    var bytes = bytesOf(inc.samples);
    var n = inc.n;
    var d = {
      inc: inc, n: n,
      x: new Uint16Array(bytes.buffer, 0, n), y: new Uint16Array(bytes.buffer, 2 * n, n),
      data: new Uint16Array(bytes.buffer, 4 * n, n), model: new Uint16Array(bytes.buffer, 6 * n, n),
      flag: new Uint8Array(bytes.buffer, 8 * n, n),
      vao: gl.createVertexArray(), buffer: gl.createBuffer(), surfaces: []
    };
    gl.bindVertexArray(d.vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, d.buffer);
    gl.bufferData(gl.ARRAY_BUFFER, bytes, gl.STATIC_DRAW);
    // While the view moves, every step-th sample only (at most about
    // 30 000): a software renderer draws 127k points in ~50 ms.
    d.step = Math.max(1, Math.ceil(n / 30000));
    d.coarse = d.step > 1 ? gl.createVertexArray() : d.vao;
    function attributes(step) {
      [['a_x', 0, gl.UNSIGNED_SHORT, true, 2], ['a_y', 2 * n, gl.UNSIGNED_SHORT, true, 2],
        ['a_data', 4 * n, gl.UNSIGNED_SHORT, true, 2], ['a_model', 6 * n, gl.UNSIGNED_SHORT, true, 2],
        ['a_flag', 8 * n, gl.UNSIGNED_BYTE, false, 1]].forEach(function (a) {
        var at = points.a(a[0]);
        if (at < 0) return;
        gl.enableVertexAttribArray(at);
        gl.vertexAttribPointer(at, 1, a[2], a[3], step > 1 ? step * a[4] : 0, a[1]);
      });
    }
    attributes(1);
    if (d.step > 1) {
      gl.bindVertexArray(d.coarse);
      gl.bindBuffer(gl.ARRAY_BUFFER, d.buffer);
      attributes(d.step);
    }
    gl.bindVertexArray(null);
    return d;
  }
  function free(d) {
    if (!d) return;
    gl.deleteBuffer(d.buffer);
    gl.deleteVertexArray(d.vao);
    if (d.coarse !== d.vao) gl.deleteVertexArray(d.coarse);
    d.surfaces.forEach(function (s) { gl.deleteBuffer(s.codes); gl.deleteBuffer(s.index); gl.deleteVertexArray(s.vao); });
  }
  // The surfaces' grid of G × G nodes over the unit disk (G per incidence).
  var G = 0;
  var gridBuffer = gl.createBuffer();
  function makeGrid(size) {
    if (size === G) return;
    G = size;
    var uv = new Float32Array(2 * G * G);
    for (var j = 0; j < G; j++) {
      for (var i = 0; i < G; i++) {
        uv[2 * (j * G + i)] = -1 + 2 * i / (G - 1);
        uv[2 * (j * G + i) + 1] = -1 + 2 * j / (G - 1);
      }
    }
    gl.bindBuffer(gl.ARRAY_BUFFER, gridBuffer);
    gl.bufferData(gl.ARRAY_BUFFER, uv, gl.STATIC_DRAW);
  }
  function loadSurface() {
    var d = current;
    makeGrid(d.inc.grid);
    d.surfaces.forEach(function (s) { gl.deleteBuffer(s.codes); gl.deleteBuffer(s.index); gl.deleteVertexArray(s.vao); });
    d.surfaces = [];
    var which = Math.min(state.surfaceOf, d.inc.surfaces.length - 1);
    var bytes = bytesOf(d.inc.surfaces[which].codes);
    d.inc.hemispheres.forEach(function (sign, h) {
      var codes = new Uint16Array(bytes.buffer, 2 * G * G * h, G * G);
      var index = [];
      for (var j = 0; j + 1 < G; j++) {
        for (var i = 0; i + 1 < G; i++) {
          var a = j * G + i, b = a + 1, c = a + G, e = c + 1;
          if (codes[a] !== NONE && codes[b] !== NONE && codes[e] !== NONE) index.push(a, b, e);
          if (codes[a] !== NONE && codes[e] !== NONE && codes[c] !== NONE) index.push(a, e, c);
        }
      }
      var s = { sign: sign, vao: gl.createVertexArray(), codes: gl.createBuffer(), index: gl.createBuffer(), count: index.length };
      gl.bindVertexArray(s.vao);
      gl.bindBuffer(gl.ARRAY_BUFFER, gridBuffer);
      gl.enableVertexAttribArray(surf.a('a_uv'));
      gl.vertexAttribPointer(surf.a('a_uv'), 2, gl.FLOAT, false, 0, 0);
      gl.bindBuffer(gl.ARRAY_BUFFER, s.codes);
      gl.bufferData(gl.ARRAY_BUFFER, codes, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(surf.a('a_code'));
      gl.vertexAttribPointer(surf.a('a_code'), 1, gl.UNSIGNED_SHORT, true, 0, 0);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, s.index);
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, new Uint32Array(index), gl.STATIC_DRAW);
      gl.bindVertexArray(null);
      d.surfaces.push(s);
    });
  }

  // Disk rims and θ rings (30°, 60°, 90°) on each hemisphere, the φ = 0
  // axis, and the light, mirror and straight-through markers.
  var guide = gl.createBuffer();
  var guideVao = gl.createVertexArray();
  var guideParts = [];
  function buildGuides(inc) {
    var v = [];
    guideParts = [];
    function part(colour, from) { guideParts.push({ colour: colour, first: from / 3, count: (v.length - from) / 3 }); }
    var start = v.length;
    [30, 60, 90].forEach(function (t) {
      var r = Math.SQRT2 * Math.sin(t * Math.PI / 360);
      for (var k = 0; k < 96; k++) {
        var a0 = 2 * Math.PI * k / 96, a1 = 2 * Math.PI * (k + 1) / 96;
        v.push(r * Math.cos(a0), r * Math.sin(a0), 0, r * Math.cos(a1), r * Math.sin(a1), 0);
      }
    });
    v.push(0, 0, 0, 1.08, 0, 0);
    part([0.55, 0.55, 0.55, 1], start);
    [['light', [0.9, 0.6, 0.0, 1]], ['mirror', [0.8, 0.0, 0.6, 1]], ['through', [0.0, 0.45, 0.7, 1]]].forEach(function (m) {
      var at = inc[m[0]];
      if (m[0] === 'through' && inc.hemispheres.indexOf(at[2]) < 0) return;
      var s = v.length;
      v.push(at[0], at[1], 0, at[0], at[1], at[2] * (HEIGHT + 0.15));
      part(m[1], s);
    });
    gl.bindVertexArray(guideVao);
    gl.bindBuffer(gl.ARRAY_BUFFER, guide);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(v), gl.STATIC_DRAW);
    gl.enableVertexAttribArray(lines.a('a_pos'));
    gl.vertexAttribPointer(lines.a('a_pos'), 3, gl.FLOAT, false, 0, 0);
    gl.bindVertexArray(null);
  }

  // --- camera -------------------------------------------------------------
  function mul(a, b) {
    var o = new Float32Array(16);
    for (var c = 0; c < 4; c++) for (var r = 0; r < 4; r++) {
      var s = 0;
      for (var k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
      o[c * 4 + r] = s;
    }
    return o;
  }
  function matrix() {
    var w = canvas.width, h = canvas.height;
    var f = 1 / Math.tan(0.5 * 35 * Math.PI / 180), near = 0.05, far = 50;
    var proj = new Float32Array([f * h / w, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / (near - far), -1,
      0, 0, 2 * far * near / (near - far), 0]);
    var cp = Math.cos(view.pitch), t = view.pan;
    var eye = [t[0] + view.dist * cp * Math.cos(view.yaw), t[1] + view.dist * cp * Math.sin(view.yaw),
      t[2] + view.dist * Math.sin(view.pitch)];
    var z = norm([eye[0] - t[0], eye[1] - t[1], eye[2] - t[2]]);
    var x = norm(cross([0, 0, 1], z));
    var y = cross(z, x);
    var look = new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
      -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
    return { mvp: mul(proj, look), x: x, y: y };
  }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function norm(a) { var l = Math.sqrt(dot(a, a)) || 1; return [a[0] / l, a[1] / l, a[2] / l]; }

  // --- drawing ------------------------------------------------------------
  function scaleOf(inc) { return [inc.lo, inc.hi, inc.bottom, Math.log(payload.ratio)]; }
  function pointSize(n) { return (n > 50000 ? 2 : n > 5000 ? 3 : n > 1000 ? 4 : 7) * (window.devicePixelRatio || 1); }
  function resize() {
    var dpr = window.devicePixelRatio || 1;
    var w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  }
  function draw() {
    pending = false;
    resize();
    var d = current, inc = d.inc, m = matrix();
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(1, 1, 1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.disable(gl.BLEND);
    gl.depthMask(true);
    gl.useProgram(lines.p);
    gl.uniformMatrix4fv(lines.u.u_mvp, false, m.mvp);
    gl.bindVertexArray(guideVao);
    guideParts.forEach(function (p) {
      gl.uniform4fv(lines.u.u_colour, p.colour);
      gl.drawArrays(gl.LINES, p.first, p.count);
    });
    if (state.points) {
      gl.useProgram(points.p);
      gl.uniformMatrix4fv(points.u.u_mvp, false, m.mvp);
      gl.uniform4fv(points.u.u_scale, scaleOf(inc));
      gl.uniform1i(points.u.u_log, state.log ? 1 : 0);
      gl.uniform1i(points.u.u_mode, state.mode);
      gl.uniform1f(points.u.u_floor, inc.floor);
      gl.uniform1f(points.u.u_size, pointSize(d.n));
      gl.uniform1i(points.u.u_round, pointSize(d.n) > 3.5 ? 1 : 0);
      gl.uniform1i(points.u.u_removed, state.removed ? 1 : 0);
      gl.uniform1f(points.u.u_height, HEIGHT);
      gl.uniform3fv(points.u.u_rdbu, rdbu);
      if (moving) {
        gl.bindVertexArray(d.coarse);
        gl.drawArrays(gl.POINTS, 0, Math.floor((d.n - 1) / d.step) + 1);
      } else {
        gl.bindVertexArray(d.vao);
        gl.drawArrays(gl.POINTS, 0, d.n);
      }
    }
    if (state.surface) {
      gl.useProgram(surf.p);
      gl.uniformMatrix4fv(surf.u.u_mvp, false, m.mvp);
      gl.uniform4fv(surf.u.u_scale, scaleOf(inc));
      gl.uniform1i(surf.u.u_log, state.log ? 1 : 0);
      gl.uniform1f(surf.u.u_height, HEIGHT);
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
      gl.depthMask(false);
      d.surfaces.forEach(function (s) {
        gl.uniform1f(surf.u.u_sign, s.sign);
        gl.bindVertexArray(s.vao);
        gl.drawElements(gl.TRIANGLES, s.count, gl.UNSIGNED_INT, 0);
      });
      gl.depthMask(true);
    }
    gl.bindVertexArray(null);
    hook.draws++;
    if (!hook.ready) hook.firstDraw = performance.now();
    hook.ready = true;
    root.dataset.draws = hook.draws;
  }
  var pending = false;
  // The view is being turned, panned or zoomed: draw the coarse cloud,
  // and the whole one once it rests.
  var moving = false, rest = 0;
  function move() {
    moving = true;
    clearTimeout(rest);
    rest = setTimeout(function () { moving = false; requestDraw(); }, 200);
    requestDraw();
  }
  function requestDraw() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(function () {
      try { draw(); } catch (e) { hook.error = String(e); throw e; }
    });
  }

  // --- legend and status ------------------------------------------------------
  function fmt(v) {
    if (!isFinite(v)) return String(v);
    if (v === 0) return '0';
    var a = Math.abs(v);
    return a >= 1e4 || a < 1e-3 ? v.toExponential(2) : v.toPrecision(3).replace(/\.?0+$/, '');
  }
  function valueOf(code, inc) { return code === 0 ? 0 : Math.pow(10, inc.lo + (code - 1) / (TOP - 1) * (inc.hi - inc.lo)); }
  function updateText() {
    var inc = current.inc;
    var html;
    if (state.mode === 2) {
      var k = payload.ratio;
      var stops = payload.rdbu.map(function (c) { return 'rgb(' + c.join(',') + ')'; }).join(',');
      html = '<div>colour: model ÷ data</div><div class="bv-bar" style="background:linear-gradient(to right,' + stops +
        ')"></div><div class="bv-ends"><span>÷' + fmt(k) + '</span><span>1</span><span>×' + fmt(k) + '</span></div>';
    } else {
      html = '<div>colour: ' + MODES[state.mode][0] + ' (log)</div><div class="bv-bar" style="background:linear-gradient(to right,' +
        '#440154,#3b528b,#21918c,#5ec962,#fde725)"></div><div class="bv-ends"><span>' + fmt(Math.pow(10, inc.bottom)) +
        '</span><span>' + fmt(Math.pow(10, inc.hi)) + '</span></div>';
    }
    html += '<div>height: ' + (state.mode === 1 ? 'model' : 'data') + ', ' + (state.log ? 'log' : 'linear') + '</div>' +
      '<div><span class="bv-key" style="background:#e69a00"></span>light ' +
      '<span class="bv-key" style="background:#cc0099"></span>mirror</div>' +
      '<div><span class="bv-key" style="background:#9e9e9e;height:8px;width:8px;border-radius:4px"></span>removed by a selection</div>' +
      (state.surface ? '<div><span class="bv-key" style="background:rgba(90,100,125,0.45);height:8px"></span>surface: ' +
        esc(inc.surfaces[Math.min(state.surfaceOf, inc.surfaces.length - 1)].label) + '</div>' : '');
    legend.innerHTML = html;
    status.textContent = payload.name + ', ' + inc.label + ': ' + inc.n.toLocaleString('en') + ' samples, ' +
      inc.fitted.toLocaleString('en') + ' fitted; ' + inc.unit + '. Drag to turn, shift-drag or right-drag to pan, wheel or pinch to zoom; hover a point for its values.';
  }
  function esc(s) { return String(s).replace(/[&<>"]/g, function (c) { return { '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[c]; }); }
  function changed() { updateText(); requestDraw(); }
  function select(k) {
    free(current);
    state.incidence = k;
    current = load(k);
    loadSurface();
    buildGuides(current.inc);
    hook.incidence = k;
    changed();
  }

  // --- interaction --------------------------------------------------------------
  var pointers = {};
  var lastPinch = null;
  canvas.addEventListener('contextmenu', function (e) { e.preventDefault(); });
  canvas.addEventListener('pointerdown', function (e) {
    canvas.setPointerCapture(e.pointerId);
    pointers[e.pointerId] = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
    tip.hidden = true;
  });
  function release(e) { delete pointers[e.pointerId]; lastPinch = null; }
  canvas.addEventListener('pointerup', release);
  canvas.addEventListener('pointercancel', release);
  canvas.addEventListener('pointermove', function (e) {
    var p = pointers[e.pointerId];
    if (!p) { hoverSoon(e); return; }
    var ids = Object.keys(pointers);
    if (ids.length >= 2) {
      var a = pointers[ids[0]], b = pointers[ids[1]];
      p.x = e.clientX; p.y = e.clientY;
      var dist = Math.hypot(a.x - b.x, a.y - b.y);
      if (lastPinch) zoom(lastPinch / dist);
      lastPinch = dist;
      return;
    }
    var dx = e.clientX - p.x, dy = e.clientY - p.y;
    p.x = e.clientX; p.y = e.clientY;
    if (p.pan) {
      var m = matrix(), s = view.dist / canvas.clientHeight;
      for (var k = 0; k < 3; k++) view.pan[k] -= s * (dx * m.x[k] - dy * m.y[k]);
    } else {
      view.yaw -= dx * 0.008;
      view.pitch = Math.max(-1.5, Math.min(1.5, view.pitch + dy * 0.008));
    }
    move();
  });
  function zoom(f) { view.dist = Math.max(0.8, Math.min(15, view.dist * f)); move(); }
  canvas.addEventListener('wheel', function (e) { e.preventDefault(); zoom(Math.exp(e.deltaY * 0.001)); }, { passive: false });
  canvas.addEventListener('pointerleave', function () { tip.hidden = true; });

  // One search per frame however often the pointer moves (a search looks
  // at every sample).
  var hoverEvent = null;
  function hoverSoon(e) {
    if (hoverEvent === null) {
      requestAnimationFrame(function () { var last = hoverEvent; hoverEvent = null; hover(last); });
    }
    hoverEvent = e;
  }

  // The sample nearest the pointer on screen (within 10 px), nearest the
  // eye among equals.
  function hover(e) {
    var d = current, inc = d.inc, m = matrix().mvp;
    var rect = canvas.getBoundingClientRect();
    var px = e.clientX - rect.left, py = e.clientY - rect.top;
    var w = rect.width, h = rect.height, best = -1, bestD = 100, bestZ = 2;
    var bottom = inc.bottom, hi = inc.hi;
    for (var k = 0; k < d.n; k++) {
      var f = d.flag[k], back = f >= 128, gate = f & 127;
      if (gate && !state.removed) continue;
      var code = state.mode === 1 ? d.model[k] : d.data[k];
      var z = 0;
      if (code) {
        var lv = inc.lo + (code - 1) / (TOP - 1) * (inc.hi - inc.lo);
        z = state.log ? Math.max(0, Math.min(1, (lv - bottom) / (hi - bottom))) : Math.pow(10, lv - hi);
      }
      z *= back ? -HEIGHT : HEIGHT;
      var x = d.x[k] / 32767.5 - 1, y = d.y[k] / 32767.5 - 1;
      var cw = m[3] * x + m[7] * y + m[11] * z + m[15];
      if (cw <= 0) continue;
      var sx = ((m[0] * x + m[4] * y + m[8] * z + m[12]) / cw + 1) * 0.5 * w;
      var sy = (1 - (m[1] * x + m[5] * y + m[9] * z + m[13]) / cw) * 0.5 * h;
      var sz = (m[2] * x + m[6] * y + m[10] * z + m[14]) / cw;
      var dd = (sx - px) * (sx - px) + (sy - py) * (sy - py);
      if (dd < bestD - 1 || (dd < bestD + 1 && sz < bestZ)) { best = k; bestD = dd; bestZ = sz; }
    }
    if (best < 0) { tip.hidden = true; return; }
    var u = d.x[best] / 32767.5 - 1, v = d.y[best] / 32767.5 - 1;
    var rho = Math.min(1, Math.hypot(u, v));
    // The equal-area disk: cos θ = 1 − ρ².
    var theta = Math.acos(1 - rho * rho) * 180 / Math.PI;
    if (d.flag[best] >= 128) theta = 180 - theta;
    var phi = (Math.atan2(v, u) * 180 / Math.PI + 360) % 360;
    var data = valueOf(d.data[best], inc), model = valueOf(d.model[best], inc);
    var gate = d.flag[best] & 127;
    tip.innerHTML = 'θ_out ' + theta.toFixed(2) + '°, φ_out ' + phi.toFixed(2) + '°<br>data ' + fmt(data) +
      '<br>model ' + fmt(model) + (data > 0 ? ' (×' + fmt(model / data) + ')' : '') + '<br>' +
      (gate ? 'removed: ' + esc(inc.gates[gate - 1] || 'a selection') : 'fitted');
    tip.hidden = false;
    tip.style.left = Math.min(px + 14, w - 200) + 'px';
    tip.style.top = (py + 14) + 'px';
    hook.hovered = best;
  }
  window.addEventListener('resize', requestDraw);
  // One frame drawn and finished now, for timing the view
  // (scripts/report-open-time.py): turns the view a little first.
  hook.frame = function (turning) {
    view.yaw += 0.01;
    moving = !!turning;
    draw();
    moving = false;
    // Reading a pixel waits for the frame (finish() may not).
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  };

  try {
    select(0);
  } catch (e) {
    hook.error = String(e);
    status.textContent = 'The 3D view failed: ' + e;
    throw e;
  }
})();
