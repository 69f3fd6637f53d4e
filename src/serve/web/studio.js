// The studio's page: controls made from the CLI's option definitions (/api/config),
// previews while a control moves (on the reduced photo, the stale request aborted) and
// at full size when it is let go, downloads, and the plot, polled so every tab agrees.
'use strict';
const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get('token') || '';
let config = null, photo = null, previewSeq = 0, inflight = null, draftTimer = null;
let trace = null, traceJob = null, drawnUpTo = 0, view = 'preview';

function api(path, opts = {}) {
  opts.headers = Object.assign({}, opts.headers || {}, token ? { 'X-Stipplot-Token': token } : {});
  return fetch(path, opts);
}
async function jsonOf(res) {
  let body = null;
  try { body = await res.json(); } catch (e) { body = { error: res.statusText }; }
  if (!res.ok) { const err = new Error(body.error || ('HTTP ' + res.status)); err.status = res.status; err.body = body; throw err; }
  return body;
}
function toast(msg) {
  const t = $('toast'); t.textContent = msg; t.style.display = 'block';
  clearTimeout(toast.timer); toast.timer = setTimeout(() => { t.style.display = 'none'; }, 6000);
}
function fmtTime(s) {
  if (s == null || s < 0 || !isFinite(s)) return '–';
  s = Math.round(s);
  const h = Math.floor(s / 3600), m = Math.floor((s % 3600) / 60), r = s % 60;
  return h ? `${h} h ${m} min` : m ? `${m} min ${r} s` : `${r} s`;
}

// ---- controls from the option schema ----
const GROUP_TITLES = { Options: 'Variant', Page: 'Page, margins and pen', Output: 'Device', Planning: 'Planning', Paths: 'Paths', Input: 'Input' };
const OPEN_GROUPS = new Set(['Options', 'Page', 'Output']);
const isNumber = (s) => /^-?\d*\.?\d+(e-?\d+)?$/i.test(String(s).trim());
// A length written with its unit ("15px"): a slider over the number, the unit kept.
const withUnit = (s) => /^(-?\d*\.?\d+)(px|mm|cm|in|pt)$/i.exec(String(s).trim());

function sliderRange(opt) {
  const d = parseFloat(opt.default);
  const integer = /^-?\d+$/.test(opt.default);
  const hi = d > 0 ? (integer ? Math.max(4, Math.ceil(d * 4)) : d * 4) : integer ? 10 : 1;
  return { min: 0, max: hi, step: integer ? 1 : hi / 200 };
}

function makeControl(opt) {
  const wrap = document.createElement('div');
  wrap.className = 'ctl-wrap';
  wrap.dataset.name = opt.name;
  const id = 'opt' + opt.name.replace(/[^a-z0-9]/gi, '_');
  const label = document.createElement('label');
  label.className = 'ctl';
  label.htmlFor = id;
  label.textContent = opt.name.replace(/^-+/, '');
  // A default written with its unit ("3px") shows that unit beside its number instead.
  if (opt.unit && !withUnit(opt.default)) { const u = document.createElement('span'); u.className = 'unit'; u.textContent = opt.unit; label.appendChild(u); }
  if (opt.default !== '' && !opt.flag) { const d = document.createElement('span'); d.className = 'def'; d.textContent = '  default ' + opt.default; label.appendChild(d); }
  let input;
  const row = document.createElement('div');
  row.className = 'ctl-row single';
  if (opt.flag) {
    input = document.createElement('input');
    input.type = 'checkbox';
    const l2 = document.createElement('label');
    l2.append(input, document.createTextNode(opt.help));
    row.appendChild(l2);
    input.addEventListener('change', () => changed(false));
  } else if (opt.name === '--profile') {
    input = document.createElement('select');
    const kinds = { hpgl: 'HPGL', ebb: 'EBB, AxiDraw', gcode: 'G-code' };
    for (const p of config.profiles) input.add(new Option(`${p.name} (${kinds[p.dialect] || p.dialect})`, p.name));
    input.value = opt.default || config.default_profile;
    row.appendChild(input);
    input.addEventListener('change', () => changed(false));
  } else if (opt.choices.length) {
    input = document.createElement('select');
    for (const c of opt.choices) input.add(new Option(c, c));
    input.value = opt.choices.includes(opt.default) ? opt.default : opt.choices[0];
    row.appendChild(input);
    input.addEventListener('change', () => changed(false));
  } else if ((isNumber(opt.default) || withUnit(opt.default)) && !/seed/.test(opt.name)) {
    row.className = 'ctl-row';
    const unit = withUnit(opt.default);
    const number = unit ? unit[1] : opt.default;
    const range = document.createElement('input');
    range.type = 'range';
    Object.assign(range, sliderRange({ ...opt, default: number }));
    range.value = number;
    input = document.createElement('input');
    input.type = 'number';
    input.step = 'any';
    input.value = number;
    if (unit) input.dataset.suffix = unit[2];
    range.addEventListener('input', () => { input.value = range.value; changed(true); });
    range.addEventListener('change', () => { input.value = range.value; changed(false); });
    input.addEventListener('change', () => { range.value = input.value; changed(false); });
    range.id = id + '_range';
    row.append(range, input);
    if (unit) { const u = document.createElement('span'); u.className = 'unit'; u.textContent = unit[2]; row.appendChild(u); row.classList.add('with-unit'); }
  } else {
    input = document.createElement('input');
    input.type = isNumber(opt.default) ? 'number' : 'text';
    input.value = opt.default;
    row.appendChild(input);
    input.addEventListener('change', () => changed(false));
  }
  input.id = id;
  input.dataset.name = opt.name;
  input.classList.add('opt');
  wrap.append(label, row);
  if (!opt.flag) { const h = document.createElement('p'); h.className = 'help'; h.textContent = opt.help; wrap.appendChild(h); }
  return wrap;
}

