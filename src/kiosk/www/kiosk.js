// kiosk.js - shared by the kiosk's pages: the API with the token, numbers and
// warnings in words, and the SVG plots. No library: every file is served by the device.
'use strict';

const gs = {};

// ---- the API -----------------------------------------------------------------
gs.token = () => localStorage.getItem('gs_token') || '';
gs.setToken = (t) => {
  localStorage.setItem('gs_token', t);
  // the live stream (EventSource) sends no headers: reads carry the token as a cookie too
  document.cookie = 'gs_token=' + encodeURIComponent(t) + '; path=/; SameSite=Strict';
};
gs.api = async (method, path, body) => {
  const opt = { method, headers: {} };
  if (gs.token()) opt.headers.Authorization = 'Bearer ' + gs.token();
  if (body !== undefined) {
    opt.headers['Content-Type'] = 'application/json';
    opt.body = JSON.stringify(body);
  }
  const r = await fetch(path, opt);
  let data = null;
  try { data = await r.json(); } catch (e) { data = null; }
  if (r.status === 401) gs.askToken();
  if (!r.ok) throw new Error((data && data.error) || (r.status + ' ' + r.statusText));
  return data;
};
// a token field in the header, shown when the device asks for one
gs.askToken = () => {
  let f = document.getElementById('token-form');
  if (!f) {
    f = document.createElement('form');
    f.id = 'token-form';
    f.className = 'token shown';
    f.innerHTML = '<input id="token-input" type="password" placeholder="kiosk token" autocomplete="off">' +
                  '<button type="submit">Use</button>';
    f.addEventListener('submit', (e) => {
      e.preventDefault();
      gs.setToken(document.getElementById('token-input').value.trim());
      location.reload();
    });
    document.querySelector('header').appendChild(f);
  }
  f.classList.add('shown');
};

// ---- words and numbers ----------------------------------------------------------
gs.words = {
  waiting: ['Name the athlete', 'Type a name above and press Start'],
  no_one: ['No one in view', 'Step onto the spot, the whole body in the picture'],
  stand_still: ['Stand still', 'Stand upright and still for a moment'],
  jump_now: ['Jump now!', 'Jump straight up and land on the same spot'],
  in_the_air: ['In the air', ''],
  result: ['Result', ''],
};
gs.warningWords = {
  camera_moved: 'The camera moved',
  left_frame: 'The body left the picture',
  out_of_plane: 'The athlete moved toward or away from the camera',
  other_motion: 'Someone else moved beside the athlete',
  few_samples: 'A very short flight: few pictures in the air',
  gravity_tilt: 'The flight was not straight up (or the camera is tilted)',
  size_changed: 'The athlete stood closer or farther than before',
  outliers: 'Many poor detections during the jump',
  edge_truncated: 'The jump was cut off (pictures missing)',
};
gs.reasonWords = {
  few_samples: 'too few pictures in the air',
  large_residual: 'the body did not fly a clean path',
  implausible_acceleration: 'the path does not match gravity',
  no_size: 'stand still and upright before jumping, so the height can be measured',
  uncertain_acceleration: 'the flight could not be measured precisely enough',
  gap: 'pictures were missing during the jump',
  other_motion: 'someone else moved beside the athlete',
  gravity_direction: 'the flight was not along gravity',
  depth_changed: 'the athlete moved toward or away from the camera',
};
gs.plain = (name, table) => table[name] || String(name).replace(/_/g, ' ');
gs.isNum = (v) => typeof v === 'number' && isFinite(v);
gs.fix = (v, scale, digits) => (gs.isNum(v) ? (v * scale).toFixed(digits) : '\u2013');
gs.cm = (m) => gs.fix(m, 100, 1);
gs.ms = (s) => gs.fix(s, 1000, 0);
gs.time = (iso) => {
  if (!iso) return '';
  const d = new Date(iso);
  return isNaN(d) ? iso : d.toLocaleTimeString([], { hour: '2-digit', minute: '2-digit', second: '2-digit' });
};
gs.el = (tag, attrs, text) => {
  const e = document.createElement(tag);
  for (const k in attrs || {}) e.setAttribute(k, attrs[k]);
  if (text !== undefined) e.textContent = text;
  return e;
};
gs.param = (name) => new URLSearchParams(location.search).get(name);
gs.today = () => {
  const d = new Date();
  return d.getFullYear() + '-' + String(d.getMonth() + 1).padStart(2, '0') + '-' + String(d.getDate()).padStart(2, '0');
};

