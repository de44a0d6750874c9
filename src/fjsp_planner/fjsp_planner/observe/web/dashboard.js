// The live mission page: draws the parts the server embedded in the page at once, then keeps
// the parts the monitor publishes (server-sent events on /events) and redraws the ones that
// changed. Plain DOM and SVG, no library.
'use strict';

const data = {};
// When each story line was first shown, and each change of a robot's mode or job
// ([robot, mode, job, Date.now()]), for measuring the page's latency.
window.fjspShown = {};
window.fjspRobotsShown = [];
const shownRow = {};
window.fjspData = data;

// matplotlib's tab20, so a job has the same colour here as in the PNG chart.
const PALETTE = ['#1f77b4', '#aec7e8', '#ff7f0e', '#ffbb78', '#2ca02c', '#98df8a', '#d62728',
  '#ff9896', '#9467bd', '#c5b0d5', '#8c564b', '#c49c94', '#e377c2', '#f7b6d2', '#7f7f7f',
  '#c7c7c7', '#bcbd22', '#dbdb8d', '#17becf', '#9edae5'];
const SVG = 'http://www.w3.org/2000/svg';

function $(id) { return document.getElementById(id); }

// Times as everywhere a person reads them: an integer as it is, any other time with three
// decimals, more (up to the data's six) where two times written together would read the same.
function numbers(...values) {
  const known = values.filter((v) => v !== null && v !== undefined);
  let places = 3;
  const alike = (a, b) => a !== b && a.toFixed(places) === b.toFixed(places);
  while (places < 6 && known.some((a) => known.some((b) => alike(a, b)))) places += 1;
  return values.map((v) => (v === null || v === undefined ? '-'
    : Number.isInteger(v) ? String(v) : v.toFixed(places)));
}

function number(value) {
  return numbers(value)[0];
}

function element(tag, attributes = {}, text = '') {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  if (text) node.textContent = text;
  return node;
}

function svg(tag, attributes = {}, title = '') {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  if (title) {
    const tip = document.createElementNS(SVG, 'title');
    tip.textContent = title;
    node.appendChild(tip);
  }
  return node;
}

function renderMission() {
  const m = data.mission;
  if (!m) return;
  $('mission-id').textContent = m.mission_id || '-';
  $('planner').textContent = m.planner ? `planner: ${m.planner}` : '';
  $('state').textContent = m.state;
  $('state').dataset.state = m.state;
  if (!m.mission_id) return;
  $('scenario').textContent = m.scenario ? `scenario ${m.scenario}` : '';
  $('revision').textContent = m.revision;
  $('jobs').textContent = `${m.jobs_done}/${m.jobs_total}`;
  $('jobs-bar').max = Math.max(m.jobs_total, 1);
  $('jobs-bar').value = m.jobs_done;
  const detail = [`${m.jobs_running} running`];
  if (m.aborted_attempts) detail.push(`${m.aborted_attempts} aborted`);
  if (m.voided_attempts) detail.push(`${m.voided_attempts} voided`);
  if (m.status_jobs && !m.agrees) detail.push(`planner says ${m.status_jobs[0]}/${m.status_jobs[1]}`);
  $('jobs-detail').textContent = detail.join(', ');
  $('time').textContent = number(m.time);
  const [planned, first, outcome] = numbers(m.planned_makespan, m.first_makespan,
    m.ended ? m.executed_makespan : m.projected_makespan);
  const parts = [`planned ${planned}`];
  if (m.revision > 1) parts.push(`(revision 1: ${first})`);
  parts.push(m.ended ? `executed ${outcome}` : `projected ${outcome}`);
  $('makespan').textContent = parts.join(', ');
  const reasons = $('reasons');
  reasons.replaceChildren();
  if (m.revision > 1 && m.replan_reasons.length) {
    reasons.appendChild(element('div', {class: 'replan'},
      `Revision ${m.revision} re-planned because: ${m.replan_reasons.join('; ')}`));
  }
  for (const w of m.warnings) reasons.appendChild(element('div', {class: 'warning'}, `Warning: ${w}`));
  for (const b of m.blocked_reasons) reasons.appendChild(element('div', {class: 'blocked'}, `${m.reasons_label}: ${b}`));
}

