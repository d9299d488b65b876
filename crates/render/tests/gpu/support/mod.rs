//! Shared helpers for the GPU tests: one device per test binary, brute-force shadow
//! rays for ground truth on small procedural scenes, and pixel footprints.
#![allow(dead_code)]

pub mod device;
pub mod figures;

pub use device::{gpu, render};

use glam::{Mat4, Vec3};
use gnomon_render::Frame;
use gnomon_scene::{DirectionalLight, Instance, Light, Material, Scene, Settings, SpotLight, geometry};

/// The default settings at a size and map resolution, unrefined: these tests measure
/// the shadow maps themselves, which the default's rays would correct where the map
/// is unsure (refinement is tested against exact shadows in `analytic_shadows.rs` and
/// against the reference in `gnomon-reference`'s `refine.rs`).
pub fn settings(width: u32, height: u32, resolution: u32) -> Settings {
    let mut s = Settings::default();
    s.screen.refine = gnomon_scene::settings::Refine::Off;
    s.image.width = width;
    s.image.height = height;
    s.shadow.map.resolution = resolution;
    s
}

/// A ground plane of `size` at y = 0 and nothing else, lit by a sun from straight
/// above, seen from above; callers add occluders and set the lights.
pub fn ground_scene(name: &str, size: f32) -> Scene {
    let mut scene = gnomon_scene::builtin::spheres();
    scene.name = name.into();
    scene.meshes = vec![geometry::plane(size, size)];
    scene.materials =
        vec![Material::new("ground", Vec3::splat(0.7)), Material::new("occluder", Vec3::new(0.8, 0.3, 0.2))];
    scene.instances = vec![Instance {
        name: "ground".into(),
        mesh: 0,
        material: 0,
        world_from_object: Mat4::IDENTITY,
        casts_shadow: true,
        motion: gnomon_scene::Motion::Static,
    }];
    scene
}

/// Adds a mesh and one instance of it.
pub fn add(scene: &mut Scene, name: &str, mesh: gnomon_scene::Mesh, world_from_object: Mat4) {
    scene.meshes.push(mesh);
    scene.instances.push(Instance {
        name: name.into(),
        mesh: scene.meshes.len() - 1,
        material: 1,
        world_from_object,
        casts_shadow: true,
        motion: gnomon_scene::Motion::Static,
    });
}

/// Möller–Trumbore ray/triangle distance, if hit in (0, max_t).
fn ray_triangle(origin: Vec3, dir: Vec3, a: Vec3, b: Vec3, c: Vec3, max_t: f32) -> bool {
    let (e1, e2) = (b - a, c - a);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return false;
    }
    let inv = 1.0 / det;
    let s = origin - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = e2.dot(q) * inv;
    t > 0.0 && t < max_t
}

fn ray_box(origin: Vec3, inv_dir: Vec3, min: Vec3, max: Vec3, max_t: f32) -> bool {
    let t0 = (min - origin) * inv_dir;
    let t1 = (max - origin) * inv_dir;
    let near = t0.min(t1).max_element();
    let far = t0.max(t1).min_element();
    near <= far && far > 0.0 && near < max_t
}

/// Exact (brute-force) hard-shadow visibility of `point` with normal `normal`: true
/// when nothing blocks the segment to the light. For small procedural scenes only.
pub fn ray_traced_lit(scene: &Scene, light: &Light, point: Vec3, normal: Vec3) -> bool {
    let origin = point + normal * 1e-4 * (1.0 + point.abs().max_element());
    let (dir, max_t) = match light {
        Light::Directional(sun) => (-sun.direction.normalize(), f32::INFINITY),
        Light::Spot(spot) => {
            let to = spot.position - origin;
            (to.normalize(), to.length())
        }
        Light::Point(point) => {
            let to = point.position - origin;
            (to.normalize(), to.length())
        }
    };
    let inv_dir = dir.recip();
    for inst in scene.instances.iter().filter(|i| i.casts_shadow) {
        let mesh = &scene.meshes[inst.mesh];
        let bounds = mesh.bounds().transformed(inst.world_from_object);
        if !ray_box(origin, inv_dir, bounds.min - 1e-4, bounds.max + 1e-4, max_t) {
            continue;
        }
        for t in mesh.indices.chunks(3) {
            let [a, b, c] =
                [0, 1, 2].map(|k| inst.world_from_object.transform_point3(mesh.positions[t[k] as usize]));
            if ray_triangle(origin, dir, a, b, c, max_t) {
                return false;
            }
        }
    }
    true
}

