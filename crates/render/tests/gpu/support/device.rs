//! The device every GPU test of a binary shares, and a render with default outputs:
//! used by the render crate's `gpu` tests and, through a `#[path]`, the reference
//! crate's `truth` tests and the examples' receiver test, so that there is one copy.
#![allow(dead_code)]

use std::sync::OnceLock;

use gnomon_render::{Frame, Gpu, OutputRequest, Renderer};
use gnomon_scene::{Scene, Settings};

/// The device shared by the tests in one binary (WGPU_BACKEND is honoured; CI sets vulkan).
pub fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new_headless().expect("a GPU adapter (install mesa-vulkan-drivers for lavapipe)"))
}

/// `scene` rendered with `settings` on the shared device, with the default outputs.
pub fn render(scene: &Scene, settings: &Settings) -> Frame {
    let mut renderer = Renderer::new(gpu()).expect("renderer");
    renderer.render(scene, settings, &OutputRequest::default()).expect("render")
}
