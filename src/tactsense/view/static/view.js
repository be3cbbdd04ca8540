// tactsense view: the sensor's frames as they arrive over a websocket.
// The server sends a layout message once, then one message per frame (see
// src/tactsense/view/feed.py for their fields). Drawing happens at most once per
// animation frame, with the latest frame; every frame still feeds the time traces.
// A finger is drawn unwrapped (layout.geometry "finger"); a pad or a point set on a
// plane in millimetres ("plane": each taxel at (u_mm, v_mm), u across, v up).
"use strict";

const CELL = 48;          // pixels per tactel spacing, along and around
const GAP = 34;           // pixels between the tip row and the cylinder
const MARGIN = { left: 56, top: 14, bottom: 40, bar: 70 };
const DOT = 0.32 * CELL;  // radius of a tactel's dot [px]
const TRAIL = 24;         // estimates kept in the contact's trail
const TRACE_S = 20;       // seconds shown by the time traces
const PLANE = { size: 480, cell: 64, minDot: 3 };   // plane: largest side, largest spacing [px]

const state = {
  layout: null,
  latest: null,
  units: "deflection",
  showSurface: true,
  showMarker: true,
  centre: 0,              // display angle at the middle of the map [deg]
  touching: false,
  trail: [],
  tracks: new Map(),      // pads, point sets: contact id -> {points [{u, v}], seen, c}
  contactMarks: [],       // canvas pixels of each contact drawn: {id, x, y} (for tests)
  selected: null,         // [row, col] followed by the tactel trace
  vmax: 0.01,             // deflection colour scale, decaying running maximum
  framesReceived: 0,
  skipped: 0,
  lastIndex: null,
  lastSerial: null,
  firstSerial: null,     // the first frame this page received (server's numbering)
  marker: null,           // canvas pixels of the marker, for tests and people alike
  drawnIndex: null,       // index of the frame the map shows
  labels: [],             // the axes' labels as drawn: text and box [canvas px]
  dirty: false,
  traces: { t: [], force: [], tactel: [] },
  showArrows: true,       // three-axis taxels: the tangential arrows (shear.js)
  tmax: 0,                // their scale, a decaying running maximum [the layout's unit]
  arrowMarks: [],         // canvas pixels of each taxel's arrow (for tests)
  shearMarks: [],         // canvas pixels of each contact's shear arrow and its slip
};
window.tactsenseView = state;

const canvas = document.getElementById("map");
const ctx = canvas.getContext("2d");
const $ = (id) => document.getElementById(id);

// ---- geometry -------------------------------------------------------------------

function wrap360(a) { return ((a % 360) + 360) % 360; }
// (-180, 180], the convention of the estimates
function signedAngle(a) { const w = wrap360(a); return w > 180 ? w - 360 : w; }

function angleSpan() {
  const L = state.layout;
  const n = L.cols;
  if (L.closes) return [state.centre - 180, state.centre + 180];
  const a0 = L.col_angle_deg[0], s = L.spacing_deg;
  return [a0 - s / 2, a0 + (n - 0.5) * s];
}

// the display angle at the middle of the map nearest to ``angle`` that puts the map's
// top and bottom edges (centre -/+ 180 deg) half-way between two columns, as the
// initial centre does: every dot then sits in the middle of its own cell band
function centreNear(angle) {
  const L = state.layout, s = L.spacing_deg;
  const base = L.col_angle_deg[0] - s / 2 + 180;   // the edges on the seam
  return base + Math.round((angle - base) / s) * s;
}

function mapHeight() { return state.layout.cols * CELL; }
function cylinderLeft() { return MARGIN.left + (state.layout.tip_row ? CELL + GAP : 0); }
function cylinderRows() { return state.layout.rows - state.layout.first_row; }

// vertical pixel of an angle [deg]
function yOfAngle(angle) {
  const [lo, hi] = angleSpan();
  const off = state.layout.closes ? wrap360(angle - lo) : angle - lo;
  return MARGIN.top + (off / (hi - lo)) * mapHeight();
}

function angleOfCol(col) {
  const L = state.layout;
  return L.col_angle_deg[0] + col * L.spacing_deg;
}

// canvas pixels of the centre of tactel (row, col); fractional row/col allowed
function cellCentre(row, col) {
  const L = state.layout;
  if (L.geometry === "plane") return planeCentre(row, col);
  const y = yOfAngle(angleOfCol(col));
  if (L.tip_row && row < L.first_row - 0.5) return [MARGIN.left + CELL / 2, y];
  return [cylinderLeft() + (row - L.first_row + 0.5) * CELL, y];
}
state.cellCentre = cellCentre;

function tactelAt(px, py) {
  const L = state.layout;
  if (L.geometry === "plane") return planeTaxelAt(px, py);
  const [lo, hi] = angleSpan();
  const frac = (py - MARGIN.top) / mapHeight();
  if (frac < 0 || frac >= 1) return null;
  let angle = lo + frac * (hi - lo);
  let col = Math.round((angle - L.col_angle_deg[0]) / L.spacing_deg);
  if (L.closes) col = ((col % L.cols) + L.cols) % L.cols;
  if (col < 0 || col >= L.cols) return null;
  if (L.tip_row && px >= MARGIN.left && px < MARGIN.left + CELL) return [0, col];
  const k = Math.floor((px - cylinderLeft()) / CELL);
  if (k < 0 || k >= cylinderRows()) return null;
  return [k + L.first_row, col];
}

