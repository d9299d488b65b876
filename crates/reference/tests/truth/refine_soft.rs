//! Penumbrae refined by GPU rays, as the defaults refine every light with an area
//! (`--refine auto`, which is `rays`): a penumbra beam's 128 samples estimate the CPU
//! reference's integral under a sun disk, a spot's disk and a point's sphere; a hard
//! edge stays hard; and at the defaults, with only the light's size given, the
//! penumbrae are within issue 74's 0.01 of the truth once a still view has gathered
//! its frames, within 0.015 in the first frame after a cut, and no pixel the map
//! calls lit lies in a penumbra.

use crate::common;

use common::{compare, figures::figure, gpu, reference};
use gnomon_reference::{
    ReferenceImage,
    metrics::{self, Metrics, PixelClass, RasterView},
};
use gnomon_render::{Frame, OutputRequest, Renderer};
use gnomon_scene::{
    Scene, Settings, builtin,
    settings::{LightKind, Refine, Technique},
};

/// `scene` at `width` × `height` under PCSS, refined as `refine`.
fn pcss(width: u32, height: u32, refine: Refine) -> Settings {
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (width, height);
    s.shadow.filter.technique = Technique::PCSS;
    s.screen.refine = refine;
    s
}

fn render(renderer: &mut Renderer, scene: &Scene, s: &Settings) -> Frame {
    renderer.render(scene, s, &OutputRequest::default()).unwrap()
}

/// The three kinds of area light, each over a scene whose casters stand on or above
/// a ground: a sun 2° wide over `grazing` (low, so its penumbrae are long), a spot of radius 0.5 over `contact`, and
/// a point light (a sphere) of radius 0.25 over `spheres`.
fn area_lights() -> Vec<(&'static str, Scene, Settings)> {
    let mut sun = pcss(320, 180, Refine::EveryPixel);
    sun.light.sun_angular_diameter = Some(2.0);
    let mut spot = pcss(320, 180, Refine::EveryPixel);
    spot.light.kind = LightKind::Spot;
    spot.light.spot_radius = Some(0.5);
    let mut point = pcss(320, 180, Refine::EveryPixel);
    point.light.kind = LightKind::Point;
    point.light.point_radius = Some(0.25);
    vec![
        ("sun 2°, grazing", builtin::grazing(), sun),
        ("spot r 0.5, contact", builtin::contact(), spot),
        ("point r 0.25, spheres", builtin::spheres(), point),
    ]
}

/// With a beam at every light-facing pixel (128 samples turned per pixel), the GPU's
/// estimate and a 1024-ray reference differ over the penumbra by about their noise:
/// the reference's standard error at a pixel in mid-penumbra is √(¼/1024) ≈ 0.016
/// before stratification. PCSS's own error there is 5–35× larger. A light sampled in
/// the wrong shape (a disk for a cone, a radius for a diameter), a sample weighed
/// wrong or a caster's edge read off its line widens or narrows every penumbra, and
/// fails the bound.
const TRACED_PENUMBRA_MAE: f64 = 0.01;

#[test]
fn penumbra_beams_estimate_the_reference_under_every_kind_of_area_light() {
    let mut renderer = Renderer::new(gpu()).unwrap();
    for (name, scene, mut s) in area_lights() {
        s.reference.samples = 1024;
        let truth = reference(&scene, &s);
        let frame = render(&mut renderer, &scene, &s);
        let traced = compare(&frame, &truth);
        let mut alone = s.clone();
        alone.screen.refine = Refine::Off;
        let map = compare(&render(&mut renderer, &scene, &alone), &truth);
        figure(
            &format!("{name}: a beam at every pixel, penumbra MAE (PCSS alone)"),
            format!("{:.4} ({:.4})", traced.penumbra.error.mae, map.penumbra.error.mae),
            format!("{TRACED_PENUMBRA_MAE}"),
        );
        assert_eq!(frame.lights[0].rays_per_pixel, gnomon_math::light_masks::SAMPLES as u32, "{name}");
        assert!(traced.penumbra.error.pixels > 500, "{name}: {traced:?}");
        assert!(traced.penumbra.error.mae <= TRACED_PENUMBRA_MAE, "{name}: {traced:?}");
    }
}

