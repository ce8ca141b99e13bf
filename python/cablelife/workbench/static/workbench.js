/* cablelife workbench page: the scene in 3D (three.js r111, served by the workbench), clips
   dragged with TransformControls, every move solved by the server (websocket), the cables
   drawn as tubes coloured by a section quantity. Test hook: window.cablelifeWorkbench. */
(function () {
  "use strict";
  var G = 12; // vertices around the tube
  var STOPS = ["#30123b", "#4669db", "#26bce1", "#3ff393", "#c3f133", "#fca50a", "#e4460a", "#7a0403"];
  var info = null, live = null, shown = null, playing = null;
  var quantity = "bending";
  var renderer, scene, camera, orbit, gizmo, dirty = true;
  var tubes = {}, clipObjects = {}, bodyMeshes = {}, junctionObjects = {}, bodyObjects = {}, selected = null;
  var ws, nextId = 1, waiting = {}, inflight = false, pending = null, dragMark = false, idleWaiters = [];
  var updateTimes = [], frameTimes = [], lastSolveMs = 0;
  var statusText = "";

  function $(id) { return document.getElementById(id); }
  function fmt(v, d) {
    if (v === null || v === undefined) return "–";
    return Math.abs(v) < 1e-9 ? "0" : Number(v).toPrecision(d || 4); // round-off shown as 0
  }
  function esc(s) { return String(s).replace(/[&<>"]/g, function (c) { return {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;"}[c]; }); }

  function showMessage(text, isError) {
    var m = $("message");
    m.textContent = text || "";
    m.className = text ? (isError ? "" : "info") : "hidden";
    m.style.background = isError ? "#fff0f0" : "#f0f7ff";
    m.style.color = isError ? "#900" : "#124";
  }

  // ---------------------------------------------------------------- colours
  function hexRgb(h) { return [parseInt(h.substr(1, 2), 16) / 255, parseInt(h.substr(3, 2), 16) / 255, parseInt(h.substr(5, 2), 16) / 255]; }
  var RGB = STOPS.map(hexRgb);
  function colour(t, out, k) {
    t = Math.max(0, Math.min(1, isFinite(t) ? t : 1)) * (RGB.length - 1);
    var i = Math.min(RGB.length - 2, Math.floor(t)), f = t - i;
    for (var c = 0; c < 3; c++) out[k + c] = RGB[i][c] * (1 - f) + RGB[i + 1][c] * f;
  }
  // Value range of the quantity over every cable shown; reversed: small values red (limits).
  function range(state) {
    var lo = Infinity, hi = -Infinity;
    Object.keys(state.cables).forEach(function (n) {
      var v = state.cables[n].values[quantity];
      if (!v) return;
      v.forEach(function (x) { if (isFinite(x)) { lo = Math.min(lo, x); hi = Math.max(hi, x); } });
    });
    if (quantity === "bend_ratio") return {lo: 0, hi: 2, reverse: true}; // 1 (the rule) mid-scale
    if (quantity === "clearance") return {lo: Math.min(0, lo), hi: Math.max(50, Math.min(hi, 200)), reverse: true};
    if (!isFinite(lo)) { lo = 0; hi = 1; }
    if (quantity === "torsion") { var a = Math.max(Math.abs(lo), Math.abs(hi), 1e-12); return {lo: -a, hi: a}; }
    if (quantity === "bending") lo = 0;
    if (hi - lo < 1e-12) hi = lo + 1e-12;
    return {lo: lo, hi: hi};
  }
  function drawColourBar(r) {
    var q = info.quantities[quantity];
    $("cb-title").textContent = q.label + (q.unit ? " [" + q.unit + "]" : "") + (quantity === "bend_ratio" ? " (< 1 breaks the rule " + info.bendFactor + " × d)" : "");
    var stops = r.reverse ? STOPS.slice().reverse() : STOPS;
    $("cb-bar").style.background = "linear-gradient(to right," + stops.join(",") + ")";
    $("cb-min").textContent = fmt(r.lo, 3);
    $("cb-mid").textContent = fmt((r.lo + r.hi) / 2, 3);
    $("cb-max").textContent = fmt(r.hi, 3) + (quantity === "bend_ratio" || quantity === "clearance" ? "+" : "");
  }

  // ---------------------------------------------------------------- 3D scene
  function setup3d() {
    var view = $("view");
    renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(view.clientWidth, view.clientHeight);
    view.appendChild(renderer.domElement);
    scene = new THREE.Scene();
    scene.background = new THREE.Color(0xf4f5f7);
    camera = new THREE.PerspectiveCamera(40, view.clientWidth / view.clientHeight, 0.001, 1000);
    camera.up.set(0, 0, 1);
    scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    var sun = new THREE.DirectionalLight(0xffffff, 0.6);
    sun.position.set(1, -2, 3);
    scene.add(sun);
    var back = new THREE.DirectionalLight(0xffffff, 0.25);
    back.position.set(-2, 1, -1);
    scene.add(back);
    orbit = new THREE.OrbitControls(camera, renderer.domElement);
    orbit.addEventListener("change", function () { dirty = true; });
    gizmo = new THREE.TransformControls(camera, renderer.domElement);
    gizmo.setSize(0.8);
    gizmo.addEventListener("change", function () { dirty = true; });
    gizmo.addEventListener("dragging-changed", function (e) {
      orbit.enabled = !e.value;
      if (e.value) dragMark = true; else if (live) applyLive(live); // snap to the last good pose
    });
    gizmo.addEventListener("objectChange", function () {
      if (!selected || !gizmo.dragging) return;
      if (selected.body) {
        var b = bodyObjects[selected.body];
        var bm = {op: "moveBody", body: selected.body, position: [b.position.x, b.position.y, b.position.z]};
        if (gizmo.getMode() === "rotate") bm.quaternion = [b.quaternion.w, b.quaternion.x, b.quaternion.y, b.quaternion.z];
        queueMove(bm);
        return;
      }
      var o = clipObjects[selected.cable][selected.clip];
      var move = {cable: selected.cable, clip: selected.clip, position: [o.position.x, o.position.y, o.position.z]};
      if (gizmo.getMode() === "rotate") move.quaternion = [o.quaternion.w, o.quaternion.x, o.quaternion.y, o.quaternion.z];
      queueMove(move);
    });
    scene.add(gizmo);
    window.addEventListener("resize", function () {
      renderer.setSize(view.clientWidth, view.clientHeight);
      camera.aspect = view.clientWidth / view.clientHeight;
      camera.updateProjectionMatrix();
      dirty = true;
    });
    var ray = new THREE.Raycaster(), down = null;
    renderer.domElement.addEventListener("pointerdown", function (e) { down = [e.clientX, e.clientY]; });
    renderer.domElement.addEventListener("pointerup", function (e) {
      if (!down || Math.abs(e.clientX - down[0]) + Math.abs(e.clientY - down[1]) > 4 || gizmo.dragging) return;
      var r = renderer.domElement.getBoundingClientRect();
      ray.setFromCamera({x: (e.clientX - r.left) / r.width * 2 - 1, y: -(e.clientY - r.top) / r.height * 2 + 1}, camera);
      var handles = [];
      Object.keys(clipObjects).forEach(function (c) { Object.keys(clipObjects[c]).forEach(function (k) { handles.push(clipObjects[c][k].userData.handle); }); });
      Object.keys(bodyObjects).forEach(function (n) { handles.push(bodyObjects[n].userData.handle); });
      var hit = ray.intersectObjects(handles)[0];
      if (hit && hit.object.userData.body) selectBody(hit.object.userData.body);
      else if (hit) select(hit.object.userData.cable, hit.object.userData.clip);
    });
    window.addEventListener("keydown", function (e) {
      if (e.target.tagName === "INPUT" || e.target.tagName === "SELECT") return;
      if (e.key === "w") setMode("translate");
      if (e.key === "e") setMode("rotate");
      if (e.key === "z" && (e.ctrlKey || e.metaKey)) undo();
    });
    (function loop(t) {
      if (dirty) {
        renderer.render(scene, camera);
        dirty = false;
        frameTimes.push(t);
        if (frameTimes.length > 120) frameTimes.shift();
      }
      requestAnimationFrame(loop);
    })(performance.now());
  }

  function addBodies(geometry) {
    geometry.bodies.forEach(function (b) {
      var g = new THREE.BufferGeometry();
      g.setAttribute("position", new THREE.Float32BufferAttribute(b.vertices, 3));
      g.setIndex(b.faces);
      g.computeVertexNormals();
      var m = new THREE.Mesh(g, new THREE.MeshLambertMaterial({color: 0x9aa3ad, transparent: true, opacity: 0.55, side: THREE.DoubleSide, depthWrite: false}));
      m.name = "body:" + b.name;
      m.matrixAutoUpdate = false;
      bodyMeshes[b.name] = m;
      scene.add(m);
    });
  }

  function makeTube(name, n) {
    var g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(new Float32Array(n * G * 3), 3));
    g.setAttribute("color", new THREE.BufferAttribute(new Float32Array(n * G * 3), 3));
    var idx = [];
    for (var i = 0; i < n - 1; i++) for (var k = 0; k < G; k++) {
      var a = i * G + k, b = i * G + (k + 1) % G, c = a + G, d = b + G;
      idx.push(a, b, d, a, d, c);
    }
    g.setIndex(idx);
    var m = new THREE.Mesh(g, new THREE.MeshLambertMaterial({vertexColors: THREE.VertexColors}));
    m.name = "cable:" + name;
    scene.add(m);
    return m;
  }

  // Rings around the nodes in frames carried along the cable (parallel transport).
  function updateTube(mesh, x, radius, values, r) {
    var n = x.length, pos = mesh.geometry.attributes.position.array, col = mesh.geometry.attributes.color.array;
    var t = new THREE.Vector3(), nrm = null, b = new THREE.Vector3(), tmp = new THREE.Vector3();
    for (var i = 0; i < n; i++) {
      var p = x[Math.min(i + 1, n - 1)], q = x[Math.max(i - 1, 0)];
      t.set(p[0] - q[0], p[1] - q[1], p[2] - q[2]).normalize();
      if (nrm === null) {
        nrm = Math.abs(t.z) < 0.9 ? new THREE.Vector3(0, 0, 1) : new THREE.Vector3(1, 0, 0);
      }
      tmp.copy(t).multiplyScalar(nrm.dot(t));
      nrm.sub(tmp);
      if (nrm.lengthSq() < 1e-20) nrm.set(t.y, -t.x, 0);
      nrm.normalize();
      b.crossVectors(t, nrm);
      var v = values ? values[i] : 0;
      var s = (v - r.lo) / (r.hi - r.lo);
      if (r.reverse) s = 1 - s;
      for (var k = 0; k < G; k++) {
        var a = 2 * Math.PI * k / G, ca = Math.cos(a) * radius, sa = Math.sin(a) * radius, o = (i * G + k) * 3;
        pos[o] = x[i][0] + ca * nrm.x + sa * b.x;
        pos[o + 1] = x[i][1] + ca * nrm.y + sa * b.y;
        pos[o + 2] = x[i][2] + ca * nrm.z + sa * b.z;
        colour(s, col, o);
      }
    }
    mesh.geometry.attributes.position.needsUpdate = true;
    mesh.geometry.attributes.color.needsUpdate = true;
    mesh.geometry.computeVertexNormals();
    mesh.geometry.computeBoundingSphere();
  }

  function makeClip(cable, clip, size) {
    var grp = new THREE.Group();
    var handle = new THREE.Mesh(new THREE.SphereBufferGeometry(size * 0.45, 16, 12), new THREE.MeshLambertMaterial({color: 0x333333}));
    handle.userData = {cable: cable, clip: clip};
    grp.add(handle);
    grp.userData.handle = handle;
    [[1, 0, 0, 0xd62728], [0, 1, 0, 0x2ca02c], [0, 0, 1, 0x1f77b4]].forEach(function (a) {
      grp.add(new THREE.ArrowHelper(new THREE.Vector3(a[0], a[1], a[2]), new THREE.Vector3(), size * 2.2, a[3], size * 0.6, size * 0.35));
    });
    grp.name = "clip:" + cable + "/" + clip;
    scene.add(grp);
    return grp;
  }

  // A hinge clip's turning axis: a grey rod through the clip (global axis, set per state).
  function setHingeAxis(o, axis, size) {
    if (!axis) { if (o.userData.axis) o.userData.axis.visible = false; return; }
    if (!o.userData.axis) {
      var rod = new THREE.Mesh(new THREE.CylinderBufferGeometry(size * 0.15, size * 0.15, size * 10, 8), new THREE.MeshLambertMaterial({color: 0x7f3fbf}));
      rod.name = "hinge-axis";
      scene.add(rod);
      o.userData.axis = rod;
    }
    var rod = o.userData.axis;
    rod.visible = o.visible;
    rod.position.copy(o.position);
    rod.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), new THREE.Vector3(axis[0], axis[1], axis[2]));
  }

  // Junctions: a sphere with its frame (a harness's break-outs), posed per state.
  function drawJunctions(junctions, size) {
    Object.keys(junctions || {}).forEach(function (n) {
      var j = junctions[n], o = junctionObjects[n];
      if (!o) {
        o = new THREE.Group();
        o.add(new THREE.Mesh(new THREE.SphereBufferGeometry(size, 16, 12), new THREE.MeshLambertMaterial({color: 0xff9f1c})));
        [[1, 0, 0, 0xd62728], [0, 1, 0, 0x2ca02c], [0, 0, 1, 0x1f77b4]].forEach(function (a) {
          o.add(new THREE.ArrowHelper(new THREE.Vector3(a[0], a[1], a[2]), new THREE.Vector3(), size * 3, a[3], size * 0.8, size * 0.5));
        });
        o.name = "junction:" + n;
        scene.add(o);
        junctionObjects[n] = o;
      }
      setClipPose(o, j.position, j.frame);
    });
  }

  // A body's handle: a grey cube with the body's axes at its origin (drag it to move the body).
  function makeBody(name, size) {
    var grp = new THREE.Group();
    var handle = new THREE.Mesh(new THREE.BoxBufferGeometry(size, size, size), new THREE.MeshLambertMaterial({color: 0x5a6470, transparent: true, opacity: 0.8}));
    handle.userData = {body: name};
    grp.add(handle);
    grp.userData.handle = handle;
    [[1, 0, 0, 0xd62728], [0, 1, 0, 0x2ca02c], [0, 0, 1, 0x1f77b4]].forEach(function (a) {
      grp.add(new THREE.ArrowHelper(new THREE.Vector3(a[0], a[1], a[2]), new THREE.Vector3(), size * 2.5, a[3], size * 0.5, size * 0.3));
    });
    grp.name = "body-handle:" + name;
    scene.add(grp);
    return grp;
  }

  function setClipPose(o, p, rows) {
    o.position.set(p[0], p[1], p[2]);
    var m = new THREE.Matrix4().makeBasis(
      new THREE.Vector3().fromArray(rows[0]), new THREE.Vector3().fromArray(rows[1]), new THREE.Vector3().fromArray(rows[2]));
    o.quaternion.setFromRotationMatrix(m);
  }

  function fitCamera(state) {
    var box = new THREE.Box3();
    Object.keys(state.cables).forEach(function (n) {
      state.cables[n].positions.forEach(function (p) { box.expandByPoint(new THREE.Vector3(p[0], p[1], p[2])); });
    });
    var c = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length() || 1;
    orbit.target.copy(c);
    camera.position.set(c.x + 0.45 * size, c.y - 1.5 * size, c.z + 0.8 * size);
    camera.near = size / 1000; camera.far = size * 100;
    camera.updateProjectionMatrix();
    orbit.update();
  }

  // ---------------------------------------------------------------- state
  function draw(state, withClips) {
    var r = range(state);
    Object.keys(state.cables).forEach(function (n) {
      var c = state.cables[n];
      if (!tubes[n]) tubes[n] = makeTube(n, c.positions.length);
      updateTube(tubes[n], c.positions, c.radius, c.values[quantity], r);
      if (withClips && c.clipPositions) {
        c.figures.clips.forEach(function (k, j) {
          var o = clipObjects[n][k.name];
          if (!(gizmo.dragging && selected && selected.cable === n && selected.clip === k.name)) setClipPose(o, c.clipPositions[j], c.clipFrames[j]);
          if (c.clipAxes) setHingeAxis(o, c.clipAxes[j], Math.max(c.radius * 2.5, 0.004));
        });
      }
    });
    var rmax = 0;
    Object.keys(state.cables).forEach(function (n) { rmax = Math.max(rmax, state.cables[n].radius); });
    if (withClips && state.junctions) drawJunctions(state.junctions, Math.max(rmax * 1.6, 0.004));
    if (withClips && state.bodies) {
      Object.keys(state.bodies).forEach(function (n) {
        var b = state.bodies[n];
        if (bodyObjects[n] && !(gizmo.dragging && selected && selected.body === n)) setClipPose(bodyObjects[n], b.origin, b.frame);
      });
      poseBodies(liveMaps(state));
    }
    drawColourBar(r);
    shown = state;
    dirty = true;
  }

  function liveMaps(state) {
    var maps = {};
    Object.keys(state.bodies || {}).forEach(function (n) { maps[n] = state.bodies[n].map; });
    return maps;
  }

  // Clip handles follow the scene's clips (added or removed in the panel).
  function syncClips(state) {
    Object.keys(state.cables).forEach(function (n) {
      var c = state.cables[n], size = Math.max(c.radius * 2.5, 0.004), names = {};
      clipObjects[n] = clipObjects[n] || {};
      c.figures.clips.forEach(function (k) {
        names[k.name] = true;
        if (!clipObjects[n][k.name]) clipObjects[n][k.name] = makeClip(n, k.name, size);
      });
      Object.keys(clipObjects[n]).forEach(function (k) {
        if (names[k]) return;
        var o = clipObjects[n][k];
        if (gizmo.object === o) gizmo.detach();
        if (o.userData.axis) scene.remove(o.userData.axis);
        scene.remove(o);
        delete clipObjects[n][k];
        if (selected && selected.cable === n && selected.clip === k) selected = null;
      });
    });
  }

  function applyLive(state) {
    syncClips(state);
    live = state;
    if (playing === null) draw(state, true);
    panel(state);
    showTime(state.time);
  }

  // ---------------------------------------------------------------- body motion
  // The live view at a time of the quasistatic grid: no handles (back to rest to edit).
  function showTime(t) {
    if (!info || !info.motion || !info.motion.steps) return;
    var moving = t !== null && t !== undefined;
    if (moving) {
      if (gizmo.object) gizmo.detach();
      $("motion-time").textContent = "t = " + Number(t.t).toFixed(3) + " s (step " + t.step + " of " + (info.motion.steps - 1) + ")";
      $("motion-step").value = t.step;
      $("motion-rest").disabled = false;
      $("time-label").textContent = "t = " + Number(t.t).toFixed(3) + " s: static equilibrium (quasistatic), not dynamics";
      $("time-label").className = "";
    } else {
      if (!gizmo.object && selected && playing === null) gizmo.attach(selectedObject());
      $("motion-time").textContent = "at rest (editable)";
      $("motion-rest").disabled = true;
      $("time-label").className = "hidden";
    }
    document.body.dataset.time = moving ? t.step : "";
  }
  function setupMotion(m) {
    var box = $("motion");
    box.className = "";
    if (!m.steps) {
      $("motion-step").className = "hidden";
      $("motion-rest").parentNode.className = "hidden";
      box.querySelector(".note").textContent = "Not available: " + m.why;
      return;
    }
    var slider = $("motion-step");
    slider.max = m.steps - 1;
    slider.value = 0;
    slider.addEventListener("input", function () { queueMove({op: "time", step: +slider.value}); });
    $("motion-rest").addEventListener("click", function () {
      request({op: "rest"}).catch(function (e) { showMessage(e.message, true); });
    });
  }

  function panel(state) {
    var html = "";
    Object.keys(state.cables).forEach(function (n) {
      var c = state.cables[n], f = c.figures;
      html += "<h2>cable " + esc(n) + "</h2>";
      if (c.message) html += '<div class="bad">' + esc(c.message) + "</div>";
      if (f.warning) html += '<div class="bad">' + esc(f.warning) + "</div>";
      html += "<table>";
      html += '<tr><td>length [m]</td><td class="num"><input type="number" step="0.01" data-cable="' + esc(n) + '" data-item="" data-key="length" value="' + f.length + '"></td></tr>';
      var rb = f.minBendRadius === null ? "straight" : fmt(f.minBendRadius * 1e3, 3) + " mm at s = " + fmt(f.minBendRadiusS, 3) + " m";
      var bad = f.minBendRadius !== null && f.minBendRadius < f.bendRule;
      html += "<tr><td>min bend radius</td><td class=\"num" + (bad ? " bad" : "") + "\">" + rb + "</td></tr>";
      html += '<tr><td>rule (' + info.bendFactor + ' × d)</td><td class="num">' + fmt(f.bendRule * 1e3, 3) + " mm</td></tr>";
      html += '<tr><td>max tension</td><td class="num">' + fmt(f.maxTension, 3) + " N at s = " + fmt(f.maxTensionS, 3) + " m</td></tr>";
      html += '<tr><td>max compression</td><td class="num">' + fmt(f.maxCompression, 3) + " N at s = " + fmt(f.maxCompressionS, 3) + " m</td></tr>";
      html += '<tr><td>max |torsion|</td><td class="num">' + fmt(f.maxTorsion, 3) + " N m at s = " + fmt(f.maxTorsionS, 3) + " m</td></tr>";
      if (f.minClearance !== undefined) html += '<tr><td>min clearance</td><td class="num' + (f.minClearance < 0 ? " bad" : "") + '">' + fmt(f.minClearance * 1e3, 3) + " mm at s = " + fmt(f.minClearanceS, 3) + " m</td></tr>";
      html += '<tr><td>last solve</td><td class="num">' + fmt(f.solveMs, 2) + " ms, " + f.iterations + " iterations</td></tr>";
      html += "</table><table><tr><th>clip</th><th>s [m]</th><th>type</th><th>length [m]</th><th>|F| [N]</th><th>|M| [N&nbsp;m]</th><th></th></tr>";
      var extra = [];
      f.clips.forEach(function (k) {
        var sel = selected && selected.cable === n && selected.clip === k.name;
        var fn = Math.hypot.apply(null, k.force), mn = Math.hypot.apply(null, k.moment);
        var opts = info.clipTypes.map(function (t) { return "<option" + (t === k.type ? " selected" : "") + ">" + t + "</option>"; }).join("");
        var d = ' data-cable="' + esc(n) + '" data-item="' + esc(k.name) + '"';
        html += '<tr class="clip' + (sel ? " sel" : "") + '"' + d + "><td>" + esc(k.name) + "</td>" +
          '<td><input type="number" step="0.01"' + d + ' data-key="s" value="' + k.s + '" style="width:46px"></td>' +
          "<td><select" + d + ' data-key="type" style="max-width:66px">' + opts + "</select></td>" +
          '<td><input type="number" step="0.005"' + d + ' data-key="length" value="' + k.length + '" style="width:46px"></td>' +
          '<td class="num">' + fmt(fn, 3) + '</td><td class="num">' + fmt(mn, 3) + "</td>" +
          '<td class="rmcell"><button class="rm"' + d + ' title="remove clip ' + esc(k.name) + '">×</button></td></tr>';
        if (k.type === "hinge" && k.axis) extra.push("<tr" + d + "><td>" + esc(k.name) + '</td><td>hinge axis (d1, d2, d3)</td><td class="num">' +
          k.axis.map(function (a, i) { return '<input type="number" step="0.1" class="axis"' + d + ' data-key="axis" data-index="' + i + '" value="' + a + '" style="width:40px">'; }).join("") + "</td></tr>");
        if (k.type === "sliding") extra.push("<tr" + d + "><td>" + esc(k.name) + '</td><td>slid through</td><td class="num slid">' + (k.slid === null ? "–" : fmt(k.slid * 1e3, 3) + " mm") + "</td></tr>");
      });
      html += "</table>";
      if (extra.length) html += '<table class="clip-extra">' + extra.join("") + "</table>";
      var bodies = ["world"].concat(Object.keys(state.bodies || {}));
      html += '<div class="row add-clip" data-cable="' + esc(n) + '">new clip at s <input type="number" step="0.01" min="0" class="add-s" value="' +
        fmt(f.length / 2, 3) + '" style="width:58px"> m <select class="add-type" style="max-width:66px">' +
        info.clipTypes.map(function (t) { return "<option>" + t + "</option>"; }).join("") + '</select> on <select class="add-body" style="max-width:80px">' +
        bodies.map(function (b) { return "<option>" + esc(b) + "</option>"; }).join("") + '</select> <button class="add">add</button></div>';
    });
    if (state.junctions) {
      html += "<h2>junctions</h2><table>";
      Object.keys(state.junctions).forEach(function (n) {
        var p = state.junctions[n].position;
        html += "<tr><td>" + esc(n) + '</td><td class="num">[' + p.map(function (v) { return fmt(v, 4); }).join(", ") + "] m</td></tr>";
      });
      html += "</table>";
    }
    var names = Object.keys(state.bodies || {});
    if (names.length) {
      html += '<h2>bodies</h2><table class="bodies">';
      names.forEach(function (n) {
        var b = state.bodies[n], sel = selected && selected.body === n;
        html += '<tr class="body' + (sel ? " sel" : "") + '" data-body="' + esc(n) + '"><td>' + esc(n) + '</td><td class="num">origin [' +
          b.origin.map(function (v) { return fmt(v, 4); }).join(", ") + "] m, " + b.clips + " clip(s)</td></tr>";
      });
      html += "</table>";
    }
    var box = $("cables");
    if (box.contains(document.activeElement) && document.activeElement.tagName === "INPUT") return; // typing
    box.innerHTML = html;
  }

  // ---------------------------------------------------------------- server
  function request(req) {
    req.id = nextId++;
    var entry = {};
    entry.promise = new Promise(function (resolve, reject) {
      entry.resolve = resolve; entry.reject = reject;
      waiting[req.id] = entry;
      ws.send(JSON.stringify(req));
    });
    entry.promise.catch(function () {}); // settled() waits for it; the caller sees the error
    return entry.promise;
  }

  function onReply(msg) {
    var w = waiting[msg.id];
    delete waiting[msg.id];
    if (msg.state) {
      applyLive(msg.state);
      if (msg.solveMs !== undefined) lastSolveMs = msg.solveMs;
      var now = performance.now();
      updateTimes.push(now);
      if (updateTimes.length > 60) updateTimes.shift();
      renderer.render(scene, camera); // on screen before the promise resolves
      frameTimes.push(now);
      dirty = false;
    }
    if (msg.ok === false || msg.error) showMessage(msg.error, msg.ok === false);
    else if (msg.saved) showMessage("saved to " + msg.saved, false);
    else showMessage("");
    if (!w) return;
    if (msg.ok === false && !msg.state) w.reject(new Error(msg.error));
    else w.resolve(msg);
  }

  // One move in flight; while it is solved, later moves replace each other (the latest wins).
  function queueMove(move) {
    if (inflight) { pending = move; return; }
    sendMove(move);
  }
  function sendMove(move) {
    inflight = true;
    var mark = dragMark; dragMark = false;
    var req = move.op === "moveBody" ? {op: "moveBody", body: move.body, position: move.position, quaternion: move.quaternion || null, mark: mark}
      : move.op === "time" ? {op: "time", step: move.step} : {op: "move", moves: [move], mark: mark};
    request(req).catch(function (e) { showMessage(e.message, true); }).then(function () {
      inflight = false;
      if (pending) { var p = pending; pending = null; sendMove(p); return; }
      var done = idleWaiters; idleWaiters = [];
      done.forEach(function (f) { f(); });
    });
  }

  function select(cable, clip) {
    selected = {cable: cable, clip: clip};
    if (!(live && live.time)) gizmo.attach(clipObjects[cable][clip]); // no handles while the motion is shown
    panel(live);
    $("selected").innerHTML = "selected: cable <b>" + esc(cable) + "</b>, clip <b>" + esc(clip) + "</b> — drag the arrows (W: move, E: turn)";
    dirty = true;
  }
  function selectBody(name) {
    var b = live.bodies[name];
    selected = {body: name};
    if (!(live && live.time)) gizmo.attach(bodyObjects[name]);
    panel(live);
    $("selected").innerHTML = "selected: body <b>" + esc(name) + "</b> (" + b.clips + " clip(s)) — drag the arrows (W: move, E: turn)";
    dirty = true;
  }
  function selectedObject() {
    if (!selected) return null;
    return selected.body ? bodyObjects[selected.body] : clipObjects[selected.cable][selected.clip];
  }
  function setMode(m) {
    gizmo.setMode(m);
    $("mode-translate").className = m === "translate" ? "on" : "";
    $("mode-rotate").className = m === "rotate" ? "on" : "";
    dirty = true;
  }
  function undo() { return request({op: "undo"}); }

  // ---------------------------------------------------------------- result file
  function showClips(on) {
    Object.keys(clipObjects).forEach(function (c) { Object.keys(clipObjects[c]).forEach(function (k) {
      var o = clipObjects[c][k];
      o.visible = on;
      if (o.userData.axis && !on) o.userData.axis.visible = false;
    }); });
    Object.keys(junctionObjects).forEach(function (n) { junctionObjects[n].visible = on; });
    Object.keys(bodyObjects).forEach(function (n) { bodyObjects[n].visible = on; });
    gizmo.visible = on && selected !== null;
    if (!on) gizmo.detach(); else if (selected) gizmo.attach(selectedObject());
  }
  // Bodies at a saved step: x = R X + t, rows of [R | t] (at rest without).
  function poseBodies(poses) {
    Object.keys(bodyMeshes).forEach(function (n) {
      var p = poses[n], m = bodyMeshes[n].matrix;
      if (p) m.set(p[0][0], p[0][1], p[0][2], p[0][3], p[1][0], p[1][1], p[1][2], p[1][3], p[2][0], p[2][1], p[2][2], p[2][3], 0, 0, 0, 1);
      else m.identity();
    });
  }
  function setupPlayer(r) {
    if (!r) return;
    $("player").className = "";
    $("player-name").textContent = r.path + " (" + r.mode + ", " + r.steps + " steps)";
    var slider = $("player-step"), timer = null;
    slider.max = r.steps - 1;
    function show(k) {
      return fetch("/api/result/" + k).then(function (x) { return x.json(); }).then(function (d) {
        playing = k;
        showClips(false);
        poseBodies(d.bodies || {});
        $("player-time").textContent = "t = " + fmt(d.time, 4) + " s (step " + k + ")";
        draw(d, false);
        renderer.render(scene, camera);
        return d;
      });
    }
    slider.addEventListener("input", function () { show(+slider.value); });
    $("player-play").addEventListener("click", function () {
      if (timer) { clearInterval(timer); timer = null; $("player-play").textContent = "play"; return; }
      $("player-play").textContent = "pause";
      var busy = false;
      timer = setInterval(function () {
        if (busy) return;
        busy = true;
        var k = (+slider.value + 1) % r.steps;
        slider.value = k;
        show(k).then(function () { busy = false; });
      }, 1000 / 25);
    });
    $("player-live").addEventListener("click", function () {
      if (timer) { clearInterval(timer); timer = null; $("player-play").textContent = "play"; }
      playing = null; $("player-time").textContent = ""; showClips(true); poseBodies(liveMaps(live)); draw(live, true);
    });
    // test hook: show saved step k of the result; resolves when drawn, with its nodes
    window.cablelifeWorkbench.showResultStep = function (k) {
      slider.value = k;
      return show(k).then(function (d) {
        var out = {time: d.time, cables: {}};
        Object.keys(d.cables).forEach(function (n) { out.cables[n] = {positions: d.cables[n].positions}; });
        return out;
      });
    };
  }

  // ---------------------------------------------------------------- start
  function start() {
    fetch("/api/scene").then(function (r) { return r.json(); }).then(function (d) {
      info = d;
      $("scene-name").textContent = d.scene;
      var sel = $("quantity");
      Object.keys(d.quantities).forEach(function (k) {
        if (k === "clearance" && d.geometry.bodies.length === 0) return;
        var o = document.createElement("option");
        o.value = k; o.textContent = d.quantities[k].label;
        sel.appendChild(o);
      });
      sel.value = quantity;
      sel.addEventListener("change", function () { quantity = sel.value; draw(shown, playing === null); });
      setup3d();
      addBodies(d.geometry);
      var st = d.state;
      Object.keys(st.cables).forEach(function (n) {
        clipObjects[n] = {};
        var c = st.cables[n], size = Math.max(c.radius * 2.5, 0.004);
        c.figures.clips.forEach(function (k) { clipObjects[n][k.name] = makeClip(n, k.name, size); });
      });
      Object.keys(st.bodies || {}).forEach(function (n) {
        if (st.bodies[n].clips > 0 || bodyMeshes[n]) bodyObjects[n] = makeBody(n, 0.012);
      });
      fitCamera(st);
      document.body.dataset.junctions = Object.keys(st.junctions || {}).length;
      applyLive(st);
      $("mode-translate").onclick = function () { setMode("translate"); };
      $("mode-rotate").onclick = function () { setMode("rotate"); };
      $("undo").onclick = undo;
      $("save").onclick = function () { request({op: "save"}); };
      $("cables").addEventListener("change", function (e) {
        var t = e.target, key = t.dataset.key;
        if (!key) return;
        var value = key === "type" ? t.value : parseFloat(t.value);
        if (key === "axis") value = Array.prototype.map.call(document.querySelectorAll('input.axis[data-cable="' + t.dataset.cable + '"][data-item="' + t.dataset.item + '"]'), function (e) { return parseFloat(e.value); });
        request({op: "edit", cable: t.dataset.cable, item: t.dataset.item, key: key, value: value}).catch(function (err) {
          showMessage(err.message, true); panel(live);
        });
      });
      $("cables").addEventListener("click", function (e) {
        if (e.target.classList.contains("rm")) {
          request({op: "removeClip", cable: e.target.dataset.cable, clip: e.target.dataset.item}).catch(function (err) { showMessage(err.message, true); });
          return;
        }
        if (e.target.classList.contains("add")) {
          var row = e.target.closest(".add-clip");
          request({op: "addClip", cable: row.dataset.cable, s: parseFloat(row.querySelector(".add-s").value),
            type: row.querySelector(".add-type").value, body: row.querySelector(".add-body").value}).catch(function (err) { showMessage(err.message, true); });
          return;
        }
        var tb = e.target.closest("tr.body");
        if (tb) { selectBody(tb.dataset.body); return; }
        var tr = e.target.closest("tr.clip");
        if (tr && e.target.tagName !== "INPUT" && e.target.tagName !== "SELECT") select(tr.dataset.cable, tr.dataset.item);
      });
      setupPlayer(d.result);
      setupMotion(d.motion);
      var first = Object.keys(st.cables)[0];
      var clips = st.cables[first].figures.clips;
      select(first, clips[clips.length - 1].name);
      document.body.dataset.ready = "yes";
    }).catch(function (e) { showMessage("cannot load the scene: " + e.message, true); document.body.dataset.ready = "failed"; });
  }

  function rate(times) {
    var now = performance.now(), recent = times.filter(function (t) { return now - t < 2000; });
    if (recent.length < 2) return 0;
    return (recent.length - 1) / ((recent[recent.length - 1] - recent[0]) / 1000);
  }

  window.cablelifeWorkbench = {
    moveClip: function (cable, clip, xyz) {
      return request({op: "move", moves: [{cable: cable, clip: clip, position: xyz}], mark: true}).then(function (msg) {
        if (msg.ok === false) throw new Error(msg.error);
        return {solveMs: msg.solveMs};
      });
    },
    // several clips at once, one update (as dragging a bracket that holds them): [[cable, clip, xyz], ...]
    moveClips: function (list) {
      var moves = list.map(function (m) { return {cable: m[0], clip: m[1], position: m[2]}; });
      return request({op: "move", moves: moves, mark: true}).then(function (msg) {
        if (msg.ok === false) throw new Error(msg.error);
        return {solveMs: msg.solveMs};
      });
    },
    // resolves when the moves of a mouse drag are all solved and drawn, and every other request answered
    settled: function () {
      var open = Object.keys(waiting).map(function (k) { return waiting[k].promise.catch(function () { return null; }); });
      var moves = inflight || pending ? new Promise(function (r) { idleWaiters.push(r); }) : Promise.resolve();
      return Promise.all([moves].concat(open)).then(function () { return true; });
    },
    state: function () {
      var out = {cables: {}};
      if (!live) return out;
      Object.keys(live.cables).forEach(function (n) { out.cables[n] = {positions: live.cables[n].positions}; });
      if (live.junctions) {
        out.junctions = {};
        Object.keys(live.junctions).forEach(function (n) { out.junctions[n] = {position: live.junctions[n].position, drawn: junctionObjects[n].position.toArray()}; });
      }
      return out;
    },
    // moves a body to a new origin (and orientation, quaternion [w, x, y, z]); resolves when drawn
    moveBody: function (body, xyz, quaternion) {
      return request({op: "moveBody", body: body, position: xyz, quaternion: quaternion || null, mark: true}).then(function (msg) {
        if (msg.ok === false) throw new Error(msg.error);
        return {solveMs: msg.solveMs};
      });
    },
    selectBody: selectBody,
    // a body's handle and mesh as drawn: handle position, quaternion [w, x, y, z], mesh map rows (3 x 4)
    bodyPose: function (body) {
      var o = bodyObjects[body], m = bodyMeshes[body], e = m ? m.matrix.elements : null;
      return {position: o.position.toArray(), quaternion: [o.quaternion.w, o.quaternion.x, o.quaternion.y, o.quaternion.z],
        map: e ? [[e[0], e[4], e[8], e[12]], [e[1], e[5], e[9], e[13]], [e[2], e[6], e[10], e[14]]] : null};
    },
    // the handle axis under the mouse ("X", "Y", "Z", "E", "XYZE", … or null), to find the rings in tests
    gizmoAxis: function () { return gizmo.axis; },
    setMode: setMode,
    bodyOnScreen: function (body) {
      var v = bodyObjects[body].position.clone().project(camera), r = renderer.domElement.getBoundingClientRect();
      return [r.left + (v.x + 1) / 2 * r.width, r.top + (1 - v.y) / 2 * r.height];
    },
    // the side panel's text of a clip's extra rows (hinge axis, slid length), for tests
    clipExtra: function (cable, clip) {
      var rows = document.querySelectorAll('table.clip-extra tr[data-cable="' + cable + '"][data-item="' + clip + '"]');
      return Array.prototype.map.call(rows, function (r) {
        var axis = r.querySelectorAll("input.axis");
        return axis.length ? {axis: Array.prototype.map.call(axis, function (e) { return parseFloat(e.value); })} : {slid: r.querySelector(".slid").textContent};
      });
    },
    // a hinge clip's drawn axis (global unit vector) or null
    hingeAxis: function (cable, clip) {
      var a = clipObjects[cable][clip].userData.axis;
      if (!a || !a.visible) return null;
      return new THREE.Vector3(0, 1, 0).applyQuaternion(a.quaternion).toArray();
    },
    stats: function () {
      return {solvesPerSecond: rate(updateTimes), lastSolveMs: lastSolveMs, framesPerSecond: rate(frameTimes)};
    },
    // the bodies' motion at step k of the quasistatic grid (static equilibrium, warm); resolves when drawn
    showTime: function (k) {
      return request({op: "time", step: k}).then(function (msg) {
        if (msg.ok === false) throw new Error(msg.error);
        return {time: msg.state.time, label: $("motion-time").textContent, solveMs: msg.solveMs};
      });
    },
    backToRest: function () { return request({op: "rest"}); },
    motionInfo: function () { return info.motion; },
    // a clip added at arc length s (type, body) / removed, as the panel's controls; resolve when drawn
    addClip: function (cable, s, type, body) { return request({op: "addClip", cable: cable, s: s, type: type || "fixed", body: body || "world"}); },
    removeClip: function (cable, clip) { return request({op: "removeClip", cable: cable, clip: clip}); },
    // the clip handles drawn, per cable
    clipNames: function () {
      var out = {};
      Object.keys(clipObjects).forEach(function (n) { out[n] = Object.keys(clipObjects[n]).filter(function (k) { return clipObjects[n][k].parent === scene; }); });
      return out;
    },
    save: function (path) { return request({op: "save", path: path || null}); },
    undo: undo,
    edit: function (cable, item, key, value) { return request({op: "edit", cable: cable, item: item, key: key, value: value}); },
    setQuantity: function (q) { quantity = q; $("quantity").value = q; draw(shown, playing === null); renderer.render(scene, camera); },
    select: select,
    // the clip's pose as drawn (and as a turn sends it): position, quaternion [w, x, y, z]
    clipPose: function (cable, clip) {
      var o = clipObjects[cable][clip];
      return {position: o.position.toArray(), quaternion: [o.quaternion.w, o.quaternion.x, o.quaternion.y, o.quaternion.z]};
    },
    // where a clip is on the page (CSS px), to drag it with the mouse in tests
    clipOnScreen: function (cable, clip) {
      var v = clipObjects[cable][clip].position.clone().project(camera), r = renderer.domElement.getBoundingClientRect();
      return [r.left + (v.x + 1) / 2 * r.width, r.top + (1 - v.y) / 2 * r.height];
    },
  };

  ws = new WebSocket("ws://" + location.host + "/ws");
  ws.onmessage = function (e) { onReply(JSON.parse(e.data)); };
  ws.onclose = function () {
    showMessage("the workbench server has stopped (restart `cablelife workbench`)", true);
    Object.keys(waiting).forEach(function (k) { waiting[k].reject(new Error("the workbench server has stopped")); });
    waiting = {};
  };
  ws.onopen = start;
})();