// ---- values and colours -----------------------------------------------------------

function values(frame) {
  if (state.units === "counts" || !frame.deflection) return countsOf(frame);
  return frame.deflection;
}

// what the tactel trace shows: nothing in deflection while the baseline is collected
function traceValues(frame) {
  if (state.units === "counts") return countsOf(frame);
  return frame.deflection;
}

function scale(frame) {
  if (state.units === "counts" || !frame.deflection) {
    let lo = Infinity, hi = -Infinity;
    for (const row of countsOf(frame)) for (const v of row) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (hi - lo < 1) hi = lo + 1;
    return [lo, hi, "counts"];
  }
  // a taxel of several components: its normal change goes both ways (a press over a magnet
  // raises it, beside one lowers it), on a diverging map centred on 0
  if (state.layout.vector) return [-state.vmax, state.vmax, state.layout.vector.map_label];
  return [0, state.vmax, "deflection [-]"];
}

function colour(value, lo, hi) {
  const lut = state.layout.colormap.lut;
  let t = (value - lo) / (hi - lo);
  if (!Number.isFinite(t)) t = 0;
  const i = Math.max(0, Math.min(lut.length - 1, Math.round(t * (lut.length - 1))));
  return lut[i];
}

function rgb(c) { return `rgb(${c[0]},${c[1]},${c[2]})`; }

// the windowed-sinc surface of eq. 48 on the fine grid: W_rows @ Z @ W_cols^T
function surfaceOf(z, first = state.layout.first_row, R = cylinderRows()) {
  const S = state.layout.surface;
  const nr = S.w_rows.length, nc = S.w_cols.length, C = state.layout.cols;
  const zc = new Float64Array(R * nc);           // Z @ W_cols^T
  for (let r = 0; r < R; r++) {
    const zr = z[r + first];
    for (let j = 0; j < nc; j++) {
      const w = S.w_cols[j];
      let s = 0;
      for (let c = 0; c < C; c++) s += zr[c] * w[c];
      zc[r * nc + j] = s;
    }
  }
  const out = new Float64Array(nr * nc);
  for (let i = 0; i < nr; i++) {
    const w = S.w_rows[i];
    for (let j = 0; j < nc; j++) {
      let s = 0;
      for (let r = 0; r < R; r++) s += w[r] * zc[r * nc + j];
      out[i * nc + j] = s;
    }
  }
  return out;
}

const offscreen = document.createElement("canvas");

// The surface always interpolates deflection (eq. 48): a tactel's raw counts carry its
// own baseline, and the sinc of those rings at the open ends of the rows (the row
// weights sum to up to 1.10 between the first two rows: +200 counts on 2000). In
// counts mode each point is shown in the counts of the tactel whose cell it lies in:
// eq. 4 solved for the reading, V = V_o / (1 - f), with that tactel's V_o =
// counts * (1 - deflection); at the tactel itself this is its own reading.
function surfaceValues(frame) {
  const L = state.layout, S = L.surface, first = L.first_row, C = L.cols;
  const f = surfaceOf(frame.deflection);
  if (state.units !== "counts") return f;
  const nr = S.w_rows.length, nc = S.w_cols.length;
  const colOf = S.col.map((y) => ((Math.round(y) % C) + C) % C);
  for (let i = 0; i < nr; i++) {
    const r = first + Math.round(S.row[i]);
    const counts = frame.counts[r], defl = frame.deflection[r];
    for (let j = 0; j < nc; j++) {
      const c = colOf[j];
      const v0 = counts[c] * (1 - defl[c]);
      f[i * nc + j] = v0 / Math.max(1 - f[i * nc + j], 1e-3);
    }
  }
  return f;
}

function drawSurface(frame, lo, hi) {
  const L = state.layout, S = L.surface;
  const nr = S.w_rows.length, nc = S.w_cols.length;
  const f = surfaceValues(frame);
  offscreen.width = nr; offscreen.height = nc;
  const octx = offscreen.getContext("2d");
  const image = octx.createImageData(nr, nc);
  // fine columns in display order (rotated so the map starts at the top of the span)
  const order = [...Array(nc).keys()].map((j) => [yOfAngle(angleOfCol(S.col[j])), j]);
  order.sort((a, b) => a[0] - b[0]);
  order.forEach(([, j], y) => {
    for (let i = 0; i < nr; i++) {
      const c = colour(f[i * nc + j], lo, hi);
      const p = 4 * (y * nr + i);
      image.data[p] = c[0]; image.data[p + 1] = c[1]; image.data[p + 2] = c[2]; image.data[p + 3] = 255;
    }
  });
  octx.putImageData(image, 0, 0);
  ctx.imageSmoothingEnabled = true;
  ctx.drawImage(offscreen, cylinderLeft(), MARGIN.top, cylinderRows() * CELL, mapHeight());
}

// ---- drawing ----------------------------------------------------------------------

