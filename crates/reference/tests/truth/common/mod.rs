//! What the tests comparing the rasterizer with the reference share: one device per
//! test binary, a render, a reference trace and the comparison of the two.
#![allow(dead_code)]

#[path = "../../../../render/tests/gpu/support/device.rs"]
pub mod device;
#[path = "../../../../render/tests/gpu/support/figures.rs"]
pub mod figures;

pub use device::{gpu, render};
pub mod rays;

use glam::{Mat4, Vec3};
use gnomon_reference::{
    ReferenceImage, ReferenceOptions, TracedScene,
    metrics::{self, Metrics, RasterView},
    reference_visibility,
};
use gnomon_render::Frame;
use gnomon_scene::{
    Camera, DirectionalLight, Instance, Material, Scene, Settings, builtin, geometry, sun_direction,
};

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

/// A real scene this repository ships for its tests (`tests/data/scenes`, with
/// their sources and licences in the README there): always present.
pub fn shipped_scene(relative: &str) -> std::path::PathBuf {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/scenes").join(relative);
    assert!(path.is_file(), "{} is missing from the checkout", path.display());
    path
}

/// A file of the shared scene collection, too large to ship (Sponza): `shared/scenes`
/// beside the checkout, or the directory `GNOMON_SHARED_SCENES` names. Where it is
/// missing, the test is skipped, saying so in its output and in `.ci/run`'s summary
/// (None); `GNOMON_REQUIRE_SHARED=1`, which `.ci/run` sets, makes a missing file a
/// failure instead, so that CI, which has the collection, never skips these tests.
pub fn shared_scene(relative: &str) -> Option<std::path::PathBuf> {
    let root = match std::env::var_os("GNOMON_SHARED_SCENES") {
        Some(dir) => std::path::PathBuf::from(dir),
        None => std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"),
    };
    let path = root.join(relative);
    if path.is_file() {
        return Some(path);
    }
    assert!(
        std::env::var_os("GNOMON_REQUIRE_SHARED").is_none_or(|v| v != "1"),
        "{} is missing: GNOMON_REQUIRE_SHARED=1 requires the shared scenes, expected in \
         `shared/scenes` beside the checkout or in GNOMON_SHARED_SCENES",
        path.display()
    );
    figures::skipped(relative, "the shared scene collection is not beside this checkout (`.ci/run` has it)");
    None
}

/// The share of a unit disk on the lit side of a straight edge at signed distance `u`
/// (in disk radii) from the disk's centre: 1 − (acos u − u√(1 − u²))/π, the circular
/// segment's area over π.
pub fn disk_visible(u: f32) -> f32 {
    let u = u.clamp(-1.0, 1.0);
    1.0 - (u.acos() - u * (1.0 - u * u).sqrt()) / std::f32::consts::PI
}

/// Width of the bars: a third of a texel of the 512² map that covers the view.
pub const BAR_WIDTH: f32 = 0.004;

/// The built-in spheres' camera and lights over `meshes`, each placed by its matrix
/// and made of `material`, casting shadows: the analytic scenes' stage.
pub fn scene_of(meshes: Vec<(gnomon_scene::Mesh, Mat4)>, material: Material) -> Scene {
    let mut scene = builtin::spheres();
    scene.materials = vec![material];
    scene.meshes = meshes.iter().map(|(m, _)| m.clone()).collect();
    scene.instances = meshes
        .iter()
        .enumerate()
        .map(|(i, (_, t))| Instance {
            name: format!("{i}"),
            mesh: i,
            material: 0,
            world_from_object: *t,
            casts_shadow: true,
            motion: gnomon_scene::Motion::Static,
        })
        .collect();
    scene
}

/// A ground under a grid of bars 4 mm wide and a metre up, turned 30° about the
/// vertical so that no bar follows the map's texel rows; the camera looks down at
/// their shadows.
pub fn thin_bars() -> Scene {
    let mut scene = builtin::spheres();
    scene.name = "thin bars".into();
    scene.materials = vec![Material::new("grey", Vec3::splat(0.7))];
    scene.meshes = vec![
        geometry::plane(8.0, 8.0),
        geometry::cuboid(Vec3::new(2.5, 0.5 * BAR_WIDTH, 0.5 * BAR_WIDTH)),
        geometry::cuboid(Vec3::new(0.5 * BAR_WIDTH, 0.5 * BAR_WIDTH, 2.5)),
    ];
    let instance = |name: String, mesh, world_from_object| Instance {
        name,
        mesh,
        material: 0,
        world_from_object,
        casts_shadow: true,
        motion: gnomon_scene::Motion::Static,
    };
    scene.instances = vec![instance("ground".into(), 0, Mat4::IDENTITY)];
    let turn = Mat4::from_rotation_y(30f32.to_radians());
    for k in -4..=4 {
        let offset = 0.5 * k as f32;
        scene.instances.push(instance(
            format!("bar x {k}"),
            1,
            turn * Mat4::from_translation(Vec3::new(0.0, 1.0, offset)),
        ));
        scene.instances.push(instance(
            format!("bar z {k}"),
            2,
            turn * Mat4::from_translation(Vec3::new(offset, 1.0, 0.0)),
        ));
    }
    scene.set_default(DirectionalLight {
        direction: -sun_direction(60.0, 40.0),
        color: Vec3::ONE,
        intensity: 1.0,
        angular_diameter_degrees: 0.0,
    });
    scene.camera = Camera {
        eye: Vec3::new(0.3, 4.5, 2.5),
        target: Vec3::new(-0.4, 0.0, -0.3),
        up: Vec3::Y,
        fov_y_degrees: 50.0,
        near: 0.05,
        far: 50.0,
    };
    scene
}
