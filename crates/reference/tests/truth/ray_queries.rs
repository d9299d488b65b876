//! The ray-query tracer (`--tracer ray-query`: the adapter's own acceleration
//! structures, through wgpu's `EXPERIMENTAL_RAY_QUERY`) against the shader tracer and
//! the CPU reference: the same answers on random rays, on cut-out casters and after
//! instances move, and the same refined frames on both paths.
//!
//! They need a device with ray queries. Where the system's Vulkan has none, each test
//! runs itself again on the lavapipe that `scripts/fetch-lavapipe-ray-query.sh`
//! fetched (Mesa 24.1 and later implement ray queries on the CPU); where there is
//! none either, it says it skipped. The fallback, where ray queries are asked for and
//! cannot run, is tested on whichever device the test has.

use crate::common;

use std::path::PathBuf;

use common::{
    compare,
    figures::{figure, percent, skipped},
    rays::{AfterMove, Rng, add_cutout_card, card_alpha, move_every_sphere, random_rays},
    reference,
};
use glam::{Mat4, Vec3};
use gnomon_reference::TracedScene;
use gnomon_render::{
    Frame, Gpu, OutputRequest, Renderer,
    rays::{RayQueriesUnavailable, ShadowRay, ShadowRays, Traversal},
};
use gnomon_scene::{
    Scene, Settings, Wrap, builtin,
    settings::{LightKind, Refine, ShadowPath, Technique, Tracer},
};

/// Set in the environment of a test run again on the fetched lavapipe.
const CHILD: &str = "GNOMON_RAY_QUERY_CHILD";

/// The device with ray queries that `test` runs on. None where this process has
/// none: the test then ran itself again on the fetched lavapipe (and failed here if
/// it failed there), or said it skipped.
fn ray_query_gpu(test: &str) -> Option<&'static Gpu> {
    let gpu = common::gpu();
    if gpu.ray_queries {
        return Some(gpu);
    }
    assert!(std::env::var_os(CHILD).is_none(), "the driver this test was run again on has no ray queries");
    let dir = std::env::var_os("GNOMON_RAY_QUERY_DRIVER")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/lavapipe-ray-query"));
    let icd = dir.join("lvp_icd.json");
    if !icd.is_file() {
        skipped(
            test,
            &format!(
                "`{}` has no ray queries and no lavapipe with them is at {} (scripts/fetch-lavapipe-ray-query.sh)",
                gpu.info.adapter,
                dir.display()
            ),
        );
        return None;
    }
    let library_path = match std::env::var_os("LD_LIBRARY_PATH") {
        Some(path) => {
            std::env::join_paths(std::iter::once(dir.join("lib")).chain(std::env::split_paths(&path)))
                .unwrap()
        }
        None => dir.join("lib").into_os_string(),
    };
    // The harness names a test by its path below the test crate: this module's path
    // without the crate's name, then the function.
    let module = module_path!().split_once("::").map_or("", |(_, module)| module);
    let name = format!("{module}::{test}");
    let output = std::process::Command::new(std::env::current_exe().unwrap())
        .args([name.as_str(), "--exact", "--nocapture", "--test-threads=1"])
        .env("VK_DRIVER_FILES", &icd)
        .env("LD_LIBRARY_PATH", library_path)
        .env(CHILD, "1")
        .output()
        .expect("running the test again on the lavapipe with ray queries");
    // Its figures, and anything it said, in this test's output (straight to stderr,
    // as `figures` writes, past the harness's capture).
    let _ = std::io::Write::write_all(&mut std::io::stderr().lock(), &output.stderr);
    assert!(
        output.status.success() && String::from_utf8_lossy(&output.stdout).contains("1 passed"),
        "{test} on the lavapipe at {}:\n{}",
        dir.display(),
        String::from_utf8_lossy(&output.stdout)
    );
    None
}