function draw() {
  state.dirty = false;
  const L = state.layout, frame = state.latest;
  if (!L) return;
  if (L.geometry === "plane") { drawPlane(frame); return; }
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  const H = mapHeight(), left = cylinderLeft(), W = cylinderRows() * CELL;
  state.map = { top: MARGIN.top, height: H, cell: CELL, dot: DOT };   // for tests
  ctx.fillStyle = "#eceff1";
  ctx.fillRect(left, MARGIN.top, W, H);
  if (L.tip_row) ctx.fillRect(MARGIN.left, MARGIN.top, CELL, H);
  if (!frame) { drawAxes(); return; }
  const z = values(frame);
  const [lo, hi, unit] = scale(frame);
  // no surface until there is a deflection to interpolate (the baseline is known)
  if (state.showSurface && frame.deflection) drawSurface(frame, lo, hi);
  // tactels: dots in the colour of their value, over the surface
  for (let r = 0; r < L.rows; r++) {
    for (let c = 0; c < L.cols; c++) {
      const [x, y] = cellCentre(r, c);
      ctx.beginPath();
      ctx.arc(x, y, DOT, 0, 2 * Math.PI);
      ctx.fillStyle = rgb(colour(z[r][c], lo, hi));
      ctx.fill();
      const sel = state.selected && state.selected[0] === r && state.selected[1] === c;
      ctx.lineWidth = sel ? 3 : 1;
      ctx.strokeStyle = sel ? "#e91e63" : "rgba(0,0,0,0.35)";
      ctx.stroke();
    }
  }
  drawAxes();   // after the dots: nothing covers a label
  drawSeam();
  drawColourBar(lo, hi, unit);
  if (state.showMarker) drawContact();
  state.drawnIndex = frame.index;   // what the map shows now (tests wait for it)
}

// the text, and its box in canvas pixels kept in state.labels (for tests)
function label(text, x, y) {
  ctx.fillText(text, x, y);
  const m = ctx.measureText(text);
  state.labels.push({
    text,
    left: x - m.actualBoundingBoxLeft, right: x + m.actualBoundingBoxRight,
    top: y - m.actualBoundingBoxAscent, bottom: y + m.actualBoundingBoxDescent,
  });
}

function drawAxes() {
  const L = state.layout, H = mapHeight(), left = cylinderLeft();
  state.labels = [];
  ctx.fillStyle = "#333"; ctx.font = "12px system-ui, sans-serif"; ctx.textAlign = "center";
  for (let r = L.first_row; r < L.rows; r++) {
    const [x] = cellCentre(r, 0);
    label(L.row_axial_mm[r].toFixed(1), x, MARGIN.top + H + 14);
  }
  label("along the finger [mm]", left + (cylinderRows() * CELL) / 2, MARGIN.top + H + 30);
  if (L.tip_row) label("tip", MARGIN.left + CELL / 2, MARGIN.top + H + 14);
  ctx.textAlign = "right";
  for (let c = 0; c < L.cols; c++) {
    const y = yOfAngle(angleOfCol(c));
    label(`${signedAngle(L.col_angle_deg[c]).toFixed(0)}°`, MARGIN.left - 6, y + 4);
  }
  ctx.save();
  ctx.translate(14, MARGIN.top + H / 2); ctx.rotate(-Math.PI / 2); ctx.textAlign = "center";
  ctx.fillText("around [deg]", 0, 0);
  ctx.restore();
}

function drawSeam() {
  const L = state.layout;
  if (!L.closes) return;
  const y = yOfAngle(L.col_angle_deg[0] - L.spacing_deg / 2);
  ctx.save();
  ctx.setLineDash([6, 4]); ctx.strokeStyle = "#b71c1c"; ctx.lineWidth = 1.5;
  ctx.beginPath();
  const x0 = L.tip_row ? MARGIN.left : cylinderLeft();
  ctx.moveTo(x0, y); ctx.lineTo(cylinderLeft() + cylinderRows() * CELL, y); ctx.stroke();
  ctx.fillStyle = "#b71c1c"; ctx.textAlign = "left"; ctx.font = "11px system-ui, sans-serif";
  ctx.fillText("seam", cylinderLeft() + cylinderRows() * CELL + 4, y + 4);
  ctx.restore();
}

function drawColourBar(lo, hi, unit, right = cylinderLeft() + cylinderRows() * CELL, H = mapHeight()) {
  const x = right + 36;
  for (let i = 0; i < H; i++) {
    ctx.fillStyle = rgb(colour(hi - (i / (H - 1)) * (hi - lo), lo, hi));
    ctx.fillRect(x, MARGIN.top + i, 12, 1);
  }
  ctx.fillStyle = "#333"; ctx.textAlign = "left"; ctx.font = "11px system-ui, sans-serif";
  const fmt = (v) => (unit === "counts" ? v.toFixed(0) : v.toPrecision(2));
  ctx.fillText(fmt(hi), x + 15, MARGIN.top + 9);
  ctx.fillText(fmt(lo), x + 15, MARGIN.top + H);
  ctx.save();
  ctx.translate(x + 26, MARGIN.top + H / 2); ctx.rotate(Math.PI / 2); ctx.textAlign = "center";
  ctx.fillText(unit, 0, 0);
  ctx.restore();
}