function buildControls() {
  const m = config.methods[$('method').value];
  $('method-help').textContent = m.description;
  const box = $('controls');
  box.innerHTML = '';
  const groups = new Map();
  for (const o of m.options) {
    if (!groups.has(o.group)) groups.set(o.group, []);
    groups.get(o.group).push(o);
  }
  // The method's own groups first, then the shared ones.
  const shared = ['Page', 'Output', 'Planning', 'Paths', 'Input'];
  const keys = [...groups.keys()];
  const order = [...keys.filter((g) => g === 'Options'), ...keys.filter((g) => g !== 'Options' && !shared.includes(g)),
    ...shared.filter((g) => groups.has(g))];
  for (const g of order) {
    const d = document.createElement('details');
    d.open = OPEN_GROUPS.has(g) || !shared.includes(g);
    const s = document.createElement('summary');
    s.textContent = GROUP_TITLES[g] || g;
    d.appendChild(s);
    for (const o of groups.get(g)) d.appendChild(makeControl(o));
    box.appendChild(d);
  }
}

// Only what differs from the CLI's default is sent (and shown in the command line).
function currentSettings() {
  const m = config.methods[$('method').value];
  const options = {};
  for (const el of document.querySelectorAll('#controls .opt')) {
    const o = m.options.find((x) => x.name === el.dataset.name);
    const wrap = el.closest('.ctl-wrap');
    let differs;
    if (o.flag) { differs = el.checked; if (differs) options[o.name] = true; }
    else {
      let v = String(el.value).trim();
      if (el.dataset.suffix && isNumber(v)) v += el.dataset.suffix;
      differs = v !== '' && !(v === o.default || (isNumber(v) && isNumber(o.default) && parseFloat(v) === parseFloat(o.default)));
      if (differs) options[o.name] = v;
    }
    wrap.classList.toggle('changed', differs);
  }
  return { method: $('method').value, options };
}

// ---- preview ----
function changed(dragging) {
  if (!photo) return;
  if (dragging) {
    clearTimeout(draftTimer);
    draftTimer = setTimeout(() => runPreview(true), 40);
  } else {
    clearTimeout(draftTimer);
    runPreview(false);
  }
}

async function runPreview(draft) {
  const seq = ++previewSeq;
  if (inflight) inflight.abort();  // the server ends the superseded work too
  const ctl = new AbortController();
  inflight = ctl;
  $('busy').textContent = draft ? 'drawing (reduced photo)…' : 'drawing…';
  const t0 = performance.now();
  try {
    const res = await api('/api/preview', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(Object.assign(currentSettings(), { draft })), signal: ctl.signal });
    if (res.status === 409) { const b = await res.json().catch(() => ({})); if (b.superseded) return; }
    const p = await jsonOf(res);
    if (seq !== previewSeq) return;
    await showPreview(p, performance.now() - t0);
  } catch (e) {
    if (e.name === 'AbortError') return;
    if (seq === previewSeq) { toast(e.message); $('busy').textContent = ''; }
  }
}

