//! Issue 7: point lights against the reference. A cube shadow map is accurate in
//! `spheres`, shows no band of error along its face seams, draws into each face only
//! the casters that face can see, and a sphere light's soft shadows follow PCSS.

use crate::common;

use common::{
    compare,
    figures::{figure, percent},
    reference, render,
};
use glam::{Mat4, Vec3};
use gnomon_reference::{
    ReferenceImage,
    metrics::{self, PixelClass, RasterView},
};
use gnomon_render::Frame;
use gnomon_scene::{
    Camera, Instance, Material, PointLight, Scene, Settings, builtin, geometry,
    settings::{LightKind, Refine, Technique},
};

fn point_settings(technique: Technique, resolution: u32, width: u32, height: u32) -> Settings {
    let mut s = Settings::default();
    s.light.kind = LightKind::Point;
    s.shadow.filter.technique = technique.clone();
    s.shadow.map.resolution = resolution;
    s.image.width = width;
    s.image.height = height;
    s
}

/// The must-show: in `spheres`, with the point light among the spheres,
/// pcf2x2 at 1024² per face mismatches the reference on under 0.5 % of the pixels.
/// Measured on lavapipe at 1280×720: 0.090 % (hard 0.101 %).
#[test]
fn point_light_in_spheres_mismatches_under_half_a_percent() {
    let scene = builtin::spheres();
    let s = point_settings(Technique::PCF2X2, 1024, 1280, 720);
    let truth = reference(&scene, &s);
    let frame = render(&scene, &s);
    let m = compare(&frame, &truth);
    eprintln!(
        "spheres, point light, pcf2x2 1024²/face: mismatch {:.3}% (false shadow {:.3}%, false lit {:.3}%) of {}",
        100.0 * m.mismatch_rate,
        100.0 * m.false_shadow_rate,
        100.0 * m.false_lit_rate,
        m.compared
    );
    assert!(m.mismatch_rate < 0.005, "{m:?}");
    // The light is among the spheres: its shadows fall every way, so every face of
    // the cube has work to do, and most of the image is compared.
    let shadowed = truth.visibility.iter().filter(|v| **v < 0.5).count();
    assert!(shadowed > frame.pixel_count() / 10, "{shadowed} shadowed pixels");
    assert!(m.compared > frame.pixel_count() / 2);
    assert_eq!(frame.lights[0].layer_draws.len(), 6);
}

/// Dual paraboloids, the two-view alternative: on the same view they draw two layers
/// instead of six, and stay under the 0.5 % mismatch, but the cube is the more
/// accurate (the paraboloids' texels grow toward the rim and their rasterized edges
/// are straight where the mapping bends them). Measured on lavapipe at 1280×720,
/// pcf2x2 1024²: cube 0.090 %, paraboloids 0.161 %.
#[test]
fn dual_paraboloids_trade_accuracy_for_two_views() {
    let scene = builtin::spheres();
    let cube = point_settings(Technique::PCF2X2, 1024, 1280, 720);
    let mut paraboloid = cube.clone();
    paraboloid.shadow.map.omni = gnomon_scene::settings::OmniMap::Paraboloid;
    let truth = reference(&scene, &cube);
    let (cube_frame, dp_frame) = (render(&scene, &cube), render(&scene, &paraboloid));
    let (c, d) = (compare(&cube_frame, &truth), compare(&dp_frame, &truth));
    eprintln!(
        "spheres, point light, pcf2x2 1024²: cube {:.3}% in 6 views, dual paraboloid {:.3}% in 2",
        100.0 * c.mismatch_rate,
        100.0 * d.mismatch_rate
    );
    assert_eq!(dp_frame.lights[0].layer_draws.len(), 2);
    assert!(d.mismatch_rate < 0.005, "{d:?}");
    assert!(c.mismatch_rate < d.mismatch_rate, "cube {c:?}\nparaboloid {d:?}");
}

