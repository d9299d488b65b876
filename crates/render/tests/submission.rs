//! Scene submission: identical meshes become instanced draws, and thousands of
//! distinct meshes cost draw calls but no extra state changes.

use glam::{Mat4, Vec3};
use gnomon_render::{Gpu, OutputRequest, Renderer};
use gnomon_scene::{Instance, Settings, builtin, geometry};

fn small() -> Settings {
    let mut s = Settings::default();
    s.image.width = 160;
    s.image.height = 90;
    s.shadow.map.resolution = 512;
    s
}

#[test]
fn identical_columns_are_one_instanced_draw() {
    let gpu = Gpu::new_headless().unwrap();
    let mut renderer = Renderer::new(&gpu).unwrap();
    let scene = builtin::columns();
    assert_eq!(scene.instances.len(), 97, "a ground and 96 columns");
    let frame = renderer.render(&scene, &small(), &OutputRequest::default()).unwrap();
    // The ground, and one instanced draw for all 96 columns, in each pass.
    assert_eq!((frame.stats.shadow_draws, frame.stats.lighting_draws), (2, 2), "{:?}", frame.stats);
}

#[test]
fn thousands_of_distinct_meshes_add_no_state_changes() {
    let gpu = Gpu::new_headless().unwrap();
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
            });
        }
        let mut renderer = Renderer::new(&gpu).unwrap();
        renderer.render(&scene, &small(), &OutputRequest::default()).unwrap().stats
    };
    let few = stats_for(10);
    let many = stats_for(2000);
    assert_eq!(many.lighting_draws, 2001, "one draw per distinct mesh: {many:?}");
    assert_eq!(
        (many.pipeline_changes, many.bind_group_changes),
        (few.pipeline_changes, few.bind_group_changes),
        "state changes do not grow with the mesh count: {few:?} vs {many:?}"
    );
}

#[test]
fn timing_alone_submits_the_same_frame_as_a_full_render() {
    let gpu = Gpu::new_headless().unwrap();
    let mut renderer = Renderer::new(&gpu).unwrap();
    let scene = builtin::spheres();
    let uploaded = renderer.upload(&scene).unwrap();
    let frame = renderer.render_uploaded(&uploaded, &scene, &small(), &OutputRequest::default()).unwrap();
    let (timings, stats) = renderer.time_passes(&uploaded, &scene, &small()).unwrap();
    assert_eq!(stats, frame.stats);
    assert_eq!(timings.is_some(), gpu.timestamp_period_ns.is_some());
    if let Some(t) = timings {
        assert!(t.shadow_ms > 0.0 && t.lighting_ms > 0.0, "{t:?}");
    }
}
