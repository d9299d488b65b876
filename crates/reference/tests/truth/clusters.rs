//! Cluster culling (`--caster-culling clusters`, `render/src/clusters.rs`) changes
//! what a shadow pass costs, never what it draws: every layer's map is identical,
//! texel for texel, to the one drawn instance by instance, for every light kind,
//! map layout and cull mode; and on Sponza, one mesh of 279k triangles, the first
//! cascade draws a small share of it. (It lives here for the shared scenes.)

use crate::common;

use gnomon_render::{Frame, OutputRequest, Renderer};
use gnomon_scene::{
    Scene, Settings, builtin,
    settings::{CasterCulling, CullMode, LightKind, OmniMap, Partition, Refine, WarpKind},
};

/// The frame drawn with `culling`, its maps read back.
fn drawn(scene: &Scene, settings: &Settings, culling: CasterCulling) -> Frame {
    let mut s = settings.clone();
    s.shadow.map.caster_culling = culling;
    let mut renderer = Renderer::new(common::gpu()).expect("renderer");
    renderer.render(scene, &s, &OutputRequest { shadow_map: true, ..Default::default() }).expect("render")
}

/// What the two cullings drew into the reported light's layers: the texels that
/// differ, and the triangles each drew.
struct Compared {
    differing: usize,
    texels: usize,
    clustered: Vec<u64>,
    whole: Vec<u64>,
}

fn compare(scene: &Scene, settings: &Settings) -> Compared {
    let clustered = drawn(scene, settings, CasterCulling::Clusters);
    let whole = drawn(scene, settings, CasterCulling::Instances);
    let (a, b) = (clustered.shadow_map.expect("map"), whole.shadow_map.expect("map"));
    assert_eq!((a.resolution, a.layers), (b.resolution, b.layers));
    let differing = a.depth.iter().zip(&b.depth).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
    Compared {
        differing,
        texels: a.depth.len(),
        clustered: clustered.lights[0].layer_triangles.clone(),
        whole: whole.lights[0].layer_triangles.clone(),
    }
}

fn settings(light: LightKind, cull: CullMode) -> Settings {
    let mut s = Settings::default();
    s.screen.refine = Refine::Off;
    s.image.width = 320;
    s.image.height = 180;
    s.shadow.map.resolution = 512;
    s.light.kind = light;
    s.shadow.bias.cull = cull;
    s
}

#[test]
fn clustered_maps_are_identical_for_every_light_layout_and_cull_mode() {
    let scene = builtin::spheres();
    let cascades = |cull| {
        let mut s = settings(LightKind::Sun, cull);
        s.shadow.partition = Partition::Cascades;
        s
    };
    let paraboloid = {
        let mut s = settings(LightKind::Point, CullMode::Auto);
        s.shadow.map.omni = OmniMap::Paraboloid;
        s
    };
    let warped = {
        let mut s = settings(LightKind::Sun, CullMode::Auto);
        s.shadow.map.warp = WarpKind::Lispsm;
        s
    };
    let cases = [
        ("sun, cull auto", settings(LightKind::Sun, CullMode::Auto)),
        ("sun cascades, cull auto", cascades(CullMode::Auto)),
        ("sun cascades, cull back", cascades(CullMode::Back)),
        ("sun cascades, cull front", cascades(CullMode::Front)),
        ("sun cascades, cull none", cascades(CullMode::None)),
        ("sun, LiSPSM", warped),
        ("spot, cull auto", settings(LightKind::Spot, CullMode::Auto)),
        ("spot, cull front", settings(LightKind::Spot, CullMode::Front)),
        ("point cube, cull auto", settings(LightKind::Point, CullMode::Auto)),
        ("point cube, cull front", settings(LightKind::Point, CullMode::Front)),
        ("point paraboloids", paraboloid),
    ];
    for (name, s) in cases {
        let c = compare(&scene, &s);
        let (clustered, whole): (u64, u64) = (c.clustered.iter().sum(), c.whole.iter().sum());
        common::figures::figure(
            &format!("clusters, spheres, {name}"),
            format!(
                "{} of {} texels differ; triangles {clustered} of {whole} (per layer {:?} of {:?})",
                c.differing, c.texels, c.clustered, c.whole
            ),
            "0 texels",
        );
        assert_eq!(c.differing, 0, "{name}: {} of {} texels differ", c.differing, c.texels);
        assert!(clustered <= whole, "{name}: clusters drew {clustered} triangles, instances {whole}");
        // Where the pass culls a side of the closed spheres, their clusters turned
        // that way are skipped: not a vacuous comparison.
        if s.shadow.bias.cull != CullMode::None && s.shadow.map.omni != OmniMap::Paraboloid {
            assert!(
                (clustered as f64) < 0.8 * whole as f64,
                "{name}: clusters drew {clustered} of {whole} triangles"
            );
        }
    }
}

#[test]
fn sponzas_first_cascade_draws_a_small_share_of_its_one_mesh_and_the_same_map() {
    let Some(path) = common::shared_scene("sponza/sponza_geometry.glb") else { return };
    let (scene, _) = gnomon_scene::gltf_loader::load(&path).unwrap();
    assert_eq!(scene.meshes.len(), 1, "Sponza is one mesh");
    // The view of the comparison with Bevy (docs/submission.md, "Clusters"): sun along (0.3, −1, −0.2).
    let mut s = settings(LightKind::Sun, CullMode::Auto);
    s.camera.eye = Some(glam::Vec3::new(-85.0, 12.0, -4.0));
    s.camera.target = Some(glam::Vec3::new(60.0, 30.0, -4.0));
    s.camera.fov_y_degrees = Some(60.0);
    s.light.sun_elevation = Some(70.17);
    s.light.sun_azimuth = Some(303.69);
    s.shadow.partition = Partition::Cascades;
    s.shadow.map.resolution = 1024;
    let c = compare(&scene, &s);
    let total = scene.triangle_count() as u64;
    common::figures::figure(
        "clusters, Sponza, 4 cascades",
        format!(
            "{} of {} texels differ; triangles per layer {:?} of {total}",
            c.differing, c.texels, c.clustered
        ),
        "0 texels; cascade 0 under 25 %",
    );
    assert_eq!(c.differing, 0, "{} of {} texels differ", c.differing, c.texels);
    assert!(c.whole.iter().all(|&t| t == total), "drawn whole, every cascade draws it all: {:?}", c.whole);
    assert!((c.clustered[0] as f64) < 0.25 * total as f64, "cascade 0 drew {} of {total}", c.clustered[0]);
}
