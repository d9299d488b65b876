//! Issue 6's measurements of perspective aliasing on `columns`: cascades and warps lower
//! Lloyd's m against one map over the whole scene, warps fall back gracefully, and
//! stable cascades shimmer less than tight ones under a moving camera.

use crate::common;

use common::{gpu, render};
use glam::Vec3;
use gnomon_math::ProjectionKind;
use gnomon_reference::{
    TracedScene,
    aliasing::{self, AliasingInput, LayerChoice},
    flicker::{Flicker, FlickerCounter, PathFrame},
    metrics::RasterView,
    reference_visibility,
};
use gnomon_render::{Frame, OutputRequest, Renderer};
use gnomon_scene::{
    DirectionalLight, Instance, Scene, Settings, builtin,
    camera_path::{CameraPathKind, camera_on_path},
    geometry,
    settings::{
        CameraSettings, CascadeFit, CascadeSelection, Fit, Partition, Refine, SplitScheme, Technique,
        WarpKind,
    },
};

/// What Lloyd's m is measured from over `frame`: its pixels against the layers
/// `layers` (each a map of `resolution`²), a pixel picking its layer by `choice`.
fn frame_input<'a>(
    frame: &'a Frame,
    layers: &'a [glam::Mat4],
    choice: LayerChoice<'a>,
    resolution: u32,
) -> AliasingInput<'a> {
    AliasingInput {
        width: frame.width,
        height: frame.height,
        position: &frame.position,
        normal: &frame.normal,
        depth: &frame.depth,
        camera: &frame.camera,
        light: &frame.light,
        layers,
        choice,
        resolution,
    }
}

fn mean_m(frame: &Frame, s: &Settings) -> f32 {
    let layers: Vec<glam::Mat4> = frame.cascades.iter().map(|p| p.clip_from_world()).collect();
    let choice = match s.shadow.cascades.cascade_selection {
        CascadeSelection::Projection => LayerChoice::Projection,
        CascadeSelection::Depth => LayerChoice::Splits(&frame.cascade_splits),
    };
    let image = aliasing::measure(&frame_input(frame, &layers, choice, frame.shadow_resolution));
    assert!(image.measured > frame.pixel_count() / 2, "m measured over {} pixels", image.measured);
    image.mean
}

/// Unrefined, as every setting here: these tests measure the maps' own aliasing and
/// flicker, which the default's rays would correct where the map is unsure.
fn pssm(fit: CascadeFit) -> Settings {
    let mut s = Settings::default();
    s.screen.refine = Refine::Off;
    s.image.width = 640;
    s.image.height = 360;
    s.shadow.partition = Partition::Cascades;
    s.shadow.map.resolution = 1024;
    s.shadow.cascades.count = 4;
    s.shadow.cascades.split = SplitScheme::Practical;
    s.shadow.cascades.split_lambda = 0.8;
    s.shadow.cascades.cascade_fit = fit;
    s
}

/// Issue 6: 4×1024² PSSM cascades reach a mean m at least 4× lower than one 2048² map
/// fitted to the whole scene. Measured on lavapipe at 640×360: 9.39 against 1.36 (6.9×)
/// with the tight fit; the stable fit spends texels on its slices' bounding spheres and
/// reaches 3.37 (2.8×), which is the price of its stability (see the next test).
#[test]
fn cascades_lower_the_aliasing_error_fourfold() {
    let scene = builtin::columns();
    let mut single = Settings::default();
    single.screen.refine = Refine::Off;
    single.image.width = 640;
    single.image.height = 360;
    single.shadow.map.resolution = 2048;
    single.shadow.map.fit = Fit::Scene;
    let m_single = mean_m(&render(&scene, &single), &single);
    let tight = pssm(CascadeFit::Tight);
    let m_tight = mean_m(&render(&scene, &tight), &tight);
    let stable = pssm(CascadeFit::Stable);
    let m_stable = mean_m(&render(&scene, &stable), &stable);
    eprintln!("mean m: one 2048² map {m_single:.3}, 4×1024² PSSM tight {m_tight:.3}, stable {m_stable:.3}");
    assert!(m_single >= 4.0 * m_tight, "{m_single} vs {m_tight}");
    // Stable cascades still beat the single map, if by less.
    assert!(m_stable < m_single / 2.0, "{m_single} vs {m_stable}");
}

