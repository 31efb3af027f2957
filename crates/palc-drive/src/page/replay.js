// The replay viewer: a record read in the browser (nothing is sent to the
// server), replayed lane change by lane change: the planned, expected and driven
// lateral paths over the lane change's steps, the takeover marked, and the
// learned weights beside them when the record holds them.
"use strict";

let changes = [];
let weights = null;
let shown = 0;

// The lane changes and weights of a record: a run (`palc learn --record`, a
// study's scene-N.json) or a study's JSONL session record.
function parse(text) {
  const trimmed = text.trim();
  if (trimmed.startsWith("{") && !trimmed.includes("\n{")) {
    const run = JSON.parse(trimmed);
    return { changes: run.records || [], weights: run.experience ? run.experience.weights : null };
  }
  const records = [];
  for (const line of trimmed.split("\n")) {
    try {
      const event = JSON.parse(line);
      if (event.event === "lane_change") records.push(event.record);
    } catch (error) {
      // A torn last line of a killed session is skipped.
    }
  }
  return { changes: records, weights: null };
}

function path(ctx, values, x, y, colour, dashed) {
  if (!values || values.length === 0) return;
  ctx.strokeStyle = colour;
  ctx.lineWidth = 2.5;
  ctx.setLineDash(dashed ? [8, 6] : []);
  ctx.beginPath();
  values.forEach((v, i) => (i === 0 ? ctx.moveTo(x(i), y(v)) : ctx.lineTo(x(i), y(v))));
  ctx.stroke();
  ctx.setLineDash([]);
}

function draw() {
  const canvas = document.getElementById("paths");
  const ctx = canvas.getContext("2d");
  ctx.fillStyle = "#3a3f44";
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  const change = changes[shown];
  if (!change) return;
  const steps = Math.max(change.planned_l.length, change.driven_l.length, 2);
  const x = (i) => 40 + (i / (steps - 1)) * (canvas.width - 60);
  const y = (l) => canvas.height - 40 - ((l + 1.75) / 7) * (canvas.height - 60);
  // The lanes: edges, the marking, the lane centres.
  ctx.strokeStyle = "#888";
  for (const l of [-1.75, 1.75, 5.25]) {
    ctx.setLineDash(l === 1.75 ? [12, 12] : []);
    ctx.beginPath(); ctx.moveTo(x(0), y(l)); ctx.lineTo(x(steps - 1), y(l)); ctx.stroke();
  }
  path(ctx, change.expected_l, x, y, "#bbbbbb", true);
  path(ctx, change.planned_l, x, y, "#4fc3f7", false);
  path(ctx, change.driven_l, x, y, "#ff7043", false);
  if (change.takeover) {
    const i = change.takeover.step;
    ctx.strokeStyle = "#ef5350";
    ctx.beginPath(); ctx.moveTo(x(i), y(-1.75)); ctx.lineTo(x(i), y(5.25)); ctx.stroke();
    ctx.fillStyle = "#ef5350";
    ctx.beginPath(); ctx.arc(x(i), y(change.driven_l[i] || 0), 6, 0, 2 * Math.PI); ctx.fill();
  }
  ctx.fillStyle = "#e8e8e8";
  ctx.font = "14px sans-serif";
  ctx.fillText(`step (dt ${change.dt} s)`, canvas.width - 140, canvas.height - 12);
  const takeover = change.takeover ? `takeover at step ${change.takeover.step}` : "no takeover";
  document.getElementById("lane-change").textContent =
    `lane change ${shown + 1} of ${changes.length}: ${takeover}, ` +
    `largest deviation ${change.max_deviation_m.toFixed(2)} m`;
  drawWeights();
}

function drawWeights() {
  const canvas = document.getElementById("weights");
  const ctx = canvas.getContext("2d");
  ctx.fillStyle = "#2b2f33";
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  if (!weights || weights.length === 0) return;
  const x = (i) => 40 + (i / Math.max(weights.length - 1, 1)) * (canvas.width - 60);
  for (const [row, colour] of [[0, "#ffd54f"], [1, "#81c784"]]) {
    const values = weights.map((column) => column[row]);
    const top = Math.max(...values.map(Math.abs), 1e-12);
    const y = (w) => canvas.height / 2 - (w / top) * (canvas.height / 2 - 10);
    path(ctx, values, x, y, colour, false);
  }
}

document.getElementById("file").addEventListener("change", async (event) => {
  const file = event.target.files[0];
  if (!file) return;
  try {
    const parsed = parse(await file.text());
    changes = parsed.changes;
    weights = parsed.weights;
    shown = 0;
    const takeovers = changes.filter((c) => c.takeover).length;
    document.getElementById("summary").textContent =
      `${file.name}: ${changes.length} lane changes, ${takeovers} takeovers`;
    draw();
  } catch (error) {
    document.getElementById("summary").textContent = `${file.name} is not a record: ${error}`;
  }
});
document.getElementById("previous").addEventListener("click", () => { shown = Math.max(0, shown - 1); draw(); });
document.getElementById("next").addEventListener("click", () => { shown = Math.min(changes.length - 1, shown + 1); draw(); });
document.addEventListener("keydown", (event) => {
  if (event.key === "ArrowLeft") { shown = Math.max(0, shown - 1); draw(); }
  if (event.key === "ArrowRight") { shown = Math.min(changes.length - 1, shown + 1); draw(); }
});