function drawContact() {
  state.marker = null;
  ctx.save();
  // trail: older points fainter; no line across the wrap
  let prev = null;
  state.trail.forEach((p, k) => {
    const [x, y] = cellCentre(p.row, p.col);
    const alpha = (k + 1) / state.trail.length;
    ctx.fillStyle = `rgba(255,255,255,${0.8 * alpha})`;
    ctx.beginPath(); ctx.arc(x, y, 2.5, 0, 2 * Math.PI); ctx.fill();
    if (prev && Math.abs(prev[1] - y) < mapHeight() / 2 && Math.abs(prev[0] - x) < 3 * CELL) {
      ctx.strokeStyle = `rgba(255,255,255,${0.6 * alpha})`; ctx.lineWidth = 1.5;
      ctx.beginPath(); ctx.moveTo(prev[0], prev[1]); ctx.lineTo(x, y); ctx.stroke();
    }
    prev = [x, y];
  });
  const est = state.latest && state.latest.estimate;
  if (est && isContact(est)) {
    const [x, y] = cellCentre(est.row, est.col);
    // a white ring (radius 7 px) edged in black: visible on any colour of the map
    ctx.lineWidth = 5; ctx.strokeStyle = "#000";
    ctx.beginPath(); ctx.arc(x, y, 7, 0, 2 * Math.PI); ctx.stroke();
    ctx.lineWidth = 3; ctx.strokeStyle = "#fff";
    ctx.beginPath(); ctx.arc(x, y, 7, 0, 2 * Math.PI); ctx.stroke();
    state.marker = { x, y };
  }
  ctx.restore();
}

// ---- a pad or a point set: taxels on a plane in millimetres ------------------------------
// One scale [px/mm] for both axes (the aspect ratio is true); u across, v up: the
// sensor seen from outside, looking down its (mean) normal.

function planeFrame() {
  const L = state.layout, [u0, u1, v0, v1] = L.bounds_mm;
  const scale = Math.min(PLANE.size / Math.max(u1 - u0, v1 - v0), PLANE.cell / L.spacing_mm);
  return {
    geometry: "plane", left: MARGIN.left, top: MARGIN.top,
    width: (u1 - u0) * scale, height: (v1 - v0) * scale,
    scale, u0, u1, v0, v1, dot: Math.max(PLANE.minDot, L.dot_mm * scale),
  };
}

function xOfU(u) { const m = state.plane; return m.left + (u - m.u0) * m.scale; }
function yOfV(v) { const m = state.plane; return m.top + (m.v1 - v) * m.scale; }

function planeCentre(row, col) {
  const L = state.layout, i = row * L.cols + col;
  return [xOfU(L.u_mm[i]), yOfV(L.v_mm[i])];
}

function planeTaxelAt(px, py) {
  const L = state.layout;
  let best = null, bestD = Math.max(1.5 * state.plane.dot, 6);
  for (let r = 0; r < L.rows; r++) {
    for (let c = 0; c < L.cols; c++) {
      const [x, y] = planeCentre(r, c), d = Math.hypot(px - x, py - y);
      if (d < bestD) { bestD = d; best = [r, c]; }
    }
  }
  return best;
}

// the reading a deflection f gives at a taxel whose frame reads `counts` at deflection
// `d`: a capacitive taxel's eq. 4 solved for the reading, a resistive taxel's linear law;
// a falling sensor's reading moves the other way (capacitive: d = (V_o - V)/(2V_o - V),
// so V = V_o (1 - 2d)/(1 - d))
function countsAt(f, counts, d) {
  const t = state.layout.transduction;
  if (t.kind !== "capacitive") {
    const sign = t.falling ? -1 : 1;
    return counts + sign * (f - d) * t.counts_per_strain;
  }
  if (t.falling) {
    const rest = (counts * (1 - d)) / Math.max(1 - 2 * d, 1e-3);
    return (rest * (1 - 2 * f)) / Math.max(1 - f, 1e-3);
  }
  return (counts * (1 - d)) / Math.max(1 - f, 1e-3);
}

// the separable windowed-sinc surface (not periodic) on the fine grid; in counts mode each
// point in the counts of the taxel whose cell it lies in, as on the finger
function planeSurfaceValues(frame) {
  const L = state.layout, S = L.surface;
  const f = surfaceOf(frame.deflection, 0, L.rows);
  if (state.units !== "counts") return f;
  const nr = S.w_rows.length, nc = S.w_cols.length;
  for (let i = 0; i < nr; i++) {
    const r = Math.round(S.row[i]);
    for (let j = 0; j < nc; j++) {
      const c = Math.round(S.col[j]);
      f[i * nc + j] = countsAt(f[i * nc + j], frame.counts[r][c], frame.deflection[r][c]);
    }
  }
  return f;
}

function drawPlaneSurface(frame, lo, hi) {
  const S = state.layout.surface, m = state.plane;
  const nr = S.w_rows.length, nc = S.w_cols.length;
  const f = planeSurfaceValues(frame);
  offscreen.width = nr; offscreen.height = nc;
  const octx = offscreen.getContext("2d");
  const image = octx.createImageData(nr, nc);
  for (let j = 0; j < nc; j++) {
    const y = nc - 1 - j;   // v up
    for (let i = 0; i < nr; i++) {
      const c = colour(f[i * nc + j], lo, hi);
      const p = 4 * (y * nr + i);
      image.data[p] = c[0]; image.data[p + 1] = c[1]; image.data[p + 2] = c[2]; image.data[p + 3] = 255;
    }
  }
  octx.putImageData(image, 0, 0);
  ctx.imageSmoothingEnabled = true;
  ctx.drawImage(offscreen, m.left, m.top, m.width, m.height);
}

