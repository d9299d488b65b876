//! Scene submission: identical meshes become instanced draws, and thousands of
//! distinct meshes cost draw calls but no extra state changes.

use std::time::Instant;

use glam::{Mat4, Vec3, Vec4};
use gnomon_render::{
    OutputRequest, Renderer,
    timing::{ClockChoice, PassKind, PassTime, TimingSource},
};
use gnomon_scene::{
    Instance, Settings, builtin, geometry,
    settings::{LightKind, Lighting, Partition},
};

fn small() -> Settings {
    let mut s = Settings::default();
    s.image.width = 160;
    s.image.height = 90;
    s.shadow.map.resolution = 512;
    s
}

#[test]
fn identical_columns_are_one_instanced_draw() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::columns();
    assert_eq!(scene.instances.len(), 97, "a ground and 96 columns");
    let frame = renderer.render(&scene, &small(), &OutputRequest::default()).unwrap();
    // The ground, and one instanced draw for all 96 columns, in each pass.
    assert_eq!((frame.stats.shadow_draws, frame.stats.lighting_draws), (2, 2), "{:?}", frame.stats);
}

/// Whether any of a mesh's world bounding box may be in view: false only when all
/// eight corners lie beyond one and the same clip-space plane (x < −w, x > w, y < −w,
/// y > w, z < 0, z > w). The conservative box test a culler must agree with, written
/// here from the clip-space definition rather than from frustum planes.
fn reaches_into_view(clip_from_world: Mat4, mesh: &gnomon_scene::Mesh, world_from_object: Mat4) -> bool {
    let (lo, hi) = mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
        let w = world_from_object.transform_point3(p);
        (lo.min(w), hi.max(w))
    });
    let corners: Vec<Vec4> = (0..8)
        .map(|k| {
            let pick = |bit: u32, a: f32, b: f32| if k & bit == 0 { a } else { b };
            clip_from_world * Vec4::new(pick(1, lo.x, hi.x), pick(2, lo.y, hi.y), pick(4, lo.z, hi.z), 1.0)
        })
        .collect();
    let beyond: [fn(&Vec4) -> bool; 6] =
        [|c| c.x < -c.w, |c| c.x > c.w, |c| c.y < -c.w, |c| c.y > c.w, |c| c.z < 0.0, |c| c.z > c.w];
    !beyond.iter().any(|outside| corners.iter().all(outside))
}

#[test]
fn thousands_of_distinct_meshes_add_no_state_changes() {
    let gpu = crate::support::gpu();
    let stats_for = |count: usize| {
        let mut scene = builtin::contact();
        scene.instances.truncate(1);
        for k in 0..count {
            // Each block its own mesh, as in a city model.
            let h = 0.2 + (k % 7) as f32 * 0.1;
            scene.meshes.push(geometry::cuboid(Vec3::new(0.05, h, 0.05)));
            let (x, z) = ((k % 50) as f32 * 0.3 - 7.5, (k / 50) as f32 * 0.3 - 6.0);
            scene.instances.push(Instance {
                name: format!("block {k}"),
                mesh: scene.meshes.len() - 1,
                material: 1 + k % 3,
                world_from_object: Mat4::from_translation(Vec3::new(x, h, z)),
                casts_shadow: true,
                motion: gnomon_scene::Motion::Static,
            });
        }
        let mut renderer = Renderer::new(gpu).unwrap();
        let stats = renderer.render(&scene, &small(), &OutputRequest::default()).unwrap().stats;
        // The instances whose bounds reach into the camera's view, counted here by
        // brute force in clip space, independently of the renderer's culling.
        let camera = small().resolve_camera(&scene).unwrap();
        let clip_from_world = camera.clip_from_world(160.0 / 90.0);
        let seen = scene
            .instances
            .iter()
            .filter(|i| reaches_into_view(clip_from_world, &scene.meshes[i.mesh], i.world_from_object))
            .count() as u32;
        (stats, seen)
    };
    let (few, _) = stats_for(10);
    let (many, seen) = stats_for(2000);
    assert!(seen > 1900, "the camera sees nearly all of them: {seen}");
    assert_eq!(
        (many.lighting_draws, many.lighting_instances),
        (seen, seen),
        "one draw per distinct mesh the camera sees: {many:?}"
    );
    assert_eq!(
        (many.pipeline_changes, many.bind_group_changes),
        (few.pipeline_changes, few.bind_group_changes),
        "state changes do not grow with the mesh count: {few:?} vs {many:?}"
    );
}

