//! The viewer (winit and egui, as `gnomon view` opens it on the desktop) on a page's
//! canvas, started from JS with a built-in scene and settings flags, and then given
//! models and asked for comparisons through the `Viewer` it returns. Its status
//! lines go to the browser's console (`gnomon view: …`); its error view measures
//! against the GPU's `raytraced`.

use gnomon_render::techniques::TechniqueRegistry;
use gnomon_scene::gltf_loader;
use gnomon_viewer::{Action, CanvasViewer, SceneSource, ViewerOptions};
use wasm_bindgen::prelude::*;

use crate::{
    api::{flags_of, js, report_panics_to_the_console},
    lab::{builtin_scene, checked_settings},
};

/// Frames drawn before a comparison asked for at the start is made: the first
/// frames compile the pipelines.
const COMPARE_AT_FRAME: u32 = 3;

/// Starts the viewer on `canvas` with the built-in scene `scene` and `flags` (as
/// `Lab.setSettings` takes them), and returns a `Viewer` at once: the browser runs
/// it from then on. `options`: `{compare: true}` compares the view with `raytraced` once
/// the first frames are drawn; `{showMaps: true}` opens the shadow-map preview;
/// `{hidePanels: true}` starts with the panels hidden (F1 shows them). Wrong flags,
/// an unknown scene or an unknown option throw, naming it.
#[wasm_bindgen(js_name = startViewer)]
pub fn start_viewer(
    canvas: web_sys::HtmlCanvasElement,
    scene: &str,
    flags: &JsValue,
    options: &JsValue,
) -> Result<JsViewer, JsError> {
    report_panics_to_the_console();
    let settings = checked_settings(&flags_of(flags)?, &TechniqueRegistry::builtin()).map_err(js)?;
    let mut loaded = builtin_scene(scene).map_err(js)?;
    if settings.scene.ground {
        loaded.add_ground_plane();
    }
    let switches = ViewerSwitches::from_js(options)?;
    let mut viewer = ViewerOptions::new(loaded, settings, SceneSource::Builtin(scene.into()));
    viewer.window_size = [canvas.client_width().max(64) as u32, canvas.client_height().max(64) as u32];
    viewer.show_maps = switches.show_maps;
    viewer.hide_panel = switches.hide_panels;
    if switches.compare {
        viewer.script.push((COMPARE_AT_FRAME, Action::CompareWithReference));
    }
    let running = gnomon_viewer::start_on_canvas(viewer, canvas).map_err(|e| js(format!("{e:#}")))?;
    Ok(JsViewer { running })
}

/// The viewer running on a canvas.
#[wasm_bindgen(js_name = Viewer)]
pub struct JsViewer {
    running: CanvasViewer,
}

#[wasm_bindgen(js_class = Viewer)]
impl JsViewer {
    /// Shows the glTF model `bytes` (a `.glb`, or a `.gltf` with its data
    /// embedded), called `name`, once the frame in flight is done; returns the
    /// loader's warnings. A model that cannot be loaded throws the command line's
    /// error, naming it, and the viewer keeps its scene.
    #[wasm_bindgen(js_name = loadGltf)]
    pub fn load_gltf(&self, bytes: &[u8], name: &str) -> Result<Vec<String>, JsError> {
        let (scene, extras) = gltf_loader::load_from_bytes(bytes, name).map_err(js)?;
        self.running.show_scene(scene, SceneSource::Gltf(name.into())).map_err(js)?;
        Ok(extras.warnings)
    }

    /// Measures the view against `raytraced`, as the panel's "Compare with the
    /// reference" does; the figures arrive in the status line and the console.
    #[wasm_bindgen(js_name = compareWithReference)]
    pub fn compare_with_reference(&self) -> Result<(), JsError> {
        self.running.act(Action::CompareWithReference).map_err(js)
    }
}

/// `startViewer`'s options.
#[derive(Default)]
struct ViewerSwitches {
    compare: bool,
    show_maps: bool,
    hide_panels: bool,
}

impl ViewerSwitches {
    const NAMES: [&str; 3] = ["compare", "showMaps", "hidePanels"];

    fn from_js(options: &JsValue) -> Result<Self, JsError> {
        let mut switches = Self::default();
        if options.is_undefined() || options.is_null() {
            return Ok(switches);
        }
        for entry in js_sys::Object::entries(options.unchecked_ref()).iter() {
            let entry: js_sys::Array = entry.unchecked_into();
            let name = entry.get(0).as_string().unwrap_or_default();
            let value = entry.get(1).as_bool().ok_or_else(|| {
                js(format!("startViewer: option `{name}` is true or false, as in {{{name}: true}}"))
            })?;
            match name.as_str() {
                "compare" => switches.compare = value,
                "showMaps" => switches.show_maps = value,
                "hidePanels" => switches.hide_panels = value,
                other => {
                    return Err(js(format!(
                        "startViewer: unknown option `{other}`; the options are {}",
                        Self::NAMES.join(", ")
                    )));
                }
            }
        }
        Ok(switches)
    }
}
