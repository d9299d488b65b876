//! One GPU test per technique: under an analytic square occluder, the umbra is dark
//! (visibility below 0.1) and the fully lit ground stays lit (above 0.9), for a sun
//! with a small angular size and a spot light with a small disk. Pixels within the
//! analytic penumbra plus the technique's filter footprint are left out.

use crate::support;

use glam::{Vec2, Vec3};
use gnomon_render::techniques::TechniqueRegistry;
use gnomon_scene::{
    DirectionalLight, Scene, SpotLight,
    settings::{LightKind, RayUse, Settings, Technique},
};
use support::*;

const RESOLUTION: u32 = 1024;

/// How far from the exact shadow edge a technique may blur: the blur radius or
/// kernel half-width, the bilinear tap, and the texel itself, in texels.
fn footprint_texels(s: &Settings) -> f32 {
    let f = &s.shadow.filter;
    let technique = TechniqueRegistry::builtin().get(&f.technique).expect("a built-in technique");
    if technique.rays() == RayUse::EveryPixel {
        // It reads no map (one texel a layer): no texel blurs its edge.
        return 0.0;
    }
    if f.technique == Technique::PCSS {
        // Its reach is the widest penumbra it may filter; its estimate of this one is
        // analytic, but its blocker search and taps add noise.
        return 2.5;
    }
    // The reach each technique states (a PCF kernel's half-width, a moment map's
    // blur radius), plus the bilinear tap and the texel itself.
    technique.filter_reach_texels(f, f.pcf_kernel) + 1.5
}

struct Outcome {
    umbra: usize,
    dark_umbra: usize,
    lit: usize,
    lit_lit: usize,
    worst_umbra: f32,
    worst_lit: f32,
}

/// Renders `scene` with `s` and classifies ground pixels by their signed distance to
/// the analytic shadow edge (`edge_distance`, negative inside), leaving out those
/// closer than the penumbra half-width plus the filter footprint plus a pixel.
fn classify(
    scene: &Scene,
    s: &Settings,
    edge_distance: impl Fn(Vec3) -> Option<f32>,
    penumbra_half: f32,
) -> Outcome {
    let frame = render(scene, s);
    let mut o = Outcome { umbra: 0, dark_umbra: 0, lit: 0, lit_lit: 0, worst_umbra: 0.0, worst_lit: 1.0 };
    for i in 0..frame.pixel_count() {
        if frame.object_id[i] != 1 {
            continue;
        }
        let p = frame.position[i];
        let Some(d) = edge_distance(p) else { continue };
        let margin = penumbra_half
            + footprint_texels(s) * frame.shadow_texel_world_size(p)
            + pixel_footprint(&frame, i);
        let v = frame.visibility[i];
        if d < -margin {
            o.umbra += 1;
            o.dark_umbra += (v < 0.1) as usize;
            o.worst_umbra = o.worst_umbra.max(v);
        } else if d > margin {
            o.lit += 1;
            o.lit_lit += (v > 0.9) as usize;
            o.worst_lit = o.worst_lit.min(v);
        }
    }
    o
}

fn check(label: &str, o: &Outcome) {
    assert!(o.umbra > 1000 && o.lit > 20_000, "{label}: too few pixels ({} umbra, {} lit)", o.umbra, o.lit);
    assert_eq!(
        o.dark_umbra,
        o.umbra,
        "{label}: {} of {} umbra pixels are not below 0.1 (brightest {})",
        o.umbra - o.dark_umbra,
        o.umbra,
        o.worst_umbra
    );
    assert_eq!(
        o.lit_lit,
        o.lit,
        "{label}: {} of {} lit pixels are not above 0.9 (darkest {})",
        o.lit - o.lit_lit,
        o.lit,
        o.worst_lit
    );
}