// ---- SVG ---------------------------------------------------------------------------
const SVG = 'http://www.w3.org/2000/svg';
gs.svg = (parent, tag, attrs, text) => {
  const e = document.createElementNS(SVG, tag);
  for (const k in attrs) e.setAttribute(k, attrs[k]);
  if (text !== undefined) e.textContent = text;
  parent.appendChild(e);
  return e;
};
// a frame with ticks: returns the mapping functions
gs.frame = (svg, x0, x1, y0, y1, xlabel, ylabel, xfmt, yfmt) => {
  while (svg.firstChild) svg.removeChild(svg.firstChild);
  const W = 600, H = 320, L = 58, R = 14, T = 14, B = 42;
  if (!(x1 > x0)) x1 = x0 + 1;
  if (!(y1 > y0)) y1 = y0 + 1;
  const X = (x) => L + (x - x0) / (x1 - x0) * (W - L - R);
  const Y = (y) => H - B - (y - y0) / (y1 - y0) * (H - T - B);
  const ticks = (a, b) => {
    const step = Math.pow(10, Math.floor(Math.log10((b - a) / 4)));
    const s = [1, 2, 5, 10].map((k) => k * step).find((k) => (b - a) / k <= 6) || step * 10;
    const out = [];
    for (let v = Math.ceil(a / s) * s; v <= b + 1e-9; v += s) out.push(Math.round(v / s) * s);
    return out;
  };
  for (const v of ticks(y0, y1)) {
    gs.svg(svg, 'line', { x1: L, x2: W - R, y1: Y(v), y2: Y(v), class: 'grid' });
    gs.svg(svg, 'text', { x: L - 6, y: Y(v) + 4, 'text-anchor': 'end' }, yfmt(v));
  }
  for (const v of ticks(x0, x1))
    gs.svg(svg, 'text', { x: X(v), y: H - B + 16, 'text-anchor': 'middle' }, xfmt(v));
  gs.svg(svg, 'line', { x1: L, x2: W - R, y1: H - B, y2: H - B, class: 'axis' });
  gs.svg(svg, 'line', { x1: L, x2: L, y1: T, y2: H - B, class: 'axis' });
  gs.svg(svg, 'text', { x: (L + W - R) / 2, y: H - 6, 'text-anchor': 'middle' }, xlabel);
  gs.svg(svg, 'text', { x: 14, y: (T + H - B) / 2, transform: 'rotate(-90 14 ' + (T + H - B) / 2 + ')',
                        'text-anchor': 'middle' }, ylabel);
  return { X, Y };
};
// the COM track of one jump: dots, the fitted parabola, the flight window shaded
gs.drawTrack = (svg, plot) => {
  if (!plot || !plot.samples || !plot.samples.length) {
    while (svg.firstChild) svg.removeChild(svg.firstChild);
    gs.svg(svg, 'text', { x: 300, y: 160, 'text-anchor': 'middle' }, 'no jump yet');
    return;
  }
  const m = plot.units === 'm';
  const ys = plot.samples.map((p) => p[1]).concat(plot.curve.map((p) => p[1]));
  const ts = plot.samples.map((p) => p[0]);
  let y0 = Math.min(...ys), y1 = Math.max(...ys);
  const pad = (y1 - y0) * 0.08 || 0.05;
  const f = gs.frame(svg, Math.min(...ts), Math.max(...ts), y0 - pad, y1 + pad, 'time from take-off (s)',
                     m ? 'centre of mass above take-off (cm)' : 'centre of mass (px)',
                     (v) => v.toFixed(1), (v) => (m ? (v * 100).toFixed(0) : v.toFixed(0)));
  const w = plot.window;
  gs.svg(svg, 'rect', { x: f.X(w[0]), y: 14, width: Math.max(1, f.X(w[1]) - f.X(w[0])), height: 320 - 14 - 42,
                        class: 'air' });
  for (const t of plot.fit_window || [])
    gs.svg(svg, 'line', { x1: f.X(t), x2: f.X(t), y1: 14, y2: 320 - 42, class: 'fitwin' });
  if (plot.curve.length)
    gs.svg(svg, 'polyline', { points: plot.curve.map((p) => f.X(p[0]).toFixed(1) + ',' + f.Y(p[1]).toFixed(1)).join(' '),
                              class: 'fit' });
  for (const p of plot.samples)
    gs.svg(svg, 'circle', { cx: f.X(p[0]).toFixed(1), cy: f.Y(p[1]).toFixed(1), r: 4, class: p[3] ? 'com' : 'com out' });
  if (plot.apex) gs.svg(svg, 'circle', { cx: f.X(plot.apex[0]), cy: f.Y(plot.apex[1]), r: 6, class: 'apex' });
};
// accepted jump heights over time (an athlete's history)
gs.drawTrend = (svg, jumps) => {
  const ok = jumps.filter((j) => j.accepted && gs.isNum(j.jump_height_m));
  if (!ok.length) {
    while (svg.firstChild) svg.removeChild(svg.firstChild);
    gs.svg(svg, 'text', { x: 300, y: 160, 'text-anchor': 'middle' }, 'no accepted jump yet');
    return;
  }
  const hs = ok.map((j) => j.jump_height_m * 100);
  const lo = Math.min(...hs), hi = Math.max(...hs), pad = (hi - lo) * 0.15 || 2;
  const f = gs.frame(svg, 1, Math.max(2, ok.length), Math.max(0, lo - pad), hi + pad, 'jump (oldest first)',
                     'jump height (cm)', (v) => (Number.isInteger(v) ? String(v) : ''), (v) => v.toFixed(0));
  gs.svg(svg, 'polyline', { points: ok.map((j, i) => f.X(i + 1) + ',' + f.Y(hs[i])).join(' '), class: 'trend' });
  const best = Math.max(...hs);
  ok.forEach((j, i) => {
    const c = gs.svg(svg, 'circle', { cx: f.X(i + 1), cy: f.Y(hs[i]), r: 5, class: hs[i] === best ? 'pt best' : 'pt' });
    gs.svg(c, 'title', {}, (j.day || '') + ' ' + gs.time(j.at) + ': ' + hs[i].toFixed(1) + ' cm');
  });
};
// a jumps table body
gs.fillJumps = (tbody, jumps, onclick) => {
  tbody.textContent = '';
  jumps.forEach((j, i) => {
    const tr = gs.el('tr');
    tr.appendChild(gs.el('td', {}, String(i + 1)));
    tr.appendChild(gs.el('td', {}, gs.time(j.at)));
    tr.appendChild(gs.el('td', {}, gs.cm(j.jump_height_m) + ' cm'));
    tr.appendChild(gs.el('td', {}, gs.ms(j.flight_time_s) + ' ms'));
    tr.appendChild(gs.el('td', {}, gs.fix(j.takeoff_velocity_m_s, 1, 2) + ' m/s'));
    tr.appendChild(j.accepted ? gs.el('td', { class: 'ok' }, 'kept')
                              : gs.el('td', { class: 'no' }, 'not kept: ' + gs.plain(j.reason, gs.reasonWords)));
    if (onclick) tr.addEventListener('click', () => onclick(j, tr));
    tbody.appendChild(tr);
  });
};