/// Renders `s` along a truck of the camera and measures the flicker of `s`'s technique.
fn flicker_along_truck(scene: &Scene, traced: &TracedScene, s: &Settings, frames: u32) -> Flicker {
    let mut renderer = Renderer::new(gpu()).unwrap();
    let uploaded = renderer.upload(scene).unwrap();
    let start = s.resolve_camera(scene).unwrap();
    let light = s.resolve_light(scene).unwrap();
    let mut counter = FlickerCounter::default();
    let mut before: Option<PathFrame> = None;
    for k in 0..frames {
        let camera = camera_on_path(&start, CameraPathKind::Truck, 0.05, k as f32 / (frames - 1) as f32);
        let mut sk = s.clone();
        sk.camera = CameraSettings::pinned(&camera);
        let frame = renderer.render_uploaded(&uploaded, scene, &sk, &OutputRequest::default()).unwrap();
        let options =
            gnomon_reference::ReferenceOptions { width: frame.width, height: frame.height, samples: 1 };
        let reference = reference_visibility(traced, &frame.camera, &light, &options, &|_| {});
        let raster =
            RasterView { visibility: &frame.visibility, object_id: &frame.object_id, depth: &frame.depth };
        let after = PathFrame::new(
            &frame.camera,
            frame.width,
            frame.height,
            raster,
            frame.position.clone(),
            &reference,
        );
        if let Some(b) = &before {
            counter.add_pair(b, &after);
        }
        before = Some(after);
    }
    counter.result()
}

/// Issue 6: under a translating camera, stable cascades flicker at least 5× less than
/// tight ones. Measured on lavapipe (1280×720, 12 frames, `hard`): shimmer 0.039 %
/// for tight against 0.0014 % for stable (28×), whose layout does not change along
/// the path at all (its residual is the reprojection's: see `flicker.rs`).
#[test]
fn stable_cascades_shimmer_five_times_less_than_tight_ones() {
    let scene = builtin::columns();
    let traced = TracedScene::build(&scene);
    let mut results = Vec::new();
    for fit in [CascadeFit::Tight, CascadeFit::Stable] {
        let mut s = pssm(fit);
        s.image.width = 1280;
        s.image.height = 720;
        s.shadow.filter.technique = Technique::HARD;
        let f = flicker_along_truck(&scene, &traced, &s, 12);
        eprintln!("{fit:?}: {f:?}");
        assert!(f.reprojected > 100_000, "{f:?}");
        results.push(f.shimmer_rate);
    }
    let (tight, stable) = (results[0], results[1]);
    assert!(tight > 0.0, "tight cascades shimmer: {tight}");
    assert!(stable * 5.0 <= tight, "stable {stable} against tight {tight}");
}

fn single_map(warp: WarpKind) -> Settings {
    let mut s = Settings::default();
    s.screen.refine = Refine::Off;
    s.image.width = 640;
    s.image.height = 360;
    s.shadow.map.resolution = 2048;
    s.shadow.map.warp = warp;
    s.shadow.filter.technique = Technique::PCF2X2;
    s
}

/// PSM, LiSPSM and TSM put the texels of one 2048² map near the camera: on `columns`,
/// measured on lavapipe (640×360): mean m 9.27 unwarped, 0.66 PSM, 0.85 LiSPSM, 0.62
/// TSM; mismatch 0.184 %, 0.064 %, 0.046 %, 0.064 % (figures at 1280×720 in the README).
#[test]
fn warps_lower_the_aliasing_error_and_the_mismatch() {
    let scene = builtin::columns();
    let truth = common::reference(&scene, &single_map(WarpKind::None));
    let measure = |warp| {
        let s = single_map(warp);
        let frame = render(&scene, &s);
        let m = mean_m(&frame, &s);
        let mismatch = common::compare(&frame, &truth).mismatch_rate;
        eprintln!("{warp:?}: mean m {m:.3}, mismatch {:.3}%", 100.0 * mismatch);
        (m, mismatch)
    };
    let (m_plain, mismatch_plain) = measure(WarpKind::None);
    for warp in [WarpKind::Psm, WarpKind::Lispsm, WarpKind::Tsm] {
        let (m, mismatch) = measure(warp);
        assert!(m * 4.0 < m_plain, "{warp:?}: mean m {m} against {m_plain} unwarped");
        assert!(mismatch < 0.5 * mismatch_plain, "{warp:?}: mismatch {mismatch} against {mismatch_plain}");
    }
}

