// tactsense view: taxels of several components (three-axis pads). Loaded before view.js,
// whose globals (state, ctx, planeCentre, xOfU, yOfV, TRACK_COLOURS) these functions use
// when called. The layout's `vector` says which component the map shows (the normal one)
// and in what unit; each frame's `tangential` (rows, cols, 2) is the change of the
// tangential components on the page's plane (u across, v up), drawn as an arrow per
// taxel; a contact's estimated shear (shear_u_n, shear_v_n [N]) as an arrow from the
// contact, its slip marked: partial (dashed amber ring), gross (thick red ring, "slip").
"use strict";

const ARROW = { reach: 0.48, min: 2, head: 6 };   // longest arrow [taxel spacings], px
const SHEAR_REACH = 1.5;   // a contact's arrow at Q/P = 1 [taxel spacings]
const SLIP_COLOURS = { stick: "#00e676", partial: "#ffab00", gross: "#ff1744", slip: "#ff1744" };

// the counts the map shows: the normal component's of a taxel of several components
function countsOf(frame) {
  const V = state.layout && state.layout.vector;
  if (!V) return frame.counts;
  if (!frame.mapCounts) {
    const k = V.normal_index;
    frame.mapCounts = frame.counts.map((row) => row.map((v) => v[k]));
  }
  return frame.mapCounts;
}

// the arrows' scale: the largest tangential change seen lately (decaying), at least the
// layout's floor (ten counts), so that noise alone draws short arrows
function updateArrowScale(frame) {
  const V = state.layout.vector;
  if (!V || !frame.tangential) return;
  let peak = 0;
  for (const row of frame.tangential) for (const [u, v] of row) peak = Math.max(peak, Math.hypot(u, v));
  state.tmax = Math.max(V.arrow_floor || 1e-9, peak, (state.tmax || 0) * 0.995);
}

function arrow(x0, y0, x1, y1, colour, width) {
  const len = Math.hypot(x1 - x0, y1 - y0);
  if (len < 1e-6) return;
  const head = Math.min(ARROW.head + width, 0.6 * len);
  const a = Math.atan2(y1 - y0, x1 - x0);
  ctx.lineCap = "round";
  for (const [stroke, w] of [["rgba(0,0,0,0.75)", width + 2], [colour, width]]) {
    ctx.strokeStyle = stroke; ctx.lineWidth = w;
    ctx.beginPath();
    ctx.moveTo(x0, y0); ctx.lineTo(x1, y1);
    ctx.moveTo(x1, y1); ctx.lineTo(x1 - head * Math.cos(a - 0.45), y1 - head * Math.sin(a - 0.45));
    ctx.moveTo(x1, y1); ctx.lineTo(x1 - head * Math.cos(a + 0.45), y1 - head * Math.sin(a + 0.45));
    ctx.stroke();
  }
}

// an arrow per taxel from its centre, along its tangential change (u across, v up)
function drawTaxelArrows(frame) {
  const L = state.layout;
  state.arrowMarks = [];
  if (!L.vector || !frame.tangential || !state.showArrows) return;
  const reach = ARROW.reach * L.spacing_mm * state.plane.scale;
  const k = reach / (state.tmax || 1);
  ctx.save();
  for (let r = 0; r < L.rows; r++) {
    for (let c = 0; c < L.cols; c++) {
      const [u, v] = frame.tangential[r][c];
      const [x0, y0] = planeCentre(r, c);
      const x1 = x0 + u * k, y1 = y0 - v * k;
      if (Math.hypot(x1 - x0, y1 - y0) >= ARROW.min) arrow(x0, y0, x1, y1, "#ffffff", 2);
      state.arrowMarks.push({ row: r, col: c, x0, y0, x1, y1, u, v });
    }
  }
  ctx.restore();
}

// a contact's estimated shear: an arrow from the contact, Q/P long (SHEAR_REACH spacings
// at 1), coloured by its slip; partial slip a dashed ring, gross slip a thick red ring
function drawContactShear(c, x, y, size) {
  const slip = c.slip_state;
  const colour = SLIP_COLOURS[slip] || "#ffffff";
  ctx.save();
  if (slip === "partial" || slip === "gross" || slip === "slip") {
    ctx.setLineDash(slip === "partial" ? [5, 4] : []);
    ctx.lineWidth = slip === "partial" ? 3 : 5; ctx.strokeStyle = colour;
    ctx.beginPath(); ctx.arc(x, y, size + 5, 0, 2 * Math.PI); ctx.stroke();
    ctx.setLineDash([]);
    ctx.font = "bold 12px system-ui, sans-serif"; ctx.textAlign = "left";
    const word = slip === "partial" ? "partial slip" : "slip";
    ctx.lineWidth = 3; ctx.strokeStyle = "#000"; ctx.strokeText(word, x + size + 3, y + size + 12);
    ctx.fillStyle = colour; ctx.fillText(word, x + size + 3, y + size + 12);
  }
  const mark = { id: c.id, x0: x, y0: y, x1: x, y1: y, slip: slip || null };
  if (Number.isFinite(c.shear_u_n) && Number.isFinite(c.shear_v_n)) {
    const q = Math.hypot(c.shear_u_n, c.shear_v_n);
    const p = Number.isFinite(c.force_n) && c.force_n > 0 ? c.force_n : q || 1;
    const reach = SHEAR_REACH * state.layout.spacing_mm * state.plane.scale * Math.min(q / p, 1.5);
    if (q > 0) {
      mark.x1 = x + (c.shear_u_n / q) * reach;
      mark.y1 = y - (c.shear_v_n / q) * reach;
      arrow(x, y, mark.x1, mark.y1, colour, 4);
    }
  }
  state.shearMarks.push(mark);
  ctx.restore();
}

// the side panel's shear columns of a contact: |Q| [N], its direction [deg] from +x
// toward +y, its slip
function shearCells(c) {
  const q = Number.isFinite(c.shear_n) ? c.shear_n
    : Number.isFinite(c.shear_x_n) && Number.isFinite(c.shear_y_n) ? Math.hypot(c.shear_x_n, c.shear_y_n) : null;
  const angle = Number.isFinite(c.shear_angle_deg) ? c.shear_angle_deg
    : Number.isFinite(c.shear_x_n) && Number.isFinite(c.shear_y_n) ? (180 / Math.PI) * Math.atan2(c.shear_y_n, c.shear_x_n) : null;
  const slip = { partial: "partial slip", gross: "gross slip", slip: "slip", stick: "stick" }[c.slip_state];
  return [q === null ? "–" : q.toFixed(4), angle === null ? "–" : angle.toFixed(1), slip || (c.slip ? "slip" : "")];
}

// once per layout: the radio's words, the arrows' checkbox and the table's columns
function onVectorLayout(L) {
  const V = L.vector;
  document.querySelectorAll(".shear-col").forEach((el) => { el.hidden = !V; });
  $("show-arrows").parentElement.hidden = !(V && V.arrow_label);
  const words = $("units-deflection");
  if (words) words.textContent = V ? ` ${V.map_label}` : " deflection [-]";
  state.tmax = 0;
  state.arrowMarks = [];
  state.shearMarks = [];
}