#[test]
fn every_technique_darkens_the_umbra_and_keeps_the_lit_ground_lit_under_a_sun() {
    let SquareOccluder { mut scene, shadow_center, shadow_half: half, height } = square_under_sun();
    let angular_diameter = 1.0f32;
    scene.light_mut::<DirectionalLight>().unwrap().angular_diameter_degrees = angular_diameter;
    // The penumbra's half-width on the ground: the occluder's distance along the ray
    // times the tangent of the sun's angular radius, stretched by the ground's slant.
    let slant = -scene.light::<DirectionalLight>().unwrap().direction.normalize().y;
    let penumbra_half = height / slant * (0.5 * angular_diameter).to_radians().tan() / slant;

    for technique in TechniqueRegistry::builtin().iter().map(|t| t.technique()) {
        let mut s = settings(640, 480, RESOLUTION);
        s.shadow.filter.technique = technique.clone();
        let o = classify(
            &scene,
            &s,
            |p| Some(square_distance(Vec2::new(p.x, p.z), shadow_center, half)),
            penumbra_half,
        );
        check(&format!("{} (sun)", technique.name()), &o);
    }
}

#[test]
fn every_technique_darkens_the_umbra_and_keeps_the_lit_ground_lit_under_a_spot() {
    let SquareOccluder { mut scene, shadow_center, shadow_half, height } = square_under_spot();
    let radius = 0.1f32;
    scene.light_mut::<SpotLight>().unwrap().radius = radius;
    let cone_radius = SPOT_HEIGHT * SPOT_OUTER_DEGREES.to_radians().tan();
    // Similar triangles: the disk's radius scaled by h / (H − h) on the ground.
    let penumbra_half = radius * height / (SPOT_HEIGHT - height);

    for technique in TechniqueRegistry::builtin().iter().map(|t| t.technique()) {
        let mut s = settings(640, 480, RESOLUTION);
        s.light.kind = LightKind::Spot;
        s.shadow.filter.technique = technique.clone();
        let o = classify(
            &scene,
            &s,
            |p| {
                // Only well inside the cone, where the light is not cut by the cone itself.
                (Vec2::new(p.x, p.z).length() < cone_radius - 0.5)
                    .then(|| square_distance(Vec2::new(p.x, p.z), shadow_center, shadow_half))
            },
            penumbra_half,
        );
        check(&format!("{} (spot)", technique.name()), &o);
    }
}

#[test]
fn filterable_techniques_also_work_with_16_bit_moment_maps() {
    // The portable format, where 32-bit float is not filterable (the GL backend):
    // exponents and the moment bias are set for half precision, as documented.
    let SquareOccluder { scene, shadow_center, shadow_half: half, .. } = square_under_sun();
    let registry = TechniqueRegistry::builtin();
    let filterable = registry.iter().filter(|t| t.filterable_map(&Default::default()).is_some());
    for technique in filterable.map(|t| t.technique()) {
        let mut s = settings(640, 480, RESOLUTION);
        s.shadow.filter.technique = technique.clone();
        let m = &mut s.shadow.filter.moments;
        m.moment_format = gnomon_scene::settings::MomentFormat::Rgba16float;
        m.evsm_positive = 5.54;
        m.evsm_negative = 5.54;
        m.moment_bias = 6e-5;
        s.validate().unwrap();
        let frame_format = {
            let renderer = gnomon_render::Renderer::new(gpu()).unwrap();
            renderer.moment_format(&s).unwrap()
        };
        assert_eq!(frame_format, wgpu::TextureFormat::Rgba16Float);
        let o =
            classify(&scene, &s, |p| Some(square_distance(Vec2::new(p.x, p.z), shadow_center, half)), 0.0);
        check(&format!("{} (16-bit)", technique.name()), &o);
    }
}

/// The world size of a texel of a sun's map fitted to the whole scene (`--fit scene`),
/// from the geometry alone: the map's window is the scene's bounding box seen along
/// the light, with the light's up toward +y, and a box of sides s spans Σ |aᵢ| sᵢ
/// along a unit axis a. The renderer uses the larger of the two spans.
fn analytic_sun_texel(scene: &Scene, resolution: u32) -> f32 {
    let (lo, hi) = scene
        .instances
        .iter()
        .flat_map(|i| scene.meshes[i.mesh].positions.iter().map(|&p| i.world_from_object.transform_point3(p)))
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let size = hi - lo;
    let forward = scene.light::<DirectionalLight>().unwrap().direction.normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let span = |axis: Vec3| (axis.abs() * size).element_sum();
    span(right).max(span(up)) / resolution as f32
}

