//! The depth-only baseline draws what the shadow pass draws, so that the ratio of
//! their times compares pipelines, not workloads: every layer, every light kind, with
//! the shadow pass's bias.

use crate::support;

use std::time::Instant;

use glam::Mat4;
use gnomon_math::linearize_perspective_depth;
use gnomon_render::{OutputRequest, Renderer, timing::ClockChoice};
use gnomon_scene::{
    Light, Scene, Settings, builtin,
    settings::{BiasSettings, LightKind, Partition},
};
use support::figures::figure;

fn small() -> Settings {
    let mut s = Settings::default();
    s.image.width = 160;
    s.image.height = 90;
    s.shadow.map.resolution = 512;
    s
}

/// `scene` with every instance's transform baked into its own copy of the mesh, so
/// that the shadow pass (object positions through an identity matrix) and the
/// baseline (positions transformed on the CPU, by the identity) draw bit-identical
/// triangles.
fn baked(mut scene: Scene) -> Scene {
    let mut meshes = Vec::with_capacity(scene.instances.len());
    for instance in &mut scene.instances {
        let mut mesh = scene.meshes[instance.mesh].clone();
        for p in &mut mesh.positions {
            *p = instance.world_from_object.transform_point3(*p);
        }
        instance.mesh = meshes.len();
        instance.world_from_object = Mat4::IDENTITY;
        meshes.push(mesh);
    }
    scene.meshes = meshes;
    scene
}

/// The shadow pass's map (every layer) and the baseline's, for `settings`.
fn both_maps(renderer: &mut Renderer, scene: &Scene, settings: &Settings) -> (Vec<f32>, Vec<f32>, u32) {
    let uploaded = renderer.upload(scene).unwrap();
    let baseline = renderer.upload_depth_baseline(scene).unwrap();
    let ours = renderer
        .render_uploaded(
            &uploaded,
            scene,
            settings,
            &OutputRequest { shadow_map: true, ..Default::default() },
        )
        .unwrap()
        .shadow_map
        .unwrap();
    let theirs = renderer.depth_baseline_map(&baseline, &uploaded, scene, settings).unwrap();
    assert_eq!(ours.depth.len(), theirs.len(), "{}: the same layers", scene.name);
    (ours.depth, theirs, ours.layers)
}

/// Sun (single map, fitted and pancaked by default), four cascades and a spot, with
/// the default bias: the same triangles drawn with the same rasterizer state give the
/// same depth in every texel of every layer.
#[test]
fn the_baseline_draws_every_projected_layer_exactly_as_the_shadow_pass() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let mut cascaded = small();
    cascaded.shadow.partition = Partition::Cascades;
    let mut spot = small();
    spot.light.kind = LightKind::Spot;
    let mut front = small();
    front.shadow.bias.cull = gnomon_scene::settings::CullMode::Front;
    assert!(small().shadow.bias.slope_bias > 0.0, "the default bias is on, and compared");
    // Each map must hold casters for the comparison to mean anything: a twentieth of
    // every layer (36,758 to 232,182 of 262,144 texels measured), but where front
    // faces are culled, which leaves only the columns' inner faces (2,603 measured).
    let texels = 512 * 512;
    for (what, scene, settings, layers, min_covered) in [
        ("sun", baked(builtin::spheres()), small(), 1, texels / 20),
        ("cascades", baked(builtin::spheres()), cascaded, 4, texels / 20),
        ("spot", baked(builtin::contact()), spot, 1, texels / 20),
        ("sun, front faces", baked(builtin::columns()), front, 1, 1000),
    ] {
        let (ours, theirs, drawn_layers) = both_maps(&mut renderer, &scene, &settings);
        assert_eq!((drawn_layers, ours.len()), (layers, layers as usize * texels), "{what}");
        for layer in 0..layers as usize {
            let range = layer * texels..(layer + 1) * texels;
            let covered = ours[range.clone()].iter().filter(|&&d| d < 1.0).count();
            assert!(covered > min_covered, "{what}, layer {layer}: only {covered} texels hold casters");
        }
        let differ = ours.iter().zip(&theirs).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
        figure(&format!("depth-only baseline vs shadow pass, {what}: texels differing"), differ, "0");
        assert_eq!(differ, 0, "{what}: {differ} of {} texels differ", ours.len());
    }
}

