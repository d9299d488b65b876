//! Whether a whole area light is in sight from a point, asked of the BVH at once: the
//! cone that holds every shadow ray the sampler could trace toward the light is
//! tested against the nodes and triangles, and where nothing that could block a ray
//! lies in it, the light is wholly visible, exactly as all of the rays would have
//! found one by one.
//!
//! This is shaft culling (E. Haines and J. Wallace, "Shaft Culling for Efficient
//! Ray-Cast Radiosity", Eurographics Workshop on Rendering, 1991), with an
//! eight-sided pyramid around the cone for the shaft. Every test is conservative: a
//! box or triangle not wholly beyond one of the pyramid's planes counts as touching
//! the cone, and then the caller samples the light ray by ray as before.
//! So the answer "clear" is only ever given where every sampled ray would have
//! arrived, and the reference's image does not change (`visibility.rs` tests this
//! against sampling every pixel).

use glam::{DVec3, UVec2, Vec3, Vec3A};
use obvhs::{cwbvh::node::extract_byte64, traverse};

use super::TracedScene;

/// Every segment that starts at `apex` and runs along a unit direction within
/// `half_angle` of `axis`, for up to `length` (infinite for a sun).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayCone {
    pub apex: Vec3,
    pub axis: Vec3,
    pub half_angle: f32,
    pub length: f32,
}

/// The surface a cone's rays leave: the plane through `point` with unit normal
/// `normal`. The rays start above it and climb (every direction of the cone has a
/// positive component along `normal`), so a triangle that lies wholly lower than
/// their start cannot meet one: the receiver's own triangle and its flat neighbours,
/// which touch the cone's apex, are left out this way instead of failing the test.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Receiver {
    pub point: Vec3,
    pub normal: Vec3,
}

/// How many side planes bound the cone: the pyramid they make holds the cone, and
/// with eight its cross-section is an octagon about 5 % larger than the cone's disk.
const SIDES: usize = 8;

/// A convex pyramid that holds a [`RayCone`]: its side planes through the apex and its
/// far plane, as outward normals. A point is outside when it lies beyond any one.
struct Pyramid {
    apex: Vec3,
    sides: [Vec3; SIDES],
    axis: Vec3,
    length: f32,
}

impl Pyramid {
    /// The pyramid whose side planes touch the cone: each at `half_angle` from the
    /// axis, tilted toward one of [`SIDES`] directions around it. (A point at angle
    /// θ toward u is `t(a cos θ + u sin θ)`, on the plane of outward normal
    /// `u cos θ − a sin θ`.) Circumscribed about the cone, so the cone is inside.
    fn around(cone: &RayCone) -> Self {
        let (a, b) = cone.axis.any_orthonormal_pair();
        // The octagon's planes touch the cone along their middles; at their corners
        // the pyramid is wider, never narrower.
        let (sin, cos) = cone.half_angle.sin_cos();
        let sides = std::array::from_fn(|k| {
            let phi = std::f32::consts::TAU * k as f32 / SIDES as f32;
            let u = a * phi.cos() + b * phi.sin();
            u * cos - cone.axis * sin
        });
        Pyramid { apex: cone.apex, sides, axis: cone.axis, length: cone.length }
    }

    /// Whether points all beyond one face of the pyramid: then none of them is
    /// inside. `points` is a box's corners or a triangle's vertices (the convex hull
    /// of points beyond a plane is beyond it too). A rounding slack of a hundred
    /// thousandth of the points' distance keeps the answer conservative.
    fn excludes(&self, points: &[Vec3]) -> bool {
        let scale = points.iter().map(|p| (*p - self.apex).length()).fold(0.0f32, f32::max);
        let slack = 1e-5 * scale;
        let beyond =
            |normal: Vec3, offset: f32| points.iter().all(|p| (*p - self.apex).dot(normal) - offset > slack);
        self.sides.iter().any(|n| beyond(*n, 0.0))
            || beyond(self.axis, self.length)
            || beyond(-self.axis, 0.0)
    }

    fn excludes_box(&self, min: Vec3, max: Vec3) -> bool {
        let corners: [Vec3; 8] = std::array::from_fn(|k| {
            Vec3::new(
                if k & 1 == 0 { min.x } else { max.x },
                if k & 2 == 0 { min.y } else { max.y },
                if k & 4 == 0 { min.z } else { max.z },
            )
        });
        self.excludes(&corners)
    }
}

impl TracedScene {
    /// True when no triangle that could block a ray of `cone` lies in the cone: every
    /// ray of it reaches its end. Triangles lying wholly lower, along the receiver's
    /// normal, than the cone's apex stands above `receiver` are left out (see
    /// [`Receiver`]); the caller guarantees that every direction of the cone climbs
    /// away from that plane. Casters and non-casters, opaque and cut-out triangles
    /// alike count as blocking: the test is conservative.
    pub(crate) fn cone_is_clear(&self, cone: &RayCone, receiver: &Receiver) -> bool {
        // Heights above the receiver's plane in f64, where the difference of two f32
        // points is exact: a vertex's height is then off by far less than the apex's
        // own height, which Wächter & Binder's offset makes hundreds of ulps.
        let normal = receiver.normal.as_dvec3();
        let point = receiver.point.as_dvec3();
        let height = |v: Vec3A| (Vec3::from(v).as_dvec3() - point).dot(normal);
        let apex_height = (cone.apex.as_dvec3() - point).dot(normal);
        // Half the apex's height: a margin for the ray tests' own rounding.
        let below = 0.5 * apex_height;
        let pyramid = Pyramid::around(cone);
        let bvh = &self.bvh;
        let mut clear = true;
        let mut state = bvh.new_traversal(Vec3A::from(cone.axis));
        let mut node;
        'walk: {
            traverse!(
                bvh,
                node,
                state,
                {
                    let (child_bits8, bit_index8) = node.get_child_and_index_bits(state.oct_inv4);
                    let mut hit_mask = 0u32;
                    for child in 0..8 {
                        let b = node.child_aabb(child);
                        if !pyramid.excludes_box(b.min.into(), b.max.into()) {
                            hit_mask |=
                                extract_byte64(child_bits8, child) << extract_byte64(bit_index8, child);
                        }
                    }
                    hit_mask
                },
                {
                    let tri = &self.triangles[state.primitive_id as usize];
                    let lower = apex_height > 0.0
                        && height(tri.v0) < below
                        && height(tri.v1) < below
                        && height(tri.v2) < below;
                    if !lower && !pyramid.excludes(&[tri.v0.into(), tri.v1.into(), tri.v2.into()]) {
                        clear = false;
                        break 'walk;
                    }
                }
            );
        }
        clear
    }
}

/// A ball of `radius` around `center`, seen from `from`: the unit axis toward it and
/// the half-angle it subtends, widened by a hair for rounding; None where `from` is
/// within twice the radius (the cone would be too wide to clear anything).
pub(crate) fn ball_cone(from: Vec3, center: Vec3, radius: f32) -> Option<(Vec3, f32, f32)> {
    let to = center.as_dvec3() - from.as_dvec3();
    let distance = to.length();
    let radius = f64::from(radius);
    // (Also where the distance is NaN, at a degenerate light.)
    if distance.partial_cmp(&(2.0 * radius)) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let axis: DVec3 = to / distance;
    let half_angle = (radius / distance).asin() * (1.0 + 1e-4) + 1e-6;
    Some((axis.as_vec3(), half_angle as f32, distance as f32))
}
