// Style sheet and script of the `pbvbus timeline` HTML page (see timeline_render.hpp for the
// data the page reads).
#include "timeline_page.hpp"

namespace pbvbus::captures::detail {

const char* const kTimelineCss = R"CSS(
:root { --fg: #1d2126; --muted: #68717d; --line: #d5dae0; --bg: #ffffff; }
* { box-sizing: border-box; }
body { margin: 0; font: 13px/1.35 system-ui, "DejaVu Sans", Arial, sans-serif; color: var(--fg); background: var(--bg); }
header { padding: 8px 14px 6px; border-bottom: 1px solid var(--line); background: #f7f8fa; }
h1 { font-size: 16px; margin: 0 0 2px; font-weight: 600; }
h1 .file { font-weight: 400; color: var(--muted); }
#info { color: var(--muted); font-size: 12px; }
.bar { display: flex; flex-wrap: wrap; align-items: center; gap: 6px 14px; margin-top: 6px; }
.controls button { font: inherit; padding: 1px 9px; margin-right: 2px; border: 1px solid #b9c0c8; border-radius: 4px; background: #fff; cursor: pointer; }
.controls button:hover { background: #eef3fb; }
#status { font-variant-numeric: tabular-nums; color: var(--fg); }
.legend { display: flex; flex-wrap: wrap; gap: 4px 12px; font-size: 12px; align-items: center; }
.legend .sw { display: inline-block; width: 14px; height: 10px; margin-right: 4px; vertical-align: -1px; border-radius: 2px; }
.legend .vl { display: inline-block; width: 3px; height: 12px; margin-right: 4px; vertical-align: -2px; }
.legend b { font-weight: 600; margin-right: 2px; }
#chart { position: relative; user-select: none; cursor: grab; }
#chart.drag { cursor: grabbing; }
#chart svg { display: block; }
#chart text { font-family: system-ui, "DejaVu Sans", Arial, sans-serif; }
#tip { position: fixed; z-index: 10; pointer-events: none; background: rgba(255,255,255,0.97); border: 1px solid #9aa3ad;
       border-radius: 4px; padding: 6px 8px; font: 12px/1.35 ui-monospace, "DejaVu Sans Mono", monospace;
       white-space: pre; max-width: 720px; box-shadow: 0 2px 8px rgba(0,0,0,0.18); }
#tip[hidden] { display: none; }
section { padding: 6px 14px 10px; }
h2 { font-size: 14px; margin: 6px 0; font-weight: 600; }
table { border-collapse: collapse; font-variant-numeric: tabular-nums; }
th, td { border-bottom: 1px solid var(--line); padding: 2px 10px 2px 0; text-align: right; white-space: nowrap; }
th { color: var(--muted); font-weight: 600; }
td:first-child, th:first-child { text-align: left; }
.help { color: var(--muted); font-size: 12px; margin: 4px 14px 14px; }
)CSS";

const char* const kTimelineJs = R"JS(
(function () {
'use strict';
const D = JSON.parse(document.getElementById('pbvbus-data').textContent);
const KIND_NAMES = ['token', 'request', 'response', 'SC', 'bad'];
const KIND_COLOURS = ['#8446c2', '#2468c9', '#2f9e48', '#13a3b4', '#e03131'];
const HOLDER_COLOURS = ['#f6bd60', '#90caf9', '#b8e0a0', '#f7a8c4', '#cdb4f0', '#ffe08a', '#9fd8cb',
  '#f4a582', '#c7d2fe', '#d9ed92', '#e5c3a6', '#a5d8ff'];
const EVENT_COLOURS = { fault: '#e8590c', repair: '#2b8a3e', event: '#5f3dc4' };
const DX_OK = '#3f9b57', DX_MISS = '#e03131';
// Colours of the lanes in the active-channel rows (by lane index).
const LANE_COLOURS = ['#1c7ed6', '#f59f00', '#0ca678', '#ae3ec9', '#d6336c', '#74b816'];
const ROW_AC = 14;
// CPU rows (docs/h-system.md): colours by state number (cpu_event.hpp), as the SVG's.
const CPU_STATE_COLOURS = ['#ced4da', '#e03131', '#fab005', '#2f9e44', '#74c0fc', '#1971c2', '#f76707',
  '#9c36b5', '#5c0a0a', '#15aabf'];
const ROW_CPU = 22, OB_COLOUR = '#212529';
// Quantum Hot Standby rows (docs/quantum-hsby.md): off, offline, primary, standby, as the SVG's.
const HSBY_STATE_COLOURS = ['#ced4da', '#fab005', '#2f9e44', '#1971c2'];
const SWITCHOVER_COLOUR = '#c2255c';
const LABEL_W = 210, AXIS_H = 34, EV_H = 46, PAD_R = 18;
const ROW_FRAMES = 30, ROW_TOKEN = 18, ROW_RULER = 20, ROW_DX = 14, LANE_GAP = 18, ROW_MPI = 16;
const MIN_SPAN = 100;  // ns: a few bit times even at 12 Mbit/s

const chart = document.getElementById('chart');
const svg = document.getElementById('svg');
const tip = document.getElementById('tip');
const status = document.getElementById('status');
const origin = Number(D.origin);
const ents = D.ent;
const entLen = ents.map(e => e[0].length / 2);

function esc(s) {
  return String(s).replace(/[&<>"']/g, c => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' }[c]));
}
function lowerBound(a, x, lo, hi) {
  lo = lo || 0; hi = hi === undefined ? a.length : hi;
  while (lo < hi) { const m = (lo + hi) >>> 1; if (a[m] < x) lo = m + 1; else hi = m; }
  return lo;
}
function bitsOf(ns, speed) {
  if (!speed) return null;
  const v = ns * speed / 1e9;
  return v < 0 ? -Math.round(-v) : Math.round(v);
}
function speedText(s) {
  if (!s) return 'speed unknown';
  if (s >= 1e6) return (s / 1e6).toString() + ' Mbit/s';
  if (s >= 1e3) return (s / 1e3).toString() + ' kbit/s';
  return s + ' bit/s';
}
function group3(digits) { return digits.replace(/(\d{3})(?=\d)/g, '$1\u2009'); }
// Absolute time of a relative time, as seconds with `dec` decimals (0..9), digits grouped.
function fmtAbs(t, dec) {
  let ns = Math.round(origin + t);
  const neg = ns < 0; if (neg) ns = -ns;
  const s = Math.floor(ns / 1e9);
  let frac = String(ns - s * 1e9).padStart(9, '0').slice(0, dec);
  return (neg ? '-' : '') + s + (dec > 0 ? '.' + group3(frac) : '') + ' s';
}
function fmtDur(ns) {
  const a = Math.abs(ns);
  if (a < 1e3) return ns.toFixed(0) + ' ns';
  if (a < 1e6) return (ns / 1e3).toFixed(3) + ' \u00b5s';
  if (a < 1e9) return (ns / 1e6).toFixed(3) + ' ms';
  return (ns / 1e9).toFixed(6) + ' s';
}
function fmtBits(ns, speed) {
  const b = bitsOf(ns, speed);
  return b === null ? '' : ' = ' + b + ' bit times';
}
function niceStep(raw) {
  const p = Math.pow(10, Math.floor(Math.log10(raw)));
  const m = raw / p;
  return (m <= 1 ? 1 : m <= 2 ? 2 : m <= 5 ? 5 : 10) * p;
}
function hexSpaced(h) { return h.replace(/(..)(?!$)/g, '$1 '); }

// ---- data -------------------------------------------------------------------------------
const holderSet = new Set();
const lanes = D.lanes.map(L => {
  const n = L.t.length;
  const start = new Float64Array(n), end = new Float64Array(n), kind = new Uint8Array(n);
  let t = 0, maxDur = 0;
  for (let i = 0; i < n; i++) {
    t += L.t[i]; start[i] = t;
    const e = L.e[i];
    const dur = L.speed > 0 ? Math.floor(entLen[e] * 11e9 / L.speed) : 0;
    end[i] = t + dur; kind[i] = ents[e][1];
    if (dur > maxDur) maxDur = dur;
  }
  const m = L.tk.length;
  const ts = new Float64Array(m), te = new Float64Array(m);
  t = 0;
  for (let i = 0; i < m; i++) { t += L.tk[i]; ts[i] = t; te[i] = t + L.tl[i]; holderSet.add(L.th[i]); }
  const dx = L.dx.map(S => {
    const k = S.t.length, tt = new Float64Array(k);
    let u = 0;
    for (let i = 0; i < k; i++) { u += S.t[i]; tt[i] = u; }
    return { a: S.a, t: tt, c0: S.c0, m: S.m, un: S.un, unSet: new Set(S.un) };
  });
  // MPI connections: label, spans [start, end, state], marks [t, pdu, from initiator, text].
  const mpi = (L.mpi || []).map(C => ({ l: C.l, s: C.s, m: C.m, mt: Float64Array.from(C.m.map(m => m[0])) }));
  return { name: L.name, desc: L.desc, speed: L.speed, iface: L['if'], start, end, kind, maxDur,
           e: L.e, ts, te, th: L.th, tp: L.tp, dx, mpi };
});
const holders = Array.from(holderSet).sort((a, b) => a - b);
const holderColour = {};
holders.forEach((h, i) => { holderColour[h] = HOLDER_COLOURS[i % HOLDER_COLOURS.length]; });
const events = D.ev.map(e => ({ t: e[0], style: e[1], cat: e[2], text: e[3] }));
const evTimes = Float64Array.from(events.map(e => e.t));
// Active channel per switched station: spans [start, end, lane, line].
const acRows = (D.ac || []).map(R => ({ a: R.a, s: R.s }));
function laneColour(i) { return LANE_COLOURS[i % LANE_COLOURS.length]; }
let acY = 0;
// CPU rows: label, system, rack, spans [start, end, state, role], OB marks [t, ob, id, reason, text].
const CPU = D.cpu || { states: [], roles: [], rows: [] };
const cpuRows = CPU.rows;
function cpuStateName(n) { return CPU.states[n] !== undefined ? CPU.states[n] : 'state ' + n; }
function cpuRoleName(n) { return CPU.roles[n] !== undefined ? CPU.roles[n] : 'role ' + n; }
function cpuStateColour(n) { return CPU_STATE_COLOURS[n] || '#868e96'; }
// Dark text on the light colours (OFF, STARTUP, LINK-UP).
function cpuTextColour(n) { return n === 0 || n === 2 || n === 4 ? '#1d2126' : '#fff'; }
function cpuLabel(sp) { return cpuStateName(sp[2]) + (sp[3] === 0 ? '' : ' ' + cpuRoleName(sp[3])); }
let cpuY = 0;
// Quantum rows: label, pair, rack, spans [start, end, state], switchovers [t, takeover ns, text].
const HSBY = D.hsby || { states: [], rows: [] };
const hsbyRows = HSBY.rows;
function hsbyStateName(n) { return HSBY.states[n] !== undefined ? HSBY.states[n] : 'state ' + n; }
function hsbyStateColour(n) { return HSBY_STATE_COLOURS[n] || '#868e96'; }
function hsbyTextColour(n) { return n === 0 || n === 1 ? '#1d2126' : '#fff'; }
let hsbyY = 0;

// ---- view -------------------------------------------------------------------------------
const full = [D.span[0], D.span[1]];
if (!(full[1] > full[0])) full[1] = full[0] + 1000;
const initial = [D.view[0], D.view[1]];
let v0 = initial[0], v1 = initial[1];
let ref = null;  // bit ruler origin: {lane, t, what}
(function fromHash() {
  const m = /^#v=(-?[\d.e+]+),(-?[\d.e+]+)$/.exec(location.hash);
  if (m) { const a = Number(m[1]), b = Number(m[2]); if (b > a) { v0 = a; v1 = b; } }
})();

let plotX = LABEL_W, plotW = 800, scale = 1, totalH = 0;
function X(t) { return plotX + (t - v0) * scale; }
function T(x) { return v0 + (x - plotX) / scale; }

function setView(a, b) {
  let span = b - a;
  const maxSpan = (full[1] - full[0]) * 1.5 + MIN_SPAN;
  if (span < MIN_SPAN) { const c = (a + b) / 2; a = c - MIN_SPAN / 2; b = c + MIN_SPAN / 2; span = MIN_SPAN; }
  if (span > maxSpan) { const c = (a + b) / 2; a = c - maxSpan / 2; b = c + maxSpan / 2; span = maxSpan; }
  const lo = full[0] - span * 0.5, hi = full[1] + span * 0.5;
  if (a < lo) { a = lo; b = lo + span; }
  if (b > hi) { b = hi; a = hi - span; }
  v0 = a; v1 = b;
  schedule();
}
function zoom(f, at) {
  if (at === undefined) at = (v0 + v1) / 2;
  setView(at - (at - v0) * f, at + (v1 - at) * f);
}
function pan(frac) { const d = (v1 - v0) * frac; setView(v0 + d, v1 + d); }

let pending = false;
function schedule() {
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => { pending = false; render(); });
}

// ---- layout -----------------------------------------------------------------------------
function layout() {
  let y = AXIS_H + EV_H;
  for (const L of lanes) {
    L.y = y;
    L.yF = y; L.yT = L.yF + ROW_FRAMES + 3; L.yR = L.yT + ROW_TOKEN + 2; L.yD = L.yR + ROW_RULER;
    L.yM = L.yD + L.dx.length * ROW_DX;
    L.h = L.yM + L.mpi.length * ROW_MPI - y;
    y += L.h + LANE_GAP;
  }
  acY = y;
  if (acRows.length) y += acRows.length * ROW_AC + LANE_GAP;
  cpuY = y;
  if (cpuRows.length) y += cpuRows.length * ROW_CPU + LANE_GAP;
  hsbyY = y;
  if (hsbyRows.length) y += hsbyRows.length * ROW_CPU + LANE_GAP;
  totalH = y;
}
layout();

// ---- drawing ----------------------------------------------------------------------------
function drawAxis(s) {
  const span = v1 - v0;
  const step = niceStep(span / Math.max(2, plotW / 130));
  const dec = Math.max(0, Math.min(9, Math.ceil(-Math.log10(step / 1e9) - 1e-9)));
  s.push('<g class="axis">');
  s.push(`<rect x="0" y="0" width="${plotX + plotW + PAD_R}" height="${AXIS_H}" fill="#f7f8fa"/>`);
  s.push(`<text x="${LABEL_W - 10}" y="21" text-anchor="end" font-size="12" fill="#68717d">time</text>`);
  const first = Math.ceil((origin + v0) / step) * step - origin;
  for (let t = first, k = 0; t <= v1 && k < 200; t += step, k++) {
    const x = X(t);
    s.push(`<line x1="${x.toFixed(1)}" y1="${AXIS_H - 8}" x2="${x.toFixed(1)}" y2="${totalH}" stroke="#e6e9ed"/>`);
    s.push(`<line x1="${x.toFixed(1)}" y1="${AXIS_H - 8}" x2="${x.toFixed(1)}" y2="${AXIS_H}" stroke="#68717d"/>`);
    const anchor = x < plotX + 40 ? 'start' : (x > plotX + plotW - 40 ? 'end' : 'middle');
    s.push(`<text x="${x.toFixed(1)}" y="${AXIS_H - 12}" text-anchor="${anchor}" font-size="11" fill="#1d2126">${esc(fmtAbs(t, dec))}</text>`);
  }
  s.push(`<line x1="${plotX}" y1="${AXIS_H}" x2="${plotX + plotW}" y2="${AXIS_H}" stroke="#68717d"/>`);
  s.push('</g>');
}

function frameRange(L) {
  return [lowerBound(L.start, v0 - L.maxDur), lowerBound(L.start, v1)];
}

let drawnFrames = 0;
function drawFrames(s, L) {
  const [i0, i1] = frameRange(L);
  const y = L.yF, h = ROW_FRAMES;
  s.push(`<rect x="${plotX}" y="${y}" width="${plotW}" height="${h}" fill="#fbfbfc" stroke="#e2e5e9"/>`);
  let n = 0;
  for (let i = i0; i < i1; i++) if (L.end[i] > v0 || L.end[i] === L.start[i]) n++;
  if (n <= 2500) {
    for (let i = i0; i < i1; i++) {
      if (!(L.end[i] > v0 || L.end[i] === L.start[i])) continue;
      const xa = Math.max(plotX, X(L.start[i])), xb = Math.min(plotX + plotW, X(L.end[i]));
      const w = Math.max(1, xb - xa);
      const k = L.kind[i];
      s.push(`<rect x="${xa.toFixed(2)}" y="${y + 3}" width="${w.toFixed(2)}" height="${h - 6}" fill="${KIND_COLOURS[k]}"/>`);
      if (w > 34) {
        const label = D.desc[ents[L.e[i]][3]];
        const fit = Math.floor((w - 6) / 6.4);
        if (fit >= 3) {
          const txt = label.length > fit ? label.slice(0, fit - 1) + '\u2026' : label;
          s.push(`<text x="${(xa + 3).toFixed(2)}" y="${y + h / 2 + 4}" font-size="11" fill="#fff">${esc(txt)}</text>`);
        }
      }
      drawnFrames++;
    }
    return;
  }
  // Aggregated: per pixel the time share of each kind; colour of the largest share (bad wins),
  // opacity by how busy the pixel is.
  const W = Math.ceil(plotW), occ = new Float32Array(W * 5);
  for (let i = i0; i < i1; i++) {
    const a = (L.start[i] - v0) * scale, b = (L.end[i] - v0) * scale;
    if (b <= 0 && b !== a) continue;
    const k = L.kind[i];
    let p = Math.max(0, Math.floor(a));
    const pe = Math.min(W - 1, Math.floor(b));
    if (a === b) { if (p < W) occ[p * 5 + k] += 0.15; continue; }
    for (; p <= pe; p++) {
      const ov = Math.min(b, p + 1) - Math.max(a, p);
      if (ov > 0) occ[p * 5 + k] += ov;
    }
    drawnFrames++;
  }
  let runStart = -1, runKey = '';
  const flush = (end) => {
    if (runStart < 0) return;
    const [k, o] = runKey.split('/');
    s.push(`<rect x="${plotX + runStart}" y="${y + 3}" width="${end - runStart}" height="${h - 6}" fill="${KIND_COLOURS[k]}" fill-opacity="${o}"/>`);
    runStart = -1;
  };
  for (let p = 0; p < W; p++) {
    let tot = 0, best = -1, bv = 0;
    for (let k = 0; k < 5; k++) { const v = occ[p * 5 + k]; tot += v; if (v > bv) { bv = v; best = k; } }
    if (occ[p * 5 + 4] > 0) best = 4;
    const key = best < 0 ? '' : best + '/' + (0.3 + 0.7 * Math.min(1, tot)).toFixed(1);
    if (key !== runKey) { flush(p); if (key) runStart = p; runKey = key; }
  }
  flush(W);
}

function drawToken(s, L) {
  const y = L.yT, h = ROW_TOKEN;
  s.push(`<rect x="${plotX}" y="${y}" width="${plotW}" height="${h}" fill="#fbfbfc" stroke="#e2e5e9"/>`);
  const i0 = Math.max(0, lowerBound(L.te, v0)), i1 = lowerBound(L.ts, v1);
  let bucket = -1, acc = {};
  const flush = () => {
    if (bucket < 0) return;
    let best = null, bv = -1;
    for (const k in acc) if (acc[k] > bv) { bv = acc[k]; best = k; }
    s.push(`<rect x="${plotX + bucket}" y="${y + 2}" width="1" height="${h - 4}" fill="${holderColour[best]}"/>`);
    bucket = -1; acc = {};
  };
  for (let i = i0; i < i1; i++) {
    const xa = Math.max(plotX, X(L.ts[i])), xb = Math.min(plotX + plotW, X(L.te[i]));
    if (xb < plotX) continue;
    const w = xb - xa, hd = L.th[i];
    if (w >= 1) {
      flush();
      s.push(`<rect x="${xa.toFixed(2)}" y="${y + 2}" width="${w.toFixed(2)}" height="${h - 4}" fill="${holderColour[hd]}"/>`);
      const label = w >= 26 ? L.tp[i] + '\u2192' + hd : (w >= 12 ? String(hd) : '');
      if (label) s.push(`<text x="${((xa + xb) / 2).toFixed(1)}" y="${y + h / 2 + 4}" text-anchor="middle" font-size="11" fill="#1d2126">${label}</text>`);
    } else {
      const p = Math.floor(xa - plotX);
      if (p !== bucket) { flush(); bucket = p; }
      acc[hd] = (acc[hd] || 0) + w;
    }
  }
  flush();
}

function drawRuler(s, L) {
  if (!L.speed) return;
  s.push(`<g class="bit-axis" data-speed="${L.speed}">`);
  drawRulerTicks(s, L);
  s.push('</g>');
}
function drawRulerTicks(s, L) {
  const y = L.yR;
  const bitNs = 1e9 / L.speed;
  const spanBits = (v1 - v0) / bitNs;
  if (spanBits > 6000) {
    s.push(`<text class="bit-axis-hint" x="${plotX + 4}" y="${y + 13}" font-size="10" fill="#9aa3ad">zoom in below ${fmtDur(6000 * bitNs)} for a bit-time axis</text>`);
    return;
  }
  const o = ref && ref.lane === L ? ref.t : 0;
  const step = Math.max(1, niceStep(spanBits / Math.max(2, plotW / 90)));
  s.push(`<line x1="${plotX}" y1="${y + 3}" x2="${plotX + plotW}" y2="${y + 3}" stroke="#495057"/>`);
  const firstBit = Math.ceil((v0 - o) / bitNs / step) * step;
  for (let b = firstBit, k = 0; o + b * bitNs <= v1 && k < 400; b += step, k++) {
    const x = X(o + b * bitNs);
    s.push(`<line x1="${x.toFixed(2)}" y1="${y + 3}" x2="${x.toFixed(2)}" y2="${y + 8}" stroke="#495057"/>`);
    s.push(`<text class="bit-tick" x="${x.toFixed(2)}" y="${y + 18}" text-anchor="middle" font-size="10" fill="#343a40">${group3(String(b))}</text>`);
  }
  if (spanBits <= 600) {
    const minor = step >= 10 ? step / 5 : (step >= 2 ? 1 : 0);
    if (minor) {
      const fb = Math.ceil((v0 - o) / bitNs / minor) * minor;
      for (let b = fb, k = 0; o + b * bitNs <= v1 && k < 1000; b += minor, k++) {
        const x = X(o + b * bitNs);
        s.push(`<line x1="${x.toFixed(2)}" y1="${y + 3}" x2="${x.toFixed(2)}" y2="${y + 5}" stroke="#868e96"/>`);
      }
    }
  }
  if (ref && ref.lane === L && ref.t >= v0 && ref.t <= v1) {
    const x = X(ref.t);
    s.push(`<line x1="${x.toFixed(2)}" y1="${L.yF}" x2="${x.toFixed(2)}" y2="${y + 8}" stroke="#212529" stroke-dasharray="3,2"/>`);
  }
}

function drawDx(s, L) {
  L.dx.forEach((S, j) => {
    const y = L.yD + j * ROW_DX;
    s.push(`<rect x="${plotX}" y="${y}" width="${plotW}" height="${ROW_DX - 1}" fill="${j % 2 ? '#fbfbfc' : '#f4f6f8'}"/>`);
    const i0 = lowerBound(S.t, v0), i1 = lowerBound(S.t, v1);
    const dense = (i1 - i0) > plotW / 3;
    let last = -1e9;
    for (let i = i0; i < i1; i++) {
      const x = X(S.t[i]);
      const miss = S.unSet.has(i);
      if (dense && !miss && x - last < 1) continue;
      last = x;
      s.push(`<rect x="${(x - 0.5).toFixed(2)}" y="${y + 2}" width="${dense ? 1 : 2}" height="${ROW_DX - 5}" fill="${miss ? DX_MISS : DX_OK}"/>`);
      if (!dense && i + 1 < S.t.length) {
        const x2 = X(S.t[i + 1]);
        if (x2 - x > 70) {
          const c = S.t[i + 1] - S.t[i];
          s.push(`<text x="${((x + Math.min(x2, plotX + plotW)) / 2).toFixed(1)}" y="${y + ROW_DX - 4}" text-anchor="middle" font-size="10" fill="#495057">${esc(fmtDur(c))}</text>`);
        }
      }
    }
  });
}

// MPI connection rows (timeline.hpp "MPI connections"), as in the SVG.
const MPI_STATE_NAMES = ['connecting', 'connected'];
function mpiSpanColour(st) { return st === 1 ? '#a5d8ff' : '#dee2e6'; }
function mpiMarkColour(m) {
  switch (m[1]) {
    case 0xE0: case 0xD0: return '#7048e8';
    case 0x05: return '#868e96';
    case 0xF1: return m[2] ? '#1971c2' : '#2b8a3e';
    case 0xB0: return '#adb5bd';
    case 0x80: return '#e8590c';
  }
  return '#495057';
}
let drawnMpiMarks = 0;
function drawMpi(s, L) {
  L.mpi.forEach((C, j) => {
    const y = L.yM + j * ROW_MPI;
    s.push(`<g class="mpi-conn" data-conn="${esc(C.l)}"><rect x="${plotX}" y="${y}" width="${plotW}" height="${ROW_MPI - 1}" fill="${j % 2 ? '#fbfbfc' : '#f4f6f8'}"/>`);
    for (const sp of C.s) {
      if (sp[1] < v0 || sp[0] > v1) continue;
      const xa = Math.max(plotX, X(sp[0])), xb = Math.min(plotX + plotW, X(sp[1]));
      s.push(`<rect class="mpi-span" data-state="${MPI_STATE_NAMES[sp[2]]}" x="${xa.toFixed(2)}" y="${y + 3}" width="${Math.max(1, xb - xa).toFixed(2)}" height="${ROW_MPI - 7}" fill="${mpiSpanColour(sp[2])}"/>`);
    }
    const i0 = lowerBound(C.mt, v0), i1 = lowerBound(C.mt, v1);
    const dense = (i1 - i0) > plotW / 3;
    let last = -1e9;
    for (let i = i0; i < i1; i++) {
      const x = X(C.mt[i]);
      if (dense && x - last < 1) continue;
      last = x;
      s.push(`<rect class="mpi-mark" data-pdu="${C.m[i][1]}" x="${(x - 0.5).toFixed(2)}" y="${y + 1}" width="${dense ? 1 : 2}" height="${ROW_MPI - 3}" fill="${mpiMarkColour(C.m[i])}"/>`);
      drawnMpiMarks++;
    }
    s.push('</g>');
  });
}
function mpiText(L, C, t, tol) {
  const j = lowerBound(C.mt, t - tol);
  const near = [];
  for (let i = j; i < C.mt.length && C.mt[i] <= t + tol && near.length < 20; i++)
    near.push(`${fmtAbs(C.m[i][0], 9)}  ${D.desc[C.m[i][3]]}`);
  if (near.length) return `MPI ${C.l}   lane ${L.name}\n` + near.join('\n');
  for (const sp of C.s)
    if (t >= sp[0] - tol && t <= sp[1] + tol)
      return `MPI ${C.l}   ${MPI_STATE_NAMES[sp[2]]}\nfrom ${fmtAbs(sp[0], 9)}\nto   ${fmtAbs(sp[1], 9)}\nfor  ${fmtDur(sp[1] - sp[0])}`;
  return null;
}

function drawLabels(s, L) {
  s.push(`<rect x="0" y="${L.y - 6}" width="${LABEL_W - 8}" height="${L.h + 12}" fill="#f7f8fa"><title>${esc(`interface ${L.iface}: ${L.name} \u2014 ${L.desc || 'no description'}, ${speedText(L.speed)}`)}</title></rect>`);
  if (acRows.length) s.push(`<rect class="lane-colour" x="3" y="${L.yF + 1}" width="4" height="${ROW_FRAMES - 2}" fill="${laneColour(lanes.indexOf(L))}"/>`);
  s.push(`<text x="12" y="${L.yF + 13}" font-size="14" font-weight="600" fill="#1d2126">${esc(L.name || '(no name)')}</text>`);
  s.push(`<text x="12" y="${L.yF + 27}" font-size="11" fill="#68717d">${esc(speedText(L.speed))} \u00b7 if ${L.iface}</text>`);
  const r = (y, t) => s.push(`<text x="${LABEL_W - 12}" y="${y}" text-anchor="end" font-size="11" fill="#495057">${esc(t)}</text>`);
  r(L.yT + 13, 'token holder');
  r(L.yR + 14, ref && ref.lane === L ? 'bit times from ref' : 'bit times');
  L.dx.forEach((S, j) => r(L.yD + j * ROW_DX + 11, 'DX slave ' + S.a));
  L.mpi.forEach((C, j) => r(L.yM + j * ROW_MPI + 12, 'MPI ' + C.l));
}

function acLineName(sp) {
  if (sp[3] < 0) return 'none';
  return sp[2] >= 0 ? (lanes[sp[2]].name || 'line ' + sp[3]) : 'line ' + sp[3] + ' (no lane)';
}
function acText(R, sp) {
  return `STATION ${R.a} ACTIVE CHANNEL   ${sp[3] < 0 ? 'none' : acLineName(sp)}\n` +
    `from ${fmtAbs(sp[0], 9)}\nto   ${fmtAbs(sp[1], 9)}\nfor  ${fmtDur(sp[1] - sp[0])}`;
}
function drawActive(s) {
  if (!acRows.length) return;
  s.push('<g class="active-channels">');
  s.push(`<rect x="0" y="${acY - 6}" width="${LABEL_W - 8}" height="${acRows.length * ROW_AC + 12}" fill="#f7f8fa"/>`);
  acRows.forEach((R, j) => {
    const y = acY + j * ROW_AC;
    s.push(`<g class="active-channel" data-station="${R.a}">`);
    s.push(`<text x="${LABEL_W - 12}" y="${y + 11}" text-anchor="end" font-size="11" fill="#495057">station ${R.a} active</text>`);
    s.push(`<g clip-path="url(#plotclip)"><rect x="${plotX}" y="${y}" width="${plotW}" height="${ROW_AC - 1}" fill="${j % 2 ? '#fbfbfc' : '#f4f6f8'}"/>`);
    for (const sp of R.s) {
      if (sp[1] < v0 || sp[0] > v1) continue;
      const xa = Math.max(plotX, X(sp[0])), xb = Math.min(plotX + plotW, X(sp[1]));
      const w = Math.max(1, xb - xa);
      const fill = sp[2] >= 0 ? laneColour(sp[2]) : 'url(#achatch)';
      s.push(`<rect class="ac-span" data-line="${sp[3]}" data-lane="${sp[2] >= 0 ? esc(lanes[sp[2]].name) : ''}" x="${xa.toFixed(2)}" y="${y + 2}" width="${w.toFixed(2)}" height="${ROW_AC - 5}" fill="${fill}"><title>${esc(acText(R, sp))}</title></rect>`);
      const label = acLineName(sp);
      if (w > label.length * 6.2 + 8)
        s.push(`<text x="${(xa + 4).toFixed(2)}" y="${y + ROW_AC - 4}" font-size="10" fill="${sp[2] >= 0 ? '#fff' : '#495057'}">${esc(label)}</text>`);
    }
    s.push('</g></g>');
  });
  s.push('</g>');
}

function cpuSpanText(R, sp) {
  return `${R.label.toUpperCase()}   ${cpuLabel(sp)}\nfrom ${fmtAbs(sp[0], 9)}\nto   ${fmtAbs(sp[1], 9)}\nfor  ${fmtDur(sp[1] - sp[0])}`;
}
function obText(R, m) {
  const id = m[2] ? ' W#16#' + m[2].toString(16).toUpperCase().padStart(4, '0') : '';
  return `${fmtAbs(m[0], 9)}  ${R.label}: OB ${m[1]}${id}\n${m[4]}`;
}
let drawnCpuSpans = 0, drawnObs = 0;
function drawCpu(s) {
  if (!cpuRows.length) return;
  s.push('<g class="cpu-rows">');
  s.push(`<rect x="0" y="${cpuY - 6}" width="${LABEL_W - 8}" height="${cpuRows.length * ROW_CPU + 12}" fill="#f7f8fa"/>`);
  cpuRows.forEach((R, j) => {
    const y = cpuY + j * ROW_CPU;
    s.push(`<g class="cpu-row" data-system="${esc(R.sys)}" data-rack="${R.r}">`);
    s.push(`<text x="${LABEL_W - 12}" y="${y + 12}" text-anchor="end" font-size="11" fill="#495057">${esc(R.label)}</text>`);
    s.push(`<g clip-path="url(#plotclip)"><rect x="${plotX}" y="${y}" width="${plotW}" height="${ROW_CPU - 1}" fill="${j % 2 ? '#fbfbfc' : '#f4f6f8'}"/>`);
    for (const sp of R.s) {
      if (sp[1] < v0 || sp[0] > v1) continue;
      const xa = Math.max(plotX, X(sp[0])), xb = Math.min(plotX + plotW, X(sp[1]));
      const w = Math.max(1, xb - xa);
      s.push(`<rect class="cpu-span" data-state="${esc(cpuStateName(sp[2]))}" data-role="${esc(cpuRoleName(sp[3]))}" x="${xa.toFixed(2)}" y="${y + 1}" width="${w.toFixed(2)}" height="13" fill="${cpuStateColour(sp[2])}"${sp[3] === 2 ? ' fill-opacity="0.6"' : ''}/>`);
      const label = cpuLabel(sp);
      if (w > label.length * 6.2 + 8)
        s.push(`<text x="${(xa + 4).toFixed(2)}" y="${y + 11}" font-size="10" fill="${cpuTextColour(sp[2])}">${esc(label)}</text>`);
      drawnCpuSpans++;
    }
    for (const m of R.ob) {
      if (m[0] < v0 || m[0] > v1) continue;
      const x = X(m[0]).toFixed(2);
      s.push(`<g class="cpu-ob" data-ob="${m[1]}"><line x1="${x}" y1="${y}" x2="${x}" y2="${y + ROW_CPU - 2}" stroke="${OB_COLOUR}" stroke-width="1.5"/>` +
        `<text x="${(X(m[0]) + 2).toFixed(2)}" y="${y + ROW_CPU - 1}" font-size="8" fill="${OB_COLOUR}">${m[1]}</text></g>`);
      drawnObs++;
    }
    s.push('</g></g>');
  });
  s.push('</g>');
}

function hsbySpanText(R, sp) {
  return `${R.label.toUpperCase()}   ${hsbyStateName(sp[2])}\nfrom ${fmtAbs(sp[0], 9)}\nto   ${fmtAbs(sp[1], 9)}\nfor  ${fmtDur(sp[1] - sp[0])}`;
}
function switchoverText(R, m) {
  const take = m[1] ? 'takeover ' + fmtDur(m[1]) : 'no takeover time';
  return `${fmtAbs(m[0], 9)}  ${R.label}: switchover to rack ${R.r}, ${take}\n${m[2]}`;
}
let drawnHsbySpans = 0, drawnSwitchovers = 0;
function drawHsby(s) {
  if (!hsbyRows.length) return;
  s.push('<g class="hsby-rows">');
  s.push(`<rect x="0" y="${hsbyY - 6}" width="${LABEL_W - 8}" height="${hsbyRows.length * ROW_CPU + 12}" fill="#f7f8fa"/>`);
  hsbyRows.forEach((R, j) => {
    const y = hsbyY + j * ROW_CPU;
    s.push(`<g class="hsby-row" data-pair="${esc(R.pair)}" data-rack="${R.r}">`);
    s.push(`<text x="${LABEL_W - 12}" y="${y + 12}" text-anchor="end" font-size="11" fill="#495057">${esc(R.label)}</text>`);
    s.push(`<g clip-path="url(#plotclip)"><rect x="${plotX}" y="${y}" width="${plotW}" height="${ROW_CPU - 1}" fill="${j % 2 ? '#fbfbfc' : '#f4f6f8'}"/>`);
    for (const sp of R.s) {
      if (sp[1] < v0 || sp[0] > v1) continue;
      const xa = Math.max(plotX, X(sp[0])), xb = Math.min(plotX + plotW, X(sp[1]));
      const w = Math.max(1, xb - xa);
      const label = hsbyStateName(sp[2]);
      s.push(`<rect class="hsby-span" data-state="${esc(label)}" x="${xa.toFixed(2)}" y="${y + 1}" width="${w.toFixed(2)}" height="13" fill="${hsbyStateColour(sp[2])}"/>`);
      if (w > label.length * 6.2 + 8)
        s.push(`<text x="${(xa + 4).toFixed(2)}" y="${y + 11}" font-size="10" fill="${hsbyTextColour(sp[2])}">${esc(label)}</text>`);
      drawnHsbySpans++;
    }
    for (const m of R.sw) {
      if (m[0] < v0 || m[0] > v1) continue;
      const x = X(m[0]);
      s.push(`<g class="hsby-switchover" data-takeover-ns="${m[1]}"><line x1="${x.toFixed(2)}" y1="${y}" x2="${x.toFixed(2)}" y2="${y + ROW_CPU - 2}" stroke="${SWITCHOVER_COLOUR}" stroke-width="2"/>` +
        `<path d="M${(x - 4).toFixed(2)} ${y}h8l-4 5z" fill="${SWITCHOVER_COLOUR}"/></g>`);
      drawnSwitchovers++;
    }
    s.push('</g></g>');
  });
  s.push('</g>');
}

function drawEvents(s) {
  const i0 = lowerBound(evTimes, v0), i1 = lowerBound(evTimes, v1 + 1e-9);
  // Group events closer than 4 px; stagger the labels over three rows.
  const groups = [];
  for (let i = i0; i < i1; i++) {
    const x = X(events[i].t);
    const g = groups[groups.length - 1];
    if (g && x - g.x < 4) g.items.push(events[i]); else groups.push({ x, items: [events[i]] });
  }
  const rowEnd = [-1e9, -1e9, -1e9];
  for (const g of groups) {
    const style = g.items.some(e => e.style === 'fault') ? 'fault' : g.items[0].style;
    const col = EVENT_COLOURS[style] || EVENT_COLOURS.event;
    s.push(`<line x1="${g.x.toFixed(2)}" y1="${AXIS_H + 2}" x2="${g.x.toFixed(2)}" y2="${totalH - LANE_GAP + 4}" stroke="${col}" stroke-width="2" stroke-opacity="0.85"${style === 'fault' ? '' : ' stroke-dasharray="5,3"'}/>`);
    let label = g.items[0].text;
    if (label.length > 60) label = label.slice(0, 59) + '\u2026';
    if (g.items.length > 1) label += ` (+${g.items.length - 1})`;
    const w = label.length * 6.2 + 8;
    let row = rowEnd.findIndex(e => g.x + 4 > e);
    if (row < 0) continue;
    rowEnd[row] = g.x + 4 + w;
    const ty = AXIS_H + 13 + row * 14;
    s.push(`<text x="${(g.x + 4).toFixed(1)}" y="${ty}" font-size="11" fill="${col}" font-weight="600">${esc(label)}</text>`);
  }
}

function render() {
  const W = Math.max(600, chart.clientWidth || 1200);
  plotX = LABEL_W; plotW = W - LABEL_W - PAD_R; scale = plotW / (v1 - v0);
  drawnFrames = 0; drawnMpiMarks = 0;
  const s = [];
  s.push(`<defs><clipPath id="plotclip"><rect x="${plotX}" y="0" width="${plotW}" height="${totalH}"/></clipPath>` +
    '<pattern id="achatch" width="6" height="6" patternUnits="userSpaceOnUse" patternTransform="rotate(45)">' +
    '<rect width="6" height="6" fill="#f1f3f5"/><line x1="0" y1="0" x2="0" y2="6" stroke="#adb5bd" stroke-width="2"/></pattern></defs>');
  drawAxis(s);
  for (const L of lanes) {
    s.push(`<g class="lane" data-lane="${esc(L.name)}" data-interface="${L.iface}" data-frames="${L.start.length}">`);
    drawLabels(s, L);
    s.push('<g clip-path="url(#plotclip)">');
    drawFrames(s, L); drawToken(s, L); drawRuler(s, L); drawDx(s, L); drawMpi(s, L);
    s.push('</g></g>');
  }
  drawActive(s);
  drawnCpuSpans = 0; drawnObs = 0;
  drawCpu(s);
  drawnHsbySpans = 0; drawnSwitchovers = 0;
  drawHsby(s);
  s.push('<g class="events" clip-path="url(#plotclip)">');
  drawEvents(s);
  s.push('</g>');
  svg.setAttribute('width', W);
  svg.setAttribute('height', totalH);
  svg.setAttribute('viewBox', `0 0 ${W} ${totalH}`);
  svg.innerHTML = s.join('');
  status.textContent = `view ${fmtAbs(v0, 6)} \u2013 ${fmtAbs(v1, 6)}  (${fmtDur(v1 - v0)})`;
  updateSummary();
  document.body.dataset.rendered = '1';
  document.body.dataset.framesDrawn = String(drawnFrames);
  document.body.dataset.lanes = String(lanes.length);
  document.body.dataset.activeRows = String(acRows.length);
  document.body.dataset.cpuRows = String(cpuRows.length);
  document.body.dataset.cpuSpansDrawn = String(drawnCpuSpans);
  document.body.dataset.cpuObsDrawn = String(drawnObs);
  document.body.dataset.hsbyRows = String(hsbyRows.length);
  document.body.dataset.hsbySpansDrawn = String(drawnHsbySpans);
  document.body.dataset.hsbySwitchoversDrawn = String(drawnSwitchovers);
  document.body.dataset.mpiRows = String(lanes.reduce((n, L) => n + L.mpi.length, 0));
  document.body.dataset.mpiMarksDrawn = String(drawnMpiMarks);
  if (history.replaceState) history.replaceState(null, '', '#v=' + Math.round(v0) + ',' + Math.round(v1));
}

// ---- DP cycle table ---------------------------------------------------------------------
function updateSummary() {
  const rows = [];
  for (const L of lanes) {
    const [i0, i1] = frameRange(L);
    const counts = [0, 0, 0, 0, 0];
    for (let i = i0; i < i1; i++) if (L.end[i] > v0) counts[L.kind[i]]++;
    rows.push(`<tr class="lane-row" data-lane="${esc(L.name)}"><td><b>${esc(L.name)}</b> (${esc(speedText(L.speed))})</td><td colspan="6" style="text-align:left">frames in view: ${counts.map((c, k) => KIND_NAMES[k] + ' ' + c).join(', ')}</td></tr>`);
    for (const S of L.dx) {
      const a = lowerBound(S.t, v0), b = lowerBound(S.t, v1);
      const cyc = [];
      let miss = 0;
      for (let i = a; i < b; i++) {
        if (S.unSet.has(i)) miss++;
        if (i > 0) cyc.push(S.t[i] - S.t[i - 1]); else if (S.c0 >= 0) cyc.push(S.c0);
      }
      cyc.sort((x, y) => x - y);
      const f = v => cyc.length ? `${(v / 1e3).toFixed(1)} \u00b5s` + (L.speed ? ` (${bitsOf(v, L.speed)})` : '') : '\u2013';
      const masters = S.m.join(', ');
      rows.push(`<tr data-slave="${S.a}"><td>slave ${S.a}</td><td>${esc(masters)}</td><td>${b - a}</td><td>${miss}</td>` +
        `<td>${f(cyc[0])}</td><td>${f(cyc[(cyc.length - 1) >> 1])}</td><td>${f(cyc[cyc.length - 1])}</td></tr>`);
    }
  }
  document.getElementById('dxbody').innerHTML = rows.join('');
}

// ---- tooltips ---------------------------------------------------------------------------
function frameText(L, i, inPixel) {
  const e = ents[L.e[i]];
  const lines = [];
  lines.push(`${KIND_NAMES[L.kind[i]].toUpperCase()}   lane ${L.name}, frame ${i + 1} of ${L.start.length}`);
  if (inPixel > 1) lines.push(`(${inPixel} frames under the pointer: zoom in)`);
  lines.push(`start ${fmtAbs(L.start[i], 9)}   length ${fmtDur(L.end[i] - L.start[i])}${fmtBits(L.end[i] - L.start[i], L.speed)}`);
  if (i > 0) {
    const gap = L.start[i] - L.end[i - 1], d = L.start[i] - L.start[i - 1];
    lines.push(gap >= 0 ? `idle before: ${fmtDur(gap)}${fmtBits(gap, L.speed)} (since the end of the previous frame)`
                        : `overlaps the previous frame by ${fmtDur(-gap)}${fmtBits(-gap, L.speed)}`);
    lines.push(`since the previous start: ${fmtDur(d)}${fmtBits(d, L.speed)}`);
  }
  lines.push('');
  lines.push(D.desc[e[2]]);
  lines.push('');
  const hx = hexSpaced(e[0]);
  for (let k = 0; k < hx.length; k += 48) lines.push((k === 0 ? 'hex  ' : '     ') + hx.slice(k, k + 48));
  return lines.join('\n');
}

function hitTest(x, y) {
  if (x < plotX || x > plotX + plotW) return null;
  const t = T(x), tol = 3 / scale;
  if (y >= AXIS_H && y < AXIS_H + EV_H) return eventText(t, tol);
  if (acRows.length && y >= acY && y < acY + acRows.length * ROW_AC) {
    const R = acRows[Math.floor((y - acY) / ROW_AC)];
    for (const sp of R.s) if (t >= sp[0] - tol && t <= sp[1] + tol) return acText(R, sp);
    return null;
  }
  if (cpuRows.length && y >= cpuY && y < cpuY + cpuRows.length * ROW_CPU) {
    const R = cpuRows[Math.floor((y - cpuY) / ROW_CPU)];
    const near = R.ob.filter(m => Math.abs(m[0] - t) <= tol);
    if (near.length) return near.slice(0, 20).map(m => obText(R, m)).join('\n');
    for (const sp of R.s) if (t >= sp[0] - tol && t <= sp[1] + tol) return cpuSpanText(R, sp);
    return null;
  }
  if (hsbyRows.length && y >= hsbyY && y < hsbyY + hsbyRows.length * ROW_CPU) {
    const R = hsbyRows[Math.floor((y - hsbyY) / ROW_CPU)];
    const near = R.sw.filter(m => Math.abs(m[0] - t) <= tol);
    if (near.length) return near.slice(0, 20).map(m => switchoverText(R, m)).join('\n');
    for (const sp of R.s) if (t >= sp[0] - tol && t <= sp[1] + tol) return hsbySpanText(R, sp);
    return null;
  }
  for (const L of lanes) {
    if (y < L.y || y >= L.y + L.h) continue;
    if (y < L.yF + ROW_FRAMES) {
      let i = lowerBound(L.start, t - L.maxDur - tol), best = -1, bd = Infinity, cnt = 0;
      const i1 = lowerBound(L.start, t + tol);
      for (; i < i1; i++) {
        if (L.end[i] < t - tol) continue;
        cnt++;
        const d = t < L.start[i] ? L.start[i] - t : (t > L.end[i] ? t - L.end[i] : 0);
        if (d < bd || (d === 0 && bd === 0)) { bd = d; best = i; }
      }
      return best >= 0 ? frameText(L, best, cnt) : null;
    }
    if (y >= L.yT && y < L.yT + ROW_TOKEN) {
      const i = lowerBound(L.ts, t + 1e-9) - 1;
      if (i < 0 || L.te[i] < t - tol) return null;
      const d = L.te[i] - L.ts[i];
      return `TOKEN HOLDER ${L.th[i]}   lane ${L.name}\npassed by ${L.tp[i]} at ${fmtAbs(L.ts[i], 9)}\nheld for ${fmtDur(d)}${fmtBits(d, L.speed)}\n(until the next token frame starts)`;
    }
    if (y >= L.yM && L.mpi.length) {
      const C = L.mpi[Math.floor((y - L.yM) / ROW_MPI)];
      return C ? mpiText(L, C, t, tol) : null;
    }
    if (y >= L.yD) {
      const S = L.dx[Math.floor((y - L.yD) / ROW_DX)];
      if (!S) return null;
      const j = lowerBound(S.t, t - tol);
      if (j >= S.t.length || S.t[j] > t + tol) return null;
      const c = j > 0 ? S.t[j] - S.t[j - 1] : (S.c0 >= 0 ? S.c0 : null);
      const m = S.m;
      return `DATA_EXCHANGE to slave ${S.a}   lane ${L.name}\nrequest at ${fmtAbs(S.t[j], 9)}` +
        (m.length === 1 ? ` from master ${m[0]}` : '') + `\n` +
        (S.unSet.has(j) ? 'NOT ANSWERED\n' : 'answered\n') +
        (c === null ? 'first poll: no cycle time' : `DP cycle (since the previous request): ${fmtDur(c)}${fmtBits(c, L.speed)}`);
    }
    return null;
  }
  return eventText(t, tol);
}

function eventText(t, tol) {
  const i0 = lowerBound(evTimes, t - tol), i1 = lowerBound(evTimes, t + tol + 1e-9);
  if (i0 >= i1) return null;
  const lines = [];
  for (let i = i0; i < i1 && lines.length < 20; i++) {
    const e = events[i];
    lines.push(`${fmtAbs(e.t, 9)}  [${e.style}, ${e.cat}] ${e.text}`);
  }
  if (i1 - i0 > 20) lines.push(`\u2026 and ${i1 - i0 - 20} more`);
  return lines.join('\n');
}

// ---- input ------------------------------------------------------------------------------
let drag = null;
function localXY(ev) { const r = svg.getBoundingClientRect(); return [ev.clientX - r.left, ev.clientY - r.top]; }
svg.addEventListener('mousemove', ev => {
  const [x, y] = localXY(ev);
  if (drag) {
    const dx = x - drag.x;
    if (Math.abs(dx) > 2) drag.moved = true;
    if (drag.moved) { const d = dx / scale; v0 = drag.v0 - d; v1 = drag.v1 - d; setView(v0, v1); }
    tip.hidden = true;
    return;
  }
  const text = hitTest(x, y);
  if (!text) { tip.hidden = true; return; }
  tip.textContent = text;
  tip.hidden = false;
  const w = tip.offsetWidth, h = tip.offsetHeight;
  let left = ev.clientX + 14, top = ev.clientY + 14;
  if (left + w > window.innerWidth - 4) left = Math.max(4, ev.clientX - w - 14);
  if (top + h > window.innerHeight - 4) top = Math.max(4, ev.clientY - h - 14);
  tip.style.left = left + 'px'; tip.style.top = top + 'px';
});
svg.addEventListener('mouseleave', () => { tip.hidden = true; });
svg.addEventListener('mousedown', ev => {
  const [x] = localXY(ev);
  drag = { x, v0, v1, moved: false };
  chart.classList.add('drag');
});
window.addEventListener('mouseup', ev => {
  if (!drag) return;
  const moved = drag.moved;
  drag = null;
  chart.classList.remove('drag');
  if (moved) return;
  // A click on a frame makes its end the origin of that lane's bit-time axis.
  const [x, y] = localXY(ev);
  for (const L of lanes) {
    if (y < L.yF || y >= L.yF + ROW_FRAMES || x < plotX) continue;
    const t = T(x);
    const i = lowerBound(L.start, t + 1e-9) - 1;
    if (i >= 0 && L.end[i] >= t - 3 / scale) { ref = { lane: L, t: L.end[i] }; schedule(); }
  }
});
svg.addEventListener('dblclick', ev => { const [x] = localXY(ev); zoom(0.25, T(x)); });
svg.addEventListener('wheel', ev => {
  const [x] = localXY(ev);
  if (x < plotX) return;  // over the labels the wheel scrolls the page
  ev.preventDefault();
  if (ev.shiftKey || Math.abs(ev.deltaX) > Math.abs(ev.deltaY)) {
    pan((ev.deltaX || ev.deltaY) / plotW);
  } else {
    zoom(Math.exp(ev.deltaY * 0.0015), Math.max(v0, Math.min(v1, T(x))));
  }
}, { passive: false });
document.addEventListener('keydown', ev => {
  if (ev.ctrlKey || ev.metaKey || ev.altKey) return;
  const k = ev.key;
  if (k === '+' || k === '=') zoom(0.5);
  else if (k === '-' || k === '_') zoom(2);
  else if (k === 'ArrowLeft') pan(-0.2);
  else if (k === 'ArrowRight') pan(0.2);
  else if (k === 'Home' || k === '0') setView(full[0], full[1]);
  else if (k === 'r' || k === 'R') setView(initial[0], initial[1]);
  else if (k === 'Escape') { ref = null; schedule(); }
  else return;
  ev.preventDefault();
});
document.querySelectorAll('.controls button').forEach(b => b.addEventListener('click', () => {
  const a = b.dataset.act;
  if (a === 'in') zoom(0.5); else if (a === 'out') zoom(2);
  else if (a === 'left') pan(-0.2); else if (a === 'right') pan(0.2);
  else if (a === 'all') setView(full[0], full[1]); else if (a === 'reset') setView(initial[0], initial[1]);
}));
window.addEventListener('resize', schedule);

// ---- legend -----------------------------------------------------------------------------
(function legend() {
  const parts = [];
  parts.push('<span><b>frames</b></span>');
  KIND_NAMES.forEach((k, i) => parts.push(`<span><span class="sw" style="background:${KIND_COLOURS[i]}"></span>${k}</span>`));
  parts.push('<span><b>token holder</b></span>');
  holders.forEach(h => parts.push(`<span><span class="sw" style="background:${holderColour[h]}"></span>${h}</span>`));
  parts.push('<span><b>DP cycle</b></span>');
  parts.push(`<span><span class="vl" style="background:${DX_OK}"></span>answered</span>`);
  parts.push(`<span><span class="vl" style="background:${DX_MISS}"></span>no answer</span>`);
  if (acRows.length) {
    parts.push('<span><b>active channel</b></span>');
    lanes.forEach((L, i) => parts.push(`<span><span class="sw" style="background:${laneColour(i)}"></span>${esc(L.name || '(no name)')}</span>`));
    parts.push('<span><span class="sw" style="background:repeating-linear-gradient(45deg,#adb5bd 0 2px,#f1f3f5 2px 5px)"></span>none</span>');
  }
  if (cpuRows.length) {
    parts.push('<span><b>CPU state</b></span>');
    const states = new Set();
    cpuRows.forEach(R => R.s.forEach(sp => states.add(sp[2])));
    Array.from(states).sort((a, b) => a - b).forEach(n => parts.push(`<span><span class="sw" style="background:${cpuStateColour(n)}"></span>${esc(cpuStateName(n))}</span>`));
    parts.push(`<span><span class="vl" style="background:${OB_COLOUR}"></span>OB</span>`);
    parts.push('<span>(lighter: standby)</span>');
  }
  if (hsbyRows.length) {
    parts.push('<span><b>Quantum rack</b></span>');
    const states = new Set();
    hsbyRows.forEach(R => R.s.forEach(sp => states.add(sp[2])));
    Array.from(states).sort((a, b) => a - b).forEach(n => parts.push(`<span><span class="sw" style="background:${hsbyStateColour(n)}"></span>${esc(hsbyStateName(n))}</span>`));
    parts.push(`<span><span class="vl" style="background:${SWITCHOVER_COLOUR}"></span>switchover</span>`);
  }
  if (lanes.some(L => L.mpi.length)) {
    parts.push('<span><b>MPI connection</b></span>');
    [0, 1].forEach(n => parts.push(`<span><span class="sw" style="background:${mpiSpanColour(n)}"></span>${MPI_STATE_NAMES[n]}</span>`));
    [[[0, 0xE0, 1], 'connect'], [[0, 0xF1, 1], 'data from PG'], [[0, 0xF1, 0], 'data to PG'], [[0, 0xB0, 1], 'data ack'],
     [[0, 0x05, 1], 'connection ack'], [[0, 0x80, 1], 'disconnect']].forEach(([m, k]) =>
      parts.push(`<span><span class="vl" style="background:${mpiMarkColour(m)}"></span>${k}</span>`));
  }
  parts.push('<span><b>events</b></span>');
  for (const k of ['fault', 'repair', 'event']) parts.push(`<span><span class="vl" style="background:${EVENT_COLOURS[k]}"></span>${k}</span>`);
  document.getElementById('legend').innerHTML = parts.join('');
})();

setView(v0, v1);
render();
})();
)JS";

}  // namespace pbvbus::captures::detail