#[test]
fn timing_alone_submits_the_same_frame_as_a_full_render() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::spheres();
    let uploaded = renderer.upload(&scene).unwrap();
    // Both frames draw their maps: the second would keep the first's otherwise.
    let mut settings = small();
    settings.shadow.map.cache = gnomon_scene::settings::MapCache::Off;
    let frame = renderer.render_uploaded(&uploaded, &scene, &settings, &OutputRequest::default()).unwrap();
    let started = Instant::now();
    let cost = renderer.time_passes(&uploaded, &scene, &settings, ClockChoice::Auto).unwrap();
    let wall_ms = started.elapsed().as_secs_f64() * 1e3;
    assert_eq!(cost.stats, frame.stats);
    let t = cost.timings.expect("timing always times, on the CPU clock at worst");
    let expected = if gpu.timestamp_period_ns.is_some() {
        TimingSource::GpuTimestamps
    } else {
        TimingSource::CpuWallClock
    };
    assert_eq!(t.source, expected);
    assert!(t.shadow_ms > 0.0 && t.lighting_ms > 0.0, "{t:?}");
    // Against the test's own clock: the call waits for the GPU, so the GPU's frame
    // and the CPU's submission both fit inside it.
    assert!(
        t.frame_ms <= wall_ms && cost.cpu.submit_ms <= wall_ms,
        "{t:?}, {:?} in a {wall_ms} ms call",
        cost.cpu
    );
    let parts = [cost.cpu.plan_ms, cost.cpu.cull_ms, cost.cpu.record_ms];
    assert!(parts.iter().all(|&ms| ms >= 0.0), "{:?}", cost.cpu);
    assert!(parts.iter().sum::<f64>() <= cost.cpu.submit_ms * (1.0 + 1e-9), "{:?}", cost.cpu);
}