/// Issue 25's bound for hard shadows, which a light a millimetre wide must still
/// meet: 0.02 % of light-facing pixels wrong.
const HARD_EDGE_MISMATCH: f64 = 0.0002;
/// The MAE within 2 px of the shadow's edge. A plain 3 × 3 average of the pixels
/// either side of the edge would leave them a quarter wrong.
const HARD_EDGE_MAE: f64 = 0.01;

/// Under a light a millimetre wide, the penumbra is narrower than a pixel: each
/// unsure pixel's beam is all lit or all hidden, and what fills the pixels a frame
/// does not beam must not blur the edge between a shadowed pixel and a lit one (a
/// fill interpolates only between answers that agree: refine_trace.wgsl).
#[test]
fn a_light_a_millimetre_wide_keeps_hard_edges_hard() {
    let mut renderer = Renderer::new(gpu()).unwrap();
    let scene = builtin::contact();
    let mut s = pcss(640, 360, Refine::Rays);
    s.light.kind = LightKind::Spot;
    s.light.spot_radius = Some(0.001);
    s.reference.samples = 64;
    let truth = reference(&scene, &s);
    let refined = compare(&render(&mut renderer, &scene, &s), &truth);
    figure(
        "spot r 0.001 on contact, beamed: mismatch, edge MAE",
        format!("{:.4} %, {:.4}", 100.0 * refined.mismatch_rate, refined.edge.mae),
        format!("{:.2} %, {HARD_EDGE_MAE}", 100.0 * HARD_EDGE_MISMATCH),
    );
    assert!(refined.mismatch_rate <= HARD_EDGE_MISMATCH, "{refined:?}");
    assert!(refined.edge.mae <= HARD_EDGE_MAE, "{refined:?}");
}

/// Issue 74's configurations at 480 × 270 with 1024-ray references, at the defaults
/// with only the light's size given: `spheres` under a spot of radius 0.3 (curved
/// penumbrae under 4 px wide), `contact` under a spot of radius 0.5 (penumbrae that
/// widen away from each contact), `grazing` under a sun 2° wide (long penumbrae,
/// which PCSS estimates half as wide as they are), and `spheres` under a point light
/// of radius 0.3 (a cube map).
fn soft_configurations() -> Vec<(&'static str, Scene, Settings)> {
    let sized = |kind| {
        let mut s = Settings::default();
        (s.image.width, s.image.height) = (480, 270);
        s.light.kind = kind;
        s.reference.samples = 1024;
        s
    };
    let mut spot_spheres = sized(LightKind::Spot);
    spot_spheres.light.spot_radius = Some(0.3);
    let mut spot_contact = sized(LightKind::Spot);
    spot_contact.light.spot_radius = Some(0.5);
    let mut sun = sized(LightKind::Sun);
    sun.light.sun_angular_diameter = Some(2.0);
    let mut point = sized(LightKind::Point);
    point.light.point_radius = Some(0.3);
    vec![
        ("spot r 0.3, spheres", builtin::spheres(), spot_spheres),
        ("spot r 0.5, contact", builtin::contact(), spot_contact),
        ("sun 2°, grazing", builtin::grazing(), sun),
        ("point r 0.3, spheres", builtin::spheres(), point),
    ]
}

fn measure(renderer: &mut Renderer, scene: &Scene, s: &Settings, truth: &ReferenceImage) -> Metrics {
    compare(&render(renderer, scene, s), truth)
}

