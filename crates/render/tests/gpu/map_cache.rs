//! Kept shadow maps (`--map-cache still-casters`, `frame/map_cache.rs`): a layer
//! keeps what its still casters drew, and is drawn again only when they or its
//! projection change; casters that move are drawn over it every frame. Every map is
//! compared, texel for texel, with the one drawn from scratch (`--map-cache off`)
//! for the same scene as it then stands.

use crate::support;

use glam::{Mat4, Vec3};
use gnomon_render::{Frame, GpuScene, LayerCache, OutputRequest, Renderer};
use gnomon_scene::{
    Motion, Scene, Settings, builtin,
    settings::{LightKind, MapCache, Partition, Technique},
};

fn settings(light: LightKind, partition: Partition) -> Settings {
    let mut s = support::settings(320, 180, 512);
    s.light.kind = light;
    s.shadow.partition = partition;
    s
}

fn with_map(renderer: &mut Renderer, uploaded: &GpuScene, scene: &Scene, s: &Settings) -> Frame {
    let request = OutputRequest { shadow_map: true, ..Default::default() };
    renderer.render_uploaded(uploaded, scene, s, &request).expect("render")
}

/// The frame of `scene` as it stands, its map drawn from scratch by a renderer of
/// its own.
fn scratch_frame(scene: &Scene, s: &Settings) -> Frame {
    let mut s = s.clone();
    s.shadow.map.cache = MapCache::Off;
    let mut renderer = Renderer::new(support::gpu()).unwrap();
    let uploaded = renderer.upload(scene).unwrap();
    with_map(&mut renderer, &uploaded, scene, &s)
}

/// The map of `scene` as it stands, drawn from scratch.
fn from_scratch(scene: &Scene, s: &Settings) -> Vec<f32> {
    scratch_frame(scene, s).shadow_map.unwrap().depth
}

/// How many texels of `frame`'s map differ from the map drawn from scratch.
fn differing(frame: &Frame, scene: &Scene, s: &Settings) -> usize {
    let kept = &frame.shadow_map.as_ref().expect("a map").depth;
    let scratch = from_scratch(scene, s);
    assert_eq!(kept.len(), scratch.len());
    kept.iter().zip(&scratch).filter(|(a, b)| a.to_bits() != b.to_bits()).count()
}

/// The index of the instance named `name`.
fn named(scene: &Scene, name: &str) -> usize {
    scene.instances.iter().position(|i| i.name == name).unwrap_or_else(|| panic!("no instance `{name}`"))
}

#[test]
fn a_moving_caster_is_drawn_over_the_kept_map_and_a_moved_still_one_redraws_it() {
    let cases = [
        ("sun", settings(LightKind::Sun, Partition::Single)),
        ("sun cascades", settings(LightKind::Sun, Partition::Cascades)),
        ("spot", settings(LightKind::Spot, Partition::Single)),
        ("point cube", settings(LightKind::Point, Partition::Single)),
    ];
    for (name, s) in cases {
        let mut scene = builtin::spheres();
        let ball = named(&scene, "sphere 1,1");
        let crate_box = named(&scene, "box");
        scene.instances[ball].motion = Motion::Dynamic;
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let mut uploaded = renderer.upload(&scene).unwrap();
        let layers = |f: &Frame| f.lights[0].layer_cache.clone();

        let first = with_map(&mut renderer, &uploaded, &scene, &s);
        let count = first.lights[0].layer_draws.len();
        assert_eq!(layers(&first), vec![LayerCache::Drawn; count], "{name}: the first frame draws");
        assert_eq!(differing(&first, &scene, &s), 0, "{name}: first frame");

        // The ball moves: the still casters are kept, the ball drawn over them.
        scene.instances[ball].world_from_object *= Mat4::from_translation(Vec3::new(0.7, 0.3, -0.4));
        renderer.move_instances(&mut uploaded, &scene, &[ball]).unwrap();
        let moved = with_map(&mut renderer, &uploaded, &scene, &s);
        assert_eq!(layers(&moved), vec![LayerCache::Kept; count], "{name}: a moving caster keeps the map");
        let drawn = moved.stats.shadow_instances;
        assert!((1..=count as u32).contains(&drawn), "{name}: only the ball is drawn: {:?}", moved.stats);
        assert_eq!(differing(&moved, &scene, &s), 0, "{name}: after the ball moved");

        // The box, a still caster, moves: every layer that can see it is drawn again.
        scene.instances[crate_box].world_from_object *= Mat4::from_translation(Vec3::new(1.0, 0.0, 1.0));
        renderer.move_instances(&mut uploaded, &scene, &[crate_box]).unwrap();
        let redrawn = with_map(&mut renderer, &uploaded, &scene, &s);
        assert_eq!(layers(&redrawn), vec![LayerCache::Drawn; count], "{name}: a moved still caster redraws");
        assert_eq!(differing(&redrawn, &scene, &s), 0, "{name}: after the box moved");
    }
}

