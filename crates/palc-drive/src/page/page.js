// The study page: draws the server's frames from above at the display's frame
// rate, interpolating between ticks, and sends the participant's controls.
"use strict";

const canvas = document.getElementById("road");
const ctx = canvas.getContext("2d");
const keys = new Set();
let socket = null;
let seq = 0;
let previous = null;
let latest = null;
let latestAt = 0;
let takeOver = false;
let sent = "";

function connect() {
  socket = new WebSocket(`ws://${location.host}/ws`);
  socket.onmessage = (event) => {
    const message = JSON.parse(event.data);
    if (message.type === "frame") {
      previous = latest;
      latest = message.frame;
      latestAt = performance.now();
      if (latest.phase !== "driving") takeOver = false;
    } else if (message.type === "error") {
      document.getElementById("message").textContent = message.message;
    }
  };
  socket.onclose = () => {
    document.getElementById("progress").textContent = "connection lost: reload the page to go on";
  };
}

function send(message) {
  if (socket && socket.readyState === WebSocket.OPEN) {
    seq += 1;
    socket.send(JSON.stringify({ ...message, seq }));
  }
}

function axes() {
  let lateral = (keys.has("ArrowLeft") ? 1 : 0) - (keys.has("ArrowRight") ? 1 : 0);
  let speed = (keys.has("ArrowUp") ? 1 : 0) - (keys.has("ArrowDown") ? 1 : 0);
  for (const pad of navigator.getGamepads ? navigator.getGamepads() : []) {
    if (!pad) continue;
    if (pad.buttons[0] && pad.buttons[0].pressed) takeOver = true;
    if (Math.abs(pad.axes[0]) > 0.1) lateral = -pad.axes[0];
    if (Math.abs(pad.axes[1]) > 0.1) speed = -pad.axes[1];
  }
  const clamp = (x) => Math.max(-1, Math.min(1, x));
  return { lateral: clamp(lateral), speed: clamp(speed) };
}

function sendControls() {
  const { lateral, speed } = axes();
  const state = JSON.stringify([takeOver, lateral, speed]);
  if (state !== sent) {
    sent = state;
    send({ type: "control", take_over: takeOver, lateral, speed });
  }
}

document.addEventListener("keydown", (event) => {
  if (event.key === " ") {
    send({ type: "start" });
  } else if (event.key === "t" || event.key === "T") {
    takeOver = true;
  }
  keys.add(event.key);
  if (event.key.startsWith("Arrow") || event.key === " ") event.preventDefault();
  sendControls();
});
document.addEventListener("keyup", (event) => {
  keys.delete(event.key);
  sendControls();
});

const LANE = 3.5;
function draw(now) {
  sendControls();
  const w = canvas.width;
  const h = canvas.height;
  ctx.fillStyle = "#3a3f44";
  ctx.fillRect(0, 0, w, h);
  if (!latest) {
    requestAnimationFrame(draw);
    return;
  }
  const tick = 1000 * latest.dt;
  const a = Math.min(1, (now - latestAt) / tick);
  const mix = (p, q) => (previous && previous.step + 1 === latest.step ? p + (q - p) * a : q);
  const egoS = previous ? mix(previous.ego[0], latest.ego[0]) : latest.ego[0];
  const egoL = previous ? mix(previous.ego[1], latest.ego[1]) : latest.ego[1];
  const scale = 5; // pixels per metre
  const x = (s) => w * 0.15 + (s - egoS) * scale;
  const y = (l) => h / 2 + LANE * scale - l * scale;
  // The road: two lanes, edges and the marking between them.
  ctx.fillStyle = "#55595e";
  ctx.fillRect(0, y(LANE * 1.5), w, 2 * LANE * scale);
  ctx.strokeStyle = "#f0f0f0";
  ctx.lineWidth = 2;
  ctx.setLineDash([]);
  for (const l of [-LANE / 2, LANE * 1.5]) {
    ctx.beginPath(); ctx.moveTo(0, y(l)); ctx.lineTo(w, y(l)); ctx.stroke();
  }
  ctx.setLineDash([24, 24]);
  ctx.lineDashOffset = egoS * scale;
  ctx.beginPath(); ctx.moveTo(0, y(LANE / 2)); ctx.lineTo(w, y(LANE / 2)); ctx.stroke();
  ctx.setLineDash([]);
  // The plan ahead.
  if (latest.plan.length > 0) {
    ctx.strokeStyle = "#4fc3f7";
    ctx.lineWidth = 3;
    ctx.beginPath();
    latest.plan.forEach(([s, l], i) => (i === 0 ? ctx.moveTo(x(s), y(l)) : ctx.lineTo(x(s), y(l))));
    ctx.stroke();
  }
  // The other vehicles, then the ego.
  latest.vehicles.forEach((v, i) => {
    const p = previous && previous.vehicles[i] ? previous.vehicles[i] : v;
    const s = mix(p[0], v[0]);
    ctx.fillStyle = "#c0c4c8";
    ctx.fillRect(x(s) - v[2] * scale, y(v[1]) - (v[3] * scale) / 2, v[2] * scale, v[3] * scale);
  });
  ctx.fillStyle = latest.taken_over ? "#ff7043" : "#66bb6a";
  ctx.fillRect(x(egoS) - 5 * scale, y(egoL) - 0.9 * scale, 5 * scale, 1.8 * scale);
  document.getElementById("speed").textContent = `${(latest.ego[2] * 3.6).toFixed(0)} km/h`;
  document.getElementById("progress").textContent =
    `scene ${Math.min(latest.scene + 1, latest.scenes)} of ${latest.scenes} · ` +
    `lane change ${latest.lane_changes + (latest.phase === "driving" ? 1 : 0)} · takeovers ${latest.takeovers}`;
  const states = {
    ready: "Press Space to start the next lane change",
    driving: latest.taken_over ? "You are driving" : "palc is driving",
    paused: "Paused: press Space to go on",
    done: "The study is complete. Thank you!",
  };
  document.getElementById("state").textContent = states[latest.phase] || latest.phase;
  requestAnimationFrame(draw);
}

connect();
requestAnimationFrame(draw);