function renderRobots() {
  const body = $('robots').tBodies[0];
  body.replaceChildren();
  for (const r of data.robots || []) {
    const key = `${r.mode}/${r.job || ''}`;
    if (shownRow[r.robot] !== key) {
      shownRow[r.robot] = key;
      window.fjspRobotsShown.push([r.robot, r.mode, r.job || '', Date.now()]);
    }
    const row = element('tr', {'data-robot': r.robot});
    row.appendChild(element('td', {class: 'name'}, r.robot));
    row.appendChild(element('td', {class: 'type'}, r.type || ''));
    const mode = element('td', {class: 'mode'});
    mode.appendChild(element('span', {'data-mode': r.mode}, r.mode));
    row.appendChild(mode);
    row.appendChild(element('td', {class: 'job'}, r.job || '-'));
    const progress = element('td', {class: 'progress'});
    if (r.mode === 'travelling' || r.mode === 'working') {
      const bar = element('progress', {max: '1'});
      bar.value = r.progress || 0;
      progress.appendChild(bar);
      progress.appendChild(document.createTextNode(` ${Math.round((r.progress || 0) * 100)}%`));
    }
    row.appendChild(progress);
    const where = r.destination ? `${r.location || '?'} \u2192 ${r.destination}` : (r.location || '-');
    row.appendChild(element('td', {class: 'where'}, where));
    let detail = r.detail || '';
    if (!detail && r.healthy === false && r.since !== null && r.since !== undefined) {
      detail = `since t=${number(r.since)}`;
    }
    row.appendChild(element('td', {class: 'detail'}, detail));
    body.appendChild(row);
  }
}

function jobColours(t) {
  const jobs = new Set(t.work.map((w) => w.job));
  for (const plan of t.plans) for (const task of plan.tasks) jobs.add(task.job);
  const colours = {};
  [...jobs].sort().forEach((job, index) => { colours[job] = PALETTE[index % PALETTE.length]; });
  return colours;
}

