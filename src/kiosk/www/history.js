// history.js - every athlete, and one athlete's history: trend, visits, jumps, CSV.
'use strict';

const $ = (id) => document.getElementById(id);

async function showList() {
  const list = await gs.api('GET', '/api/athletes');
  const tb = document.querySelector('#athletes tbody');
  tb.textContent = '';
  for (const a of list) {
    const tr = gs.el('tr');
    const td = gs.el('td');
    td.appendChild(gs.el('a', { href: '/history.html?athlete=' + a.id }, a.name));
    tr.appendChild(td);
    tr.appendChild(gs.el('td', {}, String(a.n_sessions)));
    tr.appendChild(gs.el('td', {}, String(a.n_jumps)));
    tr.appendChild(gs.el('td', {}, gs.isNum(a.best_jump_m) ? gs.cm(a.best_jump_m) + ' cm' : '\u2013'));
    tr.appendChild(gs.el('td', {}, a.last_seen ? new Date(a.last_seen).toLocaleString() : ''));
    tb.appendChild(tr);
  }
}

async function showAthlete(id) {
  const a = await gs.api('GET', '/api/athletes/' + id);
  $('athlete-box').hidden = false;
  $('athlete-title').textContent = a.name;
  $('csv').href = '/api/jumps.csv?athlete=' + id;
  const ok = a.jumps.filter((j) => j.accepted && gs.isNum(j.jump_height_m));
  $('count').textContent = String(ok.length);
  $('best').textContent = ok.length ? gs.cm(Math.max(...ok.map((j) => j.jump_height_m))) + ' cm' : '\u2013';
  $('mean').textContent = ok.length ? gs.cm(ok.reduce((s, j) => s + j.jump_height_m, 0) / ok.length) + ' cm' : '\u2013';
  gs.drawTrend($('trend'), a.jumps);
  const tb = document.querySelector('#sessions tbody');
  tb.textContent = '';
  for (const s of a.sessions) {
    const tr = gs.el('tr');
    tr.appendChild(gs.el('td', {}, s.day));
    tr.appendChild(gs.el('td', {}, gs.time(s.started_at)));
    tr.appendChild(gs.el('td', {}, String(s.n_jumps) + (s.n_rejected ? ' (+' + s.n_rejected + ' not kept)' : '')));
    tr.appendChild(gs.el('td', {}, gs.isNum(s.best_jump_m) ? gs.cm(s.best_jump_m) + ' cm' : '\u2013'));
    tr.appendChild(gs.el('td', {}, gs.isNum(s.mean_jump_m) ? gs.cm(s.mean_jump_m) + ' cm' : '\u2013'));
    tr.appendChild(gs.el('td', {}, gs.isNum(s.stature_m) ? s.stature_m.toFixed(2) + ' m' : '\u2013'));
    const td = gs.el('td');
    const del = gs.el('button', { class: 'quiet' }, 'Delete');
    del.addEventListener('click', async () => {
      if (!confirm('Delete this visit and its jumps?')) return;
      try { await gs.api('DELETE', '/api/sessions/' + s.id); showAthlete(id); } catch (e) { $('form-error').textContent = e.message; }
    });
    td.appendChild(del);
    tr.appendChild(td);
    tb.appendChild(tr);
  }
  gs.fillJumps(document.querySelector('#jumps tbody'), a.jumps, async (j, tr) => {
    document.querySelectorAll('#jumps tr.sel').forEach((r) => r.classList.remove('sel'));
    tr.classList.add('sel');
    const full = await gs.api('GET', '/api/jumps/' + j.id);
    gs.drawTrack($('plot'), full.track_json);
  });
  gs.drawTrack($('plot'), null);
}

$('rename-form').addEventListener('submit', async (e) => {
  e.preventDefault();
  const id = gs.param('athlete');
  try {
    await gs.api('PATCH', '/api/athletes/' + id, { name: $('rename-input').value });
    $('rename-input').value = '';
    showList();
    showAthlete(id);
  } catch (err) { $('form-error').textContent = err.message; }
});

showList().catch(() => {});
if (gs.param('athlete')) showAthlete(gs.param('athlete')).catch((e) => { $('form-error').textContent = e.message; });