function drawPlane(frame) {
  const L = state.layout, m = state.plane;
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  state.map = { ...m };   // for tests: origin, scale [px/mm], dot radius [px]
  ctx.fillStyle = "#eceff1";
  ctx.fillRect(m.left, m.top, m.width, m.height);
  if (!frame) { drawPlaneAxes(); return; }
  const z = values(frame);
  const [lo, hi, unit] = scale(frame);
  // (a taxel of several components: no surface in counts, which follow no one law)
  const surface = L.surface && state.showSurface && frame.deflection
    && !(L.vector && state.units === "counts");
  if (surface) drawPlaneSurface(frame, lo, hi);
  for (let r = 0; r < L.rows; r++) {
    for (let c = 0; c < L.cols; c++) {
      const [x, y] = planeCentre(r, c);
      ctx.beginPath();
      ctx.arc(x, y, m.dot, 0, 2 * Math.PI);
      ctx.fillStyle = rgb(colour(z[r][c], lo, hi));
      ctx.fill();
      const sel = state.selected && state.selected[0] === r && state.selected[1] === c;
      ctx.lineWidth = sel ? 3 : 1;
      ctx.strokeStyle = sel ? "#e91e63" : "rgba(0,0,0,0.35)";
      ctx.stroke();
    }
  }
  drawTaxelArrows(frame);
  drawPlaneAxes();
  drawColourBar(lo, hi, unit, m.left + m.width, m.height);
  if (state.showMarker && L.multi_contact) drawPlaneContacts();
  state.drawnIndex = frame.index;
}

// each tracked contact: its trail (older points fainter), a white ring at its position
// with a radius from its extent, and its id beside it
const TRACK_COLOURS = ["#ffffff", "#ffeb3b", "#ff80ab", "#80d8ff", "#b9f6ca", "#ffd180"];

function drawPlaneContacts() {
  const est = state.latest && state.latest.estimate;
  state.contactMarks = [];
  state.shearMarks = [];
  ctx.save();
  for (const [id, track] of state.tracks) {
    const colour = TRACK_COLOURS[id % TRACK_COLOURS.length];
    const pts = track.points;
    for (let k = 1; k < pts.length; k++) {
      ctx.strokeStyle = colour; ctx.globalAlpha = (k + 1) / pts.length; ctx.lineWidth = 2;
      ctx.beginPath();
      ctx.moveTo(xOfU(pts[k - 1].u), yOfV(pts[k - 1].v));
      ctx.lineTo(xOfU(pts[k].u), yOfV(pts[k].v));
      ctx.stroke();
    }
  }
  ctx.globalAlpha = 1;
  for (const c of (est && est.contacts) || []) {
    if (c.u_mm === null || c.v_mm === null) continue;
    const x = xOfU(c.u_mm), y = yOfV(c.v_mm);
    const size = Number.isFinite(c.major_mm) ? Math.max(7, c.major_mm * state.plane.scale) : 7;
    ctx.lineWidth = 3; ctx.strokeStyle = "#000";
    ctx.beginPath(); ctx.arc(x, y, size, 0, 2 * Math.PI); ctx.stroke();
    ctx.lineWidth = 2; ctx.strokeStyle = TRACK_COLOURS[c.id % TRACK_COLOURS.length];
    ctx.beginPath(); ctx.arc(x, y, size, 0, 2 * Math.PI); ctx.stroke();
    ctx.font = "bold 13px system-ui, sans-serif"; ctx.textAlign = "left";
    ctx.lineWidth = 3; ctx.strokeStyle = "#000";
    ctx.strokeText(`#${c.id}`, x + size + 3, y - size);
    ctx.fillStyle = TRACK_COLOURS[c.id % TRACK_COLOURS.length];
    ctx.fillText(`#${c.id}`, x + size + 3, y - size);
    state.contactMarks.push({ id: c.id, x, y });
    if (state.layout.vector) drawContactShear(c, x, y, size);
  }
  ctx.restore();
}

// a tick every 1, 2 or 5 x 10^k mm, at least 36 px apart
function tickStep(scale) {
  for (let k = -1; k < 4; k++) {
    for (const b of [1, 2, 5]) {
      const step = b * 10 ** k;
      if (step * scale >= 36) return step;
    }
  }
  return 10000;
}