/// How many of `rays` the ray queries answer differently from the shader and from the
/// CPU reference, and how many were left out as starting on a caster.
///
/// Left out: rays whose reference answer changes when they start a little earlier
/// (a ten-thousandth of the scene's size back along the ray). The reference and the
/// shader ignore a hit closer than their bound on the rounding error of t (PBRT's),
/// which grows with the triangle's size: a ray starting 4 mm above `columns`' ground,
/// a single triangle 400 m long, does not see it 9 mm ahead. The adapter's test has
/// no such bound, so it does; a shadow ray from a surface is kept off that surface by
/// its origin's offset (`offset_ray_origin`) on either tracer.
struct Agreement {
    vs_shader: usize,
    vs_cpu: usize,
    left_out: usize,
}

fn agreement(gpu: &Gpu, scene: &Scene, rays: &[ShadowRay]) -> Agreement {
    let queries = ShadowRays::with_tracer(gpu, scene, Tracer::RayQuery).unwrap();
    assert_eq!(queries.traversal(), Traversal::RayQuery);
    let shader = ShadowRays::with_tracer(gpu, scene, Tracer::Shader).unwrap();
    assert_eq!(shader.traversal(), Traversal::Shader);
    let answers = queries.occluded(rays).unwrap();
    let blocked = answers.iter().filter(|b| **b).count();
    assert!(
        blocked > rays.len() / 20 && blocked < rays.len() * 19 / 20,
        "{blocked} of {} rays blocked: the test would not tell tracers apart",
        rays.len()
    );
    let cpu = TracedScene::build(scene);
    let back = 1e-4 * scene.bounds().extent().max_element();
    let truth: Vec<Option<bool>> = rays
        .iter()
        .map(|r| {
            let answer = cpu.occluded(r.origin, r.direction, r.length);
            let earlier = cpu.occluded(r.origin - back * r.direction, r.direction, r.length + back);
            (answer == earlier).then_some(answer)
        })
        .collect();
    let shaded = shader.occluded(rays).unwrap();
    let kept = || truth.iter().zip(&answers).zip(&shaded).filter_map(|((t, a), s)| t.map(|t| (t, *a, *s)));
    Agreement {
        vs_shader: kept().filter(|(_, a, s)| a != s).count(),
        vs_cpu: kept().filter(|(t, a, _)| t != a).count(),
        left_out: truth.iter().filter(|t| t.is_none()).count(),
    }
}

/// Two exact tracers may split a ray that grazes an edge within rounding; 2 of 20,000
/// is what the shader tracer is held to against the CPU's (gpu_rays.rs).
const MOST_SPLIT: usize = 2;

#[test]
fn ray_queries_answer_random_rays_as_the_shader_and_the_reference_do() {
    let Some(gpu) = ray_query_gpu("ray_queries_answer_random_rays_as_the_shader_and_the_reference_do") else {
        return;
    };
    for scene in [builtin::spheres(), builtin::columns(), builtin::contact()] {
        let rays = random_rays(&scene, 20_000, 0x9e37_79b9_7f4a_7c15);
        let Agreement { vs_shader, vs_cpu, left_out } = agreement(gpu, &scene, &rays);
        figure(
            &format!(
                "ray queries vs the shader, {}: disagreements of 20,000 (vs the CPU: {vs_cpu}; {left_out} left out, starting on a caster)",
                scene.name
            ),
            vs_shader,
            MOST_SPLIT,
        );
        assert!(vs_shader <= MOST_SPLIT && vs_cpu <= MOST_SPLIT, "{}: {vs_shader}, {vs_cpu}", scene.name);
        assert!(left_out <= rays.len() / 100, "{}: {left_out} rays left out", scene.name);
    }
}