/// With the sun straight behind the camera the warps have no direction to work along
/// and fall back to the orthographic fit: the same layout, the same shadows.
#[test]
fn warps_fall_back_when_the_light_is_along_the_view() {
    let mut scene = builtin::columns();
    let forward = (scene.camera.target - scene.camera.eye).normalize();
    scene.light_mut::<DirectionalLight>().unwrap().direction = forward;
    let plain = render(&scene, &single_map(WarpKind::None));
    for warp in [WarpKind::Psm, WarpKind::Lispsm, WarpKind::Tsm] {
        let frame = render(&scene, &single_map(warp));
        assert_eq!(frame.light_projection, plain.light_projection, "{warp:?}");
        let differing = (0..frame.pixel_count())
            .filter(|&i| frame.object_id[i] != 0 && (frame.visibility[i] - plain.visibility[i]).abs() > 1e-4)
            .count();
        assert_eq!(differing, 0, "{warp:?}");
    }
    // Ten degrees off the view direction LiSPSM and TSM engage, and still agree with
    // the reference. PSM's centre of projection sits just beyond the receivers there,
    // so it falls back (see `warping::psm`).
    scene.light_mut::<DirectionalLight>().unwrap().direction =
        (forward + Vec3::new(0.0, -0.18, 0.0)).normalize();
    let truth = common::reference(&scene, &single_map(WarpKind::None));
    for warp in [WarpKind::Psm, WarpKind::Lispsm, WarpKind::Tsm] {
        let frame = render(&scene, &single_map(warp));
        let warped = matches!(frame.light_projection.kind, ProjectionKind::Warped { .. });
        assert_eq!(warped, warp != WarpKind::Psm, "{warp:?}");
        let m = common::compare(&frame, &truth);
        eprintln!("{warp:?}, sun near the view direction: mismatch {:.3}%", 100.0 * m.mismatch_rate);
        assert!(m.mismatch_rate < 0.005, "{warp:?}: {m:?}");
    }
}

/// PSM's three cases, each checked against the reference on `columns`: the sun ahead of
/// the camera (out of view) is a point light in post-perspective space, the sun behind
/// an inverted one, and the sun square to the view direction a parallel light there.
/// In each the warp engages, and the map is both finer and more accurate than the
/// orthographic one.
#[test]
fn psm_agrees_with_the_reference_ahead_behind_and_beside() {
    let mut scene = builtin::columns();
    let forward = (scene.camera.target - scene.camera.eye).normalize();
    let side = forward.cross(Vec3::Y).normalize();
    let up = side.cross(forward);
    for (case, toward_sun) in [
        ("ahead", Vec3::new(0.3, 1.0, -0.6)),
        ("behind", Vec3::new(-0.4, 1.0, 0.8)),
        ("beside", side + 0.8 * up),
    ] {
        scene.light_mut::<DirectionalLight>().unwrap().direction = -toward_sun.normalize();
        let truth = common::reference(&scene, &single_map(WarpKind::None));
        let mut rates = Vec::new();
        for warp in [WarpKind::None, WarpKind::Psm] {
            let frame = render(&scene, &single_map(warp));
            let warped = matches!(frame.light_projection.kind, ProjectionKind::Warped { .. });
            assert_eq!(warped, warp == WarpKind::Psm, "{case}: {warp:?}");
            let s = single_map(warp);
            rates.push((common::compare(&frame, &truth).mismatch_rate, mean_m(&frame, &s)));
        }
        let [(plain, m_plain), (psm, m_psm)] = rates[..] else { unreachable!() };
        eprintln!(
            "sun {case}: mismatch {:.3}% unwarped, {:.3}% PSM; mean m {m_plain:.2}, {m_psm:.2}",
            100.0 * plain,
            100.0 * psm
        );
        // Measured on lavapipe: mismatch 0.200 → 0.089 %, 0.124 → 0.032 %, 0.366 →
        // 0.136 %; mean m 7.97 → 2.35, 7.21 → 0.60, 10.54 → 1.47.
        assert!(psm < 0.6 * plain, "sun {case}: mismatch {psm} with PSM against {plain}");
        assert!(3.0 * m_psm < m_plain, "sun {case}: mean m {m_psm} with PSM against {m_plain}");
    }
}