function showPreview(p, ms) {
  return new Promise((resolve) => {
    const img = new Image();
    img.onload = () => {
      const el = $('preview');
      el.src = img.src;
      el.hidden = false;
      el.dataset.gen = p.gen;
      el.dataset.draft = p.draft ? '1' : '0';
      if (view === 'plot') placeCanvases();
      $('empty').style.display = 'none';
      $('s-marks').textContent = p.marks.toLocaleString('en');
      $('s-time').textContent = p.plot_s != null ? fmtTime(p.plot_s) : '–';
      // A draft is not measured: its fidelity comes with the full preview.
      $('s-fid').textContent = p.fidelity != null ? p.fidelity.toFixed(3) : p.draft ? '…' : '–';
      $('s-secs').textContent = (ms / 1000).toFixed(2) + ' s';
      $('draft-badge').style.visibility = p.draft ? 'visible' : 'hidden';
      $('cli').textContent = p.command;
      $('busy').textContent = p.draft ? 'reduced photo — full size when you let go' : '';
      for (const k of ['svg', 'gcode', 'hpgl', 'ebb']) $('dl-' + k).classList.toggle('off', !!p.draft);
      $('plot-start').disabled = !!p.draft || plotBusy();
      document.body.dataset.previewGen = p.gen;
      document.body.dataset.previewDraft = p.draft ? '1' : '0';
      resolve();
    };
    img.onerror = () => resolve();
    img.src = p.preview + (token ? '?token=' + encodeURIComponent(token) : '');
  });
}

// ---- photo ----
async function upload(file) {
  $('photo-info').textContent = `Uploading ${file.name} (${(file.size / 1e6).toFixed(1)} MB)…`;
  try {
    const res = await api('/api/photo', { method: 'POST', headers: { 'Content-Type': file.type || 'application/octet-stream', 'X-Filename': file.name.replace(/[^\x20-\x7e]/g, '_') }, body: file });
    photo = await jsonOf(res);
    showPhoto();
    // A landscape photo lies across the page, as the CLI's --landscape lays it.
    const landscape = document.querySelector('#controls .opt[data-name="--landscape"]');
    if (landscape) landscape.checked = photo.width > photo.height;
    runPreview(false);
  } catch (e) {
    $('photo-info').textContent = 'Not taken: ' + e.message;
    toast(e.message);
  }
}
function showPhoto() {
  $('photo-info').textContent = `${photo.original_name || photo.name}: ${photo.width} × ${photo.height} px (${(photo.width * photo.height / 1e6).toFixed(1)} MP); reduced copy for dragging ${photo.draft[0]} × ${photo.draft[1]}`;
}

// ---- plot ----
let lastPlot = null;
const selectedPort = () => $('port').value;
const plotBusy = () => lastPlot && ['preparing', 'plotting', 'paused', 'pen_change'].includes(lastPlot.status);

async function plotCommand(cmd, extra = {}) {
  try {
    const res = await api('/api/plot/' + cmd, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(Object.assign({ port: selectedPort() }, extra)) });
    showPlot(await jsonOf(res));
  } catch (e) { toast(e.message); }
}

function setView(v) {
  view = v;
  $('tab-preview').classList.toggle('on', v === 'preview');
  $('tab-plot').classList.toggle('on', v === 'plot');
  $('plotcanvas').style.display = v === 'plot' ? 'block' : 'none';
  $('pencanvas').style.display = v === 'plot' ? 'block' : 'none';
  // The plot is drawn over the preview: what is still to come stays faint underneath.
  $('preview').classList.toggle('faded', v === 'plot');
  if (v === 'plot') placeCanvases();
}

async function loadTrace(job) {
  try {
    const t = await jsonOf(await api('/api/plot/trace?port=' + encodeURIComponent(selectedPort())));
    if (!t) return;
    trace = t; traceJob = job; drawnUpTo = 0;
    drawTraceBase();
  } catch (e) { /* not made yet */ }
}

