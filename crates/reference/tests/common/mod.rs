//! What the tests comparing the rasterizer with the reference share: one device per
//! test binary, a render, a reference trace and the comparison of the two.
#![allow(dead_code)]

#[path = "../../../render/tests/support/figures.rs"]
pub mod figures;

use std::sync::OnceLock;

use gnomon_reference::{
    ReferenceImage, ReferenceOptions, TracedScene,
    metrics::{self, Metrics, RasterView},
    reference_visibility,
};
use gnomon_render::{Frame, Gpu, OutputRequest, Renderer};
use gnomon_scene::{Scene, Settings};

/// The device shared by the tests in one binary (WGPU_BACKEND is honoured; CI sets vulkan).
pub fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new_headless().expect("a GPU adapter (install mesa-vulkan-drivers for lavapipe)"))
}

pub fn render(scene: &Scene, s: &Settings) -> Frame {
    Renderer::new(gpu()).unwrap().render(scene, s, &OutputRequest::default()).unwrap()
}

/// The reference for the settings' camera and light, with `s.reference.samples` rays
/// per pixel for an area light (one for a point or a sun without size).
pub fn reference(scene: &Scene, s: &Settings) -> ReferenceImage {
    let options =
        ReferenceOptions { width: s.image.width, height: s.image.height, samples: s.reference.samples };
    let camera = s.resolve_camera(scene).unwrap();
    let light = s.resolve_light(scene).unwrap();
    reference_visibility(&TracedScene::build(scene), &camera, &light, &options, &|_| {})
}

/// `gnomon compare`'s metrics of `frame` against `reference`.
pub fn compare(frame: &Frame, reference: &ReferenceImage) -> Metrics {
    let raster =
        RasterView { visibility: &frame.visibility, object_id: &frame.object_id, depth: &frame.depth };
    let classes = metrics::classify(raster, reference);
    metrics::measure(raster, reference, &classes)
}

/// A file of the shared scene collection: `shared/scenes` beside the checkout, which
/// CI always has, or the directory `GNOMON_SHARED_SCENES` names. A test that needs
/// one fails, naming it, when it is missing: a silent skip would let a regression
/// through. `GNOMON_WITHOUT_SHARED=1` skips such tests instead, saying so in the
/// test output (None).
pub fn shared_scene(relative: &str) -> Option<std::path::PathBuf> {
    let root = match std::env::var_os("GNOMON_SHARED_SCENES") {
        Some(dir) => std::path::PathBuf::from(dir),
        None => std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"),
    };
    let path = root.join(relative);
    if path.is_file() {
        return Some(path);
    }
    if std::env::var_os("GNOMON_WITHOUT_SHARED").is_some_and(|v| v == "1") {
        figures::skipped(relative, "GNOMON_WITHOUT_SHARED=1 and the shared scene is missing");
        return None;
    }
    panic!(
        "{} is missing: this test reads the shared scenes, expected in `shared/scenes` beside the \
         checkout or in GNOMON_SHARED_SCENES (CI has them); GNOMON_WITHOUT_SHARED=1 skips it, visibly",
        path.display()
    )
}

/// The share of a unit disk on the lit side of a straight edge at signed distance `u`
/// (in disk radii) from the disk's centre: 1 − (acos u − u√(1 − u²))/π, the circular
/// segment's area over π.
pub fn disk_visible(u: f32) -> f32 {
    let u = u.clamp(-1.0, 1.0);
    1.0 - (u.acos() - u * (1.0 - u * u).sqrt()) / std::f32::consts::PI
}