/// SDSM: the cascades split exactly the view depths the camera sees, reduced on the GPU
/// from its depth, and put their texels there. Looking steeply down at the ground
/// between the columns, from inside the scene's bounds, the view frustum meets the
/// bounds from the near plane on, so the bounds-based split wastes its first cascades
/// on empty air above the ground.
#[test]
fn sdsm_splits_the_depths_the_camera_sees() {
    let mut scene = builtin::columns();
    scene.camera.eye = Vec3::new(0.0, 5.0, 4.0);
    scene.camera.target = Vec3::new(0.0, 0.0, 1.0);
    let plain_settings = pssm(CascadeFit::Tight);
    let mut sdsm_settings = plain_settings.clone();
    sdsm_settings.shadow.cascades.sdsm = true;
    let plain = render(&scene, &plain_settings);
    let sdsm = render(&scene, &sdsm_settings);
    let seen = sdsm.depth.iter().copied().filter(|d| d.is_finite());
    let (lo, hi) = seen.fold((f32::INFINITY, 0.0f32), |(lo, hi), d| (lo.min(d), hi.max(d)));
    let splits = &sdsm.cascade_splits;
    let (first, last) = (splits[0], splits[splits.len() - 1]);
    eprintln!("seen {lo:.3}..{hi:.3}; SDSM splits {splits:?}; bounds-based {:?}", plain.cascade_splits);
    // Pixel centres and the prepass see the same surfaces: the reduced range is the
    // seen one, to the depth buffer's precision.
    assert!(
        (first - lo).abs() <= 0.01 * lo && (last - hi).abs() <= 0.01 * hi,
        "{first}..{last} vs {lo}..{hi}"
    );
    let ratio = |s: &[f32]| s[s.len() - 1] / s[0];
    assert!(
        ratio(&plain.cascade_splits) > 10.0 * ratio(splits),
        "the bounds-based range spans a ratio {}, the seen one {}",
        ratio(&plain.cascade_splits),
        ratio(splits)
    );
    let (m_plain, m_sdsm) = (mean_m(&plain, &plain_settings), mean_m(&sdsm, &sdsm_settings));
    let truth = common::reference(&scene, &plain_settings);
    let (e_plain, e_sdsm) =
        (common::compare(&plain, &truth).mismatch_rate, common::compare(&sdsm, &truth).mismatch_rate);
    eprintln!("mean m {m_plain:.3} → {m_sdsm:.3}; mismatch {:.3}% → {:.3}%", 100.0 * e_plain, 100.0 * e_sdsm);
    // Measured: m 0.817 → 0.563, mismatch 0.027 % → 0.021 %: both maps already have more
    // texels than pixels here (m < 1), so the finer one barely lowers the mismatch;
    // what is checked is that it stays as small.
    assert!(m_sdsm < 0.8 * m_plain, "{m_sdsm} vs {m_plain}");
    assert!(e_sdsm < 0.001, "{e_sdsm} vs {e_plain}");
}

