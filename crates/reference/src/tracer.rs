//! The scene as a ray tracer sees it: every instance's triangles in world space, in
//! one compressed wide BVH (obvhs' CWBVH), with closest-hit and occlusion queries.

use glam::{Vec2, Vec3, Vec3A};
use gnomon_scene::{AlphaMode, Scene, Texture};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    cwbvh::{CwBvh, builder::build_cwbvh},
    ray::{Ray, RayHit},
    triangle::Triangle,
};

use crate::texture::sample_alpha;

#[path = "tracer_cone.rs"]
mod cone;
pub(crate) use cone::{RayCone, Receiver, ball_cone};

/// The closest surface along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance from the ray's origin to the hit, in world units (the direction is unit length).
    pub t: f32,
    /// World-space hit point, from the triangle's barycentrics (more exact than origin + t·direction).
    pub position: Vec3,
    /// The triangle's geometric normal, unit length, facing the ray's origin.
    pub normal: Vec3,
    /// Instance index + 1, as the rasterizer's object id.
    pub object_id: u32,
    /// Index of the triangle within its instance's mesh.
    pub triangle: u32,
}

/// What the alpha test needs of a triangle of an alpha-masked (glTF MASK) material.
struct AlphaTriangle {
    uv: [Vec2; 3],
    texture: Option<usize>,
    base_alpha: f32,
    cutoff: f32,
}

/// The triangles that cast shadows ([`TracedScene::caster_triangles`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CasterTriangles {
    /// Each triangle's three world-space vertices, in the BVH's order.
    pub vertices: Vec<[Vec3; 3]>,
    /// How many of them an alpha test cuts.
    pub alpha_tested: usize,
}

/// A scene's triangles in a BVH, ready for parallel queries.
pub struct TracedScene {
    bvh: CwBvh,
    /// World-space triangles, in BVH primitive order.
    triangles: Vec<Triangle>,
    /// For each triangle in BVH order: (instance index, triangle index in its mesh).
    owners: Vec<(u32, u32)>,
    /// For each triangle in BVH order: its alpha test, if its material is masked.
    alpha: Vec<Option<AlphaTriangle>>,
    textures: Vec<Texture>,
    /// Per instance: whether it occludes light.
    casts_shadow: Vec<bool>,
    triangle_count: usize,
}

impl TracedScene {
    /// Gathers every instance's triangles into world space and builds the BVH over them; the
    /// triangles of alpha-masked materials keep their UVs and texture for the alpha test. The
    /// scene must be valid ([`Scene::validate`]): its indices are trusted.
    pub fn build(scene: &Scene) -> Self {
        let mut triangles = Vec::with_capacity(scene.triangle_count());
        let mut owners = Vec::with_capacity(scene.triangle_count());
        let mut alpha = Vec::with_capacity(scene.triangle_count());
        for (i, inst) in scene.instances.iter().enumerate() {
            let mesh = &scene.meshes[inst.mesh];
            let material = &scene.materials[inst.material];
            let world: Vec<Vec3A> =
                mesh.positions.iter().map(|p| inst.world_from_object.transform_point3(*p).into()).collect();
            for (t, tri) in mesh.indices.chunks_exact(3).enumerate() {
                triangles.push(Triangle {
                    v0: world[tri[0] as usize],
                    v1: world[tri[1] as usize],
                    v2: world[tri[2] as usize],
                });
                owners.push((i as u32, t as u32));
                alpha.push(match material.alpha_mode {
                    AlphaMode::Mask { cutoff } => Some(AlphaTriangle {
                        uv: [0, 1, 2].map(|k| mesh.uvs[tri[k] as usize]),
                        texture: material.base_color_texture,
                        base_alpha: material.alpha,
                        cutoff,
                    }),
                    AlphaMode::Opaque | AlphaMode::Blend => None,
                });
            }
        }
        let triangle_count = triangles.len();
        // The BVH is built over bounds inflated by a hair (a millionth of the scene's
        // size, plus a few ulps of each coordinate), so that obvhs' slab tests stay
        // conservative for rays grazing a box face; the exact triangles are tested.
        // (T. Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013, §3.)
        let scene_size = scene.bounds().extent().max_element().max(1e-3);
        let inflated: Vec<Aabb> = triangles
            .iter()
            .map(|t| {
                let b = t.aabb();
                let pad = Vec3A::splat(1e-6 * scene_size) + b.min.abs().max(b.max.abs()) * 4.0 * f32::EPSILON;
                Aabb::new(b.min - pad, b.max + pad)
            })
            .collect();
        let bvh = cwbvh_over(&inflated);
        // Reorder into BVH order, so that a primitive id indexes the arrays directly.
        let order = &bvh.primitive_indices;
        let triangles = order.iter().map(|&k| triangles[k as usize]).collect();
        let owners = order.iter().map(|&k| owners[k as usize]).collect();
        let mut alpha_by_input: Vec<Option<Option<AlphaTriangle>>> = alpha.into_iter().map(Some).collect();
        let alpha = order.iter().map(|&k| alpha_by_input[k as usize].take().flatten()).collect();
        let casts_shadow = scene.instances.iter().map(|i| i.casts_shadow).collect();
        Self { bvh, triangles, owners, alpha, textures: scene.textures.clone(), casts_shadow, triangle_count }
    }