function drawPlaneAxes() {
  const L = state.layout, m = state.plane, bottom = m.top + m.height;
  state.labels = [];
  const step = tickStep(m.scale), digits = step < 1 ? 1 : 0;
  ctx.fillStyle = "#333"; ctx.strokeStyle = "#333"; ctx.lineWidth = 1;
  ctx.font = "12px system-ui, sans-serif"; ctx.textAlign = "center";
  for (let t = Math.ceil(m.u0 / step) * step; t <= m.u1 + 1e-9; t += step) {
    const x = xOfU(t);
    ctx.beginPath(); ctx.moveTo(x, bottom); ctx.lineTo(x, bottom + 3); ctx.stroke();
    label((Math.abs(t) < 1e-9 ? 0 : t).toFixed(digits), x, bottom + 14);
  }
  label(L.u_label, m.left + m.width / 2, bottom + 30);
  ctx.textAlign = "right";
  for (let t = Math.ceil(m.v0 / step) * step; t <= m.v1 + 1e-9; t += step) {
    const y = yOfV(t);
    ctx.beginPath(); ctx.moveTo(m.left - 3, y); ctx.lineTo(m.left, y); ctx.stroke();
    label((Math.abs(t) < 1e-9 ? 0 : t).toFixed(digits), m.left - 6, y + 4);
  }
  // the v axis' title, turned to read upward (its box as drawn, for tests)
  ctx.save();
  const cx = 14, cy = m.top + m.height / 2;
  ctx.translate(cx, cy); ctx.rotate(-Math.PI / 2); ctx.textAlign = "center";
  ctx.fillText(L.v_label, 0, 0);
  const w = ctx.measureText(L.v_label).width;
  ctx.restore();
  state.labels.push({ text: L.v_label, left: cx - 12, right: cx + 3, top: cy - w / 2, bottom: cy + w / 2 });
}

// ---- readouts -----------------------------------------------------------------------

function isContact(est) {
  if (state.layout.multi_contact) return Boolean(est && est.n_contacts > 0);
  const noContact = state.layout.flags.NO_CONTACT;
  return est && !(est.flags & noContact) && Number.isFinite(est.row) && Number.isFinite(est.col);
}

const fixed = (v, d) => (v === null || v === undefined || !Number.isFinite(v) ? "–" : v.toFixed(d));

// pads and point sets: the number of contacts, their total force and one row each
function showContacts(est) {
  $("n-contacts").textContent = est ? est.n_contacts : "–";
  $("total-force-n").textContent = est ? fixed(est.force_n, 4) : "–";
  $("contact-flags").textContent = est ? (est.rezeroing ? "re-zeroing…" : est.flag_names || "none") : "baseline…";
  const body = $("contact-rows");
  body.replaceChildren();
  for (const c of (est && est.contacts) || []) {
    const tr = document.createElement("tr");
    const tail = state.layout.vector ? shearCells(c) : [c.slip ? "slip" : ""];
    for (const text of [`#${c.id}`, fixed(c.x_mm, 2), fixed(c.y_mm, 2), fixed(c.force_n, 4), ...tail]) {
      const td = document.createElement("td");
      td.textContent = text;
      tr.appendChild(td);
    }
    body.appendChild(tr);
  }
}

function showEstimate(est) {
  if (state.layout.multi_contact) { showContacts(est); return; }
  const touching = est && isContact(est);
  $("axial").textContent = touching ? fixed(est.axial_mm, 2) : "–";
  $("angle").textContent = touching ? fixed(est.angle_deg, 1) : "–";
  $("force-n").textContent = touching ? fixed(est.force_n, 4) : "–";
  $("force-g").textContent = touching ? fixed(est.force_g, 1) : "–";
  $("skew").textContent = touching ? fixed(est.skew, 3) : "–";
  $("peak").textContent = est ? fixed(est.peak_deflection, 4) : "–";
  $("flags").textContent = est ? est.flag_names || "none" : "baseline…";
}

function showHealth(frame) {
  const h = frame.health || {};
  $("frame-index").textContent = frame.index;
  $("rate").textContent = h.rate_hz !== undefined ? `${h.rate_hz.toFixed(1)} /s` : "–";
  $("received").textContent = h.received ?? "–";
  for (const kind of state.layout.loss_kinds) {
    const cell = $(kind);
    if (!cell) continue;
    cell.textContent = h[kind] ?? 0;
    cell.classList.toggle("bad", (h[kind] ?? 0) > 0);
  }
  $("latency").textContent = h.latency_ms === null || h.latency_ms === undefined ? "–" : `${h.latency_ms.toFixed(2)} ms`;
  $("display-latency").textContent = `${Math.max(0, Date.now() - 1000 * frame.host_time_s).toFixed(0)} ms`;
  $("skipped").textContent = state.skipped;
}

// The speed selector shows the speed the server plays at (--speed, or another page's
// choice); a speed not among its options gets an option of its own, in order.
function showSpeed(speed) {
  if (typeof speed !== "number" || !(speed > 0)) return;
  const select = $("speed");
  if (document.activeElement === select) return;
  let option = [...select.options].find((o) => Number(o.value) === speed);
  if (!option) {
    option = new Option(`${speed}×`, String(speed));
    const after = [...select.options].find((o) => Number(o.value) > speed);
    select.add(option, after || null);
  }
  select.value = option.value;
}

function showPlayback(p) {
  if (!p) return;
  $("playback").hidden = false;
  const seek = $("seek");
  seek.max = p.n_frames - 1;
  if (document.activeElement !== seek) seek.value = p.position;
  $("play").textContent = p.playing ? "pause" : "play";
  showSpeed(p.speed);
  const f = state.latest;
  // frames count from 0, as the stream panel, the seek bar and the estimates' frame column
  if (f) $("position").textContent = `frame ${f.index} of 0–${p.n_frames - 1} · ${f.time_s.toFixed(2)} s`;
}

// ---- time traces (uPlot) --------------------------------------------------------------