/// SDSM's light-space bounds (`--sdsm-bounds`): each tight cascade narrows to the
/// samples it serves, every sample stays inside its cascades (its own and, in the
/// blend band, the next), and the texels saved go to those samples. Looking steeply
/// down at the ground, each depth slice of the frustum is a slab that the ground
/// crosses in a strip: the slab is what the tight fit covers, the strip what the
/// bounds cover.
#[test]
fn sdsm_bounds_fit_each_cascade_to_its_samples() {
    let mut scene = builtin::columns();
    scene.camera.eye = Vec3::new(0.0, 5.0, 4.0);
    scene.camera.target = Vec3::new(0.0, 0.0, 1.0);
    let mut depth_only = pssm(CascadeFit::Tight);
    depth_only.shadow.cascades.sdsm = true;
    let mut bounded = depth_only.clone();
    bounded.shadow.cascades.sdsm_bounds = true;
    let (a, b) = (render(&scene, &depth_only), render(&scene, &bounded));
    assert_eq!(a.cascade_splits, b.cascade_splits, "the same splits");
    let area = |f: &Frame| -> f32 {
        f.cascades
            .iter()
            .map(|p| p.orthographic_window().map(|(l, r, b, t)| (r - l) * (t - b)).unwrap())
            .sum()
    };
    let (area_a, area_b) = (area(&a), area(&b));
    // Every sample inside each cascade that serves it, with at least one texel to spare.
    let splits = &b.cascade_splits;
    let blend = bounded.shadow.cascades.cascade_blend;
    let spare = 1.0 - 2.0 / b.shadow_resolution as f32;
    let mut checked = 0;
    for (p, &d) in b.position.iter().zip(&b.depth).filter(|(_, d)| d.is_finite()) {
        for i in 0..b.cascades.len() {
            let start = if i == 0 { splits[0] } else { splits[i] - blend * (splits[i] - splits[i - 1]) };
            if d < start || d > splits[i + 1] {
                continue;
            }
            let ndc = b.cascades[i].clip_from_world().project_point3(*p);
            assert!(ndc.x.abs() <= spare && ndc.y.abs() <= spare, "depth {d} in cascade {i} at {ndc}");
            checked += 1;
        }
    }
    let (m_a, m_b) = (mean_m(&a, &depth_only), mean_m(&b, &bounded));
    let truth = common::reference(&scene, &depth_only);
    let (e_a, e_b) = (common::compare(&a, &truth).mismatch_rate, common::compare(&b, &truth).mismatch_rate);
    eprintln!(
        "window area {area_a:.1} → {area_b:.1}; mean m {m_a:.3} → {m_b:.3}; mismatch {:.3}% → {:.3}%; {checked} samples inside",
        100.0 * e_a,
        100.0 * e_b
    );
    assert!(checked > b.pixel_count() / 2, "{checked} samples checked");
    // Measured on lavapipe: area 418 → 304, mean m 0.563 → 0.463, mismatch below 0.05 %.
    assert!(area_b < 0.8 * area_a, "windows {area_b} against {area_a}");
    assert!(m_b < 0.9 * m_a, "mean m {m_b} against {m_a}");
    assert!(e_b < 0.001, "mismatch {e_b} (without bounds {e_a})");
}

