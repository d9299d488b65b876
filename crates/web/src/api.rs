//! The JS API, through wasm-bindgen: a `Lab` class for a page of one's own
//! (docs/web.md). Each method wraps the plain-Rust [`crate::lab::Lab`]; values
//! cross as strings, numbers, typed arrays and plain objects, and every failure is
//! a JS `Error` whose message is the command line's.

use std::{cell::RefCell, rc::Rc};

use gnomon_render::Gpu;
use gnomon_scene::builtin;
use wasm_bindgen::prelude::*;

use crate::{
    flags::Flag,
    lab::{Lab, Truth},
};

/// Gnomon's lab on the page's WebGPU device: a scene, settings, and frames measured
/// against `raytraced`.
#[wasm_bindgen(js_name = Lab)]
pub struct JsLab {
    /// Shared with the future of a render in flight; one render at a time.
    inner: Rc<RefCell<Lab>>,
}

pub(crate) fn js(error: impl std::fmt::Display) -> JsError {
    JsError::new(&error.to_string())
}

#[wasm_bindgen(js_class = Lab)]
impl JsLab {
    /// Opens the browser's WebGPU adapter and device, and a lab on them showing the
    /// built-in `spheres`.
    pub async fn create() -> Result<JsLab, JsError> {
        report_panics_to_the_console();
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
        descriptor.backends = wgpu::Backends::BROWSER_WEBGPU;
        let instance = wgpu::Instance::new(descriptor);
        let adapter = instance.request_adapter(&wgpu::RequestAdapterOptions::default()).await.map_err(|e| {
            js(format!(
                "no WebGPU adapter ({e}): this page needs a browser with WebGPU enabled (Chrome or Edge 113 and \
                 later; Chromium headless with --enable-unsafe-webgpu)"
            ))
        })?;
        let gpu = Gpu::with_adapter_async(&adapter, |_| {}).await.map_err(js)?;
        let lab = Lab::new(gpu).map_err(js)?;
        Ok(JsLab { inner: Rc::new(RefCell::new(lab)) })
    }

    /// The built-in scenes, by name.
    #[wasm_bindgen(js_name = builtinScenes)]
    pub fn builtin_scenes() -> Vec<String> {
        builtin::names().into_iter().map(String::from).collect()
    }

    /// Every settings flag the command line has, for a settings panel: an array of
    /// `{name, heading, help, choices, switch, default}`.
    #[wasm_bindgen(js_name = settingsFlags)]
    pub fn settings_flags() -> Result<JsValue, JsError> {
        let json = serde_json::to_string(&crate::flags::describe()).map_err(js)?;
        js_sys::JSON::parse(&json).map_err(|_| js("describing the settings"))
    }

    /// Every technique the renderer knows, by name.
    pub fn techniques(&self) -> Result<Vec<String>, JsError> {
        Ok(self.lab()?.techniques())
    }

    /// The adapter's name.
    pub fn adapter(&self) -> Result<String, JsError> {
        Ok(self.lab()?.adapter().to_string())
    }

    /// The scene shown, by name.
    #[wasm_bindgen(js_name = sceneName)]
    pub fn scene_name(&self) -> Result<String, JsError> {
        Ok(self.lab()?.scene_name().to_string())
    }

    /// Shows the built-in scene `name`.
    #[wasm_bindgen(js_name = loadBuiltin)]
    pub fn load_builtin(&self, name: &str) -> Result<(), JsError> {
        self.lab_mut()?.load_builtin(name).map_err(js)
    }

    /// Shows the glTF model `bytes` (a `.glb`, or a `.gltf` with its data
    /// embedded), called `name` in errors; returns the loader's warnings. A model
    /// that cannot be loaded throws, and the lab keeps its scene.
    #[wasm_bindgen(js_name = loadGltf)]
    pub fn load_gltf(&self, bytes: &[u8], name: &str) -> Result<Vec<String>, JsError> {
        self.lab_mut()?.load_gltf(bytes, name).map_err(js)
    }

    /// Sets the settings: the defaults, with `flags` over them, a plain object of
    /// the command line's settings flags without their dashes
    /// (`{technique: "pcss", width: 640, ground: true, "camera-eye": [0, 2, 5]}`).
    /// Checked as the command line checks them; wrong flags throw the command
    /// line's error and leave the settings as they were.
    #[wasm_bindgen(js_name = setSettings)]
    pub fn set_settings(&self, flags: &JsValue) -> Result<(), JsError> {
        let flags = flags_of(flags)?;
        self.lab_mut()?.set_flags(&flags).map_err(js)
    }

    /// Renders the scene and, unless `options` says `{truth: false}`, the same view
    /// with `raytraced` too, measuring the frame against it. Resolves to the frame's
    /// report: `scene`, `technique`, `width`, `height`, `lit`, `shadowed`,
    /// `mismatch_vs_raytraced`, `truth`, `adapter`, `frame_ms` and `passes`.
    // The lab stays borrowed while the frame is read back, on purpose: a call made
    // meanwhile finds it borrowed and throws BUSY, instead of changing the scene
    // under the frame.
    #[allow(clippy::await_holding_refcell_ref)]
    pub fn render(&self, options: &JsValue) -> js_sys::Promise {
        let inner = self.inner.clone();
        let truth = match render_options(options) {
            Ok(truth) => truth,
            Err(e) => return js_sys::Promise::reject(&JsValue::from(e)),
        };
        wasm_bindgen_futures::future_to_promise(async move {
            let mut lab = inner.try_borrow_mut().map_err(|_| JsValue::from(js(BUSY)))?;
            let report = lab.render(truth).await.map_err(|e| JsValue::from(js(e)))?;
            let json = serde_json::to_string(&report).map_err(|e| JsValue::from(js(e)))?;
            js_sys::JSON::parse(&json)
        })
    }