function renderTimeline() {
  const t = data.timeline;
  const box = $('timeline');
  if (!t) return;
  const rowHeight = 54, left = 90, top = 18, bottom = 26;
  const width = Math.max(box.clientWidth || 900, 500);
  const end = Math.max(t.end || 1, 1) * 1.02;
  const x = (time) => left + Math.max(time, 0) / end * (width - left - 10);
  const rows = {};
  t.robots.forEach((robot, index) => { rows[robot] = top + index * rowHeight; });
  const height = top + t.robots.length * rowHeight + bottom;
  const chart = svg('svg', {width, height, viewBox: `0 0 ${width} ${height}`});
  const colours = jobColours(t);
  const close = (item) => (item.open ? (t.now === null ? end : t.now) : item.end);

  for (const robot of t.robots) {
    chart.appendChild(svg('line', {x1: left, x2: width - 10, y1: rows[robot] + rowHeight,
      y2: rows[robot] + rowHeight, stroke: '#eee'}));
    chart.appendChild(svg('text', {x: 4, y: rows[robot] + rowHeight / 2 + 4, 'font-size': 12},
      '')).textContent = robot;
  }
  for (let tick = 0; tick <= end; tick += niceStep(end)) {
    chart.appendChild(svg('line', {x1: x(tick), x2: x(tick), y1: top, y2: height - bottom + 4,
      stroke: '#f0f0f0'}));
    chart.appendChild(svg('text', {x: x(tick) - 6, y: height - 8})).textContent = `${Math.round(tick)}`;
  }
  for (const s of t.health) {
    if (!(s.robot in rows)) continue;
    const stop = close(s);
    chart.appendChild(svg('rect', {x: x(s.start), width: Math.max(x(stop) - x(s.start), 1),
      y: rows[s.robot] + 1, height: rowHeight - 2, class: `health ${s.kind}`},
      `${s.robot} ${s.kind} from t=${number(s.start)}${s.open ? '' : ` to t=${number(s.end)}`}`));
    const mark = svg('text', {x: x(s.start) - 5, y: rows[s.robot] + 11, class: 'fault-mark',
      fill: 'red'}, `${s.robot} ${s.kind} at t=${number(s.start)}`);
    mark.appendChild(document.createTextNode('\u2716'));
    chart.appendChild(mark);
    if (!s.open) {
      const back = svg('text', {x: x(s.end) - 5, y: rows[s.robot] + 11, fill: 'green'},
        `${s.robot} back at t=${number(s.end)}`);
      back.appendChild(document.createTextNode('\u25B2'));
      chart.appendChild(back);
    }
  }
  const lanes = t.plans.length > 1 ? [6, 14] : [10];
  t.plans.forEach((plan, index) => {
    const latest = t.plans.length > 1 && index === t.plans.length - 1;
    for (const task of plan.tasks) {
      if (!(task.robot in rows)) continue;
      const y = rows[task.robot] + lanes[index];
      if (task.arrival > task.travel_start) {
        chart.appendChild(svg('line', {x1: x(task.travel_start), x2: x(task.arrival), y1: y + 3,
          y2: y + 3, stroke: '#aaa'}));
      }
      chart.appendChild(svg('rect', {x: x(task.start), y, height: 6,
        width: Math.max(x(task.end) - x(task.start), 1),
        class: latest ? 'plan-last' : 'plan-first', fill: latest ? colours[task.job] : 'none'},
        `revision ${plan.revision} plans ${task.job} on ${task.robot}: t=${number(task.start)} to ${number(task.end)}`));
    }
  });
  for (const w of t.work) {
    if (!(w.robot in rows)) continue;
    const stop = close(w);
    const y = rows[w.robot] + 22;
    const rect = svg('rect', {x: x(w.start), y, height: 16,
      width: Math.max(x(stop) - x(w.start), 2), fill: colours[w.job],
      class: `work ${w.outcome}`, 'data-job': w.job, 'data-outcome': w.outcome},
      `${w.job} attempt ${w.attempt} on ${w.robot}: ${w.outcome}, t=${number(w.start)} to ${w.open ? 'now' : number(w.end)}${w.reason ? ` (${w.reason})` : ''}`);
    chart.appendChild(rect);
    const label = svg('text', {x: x(w.start) + 2, y: y + 12});
    label.textContent = w.attempt > 1 ? `${w.job}#${w.attempt}` : w.job;
    chart.appendChild(label);
  }
  for (const a of t.activities) {
    if (!(a.robot in rows) || !['travelling', 'waiting', 'holding'].includes(a.mode)) continue;
    const stop = close(a);
    if (stop <= a.start) continue;
    const y = rows[a.robot] + 45;
    chart.appendChild(svg('line', {x1: x(a.start), x2: x(stop), y1: y, y2: y,
      class: `activity ${a.mode}`}, `${a.robot} ${a.mode}${a.job ? ` (${a.job})` : ''}`));
  }
  for (const r of t.revisions) {
    if (r.time === null) continue;
    chart.appendChild(svg('line', {x1: x(r.time), x2: x(r.time), y1: top - 4,
      y2: height - bottom, class: 'revision'},
      `revision ${r.number} at t=${number(r.time)}${r.reasons.length ? `: ${r.reasons.join('; ')}` : ''}`));
    const label = svg('text', {x: x(r.time) + 2, y: top - 6, fill: 'purple', class: 'revision-label'});
    label.textContent = `r${r.number}`;
    chart.appendChild(label);
  }
  if (t.now !== null && data.mission && !data.mission.ended) {
    chart.appendChild(svg('line', {x1: x(t.now), x2: x(t.now), y1: top - 4, y2: height - bottom,
      class: 'now'}, `now: t=${number(t.now)}`));
  }
  box.replaceChildren(chart);
}