/// Depth clamping ("pancaking", issue 6's fitting): with `--fit receivers` the map's
/// near plane moves up to the nearest receiver, and a caster before it, clamped onto
/// that plane, still casts its shadow. Here a box floats 7 units above a ground that
/// the camera sees from 1.5 units up, out to 12 units: every receiver is far below the
/// box, which lies wholly before the near plane (without clamping it would be clipped
/// away, and its shadow with it).
#[test]
fn pancaking_keeps_every_shadow_in_a_shorter_depth_range() {
    let mut scene = builtin::spheres();
    scene.meshes = vec![geometry::plane(60.0, 60.0), geometry::cuboid(Vec3::splat(1.0))];
    let instance = |name: &str, mesh, at: Vec3| Instance {
        name: name.into(),
        mesh,
        material: 0,
        world_from_object: glam::Mat4::from_translation(at),
        casts_shadow: true,
        motion: gnomon_scene::Motion::Static,
    };
    scene.instances = vec![instance("ground", 0, Vec3::ZERO), instance("box", 1, Vec3::new(0.0, 8.0, 0.0))];
    scene.light_mut::<DirectionalLight>().unwrap().direction = Vec3::new(0.3, -1.0, 0.2).normalize();
    scene.camera.eye = Vec3::new(2.4, 1.5, 6.0);
    scene.camera.target = Vec3::new(2.4, 0.0, 1.6);
    scene.camera.far = 12.0;
    let mut clamped_settings = single_map(WarpKind::None);
    clamped_settings.shadow.map.fit = Fit::Receivers;
    let mut full_settings = clamped_settings.clone();
    full_settings.shadow.map.depth_clamp = false;
    let clamped = render(&scene, &clamped_settings);
    let full = render(&scene, &full_settings);
    if !clamped.shadow_depth_clamp {
        common::figures::skipped(
            "pancaking_keeps_every_shadow_in_a_shorter_depth_range",
            "this device cannot draw with unclipped depth (DEPTH_CLIP_CONTROL)",
        );
        return;
    }
    assert!(!full.shadow_depth_clamp);
    // The whole box is nearer the sun than the clamped map's near plane.
    let light_depth = |p: Vec3| -clamped.light_projection.light_from_world.transform_point3(p).z;
    let box_far = [Vec3::new(0.0, 7.0, 0.0), Vec3::new(1.0, 7.0, 1.0), Vec3::new(-1.0, 7.0, -1.0)]
        .map(light_depth)
        .into_iter()
        .fold(f32::NEG_INFINITY, f32::max);
    assert!(
        box_far < clamped.light_projection.near,
        "box to {box_far}, near plane {}",
        clamped.light_projection.near
    );
    let range = |f: &Frame| f.light_projection.far - f.light_projection.near;
    let truth = common::reference(&scene, &clamped_settings);
    let (e_clamped, e_full) =
        (common::compare(&clamped, &truth).mismatch_rate, common::compare(&full, &truth).mismatch_rate);
    let shadowed = truth.visibility.iter().filter(|&&v| v < 0.5).count();
    eprintln!(
        "depth range {:.2} → {:.2}; mismatch {:.3}% → {:.3}%; {shadowed} shadowed pixels",
        range(&full),
        range(&clamped),
        100.0 * e_full,
        100.0 * e_clamped
    );
    assert!(shadowed > clamped.pixel_count() / 20, "the box's shadow is in view: {shadowed}");
    assert!(range(&clamped) < 0.7 * range(&full), "{} against {}", range(&clamped), range(&full));
    assert!(e_clamped <= e_full + 2e-4, "mismatch {e_clamped} clamped against {e_full}");
    assert!(e_clamped < 0.005, "the box's shadow is kept: mismatch {e_clamped}");
}

/// A virtual map reports its levels (`Frame::virtual_levels`) as layers, each pixel
/// reading the one its footprint picks. A level's texels are the coarsest no
/// larger than the footprint along the camera's axis at the pixel's view depth, so
/// they span between half a pixel and one there; off the axis, a pixel at the same
/// view depth is nearer along its ray and narrower by up to cos θ at the image's
/// corner (θ half its diagonal field of view), so m lies within [cos θ / 2, 1 / cos θ],
/// and on average between a half and one. A level off by one doubles or halves m.
#[test]
fn a_virtual_maps_levels_give_texels_between_half_a_pixel_and_one() {
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (320, 180);
    s.shadow.partition = Partition::Virtual;
    s.screen.refine = Refine::Off;
    assert_levels_span_half_a_pixel_to_one(
        &render(&builtin::columns(), &s),
        "columns under a sun",
        LowerBound::Flat,
    );
}

/// A spot's virtual map: its levels' texels grow with the distance from the spot, and
/// a pixel reads the coarsest level whose texels at its own distance are no larger
/// than its footprint, so its texels span between half a pixel and one, as a sun's
/// levels' do (above). A level off by one halves or doubles m. (A pixel whose
/// footprint is wider than the coarsest level's texels, 256 across the frustum, would
/// read finer texels than it needs, m below a half; none is here.)
#[test]
fn a_spots_virtual_levels_give_texels_between_half_a_pixel_and_one() {
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (320, 180);
    s.light.kind = gnomon_scene::settings::LightKind::Spot;
    s.shadow.partition = Partition::Virtual;
    s.screen.refine = Refine::Off;
    assert_levels_span_half_a_pixel_to_one(
        &render(&builtin::spheres(), &s),
        "spheres under a spot",
        LowerBound::Flat,
    );
}

/// The same under a point light: each pixel at its level of its cube face's chain
/// (`LayerChoice::Clipmap` picks the face's layer of the level).
#[test]
fn a_point_lights_virtual_levels_give_texels_between_half_a_pixel_and_one() {
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (320, 180);
    s.light.kind = gnomon_scene::settings::LightKind::Point;
    s.shadow.partition = Partition::Virtual;
    s.screen.refine = Refine::Off;
    assert_levels_span_half_a_pixel_to_one(
        &render(&builtin::spheres(), &s),
        "spheres under a point light",
        LowerBound::OffAxis,
    );
}

