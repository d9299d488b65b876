// The lab page. Its settings panel is built from the command line's own flags
// (`Lab.settingsFlags()`), so that it offers what `gnomon render` does and refuses
// what it refuses, in the same words. The URL holds the state
// (`?scene=spheres&technique=pcss&width=640`), so that a view can be shared as a
// link. Every change renders again; the frame, its errors against `raytraced` and
// the pass times are shown. `?status=1` is for tests: the page's title becomes
// `gnomon: done` (or `gnomon: error`) after each render, and the report is in #status.
import init, { Lab } from './gnomon.js';

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
// Keys of the URL that are the page's, not settings flags.
const PAGE_KEYS = ['scene', 'truth', 'status'];
// The flags shown first; the rest are under "Every setting".
const MAIN_FLAGS = ['technique', 'light', 'width', 'height', 'partition', 'refine', 'shadow-res'];

let lab = null;
let flags = {};
let sceneName = params.get('scene') || 'spheres';
let fromFile = false;
let generation = 0;
// The lab takes one call at a time while it renders: every action waits its turn.
let queue = Promise.resolve();
function serial(task) {
  const run = queue.then(task);
  queue = run.catch(() => {});
  return run;
}

function showError(message) {
  $('error').textContent = message || '';
}

function setTitle(state) {
  document.title = `gnomon: ${state}`;
}

function flagsFromUrl() {
  const out = {};
  for (const [key, value] of params) {
    if (!PAGE_KEYS.includes(key)) out[key] = value;
  }
  return out;
}

function updateUrl() {
  const query = new URLSearchParams();
  if (!fromFile) query.set('scene', sceneName);
  for (const [key, value] of Object.entries(flags)) query.set(key, String(value));
  if (!$('truth').checked) query.set('truth', '0');
  if (params.get('status')) query.set('status', params.get('status'));
  const url = `${location.pathname}?${query}`;
  history.replaceState(null, '', url);
  $('link').href = url;
  // The viewer takes the same keys; a model from a file stays in the lab.
  $('viewer-link').href = `viewer.html?${query}`;
  $('viewer-link').hidden = fromFile;
}

// One control for one flag: a list, a switch or a text field, showing its default.
function control(info) {
  const label = document.createElement('label');
  label.title = info.help;
  let input;
  if (info.switch) {
    input = document.createElement('input');
    input.type = 'checkbox';
    input.checked = flags[info.name] === 'true' || flags[info.name] === true;
    label.append(input, ` ${info.name}`);
  } else {
    if (info.choices.length) {
      input = document.createElement('select');
      const unset = new Option(`(default${info.default ? `: ${info.default}` : ''})`, '');
      input.append(unset, ...info.choices.map((c) => new Option(c, c)));
    } else {
      input = document.createElement('input');
      input.type = 'text';
      input.placeholder = info.default ?? "(the scene's)";
    }
    input.value = flags[info.name] ?? '';
    label.append(`${info.name} `, input);
  }
  input.id = `flag-${info.name}`;
  input.addEventListener('change', () => {
    const value = info.switch ? (input.checked ? 'true' : '') : input.value.trim();
    const next = { ...flags };
    if (value === '') delete next[info.name];
    else next[info.name] = value;
    apply(next);
  });
  return label;
}

function buildPanel() {
  const infos = Lab.settingsFlags();
  const main = $('main-settings');
  const all = $('all-settings');
  let heading = null;
  for (const info of infos) {
    // A technique's name is free (a host may register its own): the list is the
    // renderer's registry.
    if (info.name === 'technique') info.choices = lab.techniques();
    if (MAIN_FLAGS.includes(info.name)) {
      main.append(control(info));
      continue;
    }
    if (info.heading !== heading) {
      heading = info.heading;
      const h = document.createElement('h4');
      h.textContent = heading;
      all.append(h);
    }
    all.append(control(info));
  }
  const select = $('scene');
  for (const name of Lab.builtinScenes()) select.append(new Option(name, name));
  select.value = sceneName;
  select.addEventListener('change', () => loadBuiltin(select.value));
  $('truth').checked = params.get('truth') !== '0';
  $('status').hidden = params.get('status') !== '1';
  $('truth').addEventListener('change', () => { updateUrl(); render(); });
  $('render').addEventListener('click', () => render());
}

// Settings the command line accepts, or its error and the settings as they were.
function apply(next) {
  return serial(() => applyNow(next));
}

function applyNow(next) {
  try {
    lab.setSettings(next);
    flags = next;
    showError('');
    updateUrl();
    render();
  } catch (e) {
    showError(e.message);
    for (const [name, value] of Object.entries(flags)) {
      const input = $(`flag-${name}`);
      if (input && input.type !== 'checkbox') input.value = value;
    }
  }
}

