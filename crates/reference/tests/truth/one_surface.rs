//! Issue 48: every pixel's shadow belongs to the surface it shows. On the mask path
//! the prepass keeps one surface per pixel, the mask resolves its shadow there, and
//! the lighting pass shades that same surface and reports it in the outputs
//! (seen_prepass.wgsl): where two triangles reach a pixel at the same depth, along an
//! edge they share, the lighting pass used to shade the later one with the earlier
//! one's shadow. The forward path shades one fragment and reports it, so the two
//! paths must show the same surface at every pixel, to the bit.

use crate::common;
use gnomon_render::{Frame, OutputRequest, Renderer};
use gnomon_scene::{
    Instance, Scene, Settings, builtin,
    settings::{LightKind, ShadowPath},
};

/// The pixels where the two frames show different surfaces: a different object, or
/// a point or normal not equal to the bit.
fn differing_surfaces(a: &Frame, b: &Frame) -> usize {
    let bits = |v: glam::Vec3| v.to_array().map(f32::to_bits);
    (0..a.pixel_count())
        .filter(|&i| {
            a.object_id[i] != b.object_id[i]
                || (a.object_id[i] != 0
                    && (bits(a.position[i]) != bits(b.position[i])
                        || bits(a.normal[i]) != bits(b.normal[i])
                        || bits(a.geometric_normal[i]) != bits(b.geometric_normal[i])))
        })
        .count()
}

fn check(name: &str, scene: &Scene, mut s: Settings) {
    let mut renderer = Renderer::new(common::gpu()).unwrap();
    let uploaded = renderer.upload(scene).unwrap();
    s.screen.shadow_path = ShadowPath::Forward;
    let forward = renderer.render_uploaded(&uploaded, scene, &s, &OutputRequest::default()).unwrap();
    s.screen.shadow_path = ShadowPath::Mask;
    let mask = renderer.render_uploaded(&uploaded, scene, &s, &OutputRequest::default()).unwrap();
    assert!(mask.shadow_mask && !forward.shadow_mask, "{name}: the two paths");
    let seen = forward.object_id.iter().filter(|&&id| id != 0).count();
    let differing = differing_surfaces(&forward, &mask);
    common::figures::figure(
        &format!("{name}: pixels where the mask path shows another surface than the forward path"),
        format!("{differing} of {seen}"),
        "0",
    );
    assert!(seen > forward.pixel_count() / 10, "{name}: {seen} pixels show a surface");
    assert_eq!(differing, 0, "{name}");
}

fn sized(width: u32, height: u32) -> Settings {
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (width, height);
    s
}

#[test]
fn the_mask_path_shows_the_forward_paths_surface_at_every_pixel_of_the_built_in_scenes() {
    for (name, scene) in [
        ("spheres", builtin::spheres()),
        ("contact", builtin::contact()),
        ("columns", builtin::columns()),
        ("grazing", builtin::grazing()),
    ] {
        check(name, &scene, sized(480, 270));
    }
    let mut all = sized(480, 270);
    all.light.kind = LightKind::All;
    check("lamps, every light", &builtin::lamps(), all);
    // Real scenes hold coincident faces of different objects (Florence's buildings
    // share walls and roofs); a duplicated instance is the extreme: its every pixel
    // is reached at the same depth by two objects, which the lighting pass's equal
    // depth test both passes. The prepass keeps the first, and so must the lighting.
    // Under one light the light's own lighting pass shades it; under several, the
    // light list's (light_list.wgsl).
    check("spheres with an object drawn twice", &doubled(builtin::spheres()), sized(480, 270));
    let mut all = sized(480, 270);
    all.light.kind = LightKind::All;
    check("lamps with an object drawn twice, every light", &doubled(builtin::lamps()), all);
}

/// `scene` with its second instance drawn a second time, in the same place.
fn doubled(mut scene: Scene) -> Scene {
    let copy = Instance { name: format!("{} again", scene.instances[1].name), ..scene.instances[1].clone() };
    scene.instances.push(copy);
    scene
}