/// How far below a half [`assert_levels_span_half_a_pixel_to_one`] lets m go.
#[derive(Clone, Copy, PartialEq)]
enum LowerBound {
    /// cos θ / 2 at every pixel: the sun's and the spot's tests, as they always were.
    Flat,
    /// cos θ cos φ / 2, φ the angle between the light's ray to the pixel and its map's
    /// axis (a cube face's texel is as wide as the footprint the level matches in the
    /// face's plane, cos φ as wide across the ray: 1/√3 at the cube's corners), and no
    /// lower bound for a pixel whose footprint is wider than two of the coarsest
    /// level's texels (a face's chain stops at 2 × 2 pages; such a pixel reads finer
    /// texels than it needs). Widened for the point light after it failed the flat
    /// bound (4,914 pixels below it, then 2,135 with cos φ alone: all past the chain).
    OffAxis,
}

/// Lloyd's m over `frame` (a virtual map), each pixel at the level its footprint
/// picks, lies within [`lower` bound, 1 / cos θ] at every pixel (θ half the image's
/// diagonal field of view), and between a half and one on average.
fn assert_levels_span_half_a_pixel_to_one(frame: &Frame, view: &str, lower: LowerBound) {
    let levels = frame.virtual_levels.as_ref().expect("a virtual map reports its levels");
    let clipmap = &levels.clipmap;
    let layers: Vec<glam::Mat4> = levels.projections.iter().map(|p| p.clip_from_world()).collect();
    let choice = LayerChoice::Clipmap { clipmap, footprint_per_depth: levels.footprint_per_depth };
    let image = aliasing::measure(&frame_input(frame, &layers, choice, levels.resolution));
    let aspect = frame.width as f32 / frame.height as f32;
    let tan_diagonal = (0.5 * frame.camera.fov_y_degrees.to_radians()).tan() * (aspect * aspect + 1.0).sqrt();
    let cos = 1.0 / (1.0 + tan_diagonal * tan_diagonal).sqrt();
    let off_axis = |world: glam::Vec3| match (lower, clipmap.tan_half_fov()) {
        (LowerBound::Flat, _) | (LowerBound::OffAxis, None) => 1.0,
        (LowerBound::OffAxis, Some(_)) => {
            let view = clipmap.frame(world).view_from_world.transform_point3(world);
            -view.z / view.length()
        }
    };
    let coarsest = clipmap.texel_size(clipmap.shape.levels - 1);
    let past_the_chain = |world: glam::Vec3, depth: f32| {
        lower == LowerBound::OffAxis
            && clipmap.map_footprint(world, depth * levels.footprint_per_depth) >= 2.0 * coarsest
    };
    let (mut defined, mut outside, mut clamped) = (0, 0, 0);
    for ((&m, &world), &depth) in image.m.iter().zip(&frame.position).zip(&frame.depth) {
        if !m.is_finite() {
            continue;
        }
        defined += 1;
        let low = if past_the_chain(world, depth) {
            clamped += 1;
            0.0
        } else {
            0.5 * cos * off_axis(world)
        };
        outside += usize::from(!(low..=1.0 / cos).contains(&m));
    }
    assert!(defined > 20_000, "{view}: {defined} pixels measured");
    eprintln!(
        "figure: {view}, virtual map: m mean {:.3}, max {:.3}, {outside} of {defined} pixels outside [{:.3}{}, {:.3}] ({clamped} past the coarsest level)",
        image.mean,
        image.max,
        0.5 * cos,
        if lower == LowerBound::OffAxis { " cos φ" } else { "" },
        1.0 / cos
    );
    assert_eq!(
        outside,
        0,
        "{view}: m from {} (times cos φ where off axis) to {}: mean {}, max {}",
        0.5 * cos,
        1.0 / cos,
        image.mean,
        image.max
    );
    assert!(image.mean > 0.5 && image.mean <= 1.0, "{view}: mean m {}", image.mean);
}
