/* The report's 3-D view: each <figure data-view="3d"> gets a WebGL canvas drawn by three.js (the global THREE).
 *
 * Its data is the JSON in the figure's <script type="application/json"> (affinity/report/scene3d.py): typed
 * arrays in base64, findings, rule facts. Nothing from it becomes markup: text goes in with textContent.
 * Modes: "split" (two triangles 0-1-2, 0-2-3, as a GPU draws the quad), "exact" (per fragment: where the view ray
 * meets the quad's bilinear patch, on a planar quad its plane, the patch's (s, t) and the corners' values
 * interpolated bilinearly there, as render/'s `exact`) and "difference" (|split - exact| in the lint's unit). window.affinityViews lists the views for scripting (and the tests). */
(function () {
  "use strict";
  var MODES = ["split", "exact", "difference"];
  var KEYS = { s: "split", e: "exact", d: "difference" };
  var TEXELS_PER_QUAD = 8;
  var DATA_WIDTH = 4096;
  var FLY_FILL = 0.4;
  var CLIP_RADII = 2;

  function bytes(b64) {
    if (Uint8Array.fromBase64) { return Uint8Array.fromBase64(b64); }
    var text = atob(b64), out = new Uint8Array(text.length);
    for (var i = 0; i < text.length; i++) { out[i] = text.charCodeAt(i); }
    return out;
  }
  function typed(b64, Type) { var raw = bytes(b64); return new Type(raw.buffer, raw.byteOffset, raw.byteLength / Type.BYTES_PER_ELEMENT); }

  var VERTEX = [
    "uniform highp sampler2D quadData;",
    "in vec2 corner;",
    "out vec3 vWorld;",
    "out vec3 vSplit;",
    "flat out int vQuad;",
    "vec4 fetch(int quad, int k) { int i = quad * " + TEXELS_PER_QUAD + " + k;",
    "  return texelFetch(quadData, ivec2(i % " + DATA_WIDTH + ", i / " + DATA_WIDTH + "), 0); }",
    "void main() {",
    "  vQuad = int(corner.x + 0.5);",
    "  vSplit = fetch(vQuad, 4 + int(corner.y + 0.5)).xyz;",
    "  vec4 world = modelMatrix * vec4(position, 1.0);",
    "  vWorld = world.xyz;",
    "  gl_Position = projectionMatrix * viewMatrix * world;",
    "}"
  ].join("\n");

  var FRAGMENT = [
    "precision highp float;",
    "uniform highp sampler2D quadData;",
    "uniform sampler2D map;",
    "uniform int mode;", /* 0 split, 1 exact, 2 difference, 3 face ids */
    "uniform int look;", /* 0 uv pattern, 1 texture, 2 colour, 3 shaded normals, 4 raw values */
    "uniform int kind;", /* 0 uv, 1 colour, 2 normal: how a difference is measured */
    "uniform vec2 texels;", /* the texture's size, for the texel unit */
    "uniform float visible;", /* the difference drawn full red: the rule's visibility threshold */
    "in vec3 vWorld;",
    "in vec3 vSplit;",
    "flat in int vQuad;",
    "out vec4 outColour;",
    "vec4 fetch(int k) { int i = vQuad * " + TEXELS_PER_QUAD + " + k;",
    "  return texelFetch(quadData, ivec2(i % " + DATA_WIDTH + ", i / " + DATA_WIDTH + "), 0); }",
    "float cross2(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }",
    /* (s, t) with x = (1-s)(1-t) a + s(1-t) b + s t c + (1-s) t d (Quilez's inverse bilinear; the root of the
       quadratic in t taken stably, the one nearer [0, 1]). */
    "vec2 sGivenT(vec2 e, vec2 f, vec2 g, vec2 h, float t) {",
    "  vec2 across = e + g * t, rest = h - f * t;",
    "  return vec2(abs(across.x) >= abs(across.y) ? rest.x / across.x : rest.y / across.y, t);",
    "}",
    "float outside(vec2 st) { vec2 d = max(abs(st - 0.5) - 0.5, 0.0); return d.x + d.y; }",
    "vec2 inverseBilinear(vec2 x, vec2 a, vec2 b, vec2 c, vec2 d) {",
    "  vec2 e = b - a, f = d - a, g = a - b + c - d, h = x - a;",
    "  float k2 = cross2(g, f), k1 = cross2(e, f) + cross2(h, g), k0 = cross2(h, e);",
    "  if (abs(k2) <= 1e-7 * abs(k1)) { return sGivenT(e, f, g, h, -k0 / k1); }",
    "  float w = sqrt(max(k1 * k1 - 4.0 * k0 * k2, 0.0));",
    "  float q = -0.5 * (k1 + (k1 < 0.0 ? -w : w));",
    "  vec2 one = sGivenT(e, f, g, h, q / k2), other = sGivenT(e, f, g, h, k0 / q);",
    "  return outside(one) <= outside(other) ? one : other;",
    "}",
    /* The view ray meets the bilinear patch P(s, t) of the quad's corners where the corners, projected along
       the ray onto a plane across it (about the fragment's point on the split, for precision), have the ray's
       trace (the origin) at (s, t): render/patch.py's ray / patch intersection; on a planar quad, the point
       where the ray meets its plane. */
    "vec3 exactValue() {",
    "  vec3 p0 = fetch(0).xyz, p1 = fetch(1).xyz, p2 = fetch(2).xyz, p3 = fetch(3).xyz;",
    "  vec3 ray = normalize(vWorld - cameraPosition);",
    "  vec3 side = abs(ray.x) < 0.6 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);",
    "  vec3 u = normalize(cross(ray, side)), v = cross(ray, u);",
    "  mat2x3 across = mat2x3(u, v);",
    "  vec2 st = inverseBilinear(vec2(0.0), (p0 - vWorld) * across, (p1 - vWorld) * across,",
    "                           (p2 - vWorld) * across, (p3 - vWorld) * across);",
    "  if (any(isnan(st)) || any(isinf(st))) { return vSplit; }",
    "  vec3 a0 = fetch(4).xyz, a1 = fetch(5).xyz, a2 = fetch(6).xyz, a3 = fetch(7).xyz;",
    "  return mix(mix(a0, a1, st.x), mix(a3, a2, st.x), st.y);",
    "}",
    "float difference(vec3 a, vec3 b) {",
    "  if (kind == 0) { return length((a.xy - b.xy) * texels); }",
    "  if (kind == 1) { return length(a - b) * 255.0; }",
    "  return degrees(atan(length(cross(a, b)), dot(a, b)));",
    "}",
    "vec3 heat(float x) {", /* white, yellow, red, dark red */
    "  x = clamp(x, 0.0, 1.0);",
    "  return x < 0.5 ? mix(vec3(0.93), vec3(1.0, 0.85, 0.1), x * 2.0) : mix(vec3(1.0, 0.85, 0.1), vec3(0.75, 0.0, 0.1), x * 2.0 - 1.0);",
    "}",
    "float gridLines(vec2 uv) {", /* lines about 14 px apart at any zoom: two power-of-two levels blended */
    "  vec2 width = max(fwidth(uv), vec2(1e-9));",
    "  float level = log2(max(width.x, width.y) * 14.0);",
    "  float low = floor(level), blend = level - low, ink = 0.0;",
    "  for (int k = 0; k < 2; k++) {",
    "    float spacing = exp2(low + float(k));",
    "    vec2 g = uv / spacing, d = abs(fract(g - 0.5) - 0.5) / (width / spacing);",
    "    float line = 1.0 - clamp(min(d.x, d.y) - 0.5, 0.0, 1.0);",
    "    ink = max(ink, line * (k == 0 ? 1.0 - blend : 1.0));",
    "  }",
    "  return ink * clamp(-level, 0.0, 1.0);", /* lines a uv unit apart are face edges (per-face uv): fade them */
    "}",
    "vec3 appearance(vec3 a, float light) {",
    "  if (look == 4) { return kind == 0 ? vec3(fract(a.xy), 0.0) : kind == 1 ? a : normalize(a) * 0.5 + 0.5; }",
    "  if (look == 1) { return texture(map, a.xy).rgb * light; }",
    "  if (look == 2) { return a; }",
    "  if (look == 3) {",
    "    vec3 n = normalize(a), toEye = normalize(cameraPosition - vWorld);",
    "    float lambert = abs(dot(n, toEye));",
    "    return vec3(0.62, 0.66, 0.72) * (0.25 + 0.75 * lambert) + vec3(0.35) * pow(lambert, 48.0);",
    "  }",
    "  vec3 base = mix(vec3(0.86, 0.88, 0.92), vec3(0.95, 0.93, 0.86), fract(a.x) * 0.5 + fract(a.y) * 0.5);",
    "  return mix(base * light, vec3(0.1, 0.18, 0.45), gridLines(a.xy));",
    "}",
    "void main() {",
    "  if (mode == 3) {",
    "    int face = int(fetch(0).w + 0.5) + 1;",
    "    outColour = vec4(float(face & 255), float((face >> 8) & 255), float((face >> 16) & 255), 255.0) / 255.0;",
    "    return;",
    "  }",
    "  vec3 facing = normalize(cross(dFdx(vWorld), dFdy(vWorld)));",
    "  float light = 0.8 + 0.2 * abs(dot(facing, normalize(cameraPosition - vWorld)));",
    "  if (mode == 2) {",
    "    float error = difference(vSplit, exactValue());",
    "    outColour = vec4(heat(error / visible) * light, 1.0);",
    "    return;",
    "  }",
    "  outColour = vec4(appearance(mode == 1 ? exactValue() : vSplit, light), 1.0);",
    "}"
  ].join("\n");

  /* The world axis the camera keeps up, or, looking along it, the other axis most across the view
     (affinity.draw.framing.working_up). */
  var AXES = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] };
  function workingUp(forward, axis) {
    var up = new THREE.Vector3().fromArray(AXES[axis]);
    if (new THREE.Vector3().crossVectors(forward, up).length() > 1e-6) { return up; }
    var best = null;
    ["z", "y", "x"].filter(function (a) { return a !== axis; }).forEach(function (a) {
      var v = new THREE.Vector3().fromArray(AXES[a]);
      if (best === null || Math.abs(forward.dot(v)) < Math.abs(forward.dot(best))) { best = v; }
    });
    return best;
  }

  function View(figure, index) {
    var data = JSON.parse(figure.querySelector("script[type='application/json']").textContent);
    this.figure = figure;
    this.index = Number(figure.dataset.file || index);
    this.data = data;
    this.status = figure.querySelector(".view3d-status");
    this.mode = "split";
    this.raw = false;
    this.grid = false;
    this.clip = null;
    this.selected = null;
    this.build();
  }

  View.prototype.build = function () {
    var data = this.data, quads = data.quads;
    var positions = typed(data.positions, Float32Array);
    var corners = typed(data.corners, Uint32Array);
    this.faces = typed(data.faces, Uint32Array);
    this.levels = typed(data.levels, Uint8Array);
    this.corners = corners;
    this.positions = positions;
    this.canvas = this.figure.querySelector("canvas");
    this.renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: false, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(1);
    this.renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(1, 1, 1);

    var rows = Math.max(1, Math.ceil(quads * TEXELS_PER_QUAD / DATA_WIDTH));
    this.quadData = new Float32Array(rows * DATA_WIDTH * 4);
    var triangles = [0, 1, 2, 0, 2, 3];
    var vertexPositions = new Float32Array(quads * 18), cornerSlots = new Float32Array(quads * 12);
    for (var q = 0; q < quads; q++) {
      for (var k = 0; k < 4; k++) {
        var v = corners[q * 4 + k], at = (q * TEXELS_PER_QUAD + k) * 4;
        this.quadData[at] = positions[v * 3];
        this.quadData[at + 1] = positions[v * 3 + 1];
        this.quadData[at + 2] = positions[v * 3 + 2];
      }
      this.quadData[(q * TEXELS_PER_QUAD) * 4 + 3] = this.faces[q];
      for (var j = 0; j < 6; j++) {
        var c = triangles[j], w = corners[q * 4 + c];
        vertexPositions.set(positions.subarray(w * 3, w * 3 + 3), (q * 6 + j) * 3);
        cornerSlots[(q * 6 + j) * 2] = q;
        cornerSlots[(q * 6 + j) * 2 + 1] = c;
      }
    }
    this.dataTexture = new THREE.DataTexture(this.quadData, DATA_WIDTH, rows, THREE.RGBAFormat, THREE.FloatType);
    this.dataTexture.needsUpdate = true;
    var geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.BufferAttribute(vertexPositions, 3));
    geometry.setAttribute("corner", new THREE.BufferAttribute(cornerSlots, 2));
    geometry.computeBoundingSphere();
    this.bounds = geometry.boundingSphere;
    geometry.computeBoundingBox();
    var size = geometry.boundingBox.getSize(new THREE.Vector3());
    this.extent = Math.max(size.x, size.y, size.z) || 1;

    this.uniforms = {
      quadData: { value: this.dataTexture }, map: { value: null }, mode: { value: 0 }, look: { value: 0 },
      kind: { value: 0 }, texels: { value: new THREE.Vector2(1024, 1024) }, visible: { value: 1 }
    };
    this.material = new THREE.ShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: VERTEX, fragmentShader: FRAGMENT, uniforms: this.uniforms,
      side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1
    });
    this.mesh = new THREE.Mesh(geometry, this.material);
    this.mesh.frustumCulled = false;
    this.scene.add(this.mesh);
    this.outlines = this.outlineMesh();
    this.scene.add(this.outlines);
    this.selection = new THREE.LineSegments(new THREE.BufferGeometry(),
                                            new THREE.LineBasicMaterial({ color: 0x1d4ed8, depthTest: false }));
    this.selection.frustumCulled = false;
    this.scene.add(this.selection);
    this.camera = new THREE.PerspectiveCamera(40, 4 / 3, 0.01, 100);
    this.loadTexture();
    this.chooseAttribute(this.firstAttribute());
    this.buildControls();
    this.buildTable();
    this.fitCanvas();
    this.setCamera(data.camera);
    this.fromUrl();
    this.renderer.getContext().readPixels(0, 0, 1, 1, 0x1908, 0x1401, new Uint8Array(4)); /* RGBA, UNSIGNED_BYTE */
    this.firstFrame = performance.now(); /* ms from the page's navigation, the first frame drawn and read */
    var view = this;
    window.addEventListener("resize", function () { view.fitCanvas(); view.render(); });
    window.addEventListener("hashchange", function () { view.fromUrl(); });
  };

  View.prototype.firstAttribute = function () {
    var names = this.data.attributes.map(function (a) { return a.name; });
    var worst = this.data.findings.find(function (row) { return row.attribute && names.indexOf(row.attribute) >= 0; });
    return worst ? worst.attribute : names[0];
  };

  /* Edges of the flagged render quads, each in the colour of its face's worst finding's level. */
  View.prototype.outlineMesh = function () {
    var data = this.data, flagged = 0, q, k, e;
    var colourOf = data.levels_order.map(function (level) { return new THREE.Color(data.level_colours[level]); });
    for (q = 0; q < data.quads; q++) { if (this.levels[q]) { flagged++; } }
    var points = new Float32Array(flagged * 24), colours = new Float32Array(flagged * 24), at = 0;
    for (q = 0; q < data.quads; q++) {
      if (!this.levels[q]) { continue; }
      var colour = colourOf[this.levels[q] - 1];
      for (k = 0; k < 4; k++) {
        for (e = 0; e < 2; e++) {
          var v = this.corners[q * 4 + (k + e) % 4];
          points.set(this.positions.subarray(v * 3, v * 3 + 3), at);
          colours[at] = colour.r; colours[at + 1] = colour.g; colours[at + 2] = colour.b;
          at += 3;
        }
      }
    }
    var geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.BufferAttribute(points, 3));
    geometry.setAttribute("color", new THREE.BufferAttribute(colours, 3));
    var lines = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: true }));
    lines.frustumCulled = false;
    return lines;
  };

  /* Decode the embedded texture; ``this.ready`` settles once it is drawn with it (at once without one). */
  View.prototype.loadTexture = function () {
    var texture = this.data.texture, view = this, done;
    this.ready = new Promise(function (resolve) { done = resolve; });
    if (!texture) { done(); return; }
    var image = new Image();
    image.onerror = function () { view.say("the embedded texture could not be decoded: drawing uv as grid lines"); done(); };
    image.onload = function () {
      var map = new THREE.Texture(image);
      map.colorSpace = THREE.NoColorSpace;
      map.wrapS = map.wrapT = THREE.RepeatWrapping;
      map.minFilter = THREE.LinearMipmapLinearFilter;
      map.anisotropy = view.renderer.capabilities.getMaxAnisotropy();
      map.needsUpdate = true;
      view.uniforms.map.value = map;
      view.chooseAttribute(view.attribute.name);
      view.render();
      done();
    };
    image.src = texture.uri;
  };

  /* Put one attribute's corner values in the quads' data texture and pick how it is drawn. */
  View.prototype.chooseAttribute = function (name) {
    var attribute = this.data.attributes.find(function (a) { return a.name === name; }) || this.data.attributes[0];
    if (!attribute) { return; }
    this.attribute = attribute;
    var values = typed(attribute.values, Float32Array), width = attribute.width;
    for (var q = 0; q < this.data.quads; q++) {
      for (var k = 0; k < 4; k++) {
        var at = (q * TEXELS_PER_QUAD + 4 + k) * 4, from = (q * 4 + k) * width;
        for (var c = 0; c < 3; c++) { this.quadData[at + c] = c < width ? values[from + c] : 0; }
      }
    }
    this.dataTexture.needsUpdate = true;
    var kind = { uv: 0, color: 1, normal: 2 }[attribute.name];
    this.uniforms.kind.value = kind;
    this.uniforms.visible.value = attribute.visible || 1;
    var texture = this.data.texture;
    if (kind === 0 && texture) { this.uniforms.texels.value.set(texture.width, texture.height); }
    this.look = kind === 0 ? (this.uniforms.map.value && !this.grid ? 1 : 0) : kind === 1 ? 2 : 3;
    this.updateButtons();
  };

  /* uv drawn with the texture or as grid lines (which show a crease where the texture is flat). */
  View.prototype.setGrid = function (grid) {
    this.grid = grid;
    this.chooseAttribute(this.attribute.name);
    this.render();
  };

  View.prototype.buildControls = function () {
    var view = this, bar = this.figure.querySelector(".view3d-modes");
    this.buttons = {};
    MODES.forEach(function (mode) {
      var button = document.createElement("button");
      button.type = "button";
      button.textContent = mode;
      button.title = { split: "what the GPU draws: two triangles (key s)",
                       exact: "what the quad means: bilinear in its own (s, t) (key e)",
                       difference: "|split - exact| in the lint's unit (key d)" }[mode];
      button.addEventListener("click", function () { view.setMode(mode); });
      bar.appendChild(button);
      view.buttons[mode] = button;
    });
    if (this.data.texture) {
      var grid = document.createElement("button");
      grid.type = "button";
      grid.className = "grid";
      grid.textContent = "uv grid";
      grid.title = "uv as grid lines instead of the texture (key g)";
      grid.addEventListener("click", function () { view.setGrid(!view.grid); });
      bar.appendChild(grid);
      this.buttons.grid = grid;
    }
    if (this.data.attributes.length > 1) {
      this.data.attributes.forEach(function (a) {
        var button = document.createElement("button");
        button.type = "button";
        button.className = "attribute";
        button.textContent = a.name;
        button.addEventListener("click", function () { view.chooseAttribute(a.name); view.render(); });
        bar.appendChild(button);
        view.buttons["attribute " + a.name] = button;
      });
    }
    var canvas = this.canvas;
    canvas.tabIndex = 0;
    canvas.addEventListener("keydown", function (event) {
      if (KEYS[event.key]) { view.setMode(KEYS[event.key]); event.preventDefault(); }
      if (event.key === "g" && view.data.texture) { view.setGrid(!view.grid); }
      if (event.key === " ") { view.setMode(view.mode === "split" ? "exact" : "split"); event.preventDefault(); }
    });
    var drag = null;
    canvas.addEventListener("contextmenu", function (event) { event.preventDefault(); });
    canvas.addEventListener("pointerdown", function (event) {
      drag = { x: event.clientX, y: event.clientY, pan: event.button !== 0 || event.shiftKey, moved: 0 };
      view.flight = null;
      canvas.setPointerCapture(event.pointerId);
    });
    canvas.addEventListener("pointermove", function (event) {
      if (!drag) { return; }
      var dx = event.clientX - drag.x, dy = event.clientY - drag.y;
      drag.x = event.clientX; drag.y = event.clientY; drag.moved += Math.abs(dx) + Math.abs(dy);
      if (drag.pan) { view.pan(dx, dy); } else { view.orbit(dx, dy); }
    });
    canvas.addEventListener("pointerup", function (event) {
      if (drag && drag.moved < 3) { view.pick(event); }
      if (drag && drag.moved >= 3) { view.toUrl(); }
      drag = null;
    });
    canvas.addEventListener("wheel", function (event) {
      event.preventDefault();
      view.flight = null;
      view.dolly(Math.exp(event.deltaY * 0.001));
    }, { passive: false });
  };

  View.prototype.updateButtons = function () {
    if (!this.buttons) { return; }
    for (var key in this.buttons) {
      var on = key === this.mode || key === "attribute " + this.attribute.name || (key === "grid" && this.grid);
      this.buttons[key].setAttribute("aria-pressed", on ? "true" : "false");
    }
  };

  View.prototype.setMode = function (mode) {
    this.mode = mode;
    this.updateButtons();
    if (mode === "difference") {
      var a = this.attribute;
      this.say("|split - exact| in " + a.unit + ": white 0, yellow " + (a.visible || 1) / 2 + ", red " + (a.visible || 1) +
               " (the " + a.name + " visibility threshold) and above");
    }
    this.render();
  };

  View.prototype.buildTable = function () {
    var view = this, body = this.figure.querySelector(".view3d-findings tbody");
    if (this.data.prims) {  /* USD: "face" counts within the prim, the group is the prim, and no line column */
      var heads = this.figure.querySelectorAll(".view3d-findings thead th");
      heads[4].textContent = "prim";
      heads[5].remove();
    }
    this.data.findings.forEach(function (row) {
      var tr = document.createElement("tr");
      tr.tabIndex = 0;
      tr.dataset.shows = String(row.face);
      var value = Number(row.value).toPrecision(3) + " " + row.unit;
      /* A USD row shows the prim and the face within it, as check prints them; it has no source line. */
      var cells = row.prim === undefined ? [row.level, row.code, String(row.face), value, row.group, String(row.line)]
        : [row.level, row.code, String(row.prim_face), value, row.prim];
      cells.forEach(function (text, k) {
        var td = document.createElement("td");
        td.textContent = text;
        if (k === 0) { td.className = "level " + row.level; }
        tr.appendChild(td);
      });
      tr.title = row.name;
      var go = function () { view.showFinding(row); };
      tr.addEventListener("click", go);
      tr.addEventListener("keydown", function (event) { if (event.key === "Enter") { go(); } });
      body.appendChild(tr);
    });
  };

  View.prototype.showFinding = function (row, animate) {
    if (row.attribute && row.attribute !== this.attribute.name &&
        this.data.attributes.some(function (a) { return a.name === row.attribute; })) {
      this.chooseAttribute(row.attribute);
    }
    this.flyTo(row.face, animate !== false);
  };

  View.prototype.fitCanvas = function () {
    var width = Math.max(240, Math.round(this.canvas.parentElement.clientWidth));
    this.setSize(width, Math.round(width * 0.75));
  };

  View.prototype.setSize = function (width, height) {
    this.renderer.setSize(width, height, true);
    this.camera.aspect = width / height;
    this.updateProjection();
  };

  /* eye, target, vertical fov in degrees: ``affinity render --camera EX,EY,EZ,TX,TY,TZ,FOV``. */
  View.prototype.setCamera = function (values) {
    this.eye = new THREE.Vector3(values[0], values[1], values[2]);
    this.target = new THREE.Vector3(values[3], values[4], values[5]);
    this.camera.fov = values[6];
    this.updateProjection();
    this.render();
  };

  /* The projection of affinity.draw.framing.camera_for: far = distance + 2 max(extent, distance), near 1e-4 far;
     after a flight to a face, near is moved up to ``clip`` before the target, so what lies between the eye and
     the face (lips before a tongue, a car's body before its seats) is cut away while the view turns about it. */
  View.prototype.updateProjection = function () {
    if (!this.eye) { return; }
    var distance = this.eye.distanceTo(this.target), forward = this.target.clone().sub(this.eye).normalize();
    this.camera.far = distance + 2 * Math.max(this.extent, distance);
    this.camera.near = Math.max(this.camera.far * 1e-4, this.clip ? distance - this.clip : 0);
    this.camera.position.copy(this.eye);
    this.camera.up.copy(workingUp(forward, this.data.up));
    this.camera.lookAt(this.target);
    this.camera.updateProjectionMatrix();
    this.camera.updateMatrixWorld();
  };

  View.prototype.orbit = function (dx, dy) {
    var up = new THREE.Vector3().fromArray(AXES[this.data.up]), offset = this.eye.clone().sub(this.target);
    offset.applyAxisAngle(up, -dx * 0.008);
    var right = new THREE.Vector3().crossVectors(offset, up);
    if (right.lengthSq() > 0) {
      var turned = offset.clone().applyAxisAngle(right.normalize(), dy * 0.008);
      if (Math.abs(turned.clone().normalize().dot(up)) < 0.999) { offset = turned; }
    }
    this.eye.copy(this.target).add(offset);
    this.updateProjection();
    this.render();
  };

  View.prototype.pan = function (dx, dy) {
    this.clip = null;
    var distance = this.eye.distanceTo(this.target);
    var scale = 2 * distance * Math.tan(THREE.MathUtils.degToRad(this.camera.fov) / 2) / this.canvas.height;
    var right = new THREE.Vector3().setFromMatrixColumn(this.camera.matrixWorld, 0);
    var up = new THREE.Vector3().setFromMatrixColumn(this.camera.matrixWorld, 1);
    var move = right.multiplyScalar(-dx * scale).add(up.multiplyScalar(dy * scale));
    this.eye.add(move);
    this.target.add(move);
    this.updateProjection();
    this.render();
  };

  View.prototype.dolly = function (factor) {
    this.eye.copy(this.target).add(this.eye.clone().sub(this.target).multiplyScalar(factor));
    this.updateProjection();
    this.render();
    this.toUrl();
  };

  /* The face's render quads: centre, area-weighted normal (corner order's side) and radius. */
  View.prototype.faceGeometry = function (face) {
    var centre = new THREE.Vector3(), normal = new THREE.Vector3(), points = [], area = 0;
    for (var q = 0; q < this.data.quads; q++) {
      if (this.faces[q] !== face) { continue; }
      var p = [0, 1, 2, 3].map(function (k) {
        var v = this.corners[q * 4 + k];
        return new THREE.Vector3(this.positions[v * 3], this.positions[v * 3 + 1], this.positions[v * 3 + 2]);
      }, this);
      var doubled = new THREE.Vector3().crossVectors(p[2].clone().sub(p[0]), p[3].clone().sub(p[1]));
      normal.add(doubled);
      area += doubled.length() / 2;
      points.push.apply(points, p);
    }
    if (!points.length) { return null; }
    points.forEach(function (p) { centre.add(p); });
    centre.multiplyScalar(1 / points.length);
    var radius = Math.max.apply(null, points.map(function (p) { return p.distanceTo(centre); })) || this.extent * 0.01;
    /* A sliver framed whole would be a hairline: it is framed on the side of a square of its area instead,
       so it covers about as many pixels as a compact face (its long ends may leave the view). */
    return { centre: centre, normal: normal.lengthSq() > 0 ? normal.normalize() : new THREE.Vector3(0, 0, 1),
             radius: radius, size: Math.min(radius, Math.sqrt(area)) || radius };
  };

  /* Fly to a face so it fills about FLY_FILL of the view's height, looking along its normal from the side
     where more of it shows (the face id pass decides: an inward face is seen from inside). */
  View.prototype.flyTo = function (face, animate) {
    var place = this.faceGeometry(face);
    if (!place) { this.say("face " + face + " is not in this view (left out to keep the page small)"); return false; }
    this.select(face);
    this.clip = CLIP_RADII * place.radius;
    var distance = place.size / Math.tan(THREE.MathUtils.degToRad(this.camera.fov) / 2) / FLY_FILL;
    /* Along the normal from either side, then tilted 40 degrees four ways from each (a face in a hollow, a
       leg's inside, shows better at a slant); the id pass counts its pixels from each. */
    var across = new THREE.Vector3().crossVectors(place.normal, Math.abs(place.normal.x) < 0.9 ?
      new THREE.Vector3(1, 0, 0) : new THREE.Vector3(0, 1, 0)).normalize();
    var other = new THREE.Vector3().crossVectors(place.normal, across);
    var directions = [];
    [1, -1].forEach(function (sign) {
      var along = place.normal.clone().multiplyScalar(sign);
      directions.push(along);
      [across, other].forEach(function (t) {
        [1, -1].forEach(function (tilt) { directions.push(along.clone().addScaledVector(t, tilt * 0.84).normalize()); });
      });
    });
    var best = null;
    directions.forEach(function (direction) {
      this.eye = place.centre.clone().addScaledVector(direction, distance); this.target = place.centre.clone();
      this.updateProjection();
      var shown = this.facePixels(face);
      if (best === null || shown > best.shown) { best = { shown: shown, eye: this.eye, target: this.target }; }
    }, this);
    var start = this.previous || { eye: best.eye, target: best.target }, flight = this.flight = {};
    this.say("face " + face);
    if (!animate) { this.eye = best.eye; this.target = best.target; this.updateProjection(); this.render(); this.toUrl(); return true; }
    var view = this, began = performance.now();
    var step = function (now) {
      if (view.flight !== flight) { return; }
      var k = Math.min(1, (now - began) / 450), ease = k * k * (3 - 2 * k);
      view.eye = start.eye.clone().lerp(best.eye, ease);
      view.target = start.target.clone().lerp(best.target, ease);
      view.updateProjection();
      view.render();
      if (k < 1) { requestAnimationFrame(step); } else { view.toUrl(); }
    };
    this.eye = start.eye; this.target = start.target;
    requestAnimationFrame(step);
    return true;
  };

  /* Mark ``face`` (its render quads' edges, drawn over everything) and its rows in the table. */
  View.prototype.select = function (face) {
    this.selected = face;
    var points = [];
    for (var q = 0; q < this.data.quads; q++) {
      if (this.faces[q] !== face) { continue; }
      for (var k = 0; k < 4; k++) {
        for (var e = 0; e < 2; e++) {
          var v = this.corners[q * 4 + (k + e) % 4];
          points.push(this.positions[v * 3], this.positions[v * 3 + 1], this.positions[v * 3 + 2]);
        }
      }
    }
    this.selection.geometry.dispose();
    this.selection.geometry = new THREE.BufferGeometry();
    this.selection.geometry.setAttribute("position", new THREE.Float32BufferAttribute(points, 3));
    this.figure.querySelectorAll(".view3d-findings tr[data-shows]").forEach(function (tr) {
      tr.classList.toggle("selected", tr.dataset.shows === String(face));
    });
  };

  View.prototype.say = function (text) { if (this.status) { this.status.textContent = text; } };

  View.prototype.draw = function (mode, raw) {
    this.uniforms.mode.value = mode === "faces" ? 3 : MODES.indexOf(mode);
    this.uniforms.look.value = raw ? 4 : this.look;
    this.outlines.visible = this.selection.visible = mode !== "faces" && !raw;
    this.renderer.render(this.scene, this.camera);
  };

  View.prototype.render = function () {
    if (!this.eye) { return; }
    this.draw(this.mode, this.raw);
    this.previous = { eye: this.eye.clone(), target: this.target.clone() };
  };

  /* Pixels showing ``face`` in the face id pass (the canvas is redrawn in the current mode afterwards). */
  View.prototype.facePixels = function (face) {
    var gl = this.renderer.getContext(), width = this.canvas.width, height = this.canvas.height;
    this.draw("faces", false);
    var pixels = new Uint8Array(width * height * 4), count = 0, id = face + 1;
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    for (var i = 0; i < pixels.length; i += 4) {
      if (pixels[i] + pixels[i + 1] * 256 + pixels[i + 2] * 65536 === id) { count++; }
    }
    return count;
  };

  /* The canvas in ``mode`` ("split", "exact", "difference" or "faces"), raw values or not, as a PNG data URL. */
  View.prototype.snapshot = function (mode, raw) {
    this.draw(mode, raw);
    var url = this.canvas.toDataURL("image/png");
    this.render();
    return url;
  };

  View.prototype.pick = function (event) {
    var box = this.canvas.getBoundingClientRect(), gl = this.renderer.getContext();
    var x = Math.floor((event.clientX - box.left) * this.canvas.width / box.width);
    var y = this.canvas.height - 1 - Math.floor((event.clientY - box.top) * this.canvas.height / box.height);
    this.draw("faces", false);
    var pixel = new Uint8Array(4);
    gl.readPixels(x, y, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    this.render();
    var face = pixel[0] + pixel[1] * 256 + pixel[2] * 65536 - 1;
    if (face >= 0 && pixel[3] === 255 && !(pixel[0] === 255 && pixel[1] === 255 && pixel[2] === 255)) {
      var rows = this.data.findings.filter(function (row) { return row.face === face; });
      this.select(face);
      this.say(this.faceInUrl(face).replace("prim=", "prim ").replace("&face=", " face ").replace("face=", "face ") +
               (rows.length ? ": " + rows.map(function (r) {
        return r.code + " " + r.name + " " + Number(r.value).toPrecision(3) + " " + r.unit;
      }).join("; ") : ": not flagged"));
      this.toUrl();
    }
  };

  View.prototype.cameraText = function () {
    return this.eye.toArray().concat(this.target.toArray(), [this.camera.fov]).map(function (x) {
      return Number(x.toPrecision(9));
    }).join(",");
  };

  View.prototype.toUrl = function () {
    var parts = [];
    if (document.querySelectorAll("figure[data-view='3d']").length > 1) { parts.push("file=" + this.index); }
    if (this.selected !== null) { parts.push(this.faceInUrl(this.selected)); }
    parts.push("camera=" + this.cameraText());
    this.ownHash = "#" + parts.join("&");
    history.replaceState(null, "", this.ownHash);
  };

  /* The page's face ``face`` as a URL names it: "face=F", or for a USD stage "prim=/A/B&face=F", F within the
     prim (as check prints it). */
  View.prototype.faceInUrl = function (face) {
    var prims = this.data.prims;
    if (!prims) { return "face=" + face; }
    var p = prims.starts.length - 2;
    while (p > 0 && prims.starts[p] > face) { p -= 1; }
    return "prim=" + encodeURI(prims.names[p]) + "&face=" + (face - prims.starts[p]);
  };

  /* #face=F opens on face F (with #prim=/A/B, F counts within that prim of a USD stage), #camera=EX,EY,EZ,TX,TY,
     TZ,FOV on that camera (both: the face selected, the camera as given); #file=I picks the I-th view (0-based)
     of a multi-file report. */
  View.prototype.fromUrl = function () {
    if (location.hash === this.ownHash) { return; }
    var params = new URLSearchParams(location.hash.slice(1)), file = Number(params.get("file") || 0);
    if (file !== this.index) { return; }
    var face = params.get("face"), camera = params.get("camera"), prim = params.get("prim");
    if (face !== null && /^\d+$/.test(face) && prim !== null && this.data.prims) {
      var p = this.data.prims.names.indexOf(prim);
      face = p < 0 || Number(face) >= this.data.prims.starts[p + 1] - this.data.prims.starts[p] ? null :
        String(this.data.prims.starts[p] + Number(face));
    }
    if (face !== null && /^\d+$/.test(face)) {
      var rows = this.data.findings.filter(function (row) { return row.face === Number(face); });
      if (rows.length) { this.showFinding(rows[0]); } else { this.flyTo(Number(face), false); }
    }
    if (camera !== null) {
      var values = camera.split(",").map(Number);
      if (values.length === 7 && values.every(isFinite) && values[6] > 0 && values[6] < 180) { this.setCamera(values); }
    }
    if (face !== null || camera !== null) { this.figure.scrollIntoView(); }
    this.render();
  };

  function webgl2() {
    try { return !!document.createElement("canvas").getContext("webgl2"); } catch (error) { return false; }
  }

  window.affinityViews = [];
  document.querySelectorAll("figure[data-view='3d']").forEach(function (figure, index) {
    if (!webgl2()) {
      figure.querySelector(".view3d-status").textContent =
        "this browser offers no WebGL 2, so the 3-D view cannot be drawn; the pictures below show the same places";
      return;
    }
    try {
      window.affinityViews.push(new View(figure, index));
    } catch (error) {
      figure.querySelector(".view3d-status").textContent = "the 3-D view could not be drawn: " + error.message;
    }
  });
})();
