// day.js - one day's visits, who jumped and how high; CSV of that day.
'use strict';

const $ = (id) => document.getElementById(id);

async function show(day) {
  $('day').value = day;
  $('csv').href = '/api/jumps.csv?day=' + day;
  const list = await gs.api('GET', '/api/sessions?day=' + day);
  const tb = document.querySelector('#sessions tbody');
  tb.textContent = '';
  for (const s of list) {
    const tr = gs.el('tr');
    tr.appendChild(gs.el('td', {}, gs.time(s.started_at)));
    const td = gs.el('td');
    if (s.athlete_id) td.appendChild(gs.el('a', { href: '/history.html?athlete=' + s.athlete_id }, s.athlete));
    else td.textContent = 'unnamed';
    tr.appendChild(td);
    tr.appendChild(gs.el('td', {}, String(s.n_jumps) + (s.n_rejected ? ' (+' + s.n_rejected + ' not kept)' : '')));
    tr.appendChild(gs.el('td', {}, gs.isNum(s.best_jump_m) ? gs.cm(s.best_jump_m) + ' cm' : '\u2013'));
    tr.appendChild(gs.el('td', {}, gs.isNum(s.mean_jump_m) ? gs.cm(s.mean_jump_m) + ' cm' : '\u2013'));
    tr.appendChild(gs.el('td', {}, gs.isNum(s.stature_m) ? s.stature_m.toFixed(2) + ' m' : '\u2013'));
    tr.appendChild(gs.el('td', {}, s.ended_at ? gs.time(s.ended_at) + (s.end_reason ? ' (' + s.end_reason.replace(/_/g, ' ') + ')' : '') : 'in progress'));
    tb.appendChild(tr);
  }
  if (!list.length) {
    const tr = gs.el('tr');
    tr.appendChild(gs.el('td', { colspan: 7 }, 'no visits that day'));
    tb.appendChild(tr);
  }
}

$('day-form').addEventListener('submit', (e) => {
  e.preventDefault();
  const d = $('day').value;
  history.replaceState(null, '', '/day.html?day=' + d);
  show(d).catch((err) => { $('form-error').textContent = err.message; });
});

show(gs.param('day') || gs.today()).catch((err) => { $('form-error').textContent = err.message; });