function renderMap() {
  const m = data.map;
  const section = $('map-section');
  section.hidden = !m;
  if (!m) return;
  const box = $('map');
  // Seen from above, x east and y north; a height is drawn upward from the place's ground
  // point, with a dashed line down to it.
  const up = (p) => p.y + (m.three_d ? p.z : 0);
  $('map-view').textContent = m.three_d ? '(seen from above; heights drawn upward)' : '(seen from above)';
  const points = [...m.places, ...m.robots.filter((r) => r.x !== undefined)];
  const xs = points.map((p) => p.x), ys = points.flatMap((p) => [p.y, up(p)]);
  const [minX, maxX, minY, maxY] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const margin = 48, width = Math.max(box.clientWidth || 900, 400);
  const span = Math.max(maxX - minX, maxY - minY, 1e-9);
  const scale = Math.min((width - 2 * margin) / Math.max(maxX - minX, span / 4),
    440 / Math.max(maxY - minY, span / 4));
  const height = (maxY - minY) * scale + 2 * margin;
  const left = (width - (maxX - minX) * scale) / 2;
  const sx = (x) => left + (x - minX) * scale;
  const sy = (p, z = true) => margin + (maxY - (z ? up(p) : p.y)) * scale;
  const chart = svg('svg', {width, height, viewBox: `0 0 ${width} ${height}`});
  const byName = Object.fromEntries(m.places.map((p) => [p.name, p]));
  for (const p of m.places) {
    if (m.three_d && p.z !== 0) {
      chart.appendChild(svg('line', {x1: sx(p.x), x2: sx(p.x), y1: sy(p), y2: sy(p, false),
        class: 'height'}));
    }
    const done = p.done.length ? ` (done: ${p.done.join(', ')})` : '';
    chart.appendChild(svg('circle', {cx: sx(p.x), cy: sy(p), r: 6, class: 'place',
      'data-place': p.name}, `${p.name} (${[p.x, p.y, p.z].map((v) => +v.toFixed(3)).join(', ')}): ${p.jobs.join(', ') || 'no job'}${done}`));
    chart.appendChild(svg('text', {x: sx(p.x), y: sy(p) + 20, class: 'place-name'})).textContent = p.name;
  }
  for (const r of m.robots) {
    const from = byName[r.location], to = byName[r.destination];
    if (r.x === undefined || !from || !to) continue;
    chart.appendChild(svg('line', {x1: sx(from.x), y1: sy(from), x2: sx(to.x), y2: sy(to),
      class: 'leg', 'data-robot': r.robot}));
  }
  for (const r of m.robots) {
    if (r.x === undefined) continue;
    // Robots at one spot sit round it (east over north to west); each name goes outward.
    const [dx, dy] = r.spread;
    const x = sx(r.x) + 16 * dx, y = sy(r) - 16 * dy;
    const doing = r.job ? ` on ${r.job}` : '';
    const where = r.destination ? `${r.location || '?'} \u2192 ${r.destination}` : r.location;
    chart.appendChild(svg('circle', {cx: x, cy: y, r: 8, class: 'robot', 'data-robot': r.robot,
      'data-mode': r.mode}, `${r.robot}: ${r.mode}${doing} at ${where}`));
    const alone = dx === 0 && dy === 0;
    const anchor = alone || dx > 0.3 ? 'start' : dx < -0.3 ? 'end' : 'middle';
    const label = svg('text', {x: x + (alone ? 10 : 11 * dx), y: alone ? y - 8 : y - 12 * dy + 4,
      class: 'robot-name', 'text-anchor': anchor});
    label.textContent = r.robot;
    chart.appendChild(label);
  }
  box.replaceChildren(chart);
}

function niceStep(end) {
  const raw = end / 10;
  const power = 10 ** Math.floor(Math.log10(raw));
  return [1, 2, 5, 10].map((f) => f * power).find((s) => s >= raw);
}

function renderStory() {
  const list = $('story');
  const now = Date.now();
  list.replaceChildren();
  for (const item of [...(data.story || [])].reverse()) {
    if (!(item.key in window.fjspShown)) window.fjspShown[item.key] = now;
    const line = element('li', {'data-kind': item.kind, 'data-key': item.key});
    line.appendChild(element('span', {class: 't'}, `t=${number(item.time)}`));
    line.appendChild(document.createTextNode(item.text));
    list.appendChild(line);
  }
}

function renderMissions() {
  const body = $('missions').tBodies[0];
  body.replaceChildren();
  for (const m of [...(data.missions || [])].reverse()) {
    const row = element('tr', {'data-mission': m.mission_id});
    row.appendChild(element('td', {}, m.mission_id));
    row.appendChild(element('td', {}, m.scenario));
    row.appendChild(element('td', {}, m.state));
    row.appendChild(element('td', {}, `${m.jobs_done}/${m.jobs_total}`));
    body.appendChild(row);
  }
}

const RENDER = {mission: renderMission, robots: renderRobots, map: renderMap,
  timeline: renderTimeline, story: renderStory, missions: renderMissions};

function apply(update) {
  Object.assign(data, update);
  for (const name of Object.keys(update)) if (RENDER[name]) RENDER[name]();
  // The timeline's "now" line and the mission's end both depend on the mission part.
  if ('mission' in update && !('timeline' in update)) renderTimeline();
}

function connect() {
  const source = new EventSource('events');
  source.addEventListener('open', () => { $('connection').dataset.state = 'live'; $('connection').textContent = 'live'; });
  source.addEventListener('error', () => { $('connection').dataset.state = 'disconnected'; $('connection').textContent = 'disconnected, retrying'; });
  source.addEventListener('update', (event) => apply(JSON.parse(event.data)));
}

window.addEventListener('resize', () => { renderTimeline(); renderMap(); });
// What the server wrote into the page, drawn before the first update arrives.
apply(JSON.parse($('initial-state').textContent));
connect();
