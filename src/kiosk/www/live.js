// live.js - the results screen: the device's state by server-sent events (/events),
// one whole snapshot per message, drawn as it comes.
'use strict';

// when each jump reached the screen (read by the tests: event -> screen latency)
window.gsTimings = [];
let lastJumpKey = null;
let lastState = null;

const $ = (id) => document.getElementById(id);

function setNum(id, value, sd, digits, scale) {
  $(id).textContent = gs.fix(value, scale, digits);
  $(id + '-sd').textContent = gs.isNum(value) && gs.isNum(sd) ? '\u00b1 ' + (sd * scale).toFixed(digits) : '';
}

// fields the core may add: shown when present
const EXTRA = [
  ['com_rise_m', 'Centre of mass rise', 'cm', 100, 1],
  ['contact_time_s', 'Contact time', 'ms', 1000, 0],
  ['rsi', 'Reactive strength index', '', 1, 2],
];

function renderResult(s) {
  const lj = s.last_jump;
  const ev = lj ? lj.event : {};
  const sd = lj && lj.se ? lj.se.sd : {};
  setNum('jump-height', ev.jump_height_m, sd.jump_height_m, 1, 100);
  setNum('flight-time', ev.flight_time_s, sd.flight_time_s, 0, 1000);
  setNum('takeoff-velocity', ev.takeoff_velocity_m_s, sd.takeoff_velocity_m_s, 2, 1);
  const st = s.stature;
  $('stature').textContent = st ? gs.fix(st.height_m, 1, 2) : '\u2013';
  $('stature-sd').textContent = st && st.ci95_m ? '95 %: ' + st.ci95_m[0].toFixed(2) + '\u2013' + st.ci95_m[1].toFixed(2) : '';
  const extra = $('extra');
  extra.textContent = '';
  for (const [k, label, unit, scale, digits] of EXTRA) {
    if (!gs.isNum(ev[k])) continue;
    const d = gs.el('div', { class: 'num' });
    d.appendChild(gs.el('span', { class: 'label' }, label));
    const v = gs.el('span', { class: 'value', id: 'extra-' + k }, (ev[k] * scale).toFixed(digits));
    d.appendChild(v);
    if (unit) d.appendChild(gs.el('span', { class: 'unit' }, ' ' + unit));
    if (gs.isNum(sd[k])) d.appendChild(gs.el('span', { class: 'sd' }, '\u00b1 ' + (sd[k] * scale).toFixed(digits)));
    extra.appendChild(d);
  }
  $('result').classList.toggle('rejected', !!lj && ev.accepted === false);
  // warnings in words: the jump's own, and what happens now
  const ul = $('warnings');
  ul.textContent = '';
  if (lj && ev.accepted === false)
    ul.appendChild(gs.el('li', { class: 'bad' }, 'Result not kept: ' + gs.plain(ev.reason, gs.reasonWords)));
  for (const w of (lj && ev.warnings) || [])
    ul.appendChild(gs.el('li', {}, gs.plain(w, gs.warningWords) + (ev.accepted === false ? '' : ' during the jump: check the result')));
  for (const w of s.warnings || []) ul.appendChild(gs.el('li', {}, gs.plain(w, gs.warningWords) + ' (now)'));
  if (s.status && s.status.state === 'stalled') ul.appendChild(gs.el('li', { class: 'bad' }, 'The camera sends no pictures'));
  if (s.db_error) ul.appendChild(gs.el('li', { class: 'bad' }, 'The history could not be saved: ' + s.db_error));
  gs.drawTrack($('plot'), lj ? lj.plot : null);
}

function renderJumps(s) {
  $('jumps-title').textContent = s.athlete ? s.athlete.name + ' today' : 'This visit';
  gs.fillJumps(document.querySelector('#jumps tbody'), s.jumps || []);
  $('best').textContent = s.best ? gs.cm(s.best.jump_height_m) + ' cm' : '\u2013';
  $('mean').textContent = s.mean ? gs.cm(s.mean.jump_height_m) + ' cm' : '\u2013';
}

function renderFooter(s) {
  const f = $('footer');
  f.textContent = '';
  const parts = [];
  if (s.ended) parts.push('The video has ended.');
  if (s.status) {
    parts.push('camera ' + s.status.state + (gs.isNum(s.status.fps) ? ', ' + s.status.fps.toFixed(1) + ' fps' : ''));
    for (const k of s.status.sinks || [])
      if (k.state !== 'up' || k.lines_dropped)
        parts.push(k.sink + ' ' + k.target + ' ' + k.state + ', ' + k.lines_queued + ' queued, ' + k.lines_dropped + ' dropped');
  }
  f.textContent = parts.join(' \u00b7 ');
}

function render(s) {
  lastState = s;
  document.body.dataset.word = s.word;
  $('title').textContent = s.title || 'gravscale';
  const [word, hint] = gs.words[s.word] || [s.word, ''];
  $('state-word').textContent = word;
  let h = hint;
  if (s.word === 'result' && s.last_jump)
    h = s.last_jump.event.accepted === false ? 'Not kept: see below' : 'Well done';
  if (s.ended) h = 'The video has ended';
  $('state-hint').textContent = h;
  $('athlete-name').textContent = s.athlete ? s.athlete.name : '';
  $('athlete-set').textContent = s.athlete ? 'Change' : 'Start';
  renderResult(s);
  renderJumps(s);
  renderFooter(s);
  const lj = s.last_jump;
  const key = lj ? lj.received_ms + ':' + lj.event.index : null;
  if (key && key !== lastJumpKey) {
    lastJumpKey = key;
    // two frames later the update has been painted
    requestAnimationFrame(() => requestAnimationFrame(() => {
      window.gsTimings.push({ index: lj.event.index, received_ms: lj.received_ms, land_wall_ms: lj.land_wall_ms,
                              shown_ms: performance.timeOrigin + performance.now() });
    }));
  }
}

async function loadAthletes() {
  try {
    const list = await gs.api('GET', '/api/athletes');
    const dl = $('athlete-list');
    dl.textContent = '';
    for (const a of list) dl.appendChild(gs.el('option', { value: a.name }));
  } catch (e) { /* the live view works without the list */ }
}

$('athlete-form').addEventListener('submit', async (e) => {
  e.preventDefault();
  const name = $('athlete-input').value.trim();
  $('form-error').textContent = '';
  if (!name) {
    $('form-error').textContent = 'Type the athlete\'s name first';
    return;
  }
  try {
    await gs.api('PUT', '/api/current', { name });
    $('athlete-input').value = '';
    loadAthletes();
  } catch (err) {
    $('form-error').textContent = err.message;
  }
});

function connect() {
  const es = new EventSource('/events');
  es.addEventListener('state', (m) => {
    $('conn').textContent = 'live';
    $('conn').classList.remove('offline');
    render(JSON.parse(m.data));
  });
  es.onerror = () => {
    $('conn').textContent = 'device offline: retrying';
    $('conn').classList.add('offline');
  };
}

connect();
loadAthletes();