// The trace is in the method page's millimetres, where the preview shows the drawing; the
// canvases lie exactly over the preview image (or, with no preview, alone on white).
function overPreview() { const img = $('preview'); return !img.hidden && img.naturalWidth > 0; }
function placeCanvases() {
  const view_ = $('view'), img = $('preview');
  for (const c of [$('plotcanvas'), $('pencanvas')]) {
    if (overPreview()) {
      const r = img.getBoundingClientRect(), v = view_.getBoundingClientRect();
      Object.assign(c.style, { left: (r.left - v.left) + 'px', top: (r.top - v.top) + 'px', width: r.width + 'px', height: r.height + 'px' });
    } else {
      Object.assign(c.style, { left: '', top: '', width: '', height: '' });
    }
  }
}
function traceTransform() {
  const c = $('plotcanvas');
  const [pw, ph] = trace.page_mm;
  c.width = 1400; c.height = Math.round(1400 * ph / pw);
  const s = c.width / pw;
  trace.px_per_mm = s;
  return (x, y) => [x * s, y * s];
}
function strokeSegments(ctx, tf, from, to, style, width) {
  ctx.strokeStyle = style; ctx.fillStyle = style; ctx.lineWidth = width; ctx.lineCap = 'round';
  ctx.beginPath();
  const dots = new Path2D();
  for (let i = from; i < to; i++) {
    const [, a, b, c2, d] = trace.segments[i];
    const [px, py] = tf(a, b), [qx, qy] = tf(c2, d);
    if (qx === px && qy === py) { dots.moveTo(px + width * 1.2, py); dots.arc(px, py, width * 1.2, 0, 2 * Math.PI); continue; }
    ctx.moveTo(px, py);
    ctx.lineTo(qx, qy);
  }
  ctx.stroke();
  ctx.fill(dots);
}
function inkWidth() { return Math.max(1.6, 0.3 * trace.px_per_mm); }
function drawTraceBase() {
  const c = $('plotcanvas'), ctx = c.getContext('2d');
  trace.tf = traceTransform();
  placeCanvases();
  ctx.clearRect(0, 0, c.width, c.height);
  for (const k of ['plotcanvas', 'pencanvas']) $(k).classList.toggle('alone', !overPreview());
  // No preview to draw over (a journal resumed after the page was reloaded): the job, faint.
  if (!overPreview()) strokeSegments(ctx, trace.tf, 0, trace.segments.length, 'rgba(100,116,139,0.30)', inkWidth());
}
function drawTraceUpTo(linesAcked) {
  if (!trace) return;
  const ctx = $('plotcanvas').getContext('2d');
  let end = drawnUpTo;
  while (end < trace.segments.length && trace.segments[end][0] < linesAcked) end++;
  if (end > drawnUpTo) strokeSegments(ctx, trace.tf, drawnUpTo, end, '#0f766e', inkWidth());
  drawnUpTo = end;
  // Where the pen is: a ring over the last mark on the paper (an overlay canvas keeps
  // the drawing underneath intact).
  const ring = $('pencanvas'), rctx = ring.getContext('2d');
  ring.width = $('plotcanvas').width; ring.height = $('plotcanvas').height;
  if (drawnUpTo > 0 && drawnUpTo < trace.segments.length) {
    const [, , , x, y] = trace.segments[drawnUpTo - 1];
    const [px, py] = trace.tf(x, y);
    rctx.strokeStyle = '#f97316'; rctx.lineWidth = 4;
    rctx.beginPath(); rctx.arc(px, py, 14, 0, 2 * Math.PI); rctx.stroke();
  }
}

function showPlot(st) {
  lastPlot = st;
  const s = st ? st.status : 'idle';
  $('status-pill').textContent = s.replace('_', ' ');
  $('status-pill').className = s;
  const pct = st ? st.percent || 0 : 0;
  $('plot-bar').style.width = pct.toFixed(1) + '%';
  $('p-lines').textContent = st && st.lines ? `${(st.lines_acked || 0).toLocaleString('en')} / ${st.lines.toLocaleString('en')}` : '–';
  $('p-pct').textContent = st ? pct.toFixed(1) + ' %' : '–';
  $('p-eta').textContent = st && s !== 'done' ? fmtTime(st.eta_s) : s === 'done' ? 'finished' : '–';
  $('p-dev').textContent = st ? (st.port === 'sim' ? 'built-in simulator' : st.port) + (st.device_state ? ' · ' + st.device_state : '') : '–';
  let msg = '';
  if (st && s === 'done' && st.result) {
    msg = `Plotted ${st.result.lines_acked.toLocaleString('en')} lines in ${fmtTime(st.result.seconds)}`;
    if (st.result.sim_exact === true) msg += '; the simulator drew exactly the job.';
    else if (st.result.sim_segments != null && trace) msg += `; the simulator drew ${st.result.sim_segments.toLocaleString('en')} marks for the job's ${trace.segments.length.toLocaleString('en')} (a pause lifts and lowers the pen again).`;
  }
  else if (st && st.message) msg = st.message;
  else if (st && s === 'preparing') msg = 'Making the job at full size…';
  $('p-msg').textContent = msg;
  $('pen-prompt').style.display = s === 'pen_change' ? 'block' : 'none';
  if (s === 'pen_change') {
    // "M0 (MSG,Change pen: pen 2 magenta #ec008c)": the pen named, as on the terminal.
    const m = /Change pen:\s*([^)]*)/.exec(st.pen_change);
    const named = m ? m[1].trim() : st.pen_change;
    const colour = /#[0-9a-f]{6}/i.exec(named);
    $('pen-line').textContent = named;
    $('pen-swatch').style.background = colour ? colour[0] : 'transparent';
  }
  const busy = plotBusy();
  $('plot-start').disabled = busy || !photo || document.body.dataset.previewDraft !== '0';
  $('plot-pause').disabled = s !== 'plotting';
  $('plot-resume').disabled = s !== 'paused';
  $('plot-abort').disabled = !busy;
  $('plot-journal').style.display = st && st.can_resume && !busy ? 'inline-block' : 'none';
  document.body.dataset.plotStatus = s;
  if (st && s !== 'preparing' && s !== 'failed' && traceJob !== st.job + (st.resumed ? '+r' : '')) {
    traceJob = st.job + (st.resumed ? '+r' : '');
    loadTrace(traceJob);
  }
  if (st && trace) drawTraceUpTo(s === 'done' ? Infinity : st.lines_acked || 0);
}