    /// The last frame's visibility, row-major from the top: 1 lit, 0 shadowed, NaN
    /// background (what `gnomon render --visibility-out` writes).
    pub fn visibility(&self) -> Result<Option<Vec<f32>>, JsError> {
        Ok(self.lab()?.visibility().map(<[f32]>::to_vec))
    }

    /// The last frame's surfaces: each pixel's world-space point, XYZ, row-major from
    /// the top, NaN where it shows none (what `gnomon render --aov-out` writes as
    /// `position`). With [`Self::geometric_normal`], what `gnomon reference
    /// --surfaces` traces the truth from.
    pub fn position(&self) -> Result<Option<Vec<f32>>, JsError> {
        Ok(self.lab()?.surfaces().map(|(position, _)| flatten(position)))
    }

    /// The last frame's geometric normals (each pixel's triangle's plane, facing the
    /// camera), XYZ as [`Self::position`]: `--aov-out`'s `geometric_normal`.
    #[wasm_bindgen(js_name = geometricNormal)]
    pub fn geometric_normal(&self) -> Result<Option<Vec<f32>>, JsError> {
        Ok(self.lab()?.surfaces().map(|(_, normal)| flatten(normal)))
    }

    /// The last frame's image: RGBA8, sRGB, top row first (an `ImageData`'s bytes).
    pub fn color(&self) -> Result<Option<Vec<u8>>, JsError> {
        Ok(self.lab()?.color().map(<[u8]>::to_vec))
    }

    /// The last frame's errors against `raytraced` (when the truth was drawn) as
    /// RGBA8: red falsely shadowed, blue falsely lit, greys correct.
    pub fn heatmap(&self) -> Result<Option<Vec<u8>>, JsError> {
        Ok(self.lab()?.heatmap().map(<[u8]>::to_vec))
    }
}

impl JsLab {
    fn lab(&self) -> Result<std::cell::Ref<'_, Lab>, JsError> {
        self.inner.try_borrow().map_err(|_| js(BUSY))
    }

    fn lab_mut(&self) -> Result<std::cell::RefMut<'_, Lab>, JsError> {
        self.inner.try_borrow_mut().map_err(|_| js(BUSY))
    }
}

/// The error for a call made while a render is in flight.
const BUSY: &str = "the lab is still rendering: wait for render()'s promise before the next call";

/// `render`'s options: nothing, or `{truth: true}` or `{truth: false}`.
fn render_options(options: &JsValue) -> Result<Truth, JsError> {
    if options.is_undefined() || options.is_null() {
        return Ok(Truth::Measure);
    }
    let truth = js_sys::Reflect::get(options, &"truth".into()).unwrap_or(JsValue::UNDEFINED);
    match (truth.is_undefined(), truth.as_bool()) {
        (true, _) | (false, Some(true)) => Ok(Truth::Measure),
        (false, Some(false)) => Ok(Truth::Skip),
        (false, None) => Err(js("render: `truth` is true or false, as in render({truth: false})")),
    }
}

/// A plain object's entries as flags: strings as they are, numbers and booleans in
/// words, arrays of numbers joined by commas (`[0, 2, 5]` is `0,2,5`).
pub(crate) fn flags_of(object: &JsValue) -> Result<Vec<Flag>, JsError> {
    if object.is_undefined() || object.is_null() {
        return Ok(Vec::new());
    }
    if !object.is_object() || js_sys::Array::is_array(object) {
        return Err(js("settings: give a plain object of flags, such as {technique: \"pcss\", width: 640}"));
    }
    let mut flags = Vec::new();
    for entry in js_sys::Object::entries(object.unchecked_ref()).iter() {
        let entry: js_sys::Array = entry.unchecked_into();
        let name = entry.get(0).as_string().unwrap_or_default();
        let value = entry.get(1);
        let words = if let Some(s) = value.as_string() {
            s
        } else if let Some(n) = value.as_f64() {
            n.to_string()
        } else if let Some(b) = value.as_bool() {
            b.to_string()
        } else if js_sys::Array::is_array(&value) {
            let parts: Option<Vec<String>> =
                js_sys::Array::from(&value).iter().map(|v| v.as_f64().map(|n| n.to_string())).collect();
            parts
                .ok_or_else(|| {
                    js(format!("setting `{name}`: an array must hold numbers, such as [0, 2, 5]"))
                })?
                .join(",")
        } else if value.is_undefined() || value.is_null() {
            continue;
        } else {
            return Err(js(format!(
                "setting `{name}`: give a string, a number, true or false, or an array of numbers"
            )));
        };
        flags.push(Flag { name, value: words });
    }
    Ok(flags)
}

/// A panic's message in the browser's console, where it would otherwise be only
/// "unreachable executed".
pub(crate) fn report_panics_to_the_console() {
    std::panic::set_hook(Box::new(|info| web_sys::console::error_1(&info.to_string().into())));
}

/// Vectors as their components, one after another.
fn flatten(vectors: &[glam::Vec3]) -> Vec<f32> {
    vectors.iter().flat_map(|v| v.to_array()).collect()
}
