//! The GPU shadow-ray tracer (`gnomon_render::rays`) against the CPU reference's
//! (`TracedScene::occluded`): two independent tracers give the same answers, on
//! solid casters, on cut-out ones, and on rays aimed exactly at shared edges.

use crate::common;

use common::{
    figures::figure,
    gpu,
    rays::{AfterMove, Rng, add_cutout_card, card_alpha, move_every_sphere, random_rays},
};
use glam::{Mat4, Vec3};
use gnomon_reference::TracedScene;
use gnomon_render::rays::{ShadowRay, ShadowRays};
use gnomon_scene::{Scene, Wrap, builtin, geometry};

/// How many of `rays` the two tracers answer differently.
fn disagreements(scene: &Scene, rays: &[ShadowRay]) -> usize {
    let cpu = TracedScene::build(scene);
    let gpu_rays = ShadowRays::new(gpu(), scene).unwrap();
    let answers = gpu_rays.occluded(rays).unwrap();
    assert_eq!(answers.len(), rays.len());
    let blocked = answers.iter().filter(|b| **b).count();
    assert!(
        blocked > rays.len() / 20 && blocked < rays.len() * 19 / 20,
        "{blocked} of {} rays blocked: the test would not tell tracers apart",
        rays.len()
    );
    rays.iter().zip(&answers).filter(|(r, g)| cpu.occluded(r.origin, r.direction, r.length) != **g).count()
}

#[test]
fn gpu_and_cpu_tracers_agree_on_random_rays_through_solid_casters() {
    for scene in [builtin::spheres(), builtin::columns(), builtin::contact()] {
        let rays = random_rays(&scene, 20_000, 0x9e37_79b9_7f4a_7c15);
        let wrong = disagreements(&scene, &rays);
        figure(&format!("gpu rays vs cpu, {}: disagreements of 20,000", scene.name), wrong, 2);
        // Two exact tracers may still split a ray that grazes an edge within rounding
        // (the GPU has no double-precision fallback for an edge function of exactly 0).
        assert!(wrong <= 2, "{}: {wrong} of {} rays answered differently", scene.name, rays.len());
    }
}

/// A cut-out card whose alpha varies smoothly (bilinear, repeat) and one with a
/// nearest-sampled checker (mirrored): rays through them must be blocked exactly where
/// the reference's alpha test says.
fn cutout_scene(nearest: bool, wrap: Wrap) -> Scene {
    let mut scene = builtin::spheres();
    scene.name = format!("cut-out card, nearest {nearest}");
    (scene.textures, scene.materials, scene.meshes, scene.instances) = Default::default();
    let mut alpha = card_alpha(wrap);
    alpha.nearest = nearest;
    add_cutout_card(&mut scene, alpha, 4.0, Mat4::from_rotation_x(0.3));
    scene
}

#[test]
fn gpu_and_cpu_tracers_agree_on_cut_out_casters() {
    for (nearest, wrap) in [(false, Wrap::Repeat), (true, Wrap::MirroredRepeat), (false, Wrap::ClampToEdge)] {
        let scene = cutout_scene(nearest, wrap);
        let mut rng = Rng(12345);
        // From below the card, up through it.
        let rays: Vec<ShadowRay> = (0..20_000)
            .map(|_| {
                let target = rng.in_box(Vec3::new(-1.9, 0.0, -1.9), Vec3::new(1.9, 0.0, 1.9));
                let target = Mat4::from_rotation_x(0.3).transform_point3(target);
                let direction = (Vec3::new(0.0, 1.0, 0.0) + 0.4 * rng.direction()).normalize();
                ShadowRay { origin: target - 2.0 * direction, direction, length: 4.0 }
            })
            .collect();
        let wrong = disagreements(&scene, &rays);
        figure(&format!("gpu rays vs cpu, {}, {wrap:?}: disagreements of 20,000", scene.name), wrong, 2);
        assert!(wrong <= 2, "{}, {wrap:?}: {wrong} of {} rays answered differently", scene.name, rays.len());
    }
}

#[test]
fn rays_through_shared_edges_and_vertices_never_slip_through() {
    let mut scene = builtin::spheres();
    let sphere = geometry::uv_sphere(1.0, 24, 12);
    let targets: Vec<Vec3> = sphere
        .indices
        .chunks(3)
        .flat_map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| sphere.positions[t[k] as usize]);
            [a, 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a)]
        })
        .collect();
    scene.meshes = vec![sphere];
    scene.instances.truncate(1);
    scene.instances[0].mesh = 0;
    scene.instances[0].world_from_object = Mat4::IDENTITY;
    let rays: Vec<ShadowRay> = targets
        .iter()
        .map(|t| ShadowRay { origin: Vec3::ZERO, direction: t.normalize(), length: 10.0 })
        .collect();
    let answers = ShadowRays::new(gpu(), &scene).unwrap().occluded(&rays).unwrap();
    let missed = answers.iter().filter(|b| !**b).count();
    assert_eq!(missed, 0, "{missed} of {} rays slipped through the closed sphere", rays.len());
}

#[test]
fn a_scene_without_casters_blocks_nothing() {
    let mut scene = builtin::spheres();
    for instance in &mut scene.instances {
        instance.casts_shadow = false;
    }
    let tracer = ShadowRays::new(gpu(), &scene).unwrap();
    assert_eq!(tracer.triangle_count(), 0);
    let rays = random_rays(&scene, 1000, 7);
    assert!(tracer.occluded(&rays).unwrap().iter().all(|b| !b));
    assert!(tracer.occluded(&[]).unwrap().is_empty());
}

#[test]
fn a_refitted_tree_answers_as_the_reference_of_the_moved_scene() {
    // Every sphere of `spheres` moves (turned, lifted, one far past the old bounds):
    // the refitted GPU tree must answer as the CPU reference built afresh on the moved
    // scene, while the tree before the move disagrees with it on many rays.
    let mut scene = builtin::spheres();
    let mut tracer = ShadowRays::new(gpu(), &scene).unwrap();
    let AfterMove { stale, moved: wrong, rays } = move_every_sphere(&mut scene, &mut tracer);
    figure(
        &format!(
            "gpu rays after a refit vs cpu on the moved scene: disagreements of 20,000 (before the refit: {stale})"
        ),
        wrong,
        2,
    );
    assert!(stale > 500, "the move should change many answers: {stale}");
    assert!(wrong <= 2, "{wrong} of {rays} rays answered differently after the refit");
    let e = tracer.move_instances(&scene, &[99]).unwrap_err().to_string();
    assert!(e.contains("no instance 99"), "{e}");
    scene.instances.pop();
    let e = tracer.move_instances(&scene, &[0]).unwrap_err().to_string();
    assert!(e.contains(&format!("uploaded with {}", scene.instances.len() + 1)), "{e}");
}