#[test]
fn a_still_scene_under_a_still_light_draws_no_shadow_pass() {
    let scene = builtin::spheres();
    let s = settings(LightKind::Sun, Partition::Cascades);
    let mut renderer = Renderer::new(support::gpu()).unwrap();
    let uploaded = renderer.upload(&scene).unwrap();
    let first = with_map(&mut renderer, &uploaded, &scene, &s);
    assert!(first.stats.shadow_draws > 0);
    let again = with_map(&mut renderer, &uploaded, &scene, &s);
    assert_eq!(again.lights[0].layer_cache, vec![LayerCache::Kept; 4]);
    assert_eq!(again.stats.shadow_draws, 0, "{:?}", again.stats);
    assert_eq!(differing(&again, &scene, &s), 0);

    // The light turns: its layers are drawn again, and match.
    let mut turned = s.clone();
    turned.light.sun_azimuth = Some(80.0);
    let after = with_map(&mut renderer, &uploaded, &scene, &turned);
    assert_eq!(after.lights[0].layer_cache, vec![LayerCache::Drawn; 4]);
    assert_eq!(differing(&after, &scene, &turned), 0);

    // A changed bias changes what the still casters drew.
    let mut biased = turned.clone();
    biased.shadow.bias.slope_bias = 3.0;
    let rebiased = with_map(&mut renderer, &uploaded, &scene, &biased);
    assert_eq!(rebiased.lights[0].layer_cache, vec![LayerCache::Drawn; 4]);
    assert_eq!(differing(&rebiased, &scene, &biased), 0);

    // Off: every layer draws every frame.
    let mut off = biased.clone();
    off.shadow.map.cache = MapCache::Off;
    let uncached = with_map(&mut renderer, &uploaded, &scene, &off);
    assert_eq!(uncached.lights[0].layer_cache, vec![LayerCache::Off; 4]);
    assert!(uncached.stats.shadow_draws > 0);
}

/// A stable cascade's window snaps to whole texels as the camera moves: its kept
/// layer is scrolled, and only the strips it newly covers are drawn. A texel centre
/// of the moved window is the same world point, computed from another translation,
/// so the scrolled map is the map drawn from scratch but for that rounding: the
/// depth interpolated at a texel differs in its last bits, and a texel whose centre
/// lies on a caster's silhouette edge may fall on the other side of it. Each texel
/// keeps the rounding of the frame that drew it, never compounded (a scroll copies
/// depths exactly). Measured over five moves: depths within 3.7e-5 of the range
/// elsewhere, 3 silhouette texels of 4M, and no pixel whose shadow differs.
#[test]
fn a_cascade_that_moves_by_whole_texels_scrolls_its_kept_map() {
    let scene = builtin::columns();
    let mut s = settings(LightKind::Sun, Partition::Cascades);
    s.shadow.map.resolution = 1024;
    let start = s.resolve_camera(&scene).unwrap();
    let mut renderer = Renderer::new(support::gpu()).unwrap();
    let uploaded = renderer.upload(&scene).unwrap();
    let mut scrolled = 0;
    for frame in 0..6 {
        let camera = gnomon_scene::camera_path::camera_on_path(
            &start,
            gnomon_scene::camera_path::CameraPathKind::Truck,
            0.05,
            frame as f32 / 5.0,
        );
        s.camera.eye = Some(camera.eye);
        s.camera.target = Some(camera.target);
        let drawn = with_map(&mut renderer, &uploaded, &scene, &s);
        let uses = &drawn.lights[0].layer_cache;
        scrolled += uses.iter().filter(|&&u| u == LayerCache::Scrolled).count();
        let scratch = scratch_frame(&scene, &s);
        let (kept, fresh) = (&drawn.shadow_map.as_ref().unwrap().depth, &scratch.shadow_map.unwrap().depth);
        let errors: Vec<f32> = kept.iter().zip(fresh).map(|(a, b)| (a - b).abs()).collect();
        // Off by more than 1e-3: a texel on a silhouette edge, covered in one map only.
        let edge = errors.iter().filter(|&&e| e > 1e-3).count();
        let worst = errors.iter().copied().filter(|&e| e <= 1e-3).fold(0.0f32, f32::max);
        let above = errors.iter().filter(|&&e| e > 1e-6).count() as f64 / errors.len() as f64;
        let flipped = drawn
            .visibility
            .iter()
            .zip(&scratch.visibility)
            .filter(|(a, b)| (**a >= 0.5) != (**b >= 0.5))
            .count();
        support::figures::figure(
            &format!("kept map, columns, truck frame {frame}"),
            format!(
                "{uses:?}: {edge} silhouette texels differ; other depths within {worst:.1e}, above 1e-6 at {}; \
                 {flipped} pixels' shadow differs",
                support::figures::percent(above)
            ),
            "40 texels; 1e-4; 0.01% of pixels",
        );
        assert!(edge <= 40, "frame {frame}: {edge} texels off by over 1e-3 (bound 1e-5 of the texels)");
        assert!(worst <= 1e-4, "frame {frame}: a depth {worst} off");
        let pixels = drawn.visibility.len();
        assert!(flipped * 10_000 <= pixels, "frame {frame}: {flipped} of {pixels} pixels' shadow differs");
    }
    assert!(scrolled >= 4, "only {scrolled} layers scrolled over 5 moves");
}

