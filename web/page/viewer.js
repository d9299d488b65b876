// The viewer page: Gnomon's desktop viewer (winit and egui, the panels of
// `gnomon view`) on a canvas the size of the window. The URL says what it opens:
// `?scene=spheres&technique=pcss&…` (the lab's link), plus `compare=1` to measure
// the view against `raytraced` once it is drawn, `maps=1` for the shadow-map
// preview and `panels=0` to start with the panels hidden. A `.glb` dropped on the
// page is shown in place of the scene. Status lines go to the console, as
// `gnomon view: …`; the title says when it runs or failed. `window.gnomon.viewer`
// is the running `Viewer`, for tests and the console.
import init, { startViewer } from './gnomon.js';

const params = new URLSearchParams(location.search);
// Keys of the URL that are the page's, not settings flags (the lab's included, so
// that its links open here as they are).
const PAGE_KEYS = ['scene', 'compare', 'maps', 'panels', 'truth', 'status'];
const errorBox = document.getElementById('error');
const hint = document.getElementById('hint');

const flags = {};
for (const [key, value] of params) {
  if (!PAGE_KEYS.includes(key)) flags[key] = value;
}
const options = {
  compare: params.get('compare') === '1',
  showMaps: params.get('maps') === '1',
  hidePanels: params.get('panels') === '0',
};

// A model dropped anywhere on the page: the loader's error, naming the file, if it
// cannot be shown; the viewer keeps its scene then.
async function showDropped(viewer, file) {
  try {
    const bytes = new Uint8Array(await file.arrayBuffer());
    const warnings = viewer.loadGltf(bytes, file.name);
    errorBox.textContent = warnings.join('\n');
  } catch (e) {
    errorBox.textContent = e.message;
  }
}

try {
  await init();
  const canvas = document.getElementById('viewer');
  canvas.focus();
  const viewer = startViewer(canvas, params.get('scene') || 'spheres', flags, options);
  window.gnomon = { viewer };
  document.body.addEventListener('dragover', (e) => e.preventDefault());
  document.body.addEventListener('drop', (e) => {
    e.preventDefault();
    const file = e.dataTransfer.files[0];
    if (file) showDropped(viewer, file);
  });
  setTimeout(() => { hint.hidden = true; }, 10_000);
  document.title = 'gnomon viewer: running';
} catch (e) {
  errorBox.textContent = e.message;
  document.title = 'gnomon: error';
}
