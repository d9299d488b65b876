// The viewer page: Gnomon's desktop viewer (winit and egui, the panels of
// `gnomon view`) on a canvas the size of the window. The URL says what it opens:
// `?scene=spheres&technique=pcss&…` (the lab's link), plus `compare=1` to measure
// the view against `raytraced` once it is drawn, `maps=1` for the shadow-map
// preview and `panels=0` to start with the panels hidden. Its status lines go to
// the console, as `gnomon view: …`; the title says when it runs or failed.
import init, { startViewer } from './gnomon.js';

const params = new URLSearchParams(location.search);
// Keys of the URL that are the page's, not settings flags (the lab's included, so
// that its links open here as they are).
const PAGE_KEYS = ['scene', 'compare', 'maps', 'panels', 'truth', 'status'];

const flags = {};
for (const [key, value] of params) {
  if (!PAGE_KEYS.includes(key)) flags[key] = value;
}
const options = {
  compare: params.get('compare') === '1',
  showMaps: params.get('maps') === '1',
  hidePanels: params.get('panels') === '0',
};

try {
  await init();
  const canvas = document.getElementById('viewer');
  canvas.focus();
  startViewer(canvas, params.get('scene') || 'spheres', flags, options);
  document.title = 'gnomon viewer: running';
} catch (e) {
  document.getElementById('error').textContent = e.message;
  document.title = 'gnomon: error';
}