#[test]
fn ray_queries_alpha_test_cut_out_casters_as_the_reference_does() {
    let Some(gpu) = ray_query_gpu("ray_queries_alpha_test_cut_out_casters_as_the_reference_does") else {
        return;
    };
    // A cut-out card (a smooth alpha, bilinear, repeating past its UVs' unit square)
    // over the opaque spheres: both geometries of the acceleration structure.
    let scene = cut_out_card_over_spheres();
    let mut rng = Rng(12345);
    let bounds = scene.bounds();
    let rays: Vec<ShadowRay> = (0..20_000)
        .map(|_| {
            let target = rng.in_box(bounds.min, bounds.max);
            let direction = (Vec3::Y + 0.5 * rng.direction()).normalize();
            ShadowRay { origin: target - 3.0 * direction, direction, length: 6.0 }
        })
        .collect();
    let Agreement { vs_shader, vs_cpu, left_out } = agreement(gpu, &scene, &rays);
    figure(
        &format!(
            "ray queries vs the shader, a cut-out card over spheres: disagreements of 20,000 (vs the CPU: {vs_cpu}; {left_out} left out)"
        ),
        vs_shader,
        MOST_SPLIT,
    );
    assert!(vs_shader <= MOST_SPLIT && vs_cpu <= MOST_SPLIT, "{vs_shader}, {vs_cpu}");
    assert!(left_out <= rays.len() / 100, "{left_out} rays left out");
}

/// `spheres` with a cut-out card tilted over them, whose alpha varies smoothly: half
/// of it lets light through.
fn cut_out_card_over_spheres() -> Scene {
    let mut scene = builtin::spheres();
    scene.name = "cut-out card over spheres".into();
    let over = Mat4::from_translation(Vec3::new(0.0, 2.5, 0.0)) * Mat4::from_rotation_x(0.3);
    add_cutout_card(&mut scene, card_alpha(Wrap::Repeat), 6.0, over);
    scene
}

#[test]
fn ray_queries_follow_moved_instances() {
    let Some(gpu) = ray_query_gpu("ray_queries_follow_moved_instances") else { return };
    let mut scene = builtin::spheres();
    let mut tracer = ShadowRays::with_tracer(gpu, &scene, Tracer::RayQuery).unwrap();
    let AfterMove { stale, moved: moved_wrong, .. } = move_every_sphere(&mut scene, &mut tracer);
    figure(
        &format!("ray queries after a move, spheres: disagreements of 20,000 (before the move: {stale})"),
        moved_wrong,
        MOST_SPLIT,
    );
    assert!(stale > 200, "the move should change the answers: {stale}");
    assert!(moved_wrong <= MOST_SPLIT, "{moved_wrong}");
}

/// Issue 25's bounds: refined frames within 0.02 % of the reference, every pixel
/// traced within 0.01 %.
const REFINED_MISMATCH: f64 = 0.0002;
const TRACED_MISMATCH: f64 = 0.0001;

fn settings(refine: Refine, tracer: Tracer) -> Settings {
    let mut s = Settings::default();
    s.image.width = 640;
    s.image.height = 360;
    s.shadow.filter.technique = Technique::PCF2X2;
    s.screen.refine = refine;
    s.screen.tracer = tracer;
    s
}

fn render_on(gpu: &Gpu, scene: &Scene, s: &Settings) -> Frame {
    Renderer::new(gpu).unwrap().render(scene, s, &OutputRequest::default()).unwrap()
}

/// Pixels whose visibility differs by more than 0.01 between two frames.
fn differing(a: &Frame, b: &Frame) -> usize {
    a.visibility.iter().zip(&b.visibility).filter(|(x, y)| (*x - *y).abs() > 0.01).count()
}