#[test]
fn a_kernel_in_world_units_equals_the_same_width_in_texels() {
    // Under a sun the map is orthographic: one texel is the same world size
    // everywhere, so W texels and W·texel world units are the same kernel. The texel
    // comes from the scene's geometry, not from the renderer's own texel size.
    let scene = square_under_sun().scene;
    let texel = analytic_sun_texel(&scene, RESOLUTION);
    for technique in [Technique::PCF, Technique::PCF_TENT, Technique::PCF_POISSON] {
        let mut s = settings(320, 240, RESOLUTION);
        s.shadow.map.fit = gnomon_scene::settings::Fit::Scene;
        s.shadow.filter.technique = technique.clone();
        s.shadow.filter.pcf_kernel = 5.0;
        let in_texels = render(&scene, &s);
        // The fit pads the window by a thousandth of the scene's radius a side.
        let reported = in_texels.light_projection.texel_world_size(RESOLUTION, 0.0);
        assert!((reported / texel - 1.0).abs() < 0.005, "texel {reported}, analytic {texel}");
        s.shadow.filter.kernel_unit = gnomon_scene::settings::KernelUnit::World;
        s.shadow.filter.pcf_kernel = 5.0 * texel;
        let in_world = render(&scene, &s);
        let worst = in_texels
            .visibility
            .iter()
            .zip(&in_world.visibility)
            .filter(|(a, _)| !a.is_nan())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "{}: visibilities differ by up to {worst}", technique.name());
        // And the width does matter: a kernel twice as wide changes the image.
        s.shadow.filter.pcf_kernel = 10.0 * texel;
        let wider = render(&scene, &s);
        let changed =
            in_world.visibility.iter().zip(&wider.visibility).filter(|(a, b)| (*a - *b).abs() > 0.05).count();
        assert!(
            changed > 100,
            "{}: doubling the world width changed only {changed} pixels",
            technique.name()
        );
    }
}

#[test]
fn mipmapped_moment_maps_keep_the_umbra_dark_and_the_lit_ground_lit() {
    let SquareOccluder { scene, shadow_center, shadow_half: half, .. } = square_under_sun();
    for technique in [Technique::VSM, Technique::EVSM4, Technique::MSM_HAMBURGER, Technique::CONVOLUTION] {
        let mut s = settings(640, 480, RESOLUTION);
        s.shadow.filter.technique = technique.clone();
        s.shadow.filter.moments.mipmaps = true;
        let o =
            classify(&scene, &s, |p| Some(square_distance(Vec2::new(p.x, p.z), shadow_center, half)), 0.0);
        check(&format!("{} (mipmapped)", technique.name()), &o);
    }
    // The mip levels are really sampled: where the map is minified (far ground seen
    // at a grazing angle, from a low camera) the result differs from the top level's.
    let mut low = scene.clone();
    low.camera.eye = Vec3::new(0.0, 1.2, 6.0);
    let mut s = settings(320, 240, 2048);
    s.shadow.filter.technique = Technique::VSM;
    let top = render(&low, &s);
    s.shadow.filter.moments.mipmaps = true;
    let mipped = render(&low, &s);
    let changed =
        top.visibility.iter().zip(&mipped.visibility).filter(|(a, b)| (*a - *b).abs() > 0.02).count();
    assert!(changed > 50, "mipmaps changed only {changed} pixels");
}