async function poll() {
  try {
    const st = await jsonOf(await api('/api/state'));
    if (st.photo && (!photo || photo.name !== st.photo.name || photo.width !== st.photo.width)) { photo = st.photo; showPhoto(); }
    if (st.preview && $('preview').dataset.gen !== String(st.preview.gen) && !inflight_busy()) await showPreview(st.preview, st.preview.seconds * 1000);
    const p = st.plots[selectedPort()];
    if (p) { if (!lastPlot || p.status !== 'idle') { if (plotBusy() || p.status !== (lastPlot && lastPlot.status) || p.lines_acked !== (lastPlot && lastPlot.lines_acked)) { if (view !== 'plot' && ['preparing', 'plotting'].includes(p.status) && (!lastPlot || lastPlot.status !== p.status)) setView('plot'); showPlot(p); } } }
  } catch (e) { /* the server may be restarting */ }
  setTimeout(poll, plotBusy() ? 250 : 1000);
}
const inflight_busy = () => $('busy').textContent.startsWith('drawing');

async function init() {
  config = await jsonOf(await api('/api/config'));
  // Stippling first: the simplest method to start with.
  const names = Object.keys(config.methods).sort((a, b) => (b === 'stipple') - (a === 'stipple') || a.localeCompare(b));
  for (const name of names) $('method').add(new Option(name, name));
  $('method').addEventListener('change', () => { buildControls(); changed(false); });
  buildControls();
  for (const p of config.ports) $('port').add(new Option(p === 'sim' ? 'Built-in simulator' : p, p));
  const drop = $('drop');
  drop.addEventListener('click', () => $('file').click());
  $('file').addEventListener('change', () => { if ($('file').files[0]) upload($('file').files[0]); });
  drop.addEventListener('dragover', (e) => { e.preventDefault(); drop.classList.add('over'); });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => { e.preventDefault(); drop.classList.remove('over'); if (e.dataTransfer.files[0]) upload(e.dataTransfer.files[0]); });
  $('copy-cli').addEventListener('click', () => navigator.clipboard && navigator.clipboard.writeText($('cli').textContent));
  $('tab-preview').addEventListener('click', () => setView('preview'));
  $('tab-plot').addEventListener('click', () => setView('plot'));
  window.addEventListener('resize', () => { if (view === 'plot') placeCanvases(); });
  $('plot-start').addEventListener('click', () => { trace = null; traceJob = null; setView('plot'); plotCommand('start'); });
  $('plot-pause').addEventListener('click', () => plotCommand('pause'));
  $('plot-resume').addEventListener('click', () => plotCommand('resume'));
  $('plot-abort').addEventListener('click', () => plotCommand('abort'));
  $('pen-continue').addEventListener('click', () => plotCommand('continue'));
  $('pen-abort').addEventListener('click', () => plotCommand('abort'));
  $('plot-journal').addEventListener('click', () => { setView('plot'); plotCommand('start', { resume: true }); });
  document.body.dataset.ready = '1';
  poll();
}
init().catch((e) => toast('The studio could not start: ' + e.message));