#[test]
fn frames_refined_by_ray_queries_match_the_reference_and_the_shader() {
    let Some(gpu) = ray_query_gpu("frames_refined_by_ray_queries_match_the_reference_and_the_shader") else {
        return;
    };
    for (scene, kind, path) in [
        (builtin::spheres(), LightKind::Sun, ShadowPath::Auto),
        (builtin::columns(), LightKind::Sun, ShadowPath::Auto),
        (builtin::contact(), LightKind::Spot, ShadowPath::Auto),
        (builtin::spheres(), LightKind::Point, ShadowPath::Auto),
        (builtin::columns(), LightKind::Sun, ShadowPath::Forward),
    ] {
        let mut base = settings(Refine::Off, Tracer::Shader);
        base.light.kind = kind;
        base.screen.shadow_path = path;
        let truth = reference(&scene, &base);
        for (refine, bound) in [(Refine::Rays, REFINED_MISMATCH), (Refine::EveryPixel, TRACED_MISMATCH)] {
            let with = |tracer| {
                let mut s = base.clone();
                s.screen.refine = refine;
                s.screen.tracer = tracer;
                render_on(gpu, &scene, &s)
            };
            let (queries, shader) = (with(Tracer::RayQuery), with(Tracer::Shader));
            assert_eq!(queries.lights[0].traversal, Some(Traversal::RayQuery));
            assert_eq!(queries.lights[0].tracer_fallback, None);
            assert_eq!(shader.lights[0].traversal, Some(Traversal::Shader));
            let wrong = compare(&queries, &truth);
            let apart = differing(&queries, &shader);
            figure(
                &format!(
                    "{} under a {kind:?}, {path:?} path, {refine:?} by ray queries: mismatch ({apart} pixels differ from the shader's frame)",
                    scene.name
                ),
                percent(wrong.mismatch_rate),
                percent(bound),
            );
            assert!(wrong.mismatch_rate <= bound, "{}, {kind:?}, {refine:?}: {wrong:?}", scene.name);
            assert!(
                apart as f64 <= 1e-4 * queries.pixel_count() as f64,
                "{apart} pixels differ from the shader's"
            );
        }
    }
    // Penumbrae: 16 rays a pixel over a spot's disk, the same samples for both tracers.
    let scene = builtin::contact();
    let mut s = settings(Refine::Rays, Tracer::RayQuery);
    s.light.kind = LightKind::Spot;
    s.light.spot_radius = Some(0.5);
    s.shadow.filter.technique = Technique::PCSS;
    let queries = render_on(gpu, &scene, &s);
    s.screen.tracer = Tracer::Shader;
    let shader = render_on(gpu, &scene, &s);
    let apart = differing(&queries, &shader);
    let traced = queries.lights[0].traced_pixels.unwrap();
    // The pixels the rays decide: the quarter of the unsure beamed this frame, and
    // those filled from them.
    let decided = queries.lights[0].unsure_pixels.unwrap();
    figure(
        &format!(
            "contact under a spot of radius 0.5, PCSS refined by 16 ray queries a pixel at {traced} pixels ({decided} decided by them): pixels that differ from the shader's frame"
        ),
        apart,
        "1e-4 of the image",
    );
    assert!(decided > 10_000, "{decided} pixels decided by rays");
    assert!(apart as f64 <= 1e-4 * queries.pixel_count() as f64, "{apart} pixels differ from the shader's");
}

#[test]
fn the_trees_leaves_are_exact_with_ray_queries() {
    let Some(gpu) = ray_query_gpu("the_trees_leaves_are_exact_with_ray_queries") else { return };
    let path = common::shipped_scene("tree/tree.glb");
    let (scene, _) = gnomon_scene::gltf_loader::load(&path).unwrap();
    let s = settings(Refine::Rays, Tracer::RayQuery);
    let truth = reference(&scene, &s);
    let frame = render_on(gpu, &scene, &s);
    assert_eq!(frame.lights[0].traversal, Some(Traversal::RayQuery));
    let refined = compare(&frame, &truth);
    let map = compare(
        &render_on(
            gpu,
            &scene,
            &Settings { screen: settings(Refine::Off, Tracer::Auto).screen, ..s.clone() },
        ),
        &truth,
    );
    figure(
        &format!("tree, refined by ray queries: mismatch (the map alone: {})", percent(map.mismatch_rate)),
        percent(refined.mismatch_rate),
        percent(REFINED_MISMATCH),
    );
    assert!(map.mismatch_rate > 0.005, "the map alone should miss leaf edges: {map:?}");
    assert!(refined.mismatch_rate <= REFINED_MISMATCH, "{refined:?}");
}