let forcePlot = null, tactelPlot = null, lastTraceDraw = 0;

function makePlots() {
  const opts = (title, label) => ({
    title, width: 520, height: 200,
    scales: { x: { time: false } },
    axes: [{ label: "time [s]" }, { label }],
    series: [{}, { label, stroke: "#1565c0", width: 1.5, spanGaps: false }],
  });
  forcePlot = new uPlot(opts("force", "force [g]"), [[], []], $("force-trace"));
  tactelPlot = new uPlot(opts("tactel", "value"), [[], []], $("tactel-trace"));
}

function tactelValue(frame) {
  if (!state.selected) return null;
  const [r, c] = state.selected;
  const v = traceValues(frame);
  return v ? v[r][c] : null;
}

function pushTrace(frame) {
  const T = state.traces, est = frame.estimate;
  T.t.push(frame.time_s);
  // grams: the finger's force_g, or the sum of a pad's contacts (force_n / g_n)
  let grams = 0;
  if (est && isContact(est)) {
    if (est.force_g !== undefined) grams = est.force_g ?? 0;
    else if (est.force_n !== null) grams = est.force_n / 0.00980665;
  }
  T.force.push(grams);
  T.tactel.push(tactelValue(frame));
  while (T.t.length && T.t[0] < frame.time_s - TRACE_S) { T.t.shift(); T.force.shift(); T.tactel.shift(); }
  if (T.t.length > 4000) { T.t.shift(); T.force.shift(); T.tactel.shift(); }
}

function refillTactelTrace() {
  // the selected tactel or the units changed: recompute from the frames kept
  state.traces.tactel = state.history.map((f) => tactelValue(f));
}

function drawTraces(now) {
  if (!forcePlot || now - lastTraceDraw < 100) return;
  lastTraceDraw = now;
  const T = state.traces;
  forcePlot.setData([T.t, T.force]);
  const word = state.layout && state.layout.geometry === "plane" ? "taxel" : "tactel";
  const V = state.layout && state.layout.vector;
  const units = V && state.units !== "counts" ? `: ${V.map_label}` : ` [${state.units}]`;
  const title = state.selected ? `${word} (${state.selected[0]}, ${state.selected[1]})${units}` : `${word}: click one on the map`;
  tactelPlot.root.querySelector(".u-title").textContent = title;
  tactelPlot.setData([T.t, T.tactel]);
}

// ---- messages -------------------------------------------------------------------------

state.history = [];   // the frames behind the traces (bounded like the traces)

function onLayout(L) {
  state.layout = L;
  state.centre = L.closes ? centreNear(L.col_angle_deg[0] + ((L.cols - 1) / 2) * L.spacing_deg) : 0;
  $("sensor").textContent = L.sensor;
  $("source").textContent = `${L.source.kind}: ${L.source.name}`;
  $("calibration").textContent = L.estimation ? "" : L.source.calibrated
    ? "calibrated"
    : "uncalibrated: per-tactel gains not corrected (tactsense calibrate)";
  // no contact estimate for this kind of sensor (yet): one line instead of the numbers
  $("contact").hidden = Boolean(L.estimation) || Boolean(L.multi_contact);
  $("contacts").hidden = !L.multi_contact;
  $("no-estimation").hidden = !L.estimation;
  $("no-estimation").textContent = L.estimation || "";
  $("force-trace").hidden = Boolean(L.estimation);
  $("show-marker").parentElement.hidden = Boolean(L.estimation);
  onVectorLayout(L);
  if (L.geometry === "plane") {
    state.plane = planeFrame();
    canvas.width = state.plane.left + state.plane.width + MARGIN.bar + 40;
    canvas.height = state.plane.top + state.plane.height + MARGIN.bottom;
    state.selected = [Math.floor(L.rows / 2), Math.floor(L.cols / 2)];
    $("hint").textContent = "Click a taxel to follow it in the trace below. "
      + `${L.projection[0].toUpperCase()}${L.projection.slice(1)}; `
      + (L.surface ? "the surface is the windowed-sinc interpolation of the deflection, not wrapped at the edges."
        : "no surface between scattered taxels, dots only.")
      + (L.vector ? ` The map is the ${L.vector.map_label}; `
        + (L.vector.arrow_label ? `each arrow the ${L.vector.arrow_label} at its taxel, where the surface is pushed.` : "")
        : "");
    $("show-surface").parentElement.hidden = !L.surface;
  } else {
    const width = cylinderLeft() + cylinderRows() * CELL + MARGIN.bar + 40;
    canvas.width = width;
    canvas.height = MARGIN.top + mapHeight() + MARGIN.bottom;
    state.selected = [L.first_row + Math.floor(cylinderRows() / 2), 0];
  }
  state.history = []; state.traces = { t: [], force: [], tactel: [] }; state.trail = [];
  state.tracks = new Map();
  state.lastIndex = null; state.lastSerial = null;   // a (re)connection starts afresh
  if (!forcePlot) makePlots();
  onStatus(L.status);
  for (const f of L.history || []) onFrame(f, true);
  if (L.playback) showPlayback(L.playback);   // now, not as the last frame in history was
  state.dirty = true;
}