    /// Distance to triangle `id` along `ray`, or infinity; alpha-masked triangles are
    /// missed where their texture's alpha is below the cutoff, looked up exactly as
    /// the GPU does (mip 0, the material's sampler).
    fn hit_distance(&self, sheared: &ShearedRay, id: usize, t_min: f32, t_max: f32) -> f32 {
        let Some((t, barycentric)) = sheared.intersect(&self.triangles[id], t_min, t_max) else {
            return f32::INFINITY;
        };
        if let Some(a) = &self.alpha[id] {
            let uv = a.uv[0] * barycentric.x + a.uv[1] * barycentric.y + a.uv[2] * barycentric.z;
            let texture_alpha = a.texture.map_or(1.0, |k| sample_alpha(&self.textures[k], uv));
            if a.base_alpha * texture_alpha < a.cutoff {
                return f32::INFINITY;
            }
        }
        t
    }

    /// The world-space triangles of the instances that cast shadows, each as its
    /// three vertices, and how many of them an alpha test cuts (which another tracer
    /// would need the test for): what [`TracedScene::occluded`] traces against.
    pub fn caster_triangles(&self) -> CasterTriangles {
        let mut casters = CasterTriangles::default();
        for ((triangle, owner), alpha) in self.triangles.iter().zip(&self.owners).zip(&self.alpha) {
            if self.casts_shadow[owner.0 as usize] {
                casters.vertices.push([triangle.v0, triangle.v1, triangle.v2].map(Vec3::from));
                casters.alpha_tested += usize::from(alpha.is_some());
            }
        }
        casters
    }

    /// Number of triangles traced: every instance's, casters or not.
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// The closest surface along `direction` (unit length) between `t_min` and `t_max`.
    pub fn intersect(&self, origin: Vec3, direction: Vec3, t_min: f32, t_max: f32) -> Option<Hit> {
        let ray = traversal_ray(origin, direction, t_min, t_max);
        let sheared = ShearedRay::new(origin, direction);
        let mut hit = RayHit::none();
        if !self
            .bvh
            .ray_traverse(ray, &mut hit, |ray, id| self.hit_distance(&sheared, id, ray.tmin, ray.tmax))
        {
            return None;
        }
        let id = hit.primitive_id as usize;
        let tri = &self.triangles[id];
        let mut normal: Vec3 = (tri.v1 - tri.v0).cross(tri.v2 - tri.v0).normalize_or_zero().into();
        if normal.dot(direction) > 0.0 {
            normal = -normal;
        }
        let (instance, triangle) = self.owners[id];
        // The point from the triangle's own barycentrics: origin + t·direction is off
        // the plane by about t·ε, which the shadow ray's offset cannot absorb far from
        // the camera (Wächter & Binder assume an accurate hit point).
        let position = match sheared.intersect(tri, hit.t, hit.t) {
            Some((_, w)) => Vec3::from(tri.v0 * w.x + tri.v1 * w.y + tri.v2 * w.z),
            None => origin + direction * hit.t,
        };
        Some(Hit { t: hit.t, position, normal, object_id: instance + 1, triangle })
    }