/// A filterable technique's moment map is kept with its depth map: a frame whose
/// depth map is kept whole filters nothing, and shades as a frame drawn from scratch;
/// depths drawn again, or a moving caster drawn over a copy of them, are filtered
/// again.
#[test]
fn a_kept_depth_map_keeps_its_moment_map() {
    for technique in [Technique::VSM, Technique::MSM_HAMBURGER] {
        let mut scene = builtin::spheres();
        let mut s = settings(LightKind::Sun, Partition::Cascades);
        s.shadow.filter.technique = technique.clone();
        let filtered = |f: &Frame| f.lights[0].filter_ms.is_some();
        let same_shading = |f: &Frame, scene: &Scene| {
            let scratch = scratch_frame(scene, &s);
            let worst = f
                .visibility
                .iter()
                .zip(&scratch.visibility)
                .filter(|(a, b)| a.is_finite() && b.is_finite())
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f32, f32::max);
            assert_eq!(worst, 0.0, "{technique:?}: the visibility differs from scratch by {worst}");
        };
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let mut uploaded = renderer.upload(&scene).unwrap();
        let first = with_map(&mut renderer, &uploaded, &scene, &s);
        if first.timings.is_none() {
            support::figures::skipped("kept moment maps", "the frame has no pass times to tell a filter by");
            return;
        }
        assert!(filtered(&first), "{technique:?}: the first frame filters");

        // Still: the depths are kept whole, and their moments with them.
        let again = with_map(&mut renderer, &uploaded, &scene, &s);
        assert_eq!(again.lights[0].layer_cache, vec![LayerCache::Kept; 4]);
        assert!(!filtered(&again), "{technique:?}: a kept map filters nothing");
        same_shading(&again, &scene);
        let created = renderer.creations();
        let third = with_map(&mut renderer, &uploaded, &scene, &s);
        assert_eq!(renderer.creations(), created, "{technique:?}: steady frames create nothing");
        assert!(!filtered(&third));

        // A still caster moves: the depths are drawn again, and so are their moments.
        let crate_box = named(&scene, "box");
        scene.instances[crate_box].world_from_object *= Mat4::from_translation(Vec3::new(1.0, 0.0, 1.0));
        renderer.move_instances(&mut uploaded, &scene, &[crate_box]).unwrap();
        let redrawn = with_map(&mut renderer, &uploaded, &scene, &s);
        assert_eq!(redrawn.lights[0].layer_cache, vec![LayerCache::Drawn; 4]);
        assert!(filtered(&redrawn), "{technique:?}: depths drawn again are filtered");
        same_shading(&redrawn, &scene);

        // A moving caster is drawn over a copy of the kept depths every frame: the
        // moments are filtered from that copy every frame.
        let ball = named(&scene, "sphere 1,1");
        scene.instances[ball].motion = Motion::Dynamic;
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let uploaded = renderer.upload(&scene).unwrap();
        for frame in 0..2 {
            let over = with_map(&mut renderer, &uploaded, &scene, &s);
            assert!(filtered(&over), "{technique:?}, frame {frame}: depths drawn over are filtered");
            same_shading(&over, &scene);
        }
    }
}
