// tactsense: the hand's skin in 3-D (every taxel at its place in the base frame, coloured by
// its signal; contacts as arrows; a table of contacts per link). Drawn on a 2-D canvas with
// a perspective camera written out below (no WebGL: it draws wherever a canvas does).
// The state is in window.tactsenseHand, for tests and for the curious.
"use strict";

(() => {
  const canvas = document.getElementById("scene");
  const ctx = canvas.getContext("2d");
  const FOV_RAD = (40 * Math.PI) / 180; // vertical field of view of the camera
  const MAX_ARROW_MM = 40;
  const AXIS_MM = 20; // length of the base frame's axes as drawn
  const state = {
    layout: null,
    latest: null,
    camera: null, // {yaw, pitch, distance, target: [x, y, z] mm, focal px, cx, cy}
    home: null,
    positions: {}, // patch -> [[x, y, z] mm, ...] every taxel in the base frame now
    normals: {}, // patch -> [[x, y, z], ...] their outward normals in the base frame now
    poses: null, // link -> [R | t] row by row (t in mm): the hand's joint state now
    screen: {}, // patch -> [[x px, y px, depth mm], ...] where each taxel was drawn
    colourIndex: {}, // patch -> colour-map index (0-255) each taxel was drawn with
    arrows: [], // [{patch, link, tail: [x, y], head: [x, y]}] as drawn
    scale: 0, // the signal that maps to the top of the colour map [-]
    drawnSerial: null,
    dirty: false,
    playback: null,
    status: "connecting",
    project: null,
    showArrows: true,
    showBones: true,
  };
  window.tactsenseHand = state;

  // ---- the camera ---------------------------------------------------------------------
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const unit = (a) => { const n = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / n, a[1] / n, a[2] / n]; };

  // the camera's axes: it looks at `target` from `distance` along (yaw, pitch) (z up)
  function axes(cam) {
    const e = [Math.cos(cam.pitch) * Math.cos(cam.yaw), Math.cos(cam.pitch) * Math.sin(cam.yaw), Math.sin(cam.pitch)];
    const eye = [cam.target[0] + cam.distance * e[0], cam.target[1] + cam.distance * e[1], cam.target[2] + cam.distance * e[2]];
    const forward = [-e[0], -e[1], -e[2]];
    const right = unit(cross(forward, [0, 0, 1]));
    const up = cross(right, forward);
    return { eye, forward, right, up };
  }

  // a point [mm, base frame] -> [x px, y px, depth mm] (perspective: x/depth, y/depth)
  function projector(cam) {
    const { eye, forward, right, up } = axes(cam);
    return (p) => {
      const d = sub(p, eye);
      const depth = dot(d, forward);
      return [cam.cx + (cam.focal * dot(d, right)) / depth, cam.cy - (cam.focal * dot(d, up)) / depth, depth];
    };
  }

  function homeCamera(layout) {
    const all = layout.patches.flatMap((p) => p.positions_mm).concat(layout.links.map((l) => l.origin_mm));
    const lo = [0, 1, 2].map((k) => Math.min(...all.map((p) => p[k])));
    const hi = [0, 1, 2].map((k) => Math.max(...all.map((p) => p[k])));
    const target = [0, 1, 2].map((k) => 0.5 * (lo[k] + hi[k]));
    const radius = Math.max(1, 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
    const focal = canvas.height / (2 * Math.tan(FOV_RAD / 2));
    return {
      yaw: (-60 * Math.PI) / 180,
      pitch: (35 * Math.PI) / 180,
      distance: (1.02 * radius) / Math.sin(FOV_RAD / 2), // the bounding sphere fits whatever the turn
      target,
      focal,
      cx: canvas.width / 2,
      cy: canvas.height / 2,
    };
  }

  // ---- the joint state: taxels from their links' frames into the base frame -------------
  const place = (m, p) => [0, 1, 2].map((r) => m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3]);
  const turn = (m, v) => [0, 1, 2].map((r) => m[4 * r] * v[0] + m[4 * r + 1] * v[1] + m[4 * r + 2] * v[2]);

  function setPoses(poses) {
    state.poses = poses;
    for (const patch of state.layout.patches) {
      const m = poses[patch.link];
      state.positions[patch.name] = patch.positions_link_mm.map((p) => place(m, p));
      state.normals[patch.name] = patch.normals_link.map((v) => turn(m, v));
    }
  }

  // ---- drawing --------------------------------------------------------------------------
  function pitchOf(positions) {
    // the median distance of a taxel to its nearest neighbour [mm] (sizes the dots)
    if (positions.length < 2) return 3;
    const nearest = positions.map((p, i) => {
      let best = Infinity;
      positions.forEach((q, j) => { if (j !== i) best = Math.min(best, Math.hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2])); });
      return best;
    });
    nearest.sort((a, b) => a - b);
    return nearest[Math.floor(nearest.length / 2)] || 3;
  }

  function colourOf(index) {
    const c = state.layout.colormap.lut[index];
    return `rgb(${c[0]},${c[1]},${c[2]})`;
  }

  function draw() {
    state.dirty = false;
    const layout = state.layout;
    if (!layout) return;
    const project = projector(state.camera);
    state.project = (p) => project(p);
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    const signals = (state.latest && state.latest.signals) || {};
    let top = layout.signal_floor || 0.01;
    for (const values of Object.values(signals)) if (values) for (const v of values) if (v > top) top = v;
    state.scale = top;
    document.getElementById("scale").textContent = `colour scale 0 – ${top.toPrecision(3)} [-]`;
    if (state.showBones) {
      ctx.strokeStyle = "#b0bec5";
      ctx.lineWidth = 3;
      for (const bone of layout.bones) {
        const from = state.poses[bone.parent], to = state.poses[bone.child];
        const a = project([from[3], from[7], from[11]]), b = project([to[3], to[7], to[11]]);
        if (a[2] <= 0 || b[2] <= 0) continue;
        ctx.beginPath(); ctx.moveTo(a[0], a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke();
      }
    }
    // the base frame's axes at its origin (x red, y green, z blue; AXIS_MM long)
    const origin = project([0, 0, 0]);
    if (origin[2] > 0) {
      ctx.lineWidth = 2;
      [[AXIS_MM, 0, 0, "#e53935"], [0, AXIS_MM, 0, "#43a047"], [0, 0, AXIS_MM, "#1e88e5"]].forEach(([x, y, z, colour]) => {
        const end = project([x, y, z]);
        if (end[2] <= 0) return;
        ctx.strokeStyle = colour;
        ctx.beginPath(); ctx.moveTo(origin[0], origin[1]); ctx.lineTo(end[0], end[1]); ctx.stroke();
      });
    }
    // every taxel, far ones first (the painter's order)
    const dots = [];
    state.screen = {};
    state.colourIndex = {};
    for (const patch of layout.patches) {
      const values = signals[patch.name];
      const screen = [], colours = [];
      state.positions[patch.name].forEach((p, i) => {
        const s = project(p);
        const v = values ? values[i] : 0;
        const index = Math.max(0, Math.min(255, Math.round((255 * v) / top)));
        screen.push(s);
        colours.push(index);
        if (s[2] > 0) dots.push([s, index, (0.42 * patch.pitch_mm * state.camera.focal) / s[2]]);
      });
      state.screen[patch.name] = screen;
      state.colourIndex[patch.name] = colours;
    }
    dots.sort((a, b) => b[0][2] - a[0][2]);
    for (const [s, index, radius] of dots) {
      ctx.fillStyle = colourOf(index);
      ctx.beginPath();
      ctx.arc(s[0], s[1], Math.max(1.2, radius), 0, 2 * Math.PI);
      ctx.fill();
    }
    state.arrows = [];
    const contacts = (state.latest && state.latest.contacts) || [];
    if (state.showArrows) {
      ctx.strokeStyle = ctx.fillStyle = "#d32f2f";
      ctx.lineWidth = 2.5;
      for (const c of contacts) {
        const length = Math.min(MAX_ARROW_MM, (c.force_n || 0) * layout.arrow_mm_per_n + 3);
        const tail3 = [0, 1, 2].map((k) => c.position_mm[k] + length * c.normal[k]);
        const head = project(c.position_mm), tail = project(tail3);
        if (head[2] <= 0 || tail[2] <= 0) continue;
        ctx.beginPath(); ctx.moveTo(tail[0], tail[1]); ctx.lineTo(head[0], head[1]); ctx.stroke();
        const angle = Math.atan2(head[1] - tail[1], head[0] - tail[0]);
        ctx.beginPath();
        ctx.moveTo(head[0], head[1]);
        ctx.lineTo(head[0] - 10 * Math.cos(angle - 0.4), head[1] - 10 * Math.sin(angle - 0.4));
        ctx.lineTo(head[0] - 10 * Math.cos(angle + 0.4), head[1] - 10 * Math.sin(angle + 0.4));
        ctx.closePath(); ctx.fill();
        state.arrows.push({ patch: c.patch, link: c.link, tail: tail.slice(0, 2), head: head.slice(0, 2) });
      }
    }
    state.drawnSerial = state.latest ? state.latest.serial : null;
  }

  function redraw() {
    if (state.dirty) return;
    state.dirty = true;
    requestAnimationFrame(draw);
  }

  // ---- tables ---------------------------------------------------------------------------
  const fmt = (v, digits) => (v === null || v === undefined ? "–" : Number(v).toFixed(digits));

  function cells(row, values) {
    const tr = document.createElement("tr");
    values.forEach(([text, name]) => {
      const td = document.createElement("td");
      td.textContent = text;
      if (name) td.className = "name";
      tr.appendChild(td);
    });
    row.appendChild(tr);
  }

  function tables(message) {
    const linkRows = document.getElementById("link-rows");
    linkRows.replaceChildren();
    for (const l of message.links) {
      const torque = l.torque_link_n_mm ? Math.hypot(...l.torque_link_n_mm) : null;
      cells(linkRows, [[l.link, 1], [l.n_contacts], [fmt(l.force_n, 3)], [fmt(torque, 1)], [l.patches.join(", "), 1]]);
    }
    document.getElementById("no-contacts").hidden = message.links.length > 0;
    const contactRows = document.getElementById("contact-rows");
    contactRows.replaceChildren();
    for (const c of message.contacts) {
      cells(contactRows, [[c.link, 1], [c.patch, 1], [c.id ?? "–"], [fmt(c.position_mm[0], 1)],
        [fmt(c.position_mm[1], 1)], [fmt(c.position_mm[2], 1)], [fmt(c.force_n, 3)]]);
    }
    if (message.devices) {
      const list = document.getElementById("devices");
      list.replaceChildren();
      for (const d of message.devices) {
        const li = document.createElement("li");
        li.textContent = d.line;
        li.className = d.state;
        list.appendChild(li);
      }
      document.getElementById("device-panel").hidden = false;
    }
    const frames = message.frame_counts || {};
    document.querySelectorAll("#patch-rows tr").forEach((tr) => {
      tr.lastChild.textContent = frames[tr.dataset.patch] ?? "–";
    });
  }

  function showJoints(joints) {
    const items = Object.entries(joints);
    document.getElementById("joints").textContent = items.length ? items.map(([k, v]) => `${k}=${v}`).join(", ") : "all at 0";
  }

  function setLayout(layout) {
    for (const patch of layout.patches) patch.pitch_mm = pitchOf(patch.positions_mm);
    state.layout = layout;
    setPoses(layout.link_poses);
    document.getElementById("skin").textContent = layout.skin;
    document.getElementById("source").textContent = layout.source ? layout.source.name : "";
    document.getElementById("base-link").textContent = layout.base_link;
    showJoints(layout.joints);
    document.getElementById("mm-per-n").textContent = layout.arrow_mm_per_n;
    document.getElementById("estimator").textContent = layout.estimator || "–";
    const rows = document.getElementById("patch-rows");
    rows.replaceChildren();
    for (const p of layout.patches) {
      cells(rows, [[p.name, 1], [p.link, 1], [p.kind, 1], [p.n_taxels], ["–"]]);
      rows.lastChild.dataset.patch = p.name;
    }
    document.getElementById("rezero").hidden = !(layout.source && layout.source.kind === "robot live");
    if (!state.camera) {
      state.camera = homeCamera(layout);
      state.home = { ...state.camera };
    }
    if (layout.playback) setPlayback(layout.playback);
    if (layout.status) setStatus(layout.status);
    if (layout.latest) setFrame(layout.latest);
    redraw();
  }

  function setFrame(message) {
    state.latest = message;
    if (message.link_poses && state.layout) setPoses(message.link_poses);
    if (message.joints) showJoints(message.joints);
    if (message.estimator) document.getElementById("estimator").textContent = message.estimator;
    tables(message);
    if (message.playback) setPlayback(message.playback);
    redraw();
  }

  function setStatus(message) {
    state.status = message.status;
    const el = document.getElementById("status");
    el.textContent = message.error ? `${message.status}: ${message.error}` : message.status;
    el.className = `status ${message.status}`;
  }

  function setPlayback(playback) {
    state.playback = playback;
    document.getElementById("playback").hidden = false;
    document.getElementById("play").textContent = playback.playing ? "pause" : "play";
    const seek = document.getElementById("seek");
    seek.max = playback.duration_s;
    if (!seek.matches(":active")) seek.value = playback.time_s;
    document.getElementById("position").textContent = `${playback.time_s.toFixed(2)} / ${playback.duration_s.toFixed(2)} s`;
    document.getElementById("speed").value = String(playback.speed);
  }

  // ---- the connection ---------------------------------------------------------------------
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  const ws = new WebSocket(`${scheme}://${location.host}/ws`);
  const send = (command, value) => { if (ws.readyState === 1) ws.send(JSON.stringify({ command, value })); };
  ws.onmessage = (event) => {
    const message = JSON.parse(event.data);
    if (message.type === "robot_layout") setLayout(message);
    else if (message.type === "robot_frame") setFrame(message);
    else if (message.type === "status") setStatus(message);
    else if (message.type === "playback") setPlayback(message);
  };
  ws.onclose = () => setStatus({ status: "disconnected" });

  // ---- controls ---------------------------------------------------------------------------
  document.getElementById("play").onclick = () => send(state.playback && state.playback.playing ? "pause" : "play");
  document.getElementById("seek").oninput = (e) => send("seek", Number(e.target.value));
  document.getElementById("speed").onchange = (e) => send("speed", Number(e.target.value));
  document.getElementById("show-arrows").onchange = (e) => { state.showArrows = e.target.checked; redraw(); };
  document.getElementById("show-bones").onchange = (e) => { state.showBones = e.target.checked; redraw(); };
  const resetView = () => { if (state.home) { state.camera = { ...state.home }; redraw(); } };
  document.getElementById("reset-view").onclick = resetView;
  document.getElementById("rezero").onclick = () => send("rezero");
  document.addEventListener("keydown", (e) => {
    if (e.target.tagName === "INPUT" || e.target.tagName === "SELECT") return;
    if (e.key === "r") resetView();
    if (e.key === "z" && !document.getElementById("rezero").hidden) send("rezero");
    if (e.key === " ") { e.preventDefault(); document.getElementById("play").click(); }
  });
  let drag = null;
  canvas.addEventListener("pointerdown", (e) => {
    drag = { x: e.clientX, y: e.clientY };
    canvas.setPointerCapture(e.pointerId);
    canvas.classList.add("dragging");
  });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag || !state.camera) return;
    const limit = (89 * Math.PI) / 180;
    state.camera.yaw -= (e.clientX - drag.x) * 0.01;
    state.camera.pitch = Math.max(-limit, Math.min(limit, state.camera.pitch + (e.clientY - drag.y) * 0.01));
    drag = { x: e.clientX, y: e.clientY };
    redraw();
  });
  const endDrag = () => { drag = null; canvas.classList.remove("dragging"); };
  canvas.addEventListener("pointerup", endDrag);
  canvas.addEventListener("pointercancel", endDrag);
  canvas.addEventListener("wheel", (e) => {
    if (!state.camera) return;
    e.preventDefault();
    state.camera.distance = Math.max(5, state.camera.distance * Math.exp(0.001 * e.deltaY));
    redraw();
  }, { passive: false });
})();