function loadBuiltin(name) {
  return serial(() => loadBuiltinNow(name));
}

function loadBuiltinNow(name) {
  try {
    lab.loadBuiltin(name);
    sceneName = name;
    fromFile = false;
    showError('');
    updateUrl();
    render();
  } catch (e) {
    showError(e.message);
  }
}

async function loadFile(file) {
  const bytes = new Uint8Array(await file.arrayBuffer());
  return serial(() => loadBytesNow(bytes, file));
}

function loadBytesNow(bytes, file) {
  try {
    const warnings = lab.loadGltf(bytes, file.name);
    sceneName = file.name;
    fromFile = true;
    const select = $('scene');
    select.append(new Option(file.name, file.name));
    select.value = file.name;
    showError(warnings.map((w) => `warning: ${w}`).join('\n'));
    updateUrl();
    render();
  } catch (e) {
    // The lab keeps its scene: the page goes on as it was.
    showError(e.message);
  }
}

function draw(canvas, rgba, width, height) {
  canvas.width = width;
  canvas.height = height;
  const context = canvas.getContext('2d');
  if (!rgba) {
    context.clearRect(0, 0, width, height);
    return;
  }
  const pixels = new Uint8ClampedArray(rgba.buffer, rgba.byteOffset, rgba.length);
  context.putImageData(new ImageData(pixels, width, height), 0, 0);
}

function figures(report) {
  const rows = [];
  const percent = (x) => `${(100 * x).toFixed(3)} %`;
  if (report.truth) {
    const t = report.truth;
    rows.push(['mismatch vs raytraced', `${percent(t.mismatch_rate)} of ${t.compared} light-facing pixels`]);
    rows.push(['falsely shadowed / lit', `${t.false_shadow} / ${t.false_lit}`]);
  }
  rows.push(['lit / shadowed pixels', `${report.lit} / ${report.shadowed}`]);
  if (report.frame_ms != null) rows.push(['GPU frame', `${report.frame_ms.toFixed(2)} ms`]);
  for (const p of report.passes) rows.push([`  ${p.pass} passes`, `${p.ms.toFixed(2)} ms`]);
  rows.push(['adapter', report.adapter]);
  const table = $('figures');
  table.replaceChildren(...rows.map(([k, v]) => {
    const tr = document.createElement('tr');
    for (const text of [k, v]) {
      const td = document.createElement('td');
      td.textContent = text;
      tr.append(td);
    }
    return tr;
  }));
}

// Renders once the lab is free; a render asked for meanwhile replaces this one.
function render() {
  const mine = ++generation;
  setTitle('rendering');
  return serial(() => (mine === generation ? renderNow() : undefined));
}

async function renderNow() {
  try {
    const report = await lab.render({ truth: $('truth').checked });
    draw($('image'), lab.color(), report.width, report.height);
    draw($('heatmap'), lab.heatmap(), report.width, report.height);
    figures(report);
    $('status').textContent = JSON.stringify(report);
    setTitle('done');
    return report;
  } catch (e) {
    showError(e.message);
    $('status').textContent = JSON.stringify({ error: e.message });
    setTitle('error');
  }
}

function acceptDrops() {
  const body = document.body;
  body.addEventListener('dragover', (e) => { e.preventDefault(); body.classList.add('dropping'); });
  body.addEventListener('dragleave', () => body.classList.remove('dropping'));
  body.addEventListener('drop', (e) => {
    e.preventDefault();
    body.classList.remove('dropping');
    const file = e.dataTransfer.files[0];
    if (file) loadFile(file);
  });
  $('file').addEventListener('change', (e) => {
    const file = e.target.files[0];
    if (file) loadFile(file);
    e.target.value = '';
  });
}

async function main() {
  await init();
  try {
    lab = await Lab.create();
  } catch (e) {
    $('adapter').textContent = 'no WebGPU';
    showError(e.message);
    $('status').textContent = JSON.stringify({ error: e.message });
    setTitle('error');
    return;
  }
  $('adapter').textContent = lab.adapter();
  flags = flagsFromUrl();
  buildPanel();
  acceptDrops();
  // For a console, and for the browser test: the lab and the page's render.
  window.gnomon = { lab, render, loadFile };
  try {
    if (sceneName !== 'spheres') lab.loadBuiltin(sceneName);
    lab.setSettings(flags);
  } catch (e) {
    showError(e.message);
    $('status').textContent = JSON.stringify({ error: e.message });
    setTitle('error');
    return;
  }
  updateUrl();
  await render();
}

main();