/// A device opened without ray queries on the adapter Gnomon would pick, as a host
/// that did not ask for them has.
fn device_without_ray_queries() -> Gpu {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(&instance, None)).unwrap();
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
        required_limits: adapter.limits(),
        ..Default::default()
    }))
    .unwrap();
    Gpu::from_host(&adapter, &device, &queue)
}

#[test]
fn ray_queries_on_a_device_without_them_fall_back_to_the_shader_and_say_why() {
    // A frame that asks for them traces with the shader and says so; a batch of rays,
    // which has no frame to say it in, is refused; `auto` takes the shader silently.
    let scene = builtin::spheres();
    let gpu = device_without_ray_queries();
    assert!(!gpu.ray_queries);
    let frame = render_on(&gpu, &scene, &settings(Refine::Rays, Tracer::RayQuery));
    assert_eq!(frame.lights[0].traversal, Some(Traversal::Shader));
    let why = frame.lights[0].tracer_fallback.clone().expect("the frame says why it did not use ray queries");
    assert!(
        matches!(&why, RayQueriesUnavailable::NotOnDevice { adapter } if *adapter == gpu.info.adapter),
        "{why:?}"
    );
    let e = ShadowRays::with_tracer(&gpu, &scene, Tracer::RayQuery).err().expect("refused");
    assert!(e.to_string().contains(&gpu.info.adapter) && e.to_string().contains("no ray queries"), "{e}");
    let auto = render_on(&gpu, &scene, &settings(Refine::Rays, Tracer::Auto));
    assert_eq!(
        (auto.lights[0].traversal, auto.lights[0].tracer_fallback.clone()),
        (Some(Traversal::Shader), None)
    );
}

#[test]
fn a_scene_over_the_devices_structures_falls_back_to_the_shader_and_says_why() {
    let test = "a_scene_over_the_devices_structures_falls_back_to_the_shader_and_says_why";
    if ray_query_gpu(test).is_none() {
        return;
    }
    // Spheres has thousands of triangles; this device's structures take 16.
    let scene = builtin::spheres();
    let gpu = Gpu::new_headless_with(|limits| limits.max_blas_primitive_count = 16).unwrap();
    assert!(gpu.ray_queries);
    let frame = render_on(&gpu, &scene, &settings(Refine::Rays, Tracer::RayQuery));
    assert_eq!(frame.lights[0].traversal, Some(Traversal::Shader));
    let why = frame.lights[0].tracer_fallback.clone().expect("the frame says why it did not use ray queries");
    assert!(matches!(why, RayQueriesUnavailable::TooManyTriangles { limit: 16, .. }), "{why:?}");
    let e = ShadowRays::with_tracer(&gpu, &scene, Tracer::RayQuery).err().expect("refused");
    assert!(e.to_string().contains("spheres") && e.to_string().contains("at most 16"), "{e}");
}

#[test]
fn auto_takes_ray_queries_on_a_gpu_and_the_shader_on_lavapipe() {
    let test = "auto_takes_ray_queries_on_a_gpu_and_the_shader_on_lavapipe";
    let Some(gpu) = ray_query_gpu(test) else { return };
    // Lavapipe runs ray queries in software, slower than the shader's own BVH.
    let expected = match gpu.device_type {
        wgpu::DeviceType::Cpu => Traversal::Shader,
        _ => Traversal::RayQuery,
    };
    let scene = builtin::spheres();
    assert_eq!(ShadowRays::new(gpu, &scene).unwrap().traversal(), expected);
    let frame = render_on(gpu, &scene, &settings(Refine::Rays, Tracer::Auto));
    assert_eq!((frame.lights[0].traversal, frame.lights[0].tracer_fallback.clone()), (Some(expected), None));
}
