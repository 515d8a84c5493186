// mbd's 3-D viewer: the scene from the page's JSON (src/output/view.rs), drawn with three.js,
// animated from the sampled poses. window.mbdView exposes the state for tests: ready, frame,
// frames, setFrame(k), errors.
(function () {
  "use strict";
  // Errors are kept on the page (data-mbd-errors) for tests that read the DOM.
  const errors = [];
  const keep = (text) => { errors.push(String(text)); document.body.dataset.mbdErrors = JSON.stringify(errors); };
  window.addEventListener("error", (e) => keep(e.message));
  window.addEventListener("unhandledrejection", (e) => keep(e.reason));
  const consoleError = console.error.bind(console);
  console.error = (...args) => { keep(args.join(" ")); consoleError(...args); };
  const data = JSON.parse(document.getElementById("mbd-data").textContent);
  const floats = (b64) => {
    const bin = atob(b64);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    return new Float32Array(bytes.buffer);
  };
  const P = floats(data.positions), Q = floats(data.rotations), L = floats(data.load_vectors);
  const nA = data.anchors, nL = data.loads, frames = data.t.length;
  const state = { ready: false, frame: 0, frames, errors, setFrame: null };
  window.mbdView = state;

  const view = document.getElementById("view");
  document.getElementById("title").textContent = data.title;
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0xf4f5f7);
  view.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  const up = new THREE.Vector3(data.up[0], data.up[1], data.up[2]);
  const size = data.size;
  const camera = new THREE.PerspectiveCamera(40, 1, size * 1e-3, size * 100);
  camera.up.copy(up);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.4);
  sun.position.copy(up).multiplyScalar(3 * size).add(new THREE.Vector3(size, 2 * size, 0));
  scene.add(sun);

  // One group per anchor, posed each frame.
  const anchors = [];
  for (let k = 0; k < nA; k++) {
    const g = new THREE.Group();
    scene.add(g);
    anchors.push(g);
  }
  const material = (color, opts) => new THREE.MeshStandardMaterial(Object.assign({ color, roughness: 0.6, metalness: 0.1 }, opts || {}));
  const pickable = [];
  const links = [], arrows = [];
  const X = new THREE.Vector3(1, 0, 0), Y = new THREE.Vector3(0, 1, 0);
  const alongX = new THREE.Quaternion().setFromUnitVectors(Y, X);
  const triad = (s) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.Float32BufferAttribute([0, 0, 0, s, 0, 0, 0, 0, 0, 0, s, 0, 0, 0, 0, 0, 0, s], 3));
    g.setAttribute("color", new THREE.Float32BufferAttribute([1, 0, 0, 1, 0, 0, 0, 0.6, 0, 0, 0.6, 0, 0, 0, 1, 0, 0, 1], 3));
    return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true }));
  };
  // A helix of radius r and `turns` turns from y = -1/2 to 1/2, its wire r / 6 thick.
  const helix = (r, turns) => {
    class Helix extends THREE.Curve {
      getPoint(u, target = new THREE.Vector3()) {
        const a = 2 * Math.PI * turns * u;
        return target.set(r * Math.cos(a), u - 0.5, r * Math.sin(a));
      }
    }
    return new THREE.TubeGeometry(new Helix(), 24 * turns, r / 6, 6, false);
  };
  for (const s of data.shapes) {
    const look = s.look;
    let obj = null;
    if (look.type === "box") {
      obj = new THREE.Mesh(new THREE.BoxGeometry(2 * look.half[0], 2 * look.half[1], 2 * look.half[2]), material(s.color));
      obj.position.set(look.center[0], look.center[1], look.center[2]);
    } else if (look.type === "sphere") {
      obj = new THREE.Mesh(new THREE.SphereGeometry(look.radius, 24, 16), material(s.color));
      obj.position.set(look.center[0], look.center[1], look.center[2]);
    } else if (look.type === "cylinder") {
      obj = new THREE.Mesh(new THREE.CylinderGeometry(look.radius, look.radius, look.length, 24), material(s.color));
      obj.quaternion.copy(alongX);
      obj.position.set(look.center[0], look.center[1], look.center[2]);
    } else if (look.type === "triad") {
      anchors[s.anchor].add(triad(look.size));
      continue;
    } else if (look.type === "grid") {
      const grid = new THREE.GridHelper(look.size, 20, 0x9aa3ad, 0xc9ced6);
      grid.quaternion.setFromUnitVectors(Y, new THREE.Vector3(look.normal[0], look.normal[1], look.normal[2]));
      // Under the model: at its lowest point along up at the start.
      let low = 0;
      for (let i = 0; i < nA; i++) low = Math.min(low, P[3 * i] * up.x + P[3 * i + 1] * up.y + P[3 * i + 2] * up.z);
      grid.position.copy(up).multiplyScalar(low);
      anchors[s.anchor].add(grid);
      continue;
    } else if (look.type === "link") {
      // A spring is a helix of `coils` turns along the unit height, stretched with the link.
      const geometry = look.coils > 0 ? helix(look.radius, look.coils) : new THREE.CylinderGeometry(look.radius, look.radius, 1, 16, 1);
      const mesh = new THREE.Mesh(geometry, material(s.color));
      scene.add(mesh);
      links.push({ mesh, from: s.anchor, to: look.to });
      mesh.userData.shape = s;
      pickable.push(mesh);
      continue;
    } else if (look.type === "arrow") {
      const arrow = new THREE.ArrowHelper(X, new THREE.Vector3(), size * 0.1, s.color);
      scene.add(arrow);
      // A torque is a double-headed arrow (the right-hand rule's vector).
      let second = null;
      if (data.torques[look.load]) {
        second = new THREE.Mesh(arrow.cone.geometry, arrow.cone.material);
        arrow.add(second);
        second.userData.shape = s;
        pickable.push(second);
      }
      arrows.push({ arrow, second, anchor: s.anchor, load: look.load, scale: look.scale });
      arrow.line.userData.shape = s;
      arrow.cone.userData.shape = s;
      pickable.push(arrow.line, arrow.cone);
      continue;
    }
    if (obj) {
      obj.userData.shape = s;
      anchors[s.anchor].add(obj);
      pickable.push(obj);
    }
  }
  // Each load's largest magnitude over the run, drawn `scale` long.
  const loadMax = new Float32Array(nL);
  for (let f = 0; f < frames; f++) {
    for (let i = 0; i < nL; i++) {
      const o = 3 * (f * nL + i);
      loadMax[i] = Math.max(loadMax[i], Math.hypot(L[o], L[o + 1], L[o + 2]));
    }
  }

  // Traces: an anchor's path up to the current frame, toggled by clicking its shape.
  const traces = new Map();
  const traceOf = (anchor) => {
    const g = new THREE.BufferGeometry();
    const pts = new Float32Array(3 * frames);
    for (let f = 0; f < frames; f++) for (let c = 0; c < 3; c++) pts[3 * f + c] = P[3 * (f * nA + anchor) + c];
    g.setAttribute("position", new THREE.Float32BufferAttribute(pts, 3));
    const line = new THREE.Line(g, new THREE.LineBasicMaterial({ color: 0x1f77b4 }));
    scene.add(line);
    return line;
  };

  const a = new THREE.Vector3(), b = new THREE.Vector3(), d = new THREE.Vector3();
  function setFrame(k) {
    k = Math.max(0, Math.min(frames - 1, k | 0));
    state.frame = k;
    for (let i = 0; i < nA; i++) {
      const o = 3 * (k * nA + i), r = 4 * (k * nA + i);
      anchors[i].position.set(P[o], P[o + 1], P[o + 2]);
      anchors[i].quaternion.set(Q[r], Q[r + 1], Q[r + 2], Q[r + 3]);
    }
    for (const l of links) {
      a.copy(anchors[l.from].position);
      b.copy(anchors[l.to].position);
      d.subVectors(b, a);
      const len = d.length();
      l.mesh.position.addVectors(a, b).multiplyScalar(0.5);
      if (len > 0) l.mesh.quaternion.setFromUnitVectors(Y, d.clone().divideScalar(len));
      l.mesh.scale.set(1, Math.max(len, 1e-9), 1);
    }
    for (const ar of arrows) {
      const o = 3 * (k * nL + ar.load);
      d.set(L[o], L[o + 1], L[o + 2]);
      const m = d.length();
      ar.arrow.visible = m > 0 && loadMax[ar.load] > 0;
      if (ar.arrow.visible) {
        ar.arrow.position.copy(anchors[ar.anchor].position);
        ar.arrow.setDirection(d.divideScalar(m));
        const len = Math.max(ar.scale * m / loadMax[ar.load], 1e-6);
        ar.arrow.setLength(len, 0.25 * len, 0.12 * len);
        if (ar.second) {
          // The second head just below the first, as the arrow's cone is placed and scaled.
          ar.second.scale.copy(ar.arrow.cone.scale);
          ar.second.position.copy(ar.arrow.cone.position).addScaledVector(Y, -0.2 * len);
        }
      }
    }
    for (const [anchor, line] of traces) line.geometry.setDrawRange(0, k + 1);
    slider.value = String(k);
    timeLabel.textContent = "t = " + data.t[k].toPrecision(6).replace(/\.?0+$/, "") + " s";
    drawPlot();
  }
  state.setFrame = (k) => { setFrame(k); renderer.render(scene, camera); };

  // Camera: the whole model in view, from an oblique direction.
  const box = new THREE.Box3();
  for (let i = 0; i < nA; i++) box.expandByPoint(new THREE.Vector3(P[3 * i], P[3 * i + 1], P[3 * i + 2]));
  const center = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getBoundingSphere(new THREE.Sphere()).radius, 0.05 * size);
  const side = Math.abs(up.z) > 0.9 ? new THREE.Vector3(1, -1.6, 0) : new THREE.Vector3(1, 0, 1.6);
  side.normalize().multiplyScalar(3.2 * radius);
  camera.position.copy(center).add(side).add(up.clone().multiplyScalar(1.2 * radius));
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.copy(center);
  controls.update();

  // The bar: play, speed, slider, channels.
  const slider = document.getElementById("slider"), timeLabel = document.getElementById("time");
  const play = document.getElementById("play"), speed = document.getElementById("speed");
  const channels = document.getElementById("channels");
  slider.max = String(frames - 1);
  if (frames < 2) for (const id of ["play", "speed", "slider", "clear"]) document.getElementById(id).classList.add("hidden");
  const histories = data.histories.map((h) => ({ name: h.name, unit: h.unit, values: floats(h.values) }));
  histories.forEach((h, i) => {
    const opt = document.createElement("option");
    opt.value = String(i);
    opt.textContent = h.name + (h.unit ? " [" + h.unit + "]" : "");
    opt.selected = i === 0;
    channels.appendChild(opt);
  });
  channels.size = Math.min(4, Math.max(1, histories.length));
  const plot = document.getElementById("plot");
  if (!histories.length || frames < 2) plot.classList.add("hidden");
  const colors = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"];
  function drawPlot() {
    if (plot.classList.contains("hidden")) return;
    const w = plot.clientWidth, h = plot.clientHeight;
    if (plot.width !== w) plot.width = w;
    if (plot.height !== h) plot.height = h;
    const g = plot.getContext("2d");
    g.clearRect(0, 0, w, h);
    const chosen = Array.from(channels.selectedOptions).map((o) => histories[+o.value]);
    const t0 = data.t[0], t1 = data.t[frames - 1] || 1, left = 60, right = w - 10, top = 10, bottom = h - 22;
    const xs = (t) => left + (right - left) * (t - t0) / (t1 - t0 || 1);
    g.strokeStyle = "#999";
    g.strokeRect(left, top, right - left, bottom - top);
    g.fillStyle = "#222";
    g.font = "11px sans-serif";
    g.fillText(t0.toPrecision(3) + " s", left, h - 6);
    g.fillText(t1.toPrecision(4) + " s", right - 40, h - 6);
    chosen.forEach((c, n) => {
      let lo = Infinity, hi = -Infinity;
      for (const v of c.values) { if (v < lo) lo = v; if (v > hi) hi = v; }
      if (!(hi > lo)) { hi = lo + 1; lo -= 1; }
      const ys = (v) => bottom - (bottom - top) * (v - lo) / (hi - lo);
      g.strokeStyle = colors[n % colors.length];
      g.beginPath();
      for (let f = 0; f < frames; f++) (f ? g.lineTo : g.moveTo).call(g, xs(data.t[f]), ys(c.values[f]));
      g.stroke();
      g.fillStyle = colors[n % colors.length];
      g.fillText(c.name + (c.unit ? " [" + c.unit + "]" : "") + ": " + lo.toPrecision(3) + " .. " + hi.toPrecision(3), left + 6 + 230 * n, top + 12);
    });
    g.strokeStyle = "#000";
    g.beginPath();
    g.moveTo(xs(data.t[state.frame]), top);
    g.lineTo(xs(data.t[state.frame]), bottom);
    g.stroke();
  }
  channels.addEventListener("change", drawPlot);
  let playing = false, clock = 0, simTime = data.t[0];
  play.addEventListener("click", () => {
    playing = !playing;
    play.textContent = playing ? "Pause" : "Play";
    if (playing && state.frame >= frames - 1) { simTime = data.t[0]; setFrame(0); }
    clock = performance.now();
  });
  slider.addEventListener("input", () => { setFrame(+slider.value); simTime = data.t[state.frame]; });
  document.getElementById("clear").addEventListener("click", () => {
    for (const line of traces.values()) scene.remove(line);
    traces.clear();
  });

  // Names on hover; a click toggles the trace of the shape's anchor.
  const ray = new THREE.Raycaster(), mouse = new THREE.Vector2(), tip = document.getElementById("tip");
  const pick = (ev) => {
    const r = renderer.domElement.getBoundingClientRect();
    mouse.set(((ev.clientX - r.left) / r.width) * 2 - 1, -((ev.clientY - r.top) / r.height) * 2 + 1);
    ray.setFromCamera(mouse, camera);
    const hit = ray.intersectObjects(pickable, false)[0];
    return hit ? hit.object.userData.shape : null;
  };
  renderer.domElement.addEventListener("mousemove", (ev) => {
    const s = pick(ev);
    if (!s) { tip.style.display = "none"; return; }
    tip.style.display = "block";
    tip.style.left = ev.offsetX + 14 + "px";
    tip.style.top = ev.offsetY + 10 + "px";
    tip.innerHTML = "";
    const head = document.createElement("b");
    head.textContent = s.name;
    tip.appendChild(head);
    tip.appendChild(document.createTextNode(" (" + s.kind + ")"));
    tip.appendChild(document.createElement("br"));
    tip.appendChild(document.createTextNode(s.info));
  });
  renderer.domElement.addEventListener("dblclick", (ev) => {
    const s = pick(ev);
    if (!s || frames < 2) return;
    if (traces.has(s.anchor)) { scene.remove(traces.get(s.anchor)); traces.delete(s.anchor); }
    else traces.set(s.anchor, traceOf(s.anchor));
    setFrame(state.frame);
  });

  function resize() {
    const w = view.clientWidth, h = view.clientHeight;
    renderer.setSize(w, h);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    drawPlot();
  }
  window.addEventListener("resize", resize);
  resize();
  // `VIEW.html#frame=K` (or `#t=SECONDS`) opens at that sample.
  const hash = new URLSearchParams(location.hash.slice(1));
  let first = 0;
  if (hash.has("frame")) first = +hash.get("frame");
  else if (hash.has("t")) { const t = +hash.get("t"); while (first < frames - 1 && data.t[first + 1] <= t) first++; }
  setFrame(first);
  simTime = data.t[state.frame];
  function loop(now) {
    if (playing && frames > 1) {
      simTime += ((now - clock) / 1000) * (+speed.value);
      clock = now;
      let k = state.frame;
      while (k < frames - 1 && data.t[k + 1] <= simTime) k++;
      if (k !== state.frame) setFrame(k);
      if (k >= frames - 1) { playing = false; play.textContent = "Play"; }
    }
    controls.update();
    renderer.render(scene, camera);
    requestAnimationFrame(loop);
  }
  renderer.render(scene, camera);
  requestAnimationFrame(loop);
  state.ready = true;
  document.body.dataset.mbdReady = "1";
  document.body.dataset.mbdFrame = String(state.frame);
})();