    /// True when a shadow caster blocks the segment from `origin` along `direction`
    /// (unit length) before `t_max`.
    pub fn occluded(&self, origin: Vec3, direction: Vec3, t_max: f32) -> bool {
        let ray = traversal_ray(origin, direction, 0.0, t_max);
        let sheared = ShearedRay::new(origin, direction);
        !self.bvh.ray_traverse_miss(ray, |ray, id| {
            if self.casts_shadow[self.owners[id].0 as usize] {
                self.hit_distance(&sheared, id, ray.tmin, ray.tmax)
            } else {
                f32::INFINITY
            }
        })
    }
}

/// obvhs' compressed wide BVH over `boxes`: from its PLOC build, or, where many
/// boxes coincide (a mesh instanced many times in one place), from the median-split
/// tree, whose depth stays logarithmic (`gnomon_math::median_bvh` says why).
fn cwbvh_over(boxes: &[Aabb]) -> CwBvh {
    match gnomon_math::median_bvh::obvhs_fallback(boxes, 1) {
        Some(bvh2) => obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(&bvh2, 3, true, false),
        None => build_cwbvh(boxes, BvhBuildParams::medium_build(), &mut Default::default()),
    }
}

/// The ray obvhs traverses with. Its octant and slab tests read the sign bit of each
/// direction component, and a `-0.0` component makes them cull boxes the ray passes
/// through (measured: 68 of 2112 edge-aimed rays lost), so zeros are made `+0.0`.
/// The triangle test still uses the exact direction.
fn traversal_ray(origin: Vec3, direction: Vec3, t_min: f32, t_max: f32) -> Ray {
    let d = Vec3::select(direction.cmpeq(Vec3::ZERO), Vec3::ZERO, direction);
    Ray::new(origin.into(), d.into(), t_min, t_max)
}

/// A ray prepared for the watertight ray/triangle test of S. Woop, C. Benthin and
/// I. Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013: the ray is made
/// the +z axis by a permutation and a shear, so that edge tests on triangles sharing an
/// edge are evaluated identically and a ray through an edge or vertex never slips
/// between them (obvhs' Möller–Trumbore test can).
struct ShearedRay {
    origin: Vec3,
    axes: [usize; 3],
    shear: Vec3,
}

