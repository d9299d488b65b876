//! Fitting a light's projection to what the camera sees. The potential receivers of
//! a shadow are the visible part of the scene: the intersection of the camera's view
//! frustum with the scene's bounds, a convex polyhedron computed here exactly. A
//! directional light's map then covers that polyhedron in x and y (the crop), and
//! extends in z toward the light to every potential caster.

use glam::{Mat4, Vec3, Vec4};

use crate::{Aabb, LightProjection, projection::view_from_world_look_at};

/// A convex hexahedron given by its eight corners, indexed by the bits (x, y, z) of
/// the index as [`Aabb::corners`] are: the view frustum or a box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hexahedron {
    /// The corners in world space. Bit 0 of the index picks low or high x (NDC −1 or +1 for a
    /// frustum), bit 1 low or high y, bit 2 low or high z: for a frustum, the near (depth 0) or far
    /// (depth 1) face.
    pub corners: [Vec3; 8],
}

impl Hexahedron {
    /// The view frustum of `clip_from_world` (WebGPU clip space: depth in [0, 1]):
    /// the NDC cube's corners taken back to world space.
    pub fn from_clip_from_world(clip_from_world: Mat4) -> Self {
        let world_from_clip = clip_from_world.inverse();
        Self {
            corners: std::array::from_fn(|i| {
                let ndc = Vec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { 0.0 } else { 1.0 },
                );
                world_from_clip.project_point3(ndc)
            }),
        }
    }

    /// The box `bounds` as a hexahedron, with its corners in [`Aabb::corners`] order.
    pub fn from_aabb(bounds: &Aabb) -> Self {
        Self { corners: bounds.corners() }
    }

    /// The part of this frustum (given as near and far corners, bit 2 of the index)
    /// between the fractions `from` and `to` of the way from its near face to its far
    /// face, along each corner edge: a cascade's slice of the view frustum.
    pub fn slice(&self, from: f32, to: f32) -> Self {
        Self {
            corners: std::array::from_fn(|i| {
                let (near, far) = (self.corners[i & 3], self.corners[(i & 3) | 4]);
                near.lerp(far, if i & 4 == 0 { from } else { to })
            }),
        }
    }

    /// The six faces, each a cycle of four corners.
    fn faces(&self) -> [[Vec3; 4]; 6] {
        std::array::from_fn(|f| {
            let (axis, side) = (f / 2, f % 2);
            let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |u: usize, v: usize| self.corners[(side << axis) | (u << b) | (v << c)];
            [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
        })
    }

    /// The six face planes (n, d), oriented so that n·p + d ≥ 0 inside.
    fn planes(&self) -> [Vec4; 6] {
        let centre = self.corners.iter().copied().sum::<Vec3>() / 8.0;
        self.faces().map(|[a, b, c, d]| {
            // Newell's method: robust for slightly non-planar or degenerate quads.
            let mut n = Vec3::ZERO;
            for (p, q) in [(a, b), (b, c), (c, d), (d, a)] {
                n += Vec3::new(
                    (p.y - q.y) * (p.z + q.z),
                    (p.z - q.z) * (p.x + q.x),
                    (p.x - q.x) * (p.y + q.y),
                );
            }
            let n = n.normalize_or_zero();
            let origin = (a + b + c + d) / 4.0;
            let plane = n.extend(-n.dot(origin));
            if plane.dot(centre.extend(1.0)) < 0.0 { -plane } else { plane }
        })
    }
}

/// Clips a convex polygon to the half-space n·p + d ≥ 0 (Sutherland–Hodgman).
fn clip_polygon(polygon: &[Vec3], plane: Vec4) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for (i, &p) in polygon.iter().enumerate() {
        let q = polygon[(i + 1) % polygon.len()];
        let (dp, dq) = (plane.dot(p.extend(1.0)), plane.dot(q.extend(1.0)));
        if dp >= 0.0 {
            out.push(p);
        }
        if (dp >= 0.0) != (dq >= 0.0) {
            out.push(p + (q - p) * (dp / (dp - dq)));
        }
    }
    out
}