/// Issue 74's bound at the defaults: the penumbra MAE of a still view against the
/// truth (there a 4096-ray reference; here a 1024-ray one, whose own noise adds).
const DEFAULT_PENUMBRA_MAE: f64 = 0.01;
/// Issue 74's bound for a frame of a moving light or caster, which starts afresh: the
/// first frame after a cut, a quarter of its unsure pixels beamed.
const FIRST_FRAME_PENUMBRA_MAE: f64 = 0.015;
/// Issue 25's bound, kept: refined penumbrae have at most half of PCSS's error.
const REFINED_OVER_PCSS: f64 = 0.5;
/// A pixel the map calls lit (visibility exactly 1) whose truth is this far below
/// 1 lies in a penumbra the classification missed (the reference's noise is a few
/// hundredths at most).
const MISSED_PENUMBRA: f32 = 0.1;

#[test]
fn the_defaults_beam_a_lights_penumbrae_to_the_truth() {
    let mut renderer = Renderer::new(gpu()).unwrap();
    for (name, scene, mut s) in soft_configurations() {
        let truth = reference(&scene, &s);
        let frame = render(&mut renderer, &scene, &s);
        let still = compare(&frame, &truth);
        let light = &frame.lights[0];
        assert_eq!(light.refine, Refine::Rays, "{name}: the defaults no longer trace");
        assert_eq!(light.rays_per_pixel, gnomon_math::light_masks::SAMPLES as u32, "{name}");
        assert_eq!(
            light.penumbra_frames,
            Some(s.screen.penumbra_frames),
            "{name}: the frames a still view gathers"
        );
        // Over the pixels compared: where both see the same surface, facing the light.
        let raster =
            RasterView { visibility: &frame.visibility, object_id: &frame.object_id, depth: &frame.depth };
        let classes = metrics::classify(raster, &truth);
        let missed: Vec<(u32, u32, f32)> = (0..frame.visibility.len())
            .filter(|&i| classes[i] == PixelClass::Compared)
            .filter(|&i| frame.visibility[i] == 1.0 && truth.visibility[i] < 1.0 - MISSED_PENUMBRA)
            .map(|i| {
                (
                    (i % s.image.width as usize) as u32,
                    (i / s.image.width as usize) as u32,
                    truth.visibility[i],
                )
            })
            .collect();
        s.screen.penumbra_frames = 1;
        renderer.forget_penumbra_history();
        let first_frame = render(&mut renderer, &scene, &s);
        // The first frame beams (a still view's last may not: its unsure pixels may
        // all hold their beams by then), and at most a quarter of the screen.
        let traced = first_frame.lights[0].traced_pixels.expect("a refined frame reports its pixels");
        assert!(traced > 0 && (traced as usize) < frame.pixel_count() / 4, "{name}: {traced} pixels traced");
        let first = compare(&first_frame, &truth);
        let mut alone = s.clone();
        alone.screen.refine = Refine::Off;
        alone.shadow.filter.technique = Technique::PCSS;
        let pcss = measure(&mut renderer, &scene, &alone, &truth);
        figure(
            &format!("{name}, 480×270, the defaults: penumbra MAE, still view (first frame; PCSS alone)"),
            format!(
                "{:.4} ({:.4}; {:.4})",
                still.penumbra.error.mae, first.penumbra.error.mae, pcss.penumbra.error.mae
            ),
            format!("≤ {DEFAULT_PENUMBRA_MAE} ({FIRST_FRAME_PENUMBRA_MAE})"),
        );
        assert!(still.penumbra.error.pixels > 500, "{name}: {still:?}");
        assert!(still.penumbra.error.mae <= DEFAULT_PENUMBRA_MAE, "{name}: {still:?}");
        assert!(first.penumbra.error.mae <= FIRST_FRAME_PENUMBRA_MAE, "{name}: {first:?}");
        assert!(
            still.penumbra.error.mae <= REFINED_OVER_PCSS * pcss.penumbra.error.mae,
            "{name}: {still:?}\n{pcss:?}"
        );
        assert!(missed.is_empty(), "{name}: pixels called lit lie in a penumbra (x, y, truth): {missed:?}");
    }
}