impl ShearedRay {
    fn new(origin: Vec3, direction: Vec3) -> Self {
        let kz = direction.abs().max_position();
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        // Keep the winding: swap when the dominant axis points backward.
        if direction[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let dz = direction[kz];
        Self {
            origin,
            axes: [kx, ky, kz],
            shear: Vec3::new(direction[kx] / dz, direction[ky] / dz, 1.0 / dz),
        }
    }

    /// Distance along the ray to `tri` within [t_min, t_max] and the barycentric
    /// weights of its vertices there, or `None`.
    fn intersect(&self, tri: &Triangle, t_min: f32, t_max: f32) -> Option<(f32, Vec3)> {
        let [kx, ky, kz] = self.axes;
        let s = self.shear;
        let rel = |v: Vec3A| Vec3::from(v) - self.origin;
        let (a, b, c) = (rel(tri.v0), rel(tri.v1), rel(tri.v2));
        let project = |p: Vec3| (p[kx] - s.x * p[kz], p[ky] - s.y * p[kz]);
        let ((ax, ay), (bx, by), (cx, cy)) = (project(a), project(b), project(c));
        let (mut u, mut v, mut w) = (cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax);
        // On an exact zero, redo the edge functions in double precision (paper, §3).
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let d = |x: f32| x as f64;
            u = (d(cx) * d(by) - d(cy) * d(bx)) as f32;
            v = (d(ax) * d(cy) - d(ay) * d(cx)) as f32;
            w = (d(bx) * d(ay) - d(by) * d(ax)) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let (az, bz, cz) = (s.z * a[kz], s.z * b[kz], s.z * c[kz]);
        let t = (u * az + v * bz + w * cz) / det;
        // A hit closer than the rounding error of t may be the surface the ray leaves
        // from: a bound on that error (Pharr, Jakob & Humphreys, PBRT 3rd ed., §3.9.6)
        // keeps such a hit out. A triangle far larger than the offset of the ray's
        // origin (a city's ground seen from above) otherwise shadows itself.
        let gamma = |n: f32| n * 0.5 * f32::EPSILON / (1.0 - n * 0.5 * f32::EPSILON);
        let max_z = az.abs().max(bz.abs()).max(cz.abs());
        let max_x = ax.abs().max(bx.abs()).max(cx.abs());
        let max_y = ay.abs().max(by.abs()).max(cy.abs());
        let (delta_x, delta_y, delta_z) =
            (gamma(5.0) * (max_x + max_z), gamma(5.0) * (max_y + max_z), gamma(3.0) * max_z);
        let delta_e = 2.0 * (gamma(2.0) * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let delta_t = 3.0 * (gamma(3.0) * max_e * max_z + delta_e * max_z + delta_z * max_e) / det.abs();
        // U weighs the vertex opposite edge BC (A), V the one opposite CA (B), W C.
        (t > delta_t && t >= t_min && t <= t_max).then(|| (t, Vec3::new(u, v, w) / det))
    }
}

/// Moves a hit point off its surface, along the geometric normal `n` (facing the side
/// the new ray leaves from), by a few units in the last place of its coordinates:
/// C. Wächter and N. Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
/// Ray Tracing Gems, ch. 6, 2019. The offset scales with the position's magnitude, so it
/// is robust near the origin and far from it alike.
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let of_i = (n * INT_SCALE).as_ivec3();
    let nudge = |x: f32, o: i32| f32::from_bits((x.to_bits() as i32 + if x < 0.0 { -o } else { o }) as u32);
    let p_i = Vec3::new(nudge(p.x, of_i.x), nudge(p.y, of_i.y), nudge(p.z, of_i.z));
    Vec3::new(
        if p.x.abs() < ORIGIN { p.x + FLOAT_SCALE * n.x } else { p_i.x },
        if p.y.abs() < ORIGIN { p.y + FLOAT_SCALE * n.y } else { p_i.y },
        if p.z.abs() < ORIGIN { p.z + FLOAT_SCALE * n.z } else { p_i.z },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;
    use gnomon_scene::{Instance, builtin, geometry};

    /// Florence's open ground (y = 0, seen from 400 units away) came out speckled with
    /// false shadow: a hit point taken as origin + t·direction is off the plane by
    /// about t·ε, more than the offset near y = 0, so the shadow ray started below the
    /// ground and hit it. Hits come from the barycentrics, on the plane to its own
    /// rounding.
    #[test]
    fn distant_ground_does_not_shadow_itself() {
        let mut scene = builtin::spheres();
        scene.meshes = vec![geometry::plane(1000.0, 1000.0)];
        scene.instances = vec![Instance {
            name: "ground".into(),
            mesh: 0,
            material: 0,
            world_from_object: Mat4::IDENTITY,
            casts_shadow: true,
            motion: gnomon_scene::Motion::Static,
        }];
        let traced = TracedScene::build(&scene);
        let eye = Vec3::new(150.0, 220.0, 380.0);
        let to_sun = Vec3::new(0.5, 0.5, -0.4).normalize();
        let mut self_shadowed = 0;
        for i in 0..100 {
            for j in 0..100 {
                let target = Vec3::new(-300.0 + 6.0 * i as f32 + 0.37, 0.0, -300.0 + 6.0 * j as f32 + 0.61);
                let direction = (target - eye).normalize();
                let hit = traced.intersect(eye, direction, 0.0, 1e4).unwrap();
                let origin = offset_ray_origin(hit.position, hit.normal);
                self_shadowed += traced.occluded(origin, to_sun, 1e4) as u32;
            }
        }
        assert_eq!(self_shadowed, 0, "of 10000 ground points");
    }

    #[test]
    fn hits_the_ground_and_respects_casts_shadow() {
        let mut scene = builtin::spheres();
        scene.meshes = vec![geometry::plane(10.0, 10.0), geometry::cuboid(Vec3::splat(0.5))];
        scene.instances = vec![
            Instance {
                name: "g".into(),
                mesh: 0,
                material: 0,
                world_from_object: Mat4::IDENTITY,
                casts_shadow: true,
                motion: gnomon_scene::Motion::Static,
            },
            Instance {
                name: "b".into(),
                mesh: 1,
                material: 0,
                world_from_object: Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0)),
                casts_shadow: false,
                motion: gnomon_scene::Motion::Static,
            },
        ];
        let traced = TracedScene::build(&scene);
        assert_eq!(traced.triangle_count(), 14);
        // Straight down from above the box: the box is hit first (it is visible even
        // though it casts no shadow), at its top face y = 2.5.
        let hit = traced.intersect(Vec3::new(0.0, 5.0, 0.0), Vec3::NEG_Y, 0.0, 100.0).unwrap();
        assert_eq!(hit.object_id, 2);
        assert!((hit.t - 2.5).abs() < 1e-5 && hit.normal.abs_diff_eq(Vec3::Y, 1e-5));
        // Beside the box: the ground, normal up, facing the ray.
        let hit = traced.intersect(Vec3::new(3.0, 5.0, 0.0), Vec3::NEG_Y, 0.0, 100.0).unwrap();
        assert_eq!(hit.object_id, 1);
        // Seen from below, the ground's normal faces down, toward the ray's origin.
        let hit = traced.intersect(Vec3::new(3.0, -5.0, 0.0), Vec3::Y, 0.0, 100.0).unwrap();
        assert!(hit.normal.abs_diff_eq(Vec3::NEG_Y, 1e-5));
        // The non-casting box does not occlude; the ground does, from below.
        assert!(!traced.occluded(Vec3::new(0.0, 0.01, 0.0), Vec3::Y, 100.0));
        assert!(traced.occluded(Vec3::new(0.0, -1.0, 0.0), Vec3::Y, 100.0));
        assert!(
            !traced.occluded(Vec3::new(0.0, -1.0, 0.0), Vec3::Y, 0.5),
            "t_max stops the ray short of the ground"
        );
    }