/// Creases and outlines in numbers: the tree's leaves, and a close view of a city,
/// where roofs meet walls along thousands of shared edges.
#[test]
fn the_mask_path_shows_the_forward_paths_surface_at_every_pixel_of_real_scenes() {
    let (tree, _) = gnomon_scene::gltf_loader::load(&common::shipped_scene("tree/tree.glb")).unwrap();
    check("tree", &tree, sized(480, 270));
    let view = |eye: [f32; 3], target: [f32; 3], fov: f32| {
        let mut s = sized(640, 360);
        s.camera.eye = Some(glam::Vec3::from(eye));
        s.camera.target = Some(glam::Vec3::from(target));
        s.camera.fov_y_degrees = Some(fov);
        s
    };
    if let Some(path) = common::shared_scene("florence/florence.glb") {
        let (florence, _) = gnomon_scene::gltf_loader::load(&path).unwrap();
        check("Florence, close view", &florence, view([250.0, 150.0, 350.0], [0.0; 3], 50.0));
    }
    if let Some(path) = common::shared_scene("sponza/sponza_geometry.glb") {
        let (sponza, _) = gnomon_scene::gltf_loader::load(&path).unwrap();
        let mut arcades = view([0.0, 10.0, -4.0], [60.0, 20.0, -50.0], 50.0);
        arcades.light.sun_elevation = Some(70.17);
        arcades.light.sun_azimuth = Some(303.69);
        check("Sponza, the arcades", &sponza, arcades);
    }
}

/// The drawn metric of `compare`: the frame's visibility against the truth traced
/// from its own surfaces, every light-facing pixel counted.
pub(crate) fn drawn_metrics(
    scene: &Scene,
    s: &Settings,
    frame: &Frame,
) -> gnomon_reference::drawn::DrawnMetrics {
    use gnomon_reference::drawn::{DrawnOptions, DrawnSurfaces, drawn_truth, measure_drawn};
    let traced = gnomon_reference::TracedScene::build(scene);
    let light = s.resolve_light(scene).unwrap();
    let surfaces = DrawnSurfaces {
        width: frame.width,
        position: &frame.position,
        geometric_normal: &frame.geometric_normal,
    };
    let options =
        DrawnOptions { samples: s.reference.samples, lift: 1e-5 * scene.bounds().extent().length() };
    measure_drawn(&frame.visibility, &drawn_truth(&traced, &light, surfaces, &options, &|_| {}))
}

/// Issue 48's bounds, every pixel counted: at the defaults at most 0.02 % of the
/// light-facing pixels wrong, with a ray at every pixel (`raytraced`) at most
/// 0.005 %, and the pixels whose truth is ambiguous under 0.5 %. Measured at 480×270:
/// the defaults 0.000 % on the procedural scenes and 0.015 % on the tree (whose
/// leaves' cards cross: 0.152 % ambiguous), `raytraced` 0.000 % on all;
/// docs/measured.md has 51 cases at 1280×720.
#[test]
fn every_light_facing_pixel_of_the_built_in_scenes_is_right() {
    for (name, scene) in [
        ("spheres", builtin::spheres()),
        ("contact", builtin::contact()),
        ("columns", builtin::columns()),
        ("grazing", builtin::grazing()),
        ("tree", gnomon_scene::gltf_loader::load(&common::shipped_scene("tree/tree.glb")).unwrap().0),
    ] {
        let mut renderer = Renderer::new(common::gpu()).unwrap();
        for (technique, bound) in [
            (gnomon_scene::settings::Technique::PCF2X2, 2e-4),
            (gnomon_scene::settings::Technique::RAYTRACED, 5e-5),
        ] {
            let mut s = sized(480, 270);
            s.shadow.filter.technique = technique.clone();
            let frame = renderer.render(&scene, &s, &OutputRequest::default()).unwrap();
            let m = drawn_metrics(&scene, &s, &frame);
            common::figures::figure(
                &format!("{name}, {}, every light-facing pixel: mismatch (ambiguous)", technique.name()),
                format!(
                    "{} ({})",
                    common::figures::percent(m.mismatch_rate),
                    common::figures::percent(m.ambiguous_rate)
                ),
                format!("{} (0.5 %)", common::figures::percent(bound)),
            );
            assert!(m.compared > 20_000, "{name}: {m:?}");
            assert!(m.mismatch_rate <= bound, "{name}, {}: {m:?}", technique.name());
            assert!(m.ambiguous_rate < 5e-3, "{name}: {m:?}");
        }
    }
}