/// A low sun's first frame after a cut (a moving sun's every frame), over `grazing`'s
/// far posts: their shadows, seen along the sun's azimuth from afar, are penumbrae a
/// pixel tall across a lit floor. The fill once took the mean of a pair of
/// neighbours on either side of such a pixel of which one was lit, and called the
/// shadow nearly lit; then the mean of a pair both inside the penumbra but far apart
/// along the foreshortened floor, and missed a shadow between them. It now takes
/// only pairs inside a penumbra within three pixel widths along the surface, and
/// beams the rest. Penumbra MAE on lavapipe, where a still view's 16th frame is
/// 0.004: under the sun at 97°, 0.073, then 0.0066; at 100.7° (`bench --sun-path
/// day` at 7 h), 0.0177, then 0.0064.
#[test]
fn a_first_frame_keeps_the_far_posts_thin_penumbrae() {
    let mut renderer = Renderer::new(gpu()).unwrap();
    let scene = builtin::grazing();
    for azimuth in [97.0, 100.73] {
        let mut s = Settings::default();
        (s.image.width, s.image.height) = (320, 180);
        s.light.sun_angular_diameter = Some(2.0);
        (s.light.sun_elevation, s.light.sun_azimuth) = (Some(10.545), Some(azimuth));
        s.reference.samples = 1024;
        s.screen.penumbra_frames = 1;
        let truth = reference(&scene, &s);
        let first = compare(&render(&mut renderer, &scene, &s), &truth);
        figure(
            &format!(
                "sun 2° 10.5° up at {azimuth}°, grazing, 320×180, the defaults' first frame: penumbra MAE"
            ),
            format!("{:.4} over {} pixels", first.penumbra.error.mae, first.penumbra.error.pixels),
            format!("≤ {FIRST_FRAME_PENUMBRA_MAE}"),
        );
        assert!(first.penumbra.error.pixels > 200, "{azimuth}°: {first:?}");
        assert!(first.penumbra.error.mae <= FIRST_FRAME_PENUMBRA_MAE, "{azimuth}°: {first:?}");
    }
}

/// A city under a 2° sun 35° up (`florence` at its close view), every light-facing
/// pixel counted against the truth traced from the frame's own surfaces: at most
/// 0.05 % of them called lit (≥ ½) where the truth is shadowed. The classification
/// once cleared a square by its own plane (a floor's far squares under a low sun),
/// and called 0.151 % of them lit in umbra here (lavapipe; 0.021 % without it).
#[test]
fn a_city_under_a_sun_with_a_size_keeps_its_shadows() {
    let Some(path) = common::shared_scene("florence/florence.glb") else {
        return;
    };
    let (florence, _) = gnomon_scene::gltf_loader::load(&path).unwrap();
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (320, 180);
    s.camera.eye = Some(glam::Vec3::new(250.0, 150.0, 350.0));
    s.camera.target = Some(glam::Vec3::ZERO);
    s.camera.fov_y_degrees = Some(50.0);
    (s.light.sun_elevation, s.light.sun_azimuth) = (Some(35.0), Some(40.0));
    s.light.sun_angular_diameter = Some(2.0);
    s.reference.samples = 64;
    let mut renderer = Renderer::new(gpu()).unwrap();
    let frame = render(&mut renderer, &florence, &s);
    let drawn = crate::one_surface::drawn_metrics(&florence, &s, &frame);
    figure(
        "florence close up, sun 2° 35° up, 320×180, the defaults: light-facing pixels called lit in shadow",
        format!("{:.3} % of {}", 100.0 * drawn.false_lit_rate, drawn.compared),
        "≤ 0.05 %".to_string(),
    );
    assert!(drawn.compared > 20_000, "{drawn:?}");
    assert!(drawn.false_lit_rate <= 0.0005, "{drawn:?}");
}