    #[test]
    fn rays_through_shared_edges_and_vertices_never_slip_through() {
        // From inside a closed sphere, aim exactly at every vertex and every edge
        // midpoint: each ray must hit. (A non-watertight test loses some of these.)
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
        scene.instances = vec![Instance {
            name: "s".into(),
            mesh: 0,
            material: 0,
            world_from_object: Mat4::IDENTITY,
            casts_shadow: true,
            motion: gnomon_scene::Motion::Static,
        }];
        let traced = TracedScene::build(&scene);
        let brute = targets
            .iter()
            .filter(|t| {
                let r = ShearedRay::new(Vec3::ZERO, t.normalize());
                traced.triangles.iter().all(|tri| r.intersect(tri, 0.0, 10.0).is_none())
            })
            .count();
        assert_eq!(brute, 0, "the triangle test itself is watertight");
        let missed = targets
            .iter()
            .filter(|t| traced.intersect(Vec3::ZERO, t.normalize(), 0.0, 10.0).is_none())
            .count();
        assert_eq!(missed, 0, "{missed} of {} rays slipped through the mesh", targets.len());
        // And the ground quad's diagonal, hit head-on from below and above.
        let mut scene = builtin::spheres();
        scene.meshes = vec![geometry::plane(10.0, 10.0)];
        scene.instances.truncate(1);
        scene.instances[0].mesh = 0;
        scene.instances[0].world_from_object = Mat4::IDENTITY;
        let traced = TracedScene::build(&scene);
        for x in [-2.0f32, 0.0, 3.0] {
            let p = Vec3::new(x, 0.0, -x);
            assert!(traced.occluded(p - Vec3::Y, Vec3::Y, 10.0), "diagonal at {p}");
            assert!(traced.intersect(p + Vec3::Y, Vec3::NEG_Y, 0.0, 10.0).is_some(), "diagonal at {p}");
        }
    }

    #[test]
    fn offset_origin_leaves_the_surface_on_the_normal_side() {
        for p in [Vec3::new(0.001, 0.0, 0.0), Vec3::new(1234.5, 0.0, -77.0), Vec3::new(-3.0, 1e-3, 2.0)] {
            let o = offset_ray_origin(p, Vec3::Y);
            assert!(o.y > p.y, "{p} → {o}");
            assert!((o - p).length() < 1e-2 * (1.0 + p.length()));
        }
    }
}