/// A ground under a point light 2 m up, with posts standing across the lines where the
/// ground crosses from the cube's bottom face to its side faces (|x| = 2 or |z| = 2),
/// seen from above.
fn seam_scene() -> Scene {
    let mut scene = builtin::spheres();
    scene.name = "seams".into();
    scene.meshes = vec![geometry::plane(16.0, 16.0), geometry::cuboid(Vec3::new(0.06, 0.6, 0.06))];
    scene.materials = vec![Material::new("ground", Vec3::splat(0.7)), Material::new("post", Vec3::ONE)];
    scene.instances = vec![Instance {
        name: "ground".into(),
        mesh: 0,
        material: 0,
        world_from_object: Mat4::IDENTITY,
        casts_shadow: true,
        motion: gnomon_scene::Motion::Static,
    }];
    // Posts at 45° steps around the light's foot, some on the seam lines, some
    // across them, so that their shadows run over the seams.
    for i in 0..16 {
        let angle = i as f32 * std::f32::consts::TAU / 16.0;
        let radius = if i % 2 == 0 { 1.8 } else { 2.3 };
        let p = Vec3::new(radius * angle.cos(), 0.6, radius * angle.sin());
        scene.instances.push(Instance {
            name: format!("post {i}"),
            mesh: 1,
            material: 1,
            world_from_object: Mat4::from_translation(p),
            casts_shadow: true,
            motion: gnomon_scene::Motion::Static,
        });
    }
    let point = *scene.light::<PointLight>().unwrap();
    scene.set_default(PointLight { position: Vec3::new(0.0, 2.0, 0.0), range: 30.0, ..point });
    scene.camera = Camera {
        eye: Vec3::new(0.0, 9.0, 3.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_degrees: 55.0,
        near: 0.1,
        far: 40.0,
    };
    scene.replace_listed_lights([]);
    scene
}

/// Texels between the cube-face seam and the direction from the light to `p`, for
/// faces of `resolution`²: a face coordinate is the second-largest component over the
/// largest, and reaches 1 at the seam.
fn texels_from_seam(p: Vec3, light: Vec3, resolution: u32) -> f32 {
    let mut a = (p - light).abs().to_array();
    a.sort_by(f32::total_cmp);
    (1.0 - a[1] / a[2]) * 0.5 * resolution as f32
}

/// Mismatch rates inside and outside the band within `band` texels of a seam.
fn seam_band_mismatch(
    visibility: &[f32],
    frame: &Frame,
    truth: &ReferenceImage,
    band: f32,
) -> (f64, f64, usize) {
    let raster = RasterView { visibility, object_id: &frame.object_id, depth: &frame.depth };
    let classes = metrics::classify(raster, truth);
    let gnomon_scene::Light::Point(light) = frame.light else { panic!("a point light's frame") };
    let light = light.position;
    let (mut inside, mut inside_bad, mut outside, mut outside_bad) = (0usize, 0usize, 0usize, 0usize);
    for (i, class) in classes.iter().enumerate() {
        if *class != PixelClass::Compared {
            continue;
        }
        let bad = (visibility[i] >= 0.5) != (truth.visibility[i] >= 0.5);
        if texels_from_seam(truth.position[i], light, frame.shadow_resolution) < band {
            inside += 1;
            inside_bad += bad as usize;
        } else {
            outside += 1;
            outside_bad += bad as usize;
        }
    }
    (inside_bad as f64 / inside.max(1) as f64, outside_bad as f64 / outside.max(1) as f64, inside)
}

/// How much worse the seams may be than the rest of the image, and an absolute cap
/// on them: measured 0.19–0.22 % near them against 0.23 % elsewhere, a ratio of 0.81
/// to 0.94 (was: under 1 % near them, whatever elsewhere). Faces drawn 0.2° short of
/// 90° give 1.50 % against 0.40 %.
const SEAM_OVER_ELSEWHERE: f64 = 1.25;
const SEAM_MISMATCH: f64 = 0.0035;

/// The must-show: where the ground crosses a cube-face boundary there is no
/// band of mismatch along it, for the point-sampled, bilinear, filtered and PCSS
/// lookups alike (their taps cross the seam; PCSS's blocker search too, here for a
/// point light, whose penumbra is its smallest kernel). A seam drawn or looked up wrong (a face rotated
/// or mirrored, a field of view short of 90°, taps clamped at a face's edge) shows
/// as a line of error along it: the planted line below is caught.
#[test]
fn no_band_of_mismatch_along_cube_face_seams() {
    let scene = seam_scene();
    let band = 3.0;
    for technique in [
        Technique::HARD,
        Technique::PCF2X2,
        Technique::PCF,
        Technique::PCF_TENT,
        Technique::PCF_POISSON,
        Technique::PCSS,
    ] {
        let mut s = point_settings(technique.clone(), 512, 960, 640);
        s.shadow.filter.pcf_kernel = 3.0;
        let truth = reference(&scene, &s);
        let frame = render(&scene, &s);
        let (near_seam, elsewhere, pixels) = seam_band_mismatch(&frame.visibility, &frame, &truth, band);
        eprintln!(
            "seams, {}: mismatch {:.3}% within {band} texels of a seam ({pixels} pixels), {:.3}% elsewhere",
            technique.name(),
            100.0 * near_seam,
            100.0 * elsewhere
        );
        assert!(pixels > 5_000, "the seams cross the view: {pixels} pixels near them");
        // The seams are no worse than the rest of the image.
        figure(
            &format!("cube seams, {}: mismatch near the seams / elsewhere", technique.name()),
            format!("{} / {}", percent(near_seam), percent(elsewhere)),
            format!("near < {SEAM_OVER_ELSEWHERE} × elsewhere and < {}", percent(SEAM_MISMATCH)),
        );
        assert!(
            near_seam < SEAM_OVER_ELSEWHERE * elsewhere && near_seam < SEAM_MISMATCH,
            "{}: {:.3}% near the seams, {:.3}% elsewhere",
            technique.name(),
            100.0 * near_seam,
            100.0 * elsewhere
        );

        // A one-texel line of false shadow along every seam, as a gap between faces
        // would leave, is caught by the same measure.
        let planted: Vec<f32> = frame
            .visibility
            .iter()
            .zip(&truth.position)
            .map(|(&v, &p)| {
                let on_seam = p.is_finite()
                    && texels_from_seam(p, scene.light::<PointLight>().unwrap().position, 512) < 0.5;
                if on_seam { 0.0 } else { v }
            })
            .collect();
        let (planted_rate, planted_elsewhere, _) = seam_band_mismatch(&planted, &frame, &truth, band);
        figure(
            &format!("cube seams, {}: a planted seam line", technique.name()),
            percent(planted_rate),
            format!("caught: > {SEAM_OVER_ELSEWHERE} × elsewhere"),
        );
        assert!(
            planted_rate > SEAM_OVER_ELSEWHERE * planted_elsewhere,
            "a planted seam line gives only {:.3}%",
            100.0 * planted_rate
        );
        assert!(planted_rate > 0.05, "a planted seam line gives only {:.3}%", 100.0 * planted_rate);
    }
}

/// The must-show: casters are culled per cube face. A box beside the light,
/// level with it on +x, is drawn into the +x face alone; the ground under the light
/// into the five faces that look down or sideways, never into +y. A spot light aimed
/// away from the box does not draw it at all. The shadows stay right.
#[test]
fn casters_outside_a_face_are_not_drawn_into_it() {
    let mut scene = seam_scene();
    scene.instances.truncate(1);
    scene.meshes.push(geometry::cuboid(Vec3::splat(0.5)));
    scene.instances.push(Instance {
        name: "box".into(),
        mesh: 2,
        material: 1,
        world_from_object: Mat4::from_translation(Vec3::new(4.0, 2.0, 0.0)),
        casts_shadow: true,
        motion: gnomon_scene::Motion::Static,
    });
    let s = point_settings(Technique::PCF2X2, 512, 480, 320);
    let frame = render(&scene, &s);
    // Layers in WebGPU's order: +x, −x, +y, −y, +z, −z.
    assert_eq!(frame.lights[0].layer_draws, vec![2, 1, 0, 1, 1, 1], "{:?}", frame.lights[0]);
    assert_eq!(frame.stats.shadow_draws, 6);
    // The box's shadow, drawn into +x only, still falls on the ground beyond it.
    let truth = reference(&scene, &s);
    let m = compare(&frame, &truth);
    assert!(m.mismatch_rate < 0.005, "{m:?}");

    let mut spot = s.clone();
    spot.light.kind = LightKind::Spot;
    spot.light.spot_position = Some(Vec3::new(0.0, 3.0, 0.0));
    spot.light.spot_target = Some(Vec3::new(-3.0, 0.0, 0.0));
    spot.light.spot_outer_angle = Some(30.0);
    let away = render(&scene, &spot);
    assert_eq!(away.lights[0].layer_draws, vec![1], "only the ground: {:?}", away.lights[0]);
    spot.light.spot_target = Some(Vec3::new(4.0, 1.0, 0.0));
    let toward = render(&scene, &spot);
    assert_eq!(toward.lights[0].layer_draws, vec![2], "ground and box: {:?}", toward.lights[0]);
}

/// Cube PCSS's MAE under a sphere light of radius 0.25 on `spheres` (0.0264 measured),
/// and against a hard lookup's (0.0531 measured: a ratio of 0.50).
const SPHERE_PCSS_MAE: f64 = 0.03;
const SPHERE_PCSS_OVER_HARD: f64 = 0.7;

/// A sphere light's soft shadows: PCSS on the cube against the Monte Carlo reference
/// over the sphere's solid angle. PCSS follows the penumbra far better than a hard
/// lookup does.
#[test]
fn sphere_light_pcss_follows_the_monte_carlo_penumbra() {
    let scene = builtin::spheres();
    let mut s = point_settings(Technique::PCSS, 1024, 480, 270);
    s.light.point_radius = Some(0.25);
    s.reference.samples = 128;
    // The techniques' own penumbrae: under `auto`, a light with an area is beamed.
    s.screen.refine = Refine::Off;
    let truth = reference(&scene, &s);
    let pcss = compare(&render(&scene, &s), &truth);
    let mut hard = s.clone();
    hard.shadow.filter.technique = Technique::HARD;
    let hard = compare(&render(&scene, &hard), &truth);
    eprintln!("sphere light r = 0.25: MAE pcss {:.4}, hard {:.4}", pcss.mae, hard.mae);
    figure(
        "sphere light, cube PCSS: MAE (hard)",
        format!("{:.4} ({:.4})", pcss.mae, hard.mae),
        format!("{SPHERE_PCSS_MAE}, and < {SPHERE_PCSS_OVER_HARD} × hard"),
    );
    assert!(pcss.mae < SPHERE_PCSS_OVER_HARD * hard.mae, "pcss {pcss:?}\nhard {hard:?}");
    assert!(pcss.mae < SPHERE_PCSS_MAE, "{pcss:?}");
}

/// Issue 25's footprint test on a cube map: under its point light, the alpha-tested
/// tree's leaves leave errors that pcf2x2's taps agree on (all lit, or all shadowed);
/// rays catch them only where the cube's footprint around each lookup is read too.
/// Measured on lavapipe at 640×360: the map alone 1.93 %, refined by the filter's
/// disagreement alone 0.175 %, with the footprint test 0.0215 %, every pixel traced
/// 0.0099 %.
#[test]
fn rays_where_the_cube_is_unsure_correct_the_trees_point_light_shadow() {
    let path = common::shipped_scene("tree/tree.glb");
    let (scene, _) = gnomon_scene::gltf_loader::load(&path).unwrap();
    let mut s = point_settings(Technique::PCF2X2, 2048, 640, 360);
    let truth = reference(&scene, &s);
    let mut rates = Vec::new();
    for refine in [Refine::Off, Refine::Rays, Refine::EveryPixel] {
        s.screen.refine = refine;
        let m = compare(&render(&scene, &s), &truth);
        let bound = match refine {
            Refine::Off => "> 1 %",
            Refine::Rays => "≤ 0.03 % and ≤ every pixel's + 0.02 %",
            Refine::Auto | Refine::EveryPixel => "(for scale)",
        };
        figure(
            &format!("tree, point light, pcf2x2, --refine {refine:?}: mismatch"),
            percent(m.mismatch_rate),
            bound,
        );
        rates.push(m.mismatch_rate);
    }
    let [map, refined, traced] = rates[..] else { unreachable!() };
    assert!(map > 0.01, "the map alone should miss the leaves' shadows: {map}");
    assert!(refined <= 0.0003 && refined <= traced + 0.0002, "refined {refined}, every pixel {traced}");
}