#[test]
fn techniques_stay_correct_with_cascades() {
    use gnomon_scene::settings::{CascadeFit, CascadeSelection, Partition};
    let SquareOccluder { scene, shadow_center, shadow_half: half, .. } = square_under_sun();
    for fit in [CascadeFit::Tight, CascadeFit::Stable] {
        for selection in [CascadeSelection::Depth, CascadeSelection::Projection] {
            for technique in [
                Technique::HARD,
                Technique::PCF2X2,
                Technique::PCF_TENT,
                Technique::PCSS,
                Technique::VSM,
                Technique::ESM,
                Technique::MSM_HAMBURGER,
            ] {
                let mut s = settings(640, 480, RESOLUTION);
                s.shadow.filter.technique = technique.clone();
                s.shadow.partition = Partition::Cascades;
                s.shadow.cascades.cascade_fit = fit;
                s.shadow.cascades.cascade_selection = selection;
                let frame = render(&scene, &s);
                assert_eq!(frame.cascades.len(), 4);
                assert_eq!(frame.cascade_splits.len(), 5);
                let o = classify(
                    &scene,
                    &s,
                    |p| Some(square_distance(Vec2::new(p.x, p.z), shadow_center, half)),
                    0.0,
                );
                check(&format!("{} ({fit:?} cascades by {selection:?})", technique.name()), &o);
            }
        }
    }
}

#[test]
fn cascades_put_finer_texels_near_the_camera() {
    use gnomon_scene::settings::Partition;
    let scene = gnomon_scene::builtin::columns();
    let mut s = settings(320, 180, 1024);
    s.shadow.partition = Partition::Cascades;
    let frame = render(&scene, &s);
    let texels: Vec<f32> = frame.cascades.iter().map(|c| c.texel_world_size(1024, 0.0)).collect();
    assert!(texels.windows(2).all(|w| w[1] > w[0]), "texel sizes should grow with distance: {texels:?}");
    let splits = &frame.cascade_splits;
    assert!(splits.windows(2).all(|w| w[1] > w[0]), "{splits:?}");
    let single = {
        let mut s = settings(320, 180, 2048);
        s.shadow.map.fit = gnomon_scene::settings::Fit::Scene;
        render(&scene, &s).light_projection.texel_world_size(2048, 0.0)
    };
    assert!(
        texels[0] < single,
        "the nearest cascade's texels ({}) beat one 2048² map's ({single})",
        texels[0]
    );
}

/// Whether changing `change` in `s` changes any pixel's visibility by more than 1e-3.
fn image_moves(scene: &Scene, s: &Settings, change: impl Fn(&mut Settings)) -> usize {
    let before = render(scene, s);
    let mut changed = s.clone();
    change(&mut changed);
    let after = render(scene, &changed);
    before.visibility.iter().zip(&after.visibility).filter(|(a, b)| (*a - *b).abs() > 1e-3).count()
}

/// The contract's `tunables`: a technique states exactly the settings that move its
/// shadow, which is what `gnomon calibrate` sweeps. A stated setting changes the
/// image under the square occluder; an unstated one leaves every pixel as it was.
#[test]
fn every_technique_states_exactly_the_settings_that_move_its_shadow() {
    let SquareOccluder { scene, .. } = square_under_sun();
    for technique in TechniqueRegistry::builtin().iter() {
        let mut s = settings(320, 240, 512);
        s.shadow.filter.technique = technique.technique();
        s.shadow.bias.normal_offset = 0.0;
        let stated = technique.tunables();
        let name = technique.technique().name().to_owned();
        // A constant bias of half the light's depth range pushes every caster behind
        // its receivers; an offset of 10 texels (scaled down to a fifth or so on ground facing the sun) moves
        // the lookup across the edge; a
        // kernel of 9 texels instead of 3 widens the filtered edge.
        let moved = [
            (
                "raster bias",
                stated.raster_bias,
                image_moves(&scene, &s, |s| s.shadow.bias.depth_bias = 1 << 23),
            ),
            (
                "normal offset",
                stated.normal_offset,
                image_moves(&scene, &s, |s| s.shadow.bias.normal_offset = 10.0),
            ),
            ("kernel", stated.kernel, image_moves(&scene, &s, |s| s.shadow.filter.pcf_kernel = 9.0)),
        ];
        for (setting, stated, pixels) in moved {
            if stated {
                assert!(
                    pixels > 50,
                    "{name} states that the {setting} moves its shadow, but {pixels} pixels moved"
                );
            } else {
                assert_eq!(pixels, 0, "{name} states that the {setting} leaves its shadow alone");
            }
        }
    }
}