/// A point light's cube: the shadow pass stores distance over range, the baseline the
/// face's projected depth. Converted to distance, the baseline's depth is the shadow
/// pass's, in every texel of all six faces, and both cover the same texels.
#[test]
fn the_baseline_draws_the_cube_faces_the_shadow_pass_draws() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = baked(builtin::spheres());
    let mut s = small();
    s.light.kind = LightKind::Point;
    // The distance pass biases in its fragment stage, which a projected depth cannot
    // reproduce: compared without bias here, with it for coverage below.
    s.shadow.bias = BiasSettings { cull: s.shadow.bias.cull, ..BiasSettings::none() };
    let Light::Point(point) = s.resolve_light(&scene).unwrap() else { panic!("a point light") };
    let (near, far) = (point.shadow_near(), point.range);
    let (ours, theirs, layers) = both_maps(&mut renderer, &scene, &s);
    assert_eq!(layers, 6);
    let n = s.shadow.map.resolution as usize;
    let mut worst = 0.0f32;
    for (i, (&ours, &theirs)) in ours.iter().zip(&theirs).enumerate() {
        assert_eq!(ours < 1.0, theirs < 1.0, "texel {i}: coverage differs ({ours} vs {theirs})");
        if ours < 1.0 {
            // A 90° face: the texel centre's ray is (u, v, 1) in face space.
            let (x, y) = ((i % n) as f32 + 0.5, ((i / n) % n) as f32 + 0.5);
            let (u, v) = (2.0 * x / n as f32 - 1.0, 2.0 * y / n as f32 - 1.0);
            let distance = linearize_perspective_depth(theirs, near, far) * (1.0 + u * u + v * v).sqrt();
            worst = worst.max((ours - distance / far).abs());
        }
    }
    // The float error of inverting the perspective depth, which grows as z / near:
    // 9.8e-6 of the range measured on lavapipe (near / far = 1 / 500).
    let bound = 2e-5;
    figure("depth-only baseline vs cube faces: worst distance error (of range)", worst, bound);
    assert!(worst < bound, "distance differs by up to {worst} of the range (bound {bound})");

    // With the default bias, the same texels are covered but for those whose
    // slope-scaled bias (huge where a caster is seen edge-on) pushes the distance past
    // the range: the shadow pass only ever loses texels there, never gains any.
    let mut biased = s.clone();
    biased.shadow.bias = small().shadow.bias;
    let (ours, theirs, _) = both_maps(&mut renderer, &scene, &biased);
    let covered = theirs.iter().filter(|&&d| d < 1.0).count();
    let gained = ours.iter().zip(&theirs).filter(|(a, b)| **a < 1.0 && **b >= 1.0).count();
    let lost = ours.iter().zip(&theirs).filter(|(a, b)| **a >= 1.0 && **b < 1.0).count();
    // 6 of 834,823 measured.
    let lost_share = lost as f64 / covered as f64;
    let bound = 5e-4;
    figure("biased cube faces vs baseline: share of texels lost to the bias", lost_share, bound);
    assert_eq!(gained, 0, "the biased shadow pass covers {gained} texels the baseline does not");
    assert!(lost_share < bound, "the bias pushed {lost} of {covered} texels past the range");
}

/// Instanced casters: the shadow pass transforms object positions on the GPU, the
/// baseline took them pre-transformed from the CPU, so depths may differ by rounding
/// alone.
#[test]
fn instanced_casters_differ_from_the_baseline_by_rounding_alone() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::spheres();
    assert!(scene.instances.iter().any(|i| i.world_from_object != Mat4::IDENTITY));
    let (ours, theirs, _) = both_maps(&mut renderer, &scene, &small());
    let coverage = ours.iter().zip(&theirs).filter(|(a, b)| (**a < 1.0) != (**b < 1.0)).count();
    let worst = ours
        .iter()
        .zip(&theirs)
        .filter(|(a, b)| **a < 1.0 && **b < 1.0)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    // 0 and 0 measured on lavapipe. In general the GPU's and the CPU's transforms may
    // round a position differently (fused multiply-adds): a triangle edge through a
    // texel centre may then fall either way, and a depth move by a few ulps (2⁻²⁴
    // each, ~1e-7 at depth 1).
    let (coverage_bound, depth_bound) = (4, 1e-6);
    figure(
        "instanced shadow pass vs baseline: coverage differences, worst depth",
        format!("{coverage}, {worst:e}"),
        format!("{coverage_bound}, {depth_bound:e}"),
    );
    assert!(coverage <= coverage_bound, "coverage differs in {coverage} texels");
    assert!(worst < depth_bound, "depths differ by up to {worst}");
}

/// The baseline is timed per light, on the GPU clock or the CPU's, and its times fit
/// in the wall-clock time the test measures around the call: each clock is checked
/// against an independent one.
#[test]
fn the_baseline_times_fit_in_the_wall_clock_time_of_the_call() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::lamps();
    let mut s = small();
    s.light.kind = LightKind::All;
    let uploaded = renderer.upload(&scene).unwrap();
    let baseline = renderer.upload_depth_baseline(&scene).unwrap();
    for clock in [ClockChoice::Auto, ClockChoice::Cpu] {
        let started = Instant::now();
        let times = renderer.time_depth_baseline(&baseline, &uploaded, &scene, &s, clock).unwrap();
        let wall_ms = started.elapsed().as_secs_f64() * 1e3;
        assert_eq!(times.len(), scene.listed_lights().count(), "a time per light");
        let total: f64 =
            times.iter().map(|t| t.expect("no paraboloid here: every light has a baseline")).sum();
        assert!(times.iter().all(|t| t.is_some_and(|ms| ms > 0.0)), "{times:?}");
        assert!(total <= wall_ms, "{clock:?}: the lights' times sum to {total} ms in a {wall_ms} ms call");
    }
}