/// World size of pixel `i`: the largest distance to a horizontal or vertical
/// neighbour on the same object.
pub fn pixel_footprint(frame: &Frame, i: usize) -> f32 {
    let (w, h) = (frame.width as usize, frame.height as usize);
    let (x, y) = (i % w, i / w);
    let mut size = 0.0f32;
    for (nx, ny) in [(x.wrapping_sub(1), y), (x + 1, y), (x, y.wrapping_sub(1)), (x, y + 1)] {
        if nx < w && ny < h {
            let j = ny * w + nx;
            if frame.object_id[j] == frame.object_id[i] {
                size = size.max(frame.position[j].distance(frame.position[i]));
            }
        }
    }
    size
}

/// Signed distance from `p` to the axis-aligned square of half-size `half` at
/// `center` (negative inside).
pub fn square_distance(p: glam::Vec2, center: glam::Vec2, half: f32) -> f32 {
    let d = (p - center).abs() - glam::Vec2::splat(half);
    d.max(glam::Vec2::ZERO).length() + d.max_element().min(0.0)
}

/// A square occluder over a ground plane, and where its hard shadow falls.
pub struct SquareOccluder {
    pub scene: Scene,
    /// Centre of the shadow on the ground (x, z).
    pub shadow_center: glam::Vec2,
    /// Half-size of the shadow on the ground.
    pub shadow_half: f32,
    /// Height of the occluder above the ground.
    pub height: f32,
}

/// A 2 × 2 square 1.5 above a 12 × 12 ground, under a sun 50° high at azimuth 30°,
/// seen from above. Its shadow is the square translated along the light by
/// height / (−d.y).
pub fn square_under_sun() -> SquareOccluder {
    let (half, height) = (1.0f32, 1.5f32);
    let center = Vec3::new(0.5, height, -0.5);
    let mut scene = ground_scene("square under a sun", 12.0);
    add(&mut scene, "square", geometry::plane(2.0 * half, 2.0 * half), Mat4::from_translation(center));
    scene.camera.eye = Vec3::new(0.0, 9.0, 6.0);
    scene.camera.target = Vec3::ZERO;
    let sun_dir = -gnomon_scene::sun_direction(50.0, 30.0);
    scene.light_mut::<DirectionalLight>().unwrap().direction = sun_dir;
    let offset = glam::Vec2::new(sun_dir.x, sun_dir.z) * (height / -sun_dir.y);
    SquareOccluder {
        scene,
        shadow_center: glam::Vec2::new(center.x, center.z) + offset,
        shadow_half: half,
        height,
    }
}

/// Height of the spot light of [`square_under_spot`] and its cone's half-angle.
pub const SPOT_HEIGHT: f32 = 8.0;
pub const SPOT_OUTER_DEGREES: f32 = 30.0;

/// A 1.5 × 1.5 square 2 above a 16 × 16 ground, under a spot light 8 above the
/// origin pointing down (outer cone 30°). Seen from a point light at height H, a
/// square at height h projects onto the ground scaled by k = H / (H − h) about the
/// light's foot.
pub fn square_under_spot() -> SquareOccluder {
    let (half, height) = (0.75f32, 2.0f32);
    let center = Vec3::new(1.0, height, 0.5);
    let mut scene = ground_scene("square under a spot", 16.0);
    add(&mut scene, "square", geometry::plane(2.0 * half, 2.0 * half), Mat4::from_translation(center));
    scene.camera.eye = Vec3::new(0.0, 12.0, 8.0);
    scene.camera.target = Vec3::ZERO;
    let spot = scene.light_mut::<SpotLight>().unwrap();
    spot.position = Vec3::new(0.0, SPOT_HEIGHT, 0.0);
    spot.direction = Vec3::NEG_Y;
    spot.outer_angle_degrees = SPOT_OUTER_DEGREES;
    spot.inner_angle_degrees = 25.0;
    spot.range = 20.0;
    let k = SPOT_HEIGHT / (SPOT_HEIGHT - height);
    SquareOccluder {
        scene,
        shadow_center: glam::Vec2::new(center.x, center.z) * k,
        shadow_half: half * k,
        height,
    }
}
