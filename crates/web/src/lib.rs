//! Gnomon in the browser: the lab (a scene, settings from the command line's flags,
//! frames measured against `raytraced`) on the page's WebGPU device, behind a small
//! JS API. `flags` turns name and value pairs into checked settings, `lab` holds the
//! state and renders (plain Rust, tested natively), `api` is the wasm-bindgen class
//! a page uses, and `viewer` starts the desktop viewer (winit and egui) on a canvas.
//! The pages themselves, their build and their browser test are in `web/`
//! (docs/web.md).

/// Settings from flags: shared with the Python package, so in `gnomon-scene`.
pub use gnomon_scene::flags;
pub mod lab;

#[cfg(target_arch = "wasm32")]
mod api;
#[cfg(target_arch = "wasm32")]
mod viewer;