function onStatus(s) {
  if (!s) return;
  const el = $("status");
  el.textContent = s.error ? `${s.status}: ${s.error}` : s.status;
  el.className = `status ${s.status}`;
}

function onFrame(f, fromHistory) {
  if (!fromHistory) {
    state.framesReceived += 1;
    // frames the server had but this page did not get (not those lost on the line)
    if (state.lastSerial !== null && f.serial > state.lastSerial + 1) {
      state.skipped += f.serial - state.lastSerial - 1;
    }
    state.lastSerial = f.serial;
    if (state.firstSerial === null) state.firstSerial = f.serial;
  }
  if (state.lastIndex !== null && f.index < state.lastIndex) {   // a seek back
    state.history = []; state.traces = { t: [], force: [], tactel: [] }; state.trail = [];
    state.tracks = new Map();
  }
  state.lastIndex = f.index;
  state.latest = f;
  if (f.deflection) {
    let peak = 0;
    const size = state.layout.vector ? Math.abs : (v) => v;
    for (const row of f.deflection) for (const v of row) peak = Math.max(peak, size(v));
    state.vmax = Math.max(0.01, peak, state.vmax * 0.995);
  }
  if (state.layout.vector) updateArrowScale(f);
  const est = f.estimate;
  const touching = est && isContact(est);
  if (state.layout.multi_contact) updateTracks(f);
  else if (touching) {
    const L = state.layout;
    if (L.closes && !state.touching) {
      // a new touch near the top or bottom edge: centre the map on it, so a contact
      // on the seam is one blob
      const angle = angleOfCol(est.col);
      const off = wrap360(angle - state.centre + 180) - 180;
      if (Math.abs(off) > 180 - L.spacing_deg) state.centre = centreNear(angle);
    }
    state.trail.push({ row: est.row, col: est.col });
    if (state.trail.length > TRAIL) state.trail.shift();
  }
  state.touching = touching;
  state.history.push(f);
  while (state.history.length && state.history[0].time_s < f.time_s - TRACE_S) state.history.shift();
  if (state.history.length > 4000) state.history.shift();
  pushTrace(f);
  showEstimate(est);
  showHealth(f);
  showPlayback(f.playback);
  state.dirty = true;
}

// each contact id's trail; an id unseen for TRAIL frames is dropped
function updateTracks(f) {
  const est = f.estimate;
  for (const c of (est && est.contacts) || []) {
    if (c.u_mm === null || c.v_mm === null) continue;
    const track = state.tracks.get(c.id) || { points: [], seen: f.index };
    track.points.push({ u: c.u_mm, v: c.v_mm });
    if (track.points.length > TRAIL) track.points.shift();
    track.seen = f.index;
    state.tracks.set(c.id, track);
  }
  for (const [id, track] of state.tracks) {
    if (f.index - track.seen > TRAIL) state.tracks.delete(id);
  }
}

function connect() {
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  const ws = new WebSocket(`${scheme}://${location.host}/ws`);
  state.socket = ws;
  ws.onmessage = (event) => {
    const m = JSON.parse(event.data);
    if (m.type === "layout") onLayout(m);
    else if (m.type === "frame") onFrame(m, false);
    else if (m.type === "status") onStatus(m);
    else if (m.type === "playback") showPlayback(m);
  };
  ws.onclose = () => {
    onStatus({ status: "disconnected", error: "the server closed the connection; retrying" });
    setTimeout(connect, 1000);
  };
}

function send(command, value) {
  if (state.socket && state.socket.readyState === WebSocket.OPEN) {
    state.socket.send(JSON.stringify({ command, value }));
  }
}

function loop(now) {
  if (state.dirty) draw();
  drawTraces(now);
  requestAnimationFrame(loop);
}

// ---- controls -----------------------------------------------------------------------

document.querySelectorAll('input[name="units"]').forEach((el) =>
  el.addEventListener("change", () => { state.units = el.value; refillTactelTrace(); state.dirty = true; }));
$("show-surface").addEventListener("change", (e) => { state.showSurface = e.target.checked; state.dirty = true; });
$("show-marker").addEventListener("change", (e) => { state.showMarker = e.target.checked; state.dirty = true; });
$("show-arrows").addEventListener("change", (e) => { state.showArrows = e.target.checked; state.dirty = true; });
canvas.addEventListener("click", (e) => {
  if (!state.layout) return;
  const rect = canvas.getBoundingClientRect();
  const t = tactelAt(e.clientX - rect.left, e.clientY - rect.top);
  if (t) { state.selected = t; refillTactelTrace(); state.dirty = true; }
});
$("rezero").addEventListener("click", () => send("rezero"));
document.addEventListener("keydown", (e) => {
  // z: re-zero (take the baseline anew from the next frames; lift everything first)
  if (e.key === "z" && !e.ctrlKey && !e.metaKey && !e.altKey && e.target.tagName !== "INPUT") send("rezero");
});
$("play").addEventListener("click", () => send($("play").textContent === "pause" ? "pause" : "play"));
$("step-back").addEventListener("click", () => send("step", -1));
$("step-fwd").addEventListener("click", () => send("step", 1));
$("seek").addEventListener("change", (e) => send("seek", Number(e.target.value)));
$("speed").addEventListener("change", (e) => send("speed", Number(e.target.value)));

connect();
requestAnimationFrame(loop);