/// The vertices of the intersection of two convex hexahedra (empty when they do not
/// meet). Every vertex of the intersection lies on a face of one of them inside the
/// other, so clipping each one's faces by the other's planes finds them all.
pub fn intersection_vertices(a: &Hexahedron, b: &Hexahedron) -> Vec<Vec3> {
    let mut points = Vec::new();
    for (faces, planes) in [(a.faces(), b.planes()), (b.faces(), a.planes())] {
        for face in faces {
            let mut polygon = face.to_vec();
            for plane in planes {
                polygon = clip_polygon(&polygon, plane);
                if polygon.is_empty() {
                    break;
                }
            }
            points.extend(polygon);
        }
    }
    points
}

/// The light's view for a directional light travelling along `direction` over
/// `scene`: orientation only, with the origin of depth outside the scene.
pub fn directional_light_view(direction: Vec3, scene: &Aabb) -> Mat4 {
    let direction = direction.normalize();
    let center = scene.center();
    let radius = scene.bounding_radius().max(1e-3);
    view_from_world_look_at(center - direction * (2.0 * radius), center, Vec3::Y)
}

/// An orthographic projection for a directional light over the receivers `receivers`
/// (world points, e.g. [`intersection_vertices`] of the view frustum and the scene):
/// x and y cover the receivers, z spans from the nearest point of `scene` toward the
/// light, where casters may be, to the farthest receiver. With no receivers, the map
/// covers the whole scene.
pub fn fit_directional_to_receivers(direction: Vec3, scene: &Aabb, receivers: &[Vec3]) -> LightProjection {
    let light_from_world = directional_light_view(direction, scene);
    let casters = scene.transformed(light_from_world);
    let seen = if receivers.is_empty() {
        casters
    } else {
        Aabb::from_points(receivers.iter().map(|&p| light_from_world.transform_point3(p)))
    };
    let margin = 1e-3 * scene.bounding_radius().max(1e-3);
    let (left, right) = (seen.min.x - margin, seen.max.x + margin);
    let (bottom, top) = (seen.min.y - margin, seen.max.y + margin);
    // View space looks down −z: the point nearest the light has the largest z.
    let near = -casters.max.z - margin;
    let far = -seen.min.z + margin;
    LightProjection::orthographic(light_from_world, (left, right, bottom, top), near, far)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ProjectionKind;

    use crate::test_rng::Lcg;

    fn random_camera(rng: &mut Lcg) -> Mat4 {
        let eye = rng.vec(-12.0, 12.0);
        let target = rng.vec(-3.0, 3.0);
        let view = view_from_world_look_at(eye, target + Vec3::new(1e-3, 0.0, 0.0), Vec3::Y);
        let near = rng.range(0.05, 1.0);
        let far = near + rng.range(2.0, 40.0);
        crate::camera_clip_from_view(rng.range(0.3, 1.8), rng.range(0.5, 2.5), near, far) * view
    }

    fn inside_frustum(clip_from_world: Mat4, p: Vec3, eps: f32) -> bool {
        let c = clip_from_world * p.extend(1.0);
        c.w > 0.0
            && c.x.abs() <= c.w * (1.0 + eps)
            && c.y.abs() <= c.w * (1.0 + eps)
            && c.z >= -eps * c.w
            && c.z <= c.w * (1.0 + eps)
    }

    #[test]
    fn intersection_of_a_box_with_itself_is_its_corners() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::new(2.0, 3.0, 1.0));
        let points = intersection_vertices(&Hexahedron::from_aabb(&b), &Hexahedron::from_aabb(&b));
        let hull = Aabb::from_points(points.iter().copied());
        assert!(
            (hull.min - b.min).abs().max_element() < 1e-5 && (hull.max - b.max).abs().max_element() < 1e-5
        );
    }

    #[test]
    fn intersection_vertices_lie_in_both_and_bound_every_common_point() {
        let mut rng = Lcg(7);
        let scene = Aabb::new(Vec3::new(-6.0, 0.0, -6.0), Vec3::new(6.0, 3.0, 6.0));
        for _ in 0..200 {
            let clip_from_world = random_camera(&mut rng);
            let frustum = Hexahedron::from_clip_from_world(clip_from_world);
            let points = intersection_vertices(&frustum, &Hexahedron::from_aabb(&scene));
            for p in &points {
                assert!(scene.contains(*p) || (p.clamp(scene.min, scene.max) - *p).length() < 1e-3);
                assert!(inside_frustum(clip_from_world, *p, 1e-3), "{p} outside the frustum");
            }
            // Every random point inside both lies within the vertices' bounding box
            // (the intersection is their convex hull).
            let hull = Aabb::from_points(points.iter().copied());
            for _ in 0..200 {
                let p = Vec3::new(
                    rng.range(scene.min.x, scene.max.x),
                    rng.range(scene.min.y, scene.max.y),
                    rng.range(scene.min.z, scene.max.z),
                );
                if inside_frustum(clip_from_world, p, 0.0) {
                    assert!(!points.is_empty());
                    let slack = 1e-3 * (1.0 + p.length());
                    assert!(
                        p.cmpge(hull.min - slack).all() && p.cmple(hull.max + slack).all(),
                        "common point {p} outside the intersection's bounds {hull:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn fitted_light_frustum_contains_every_receiver_and_every_caster_in_front_of_it() {
        let mut rng = Lcg(11);
        let scene = Aabb::new(Vec3::new(-6.0, 0.0, -6.0), Vec3::new(6.0, 3.0, 6.0));
        for _ in 0..200 {
            let clip_from_world = random_camera(&mut rng);
            let direction = Vec3::new(rng.range(-1.0, 1.0), -rng.range(0.1, 1.0), rng.range(-1.0, 1.0));
            let frustum = Hexahedron::from_clip_from_world(clip_from_world);
            let receivers = intersection_vertices(&frustum, &Hexahedron::from_aabb(&scene));
            let fitted = fit_directional_to_receivers(direction, &scene, &receivers);
            let light_clip = fitted.clip_from_world();
            // Random receiver points: inside the scene and the view frustum.
            for _ in 0..300 {
                let p = Vec3::new(
                    rng.range(scene.min.x, scene.max.x),
                    rng.range(scene.min.y, scene.max.y),
                    rng.range(scene.min.z, scene.max.z),
                );
                if !inside_frustum(clip_from_world, p, 0.0) {
                    continue;
                }
                let ndc = light_clip.project_point3(p);
                assert!(ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0, "receiver {p} outside the map: {ndc}");
                assert!((0.0..=1.0).contains(&ndc.z), "receiver {p} outside the depth range: {ndc}");
                // Any caster between it and the light, inside the scene, is in range too.
                let t = rng.range(0.0, 30.0);
                let caster = p - direction.normalize() * t;
                if scene.contains(caster) {
                    let c = light_clip.project_point3(caster);
                    assert!((0.0..=1.0).contains(&c.z), "caster {caster} outside the depth range: {c}");
                    assert!(
                        (c.truncate() - ndc.truncate()).length() < 1e-3,
                        "a caster shares its receiver's texel"
                    );
                }
            }
            // And the crop is never larger than the whole-scene fit.
            let whole = crate::directional_light_projection(direction, &scene);
            let (
                ProjectionKind::Orthographic { width: w, height: h },
                ProjectionKind::Orthographic { width: ws, height: hs },
            ) = (fitted.kind, whole.kind)
            else {
                unreachable!()
            };
            assert!(w <= ws * 1.0001 && h <= hs * 1.0001, "crop {w}×{h} vs scene {ws}×{hs}");
        }
    }

    #[test]
    fn a_slice_of_the_frustum_spans_its_fraction_of_each_edge() {
        let clip_from_world = crate::camera_clip_from_view(1.0, 1.5, 1.0, 11.0);
        let f = Hexahedron::from_clip_from_world(clip_from_world);
        let s = f.slice(0.5, 1.0);
        for i in 0..4 {
            assert!((s.corners[i] - f.corners[i].lerp(f.corners[i | 4], 0.5)).length() < 1e-5);
            assert!((s.corners[i | 4] - f.corners[i | 4]).length() < 1e-5);
        }
    }
}