#[test]
fn every_cascade_and_every_light_is_timed_on_either_clock() {
    // Three cascades of a sun, then the eight lights of `lamps` (cube faces, spots):
    // one shadow time per layer, one lighting time per light (or one for them all,
    // from the light list), on GPU timestamps and on the CPU wall clock, with the
    // layer times summing to the light's shadow time.
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let mut cascaded = small();
    cascaded.shadow.partition = Partition::Cascades;
    cascaded.shadow.cascades.count = 3;
    let mut all = small();
    all.light.kind = LightKind::All;
    // Every frame draws every layer, to have its time: a kept map would draw none
    // after the first frame (`map_cache.rs` tests that).
    for settings in [&mut cascaded, &mut all] {
        settings.shadow.map.cache = gnomon_scene::settings::MapCache::Off;
    }
    let mut listed = all.clone();
    all.screen.lighting = Lighting::PerLight;
    listed.screen.lighting = Lighting::LightList;
    for (scene, settings) in
        [(builtin::spheres(), cascaded), (builtin::lamps(), all), (builtin::lamps(), listed)]
    {
        let uploaded = renderer.upload(&scene).unwrap();
        for clock in [ClockChoice::Auto, ClockChoice::Cpu] {
            let started = Instant::now();
            let cost = renderer.time_passes(&uploaded, &scene, &settings, clock).unwrap();
            let wall_ms = started.elapsed().as_secs_f64() * 1e3;
            let t = cost.timings.unwrap();
            if clock == ClockChoice::Cpu {
                assert_eq!(t.source, TimingSource::CpuWallClock);
            }
            // Three clocks that must nest: every pass inside the frame's span (its
            // first start to its last end), the frame inside the call the test timed.
            // On the CPU clock the passes run one by one, so they also sum within it.
            assert!(t.frame_ms <= wall_ms, "{clock:?}: a {} ms frame in a {wall_ms} ms call", t.frame_ms);
            assert!(cost.passes.iter().all(|p| p.ms <= t.frame_ms), "{clock:?}: {:?} vs {t:?}", cost.passes);
            if t.source == TimingSource::CpuWallClock {
                let total: f64 = cost.passes.iter().map(|p| p.ms).sum();
                assert!(
                    total <= t.frame_ms,
                    "{clock:?}: passes sum to {total} ms in a {} ms frame",
                    t.frame_ms
                );
            }
            // Several lights under the light list share one lighting pass.
            let one_pass = settings.screen.lighting == Lighting::LightList && cost.lights.len() > 1;
            for (index, light) in cost.lights.iter().enumerate() {
                let layers: Vec<&PassTime> = cost
                    .passes
                    .iter()
                    .filter(|p| p.kind == PassKind::Shadow && p.light == Some(index as u32))
                    .collect();
                assert_eq!(layers.len(), light.layer_draws.len(), "{}: a time per layer", light.name);
                assert!(layers.iter().enumerate().all(|(i, p)| p.layer == Some(i as u32) && p.ms > 0.0));
                let listed: Vec<f64> = layers.iter().map(|p| p.ms).collect();
                assert_eq!(light.layer_ms, listed, "{}: the layer times, in layer order", light.name);
                let total: f64 = listed.iter().sum();
                assert!((total - light.shadow_ms.unwrap()).abs() < 1e-9, "{}: {total}", light.name);
                if one_pass {
                    // One pass for them all, timed for no light in particular.
                    assert_eq!(light.lighting_ms, None, "{}", light.name);
                } else {
                    assert!(light.lighting_ms.unwrap() > 0.0, "{}", light.name);
                }
            }
            let lighting: Vec<&PassTime> =
                cost.passes.iter().filter(|p| p.kind == PassKind::Lighting).collect();
            let expected = if one_pass { 1 } else { cost.lights.len() };
            assert_eq!(lighting.len(), expected, "{:?}", settings.screen.lighting);
            let total: f64 = lighting.iter().map(|p| p.ms).sum();
            assert!(total > 0.0 && (total - t.lighting_ms).abs() < 1e-9, "{total} vs {t:?}");
            assert!(t.frame_ms >= t.shadow_ms, "{t:?}");
        }
    }
}

#[test]
fn culling_draws_only_what_the_light_and_camera_see_in_few_draws() {
    // 20 000 objects, nine tenths of them far away: each pass draws about a tenth of
    // them, in a number of draws far below the number of objects drawn.
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::build("instances:20000").unwrap();
    let uploaded = renderer.upload(&scene).unwrap();
    assert_eq!(uploaded.instance_count(), 20_001);
    let cost = renderer.time_passes(&uploaded, &scene, &small(), ClockChoice::Auto).unwrap();
    let light = &cost.lights[0];
    assert_eq!(light.layer_instances.len(), 1, "a single map by default");
    let near_objects = 2000;
    // Every near object and the ground, and at most a few stragglers.
    let drawn = light.layer_instances[0] as usize;
    assert!((near_objects + 1..near_objects + 100).contains(&drawn), "{drawn} drawn into the map");
    let seen = cost.stats.lighting_instances as usize;
    assert!((near_objects / 2..near_objects + 100).contains(&seen), "{seen} drawn by the camera");
    assert!(light.layer_draws[0] < 300, "{} draws for {drawn} instances", light.layer_draws[0]);
}
