//! Which way a projection turns a triangle: the winding the rasterizer culls faces
//! by, found from the world-space triangle and the projection's centre, and a cone
//! of normals that answers it for a whole cluster of triangles at once, so that a
//! shadow pass can skip the clusters its cull mode would discard triangle by
//! triangle (Shirman & Abi-Ezzi, "The cone of normals technique for fast processing
//! of curved patches", 1993).
//!
//! Let A be the x, y and w rows of a projective `clip_from_world`. A triangle whose
//! homogeneous corners P₀, P₁, P₂ all lie in front of it (w > 0) has the signed NDC
//! area det(A·[P₀ P₁ P₂]) / (2·w₀·w₁·w₂), positive when it winds counter-clockwise
//! with y up (what `wgpu::FrontFace::Ccw` calls front). The determinant is an
//! alternating form in the three corners, so it is a dot product with their plane
//! π = (n, −n·p₀), n = (p₁ − p₀) × (p₂ − p₀):
//!
//!   det(A·[P₀ P₁ P₂]) = h · π,  h_j = (−1)^j · det(A without column j),
//!
//! and h, the kernel of A, is the centre of projection in homogeneous coordinates:
//! a point (the eye of a perspective) or a direction (w = 0, an orthographic view).
//! The winding of a triangle is the side of its plane the centre lies on. This holds
//! for every projective map, warped ones (PSM, LiSPSM, TSM) and mirrored cube faces
//! alike, and does not need to know which it is.

use glam::{DMat3, DVec3, DVec4, Mat4, Vec3};

use crate::Aabb;

/// How a triangle winds in normalized device coordinates, with y up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Winding {
    /// Counter-clockwise: the signed area is positive.
    CounterClockwise,
    /// Clockwise: the signed area is negative.
    Clockwise,
}

/// The centre of a projective `clip_from_world`, in homogeneous coordinates, scaled
/// so that its dot product with a triangle's plane is the triangle's doubled NDC
/// area times w₀·w₁·w₂ (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectionCentre {
    h: DVec4,
}

impl ProjectionCentre {
    /// The centre in homogeneous coordinates, (x, y, z, w): a point where w ≠ 0, a
    /// direction where w = 0. Any positive multiple of it answers every winding the
    /// same way, so a GPU culler may take it normalized.
    pub fn homogeneous(&self) -> DVec4 {
        self.h
    }

    /// The centre of `clip_from_world`, computed in f64 from its x, y and w rows.
    pub fn of(clip_from_world: Mat4) -> ProjectionCentre {
        let m = clip_from_world.as_dmat4();
        let rows = [m.row(0), m.row(1), m.row(3)];
        let minor = |skip: usize| {
            let column = |k: usize| {
                let pick = |row: DVec4| {
                    let kept: Vec<f64> = (0..4).filter(|&c| c != skip).map(|c| row[c]).collect();
                    kept[k]
                };
                DVec3::new(pick(rows[0]), pick(rows[1]), pick(rows[2]))
            };
            DMat3::from_cols(column(0), column(1), column(2)).determinant()
        };
        ProjectionCentre { h: DVec4::new(minor(0), -minor(1), minor(2), -minor(3)) }
    }

    /// The doubled signed NDC area of the triangle `corners` times w₀·w₁·w₂: its sign
    /// is the triangle's winding where every corner lies in front of the projection.
    /// Zero for a triangle seen edge-on, or a degenerate one.
    pub fn signed_area(&self, corners: [Vec3; 3]) -> f64 {
        let [p0, p1, p2] = corners.map(|p| p.as_dvec3());
        let n = (p1 - p0).cross(p2 - p0);
        self.h.dot(n.extend(-n.dot(p0)))
    }

    /// The winding of the triangle `corners` where every corner lies in front of the
    /// projection; None when it is seen edge-on.
    pub fn winding(&self, corners: [Vec3; 3]) -> Option<Winding> {
        let area = self.signed_area(corners);
        if area > 0.0 {
            Some(Winding::CounterClockwise)
        } else if area < 0.0 {
            Some(Winding::Clockwise)
        } else {
            None
        }
    }
}

/// A cone holding the normals of a cluster of triangles: every non-degenerate
/// triangle's normal (p₁ − p₀) × (p₂ − p₀) makes at most the cone's half-angle with
/// its axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalCone {
    /// Unit length.
    axis: DVec3,
    /// The sine of the half-angle, widened by [`NormalCone::MARGIN`].
    sin_half_angle: f64,
}

impl NormalCone {
    /// The cone's axis, unit length.
    pub fn axis(&self) -> DVec3 {
        self.axis
    }

    /// The sine of its half-angle, [`NormalCone::MARGIN`] included.
    pub fn sin_half_angle(&self) -> f64 {
        self.sin_half_angle
    }

    /// The angle the cone is widened by, in radians (about 0.6°): a triangle within it
    /// of being seen edge-on may still cover a sample once its corners are snapped to
    /// the rasterizer's sub-pixel grid, so it is never the one that decides.
    pub const MARGIN: f64 = 0.01;

    /// The cone of the normals of `triangles`: its axis is their mean direction, its
    /// half-angle the widest of them from it. None when the normals open to a
    /// hemisphere or more (nothing can be said of the cluster), or every triangle is
    /// degenerate.
    pub fn of_triangles(triangles: &[[Vec3; 3]]) -> Option<NormalCone> {
        let normals: Vec<DVec3> = triangles
            .iter()
            .filter_map(|t| {
                let [p0, p1, p2] = t.map(|p| p.as_dvec3());
                (p1 - p0).cross(p2 - p0).try_normalize()
            })
            .collect();
        let axis = normals.iter().sum::<DVec3>().try_normalize()?;
        let min_cos = normals.iter().map(|n| n.dot(axis)).fold(1.0f64, f64::min);
        let half_angle = min_cos.clamp(-1.0, 1.0).acos() + Self::MARGIN;
        (half_angle < std::f64::consts::FRAC_PI_2)
            .then(|| NormalCone { axis, sin_half_angle: half_angle.sin() })
    }

    /// The winding every triangle of the cluster has under the projection whose
    /// centre is `centre`, where its corners lie in front of it, when one winding holds
    /// for all of them: `bounds` holds the cluster's corners. None when the cluster
    /// may hold both.
    ///
    /// A triangle's area sign is that of h·π = −n·v with v = h_w·p − h_xyz for any
    /// point p of it (module docs), so it is the same for every normal n of the cone
    /// where the angle between v and the axis a stays under 90° minus the cone's
    /// half-angle θ, i.e. â·v̂ > sin θ. For v anywhere in the ball B(v_c, ρ) that the
    /// box's bounding sphere B(c, r) maps to (v_c = h_w·c − h_xyz, ρ = |h_w|·r),
    /// a·v ≥ a·v_c − ρ and |v| ≤ |v_c| + ρ, so a·v_c > sin θ·|v_c| + ρ·(1 + sin θ) is
    /// enough. An orthographic centre (h_w = 0) has ρ = 0: the test is then exact.
    pub fn winding(&self, centre: &ProjectionCentre, bounds: &Aabb) -> Option<Winding> {
        if bounds.is_empty() {
            return None;
        }
        let h = centre.h;
        let (min, max) = (bounds.min.as_dvec3(), bounds.max.as_dvec3());
        let c = 0.5 * (min + max);
        let r = 0.5 * (max - min).length();
        let v_c = h.w * c - h.truncate();
        let rho = h.w.abs() * r;
        let s = self.sin_half_angle;
        let needed = s * v_c.length() + rho * (1.0 + s);
        let along = self.axis.dot(v_c);
        if along > needed {
            // n·v > 0 for every normal and point: h·π < 0.
            Some(Winding::Clockwise)
        } else if -along > needed {
            Some(Winding::CounterClockwise)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::{Mat4, Vec3, Vec4Swizzles};

    use super::*;
    use crate::test_rng::Lcg;

    /// The doubled signed NDC area of `corners` under `clip_from_world`, by projecting
    /// them: None unless every corner lies in front (w > 0).
    fn projected_area(clip_from_world: Mat4, corners: [Vec3; 3]) -> Option<f64> {
        let clip = corners.map(|p| (clip_from_world * p.extend(1.0)).as_dvec4());
        if clip.iter().any(|c| c.w <= 1e-6) {
            return None;
        }
        let ndc = clip.map(|c| c.xy() / c.w);
        Some((ndc[1] - ndc[0]).perp_dot(ndc[2] - ndc[0]))
    }

    /// A perspective, an orthographic and a warped (perspective after orthographic)
    /// projection, each looking from a random place at the origin, some mirrored.
    fn random_projection(rng: &mut Lcg, kind: usize) -> Mat4 {
        let eye = rng.vec(-10.0, 10.0).normalize_or(Vec3::Z) * rng.range(4.0, 20.0);
        let up = if eye.normalize().y.abs() > 0.9 { Vec3::X } else { Vec3::Y };
        let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, up);
        let mirror =
            if rng.next() < 0.5 { Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)) } else { Mat4::IDENTITY };
        let projection = match kind % 3 {
            0 => glam::camera::rh::proj::directx::perspective(
                rng.range(0.3, 2.0),
                rng.range(0.5, 2.0),
                0.1,
                100.0,
            ),
            1 => glam::camera::rh::proj::directx::orthographic(-6.0, 6.0, -5.0, 5.0, 0.1, 100.0),
            _ => {
                glam::camera::rh::proj::directx::perspective(1.2, 1.0, 0.5, 50.0)
                    * Mat4::from_translation(Vec3::new(0.0, 0.0, -2.0))
                    * glam::camera::rh::proj::directx::orthographic(-6.0, 6.0, -5.0, 5.0, 0.1, 100.0)
            }
        };
        mirror * projection * view
    }

    #[test]
    fn the_centre_gives_every_projected_triangles_winding() {
        let mut rng = Lcg(7);
        let mut compared = 0;
        for case in 0..600 {
            let clip_from_world = random_projection(&mut rng, case);
            let centre = ProjectionCentre::of(clip_from_world);
            let corners = [rng.vec(-3.0, 3.0), rng.vec(-3.0, 3.0), rng.vec(-3.0, 3.0)];
            let Some(area) = projected_area(clip_from_world, corners) else { continue };
            if area.abs() < 1e-4 {
                continue;
            }
            let expected = if area > 0.0 { Winding::CounterClockwise } else { Winding::Clockwise };
            assert_eq!(centre.winding(corners), Some(expected), "case {case}: area {area}");
            compared += 1;
        }
        assert!(compared > 300, "only {compared} triangles were in front");
    }

    #[test]
    fn a_perspective_centre_is_its_eye_and_an_orthographic_one_its_direction() {
        let eye = Vec3::new(1.0, 2.0, 3.0);
        let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
        let perspective =
            ProjectionCentre::of(glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 10.0) * view);
        let point = perspective.h.truncate() / perspective.h.w;
        assert!(point.distance(eye.as_dvec3()) < 1e-5, "{point}");
        let ortho = ProjectionCentre::of(
            glam::camera::rh::proj::directx::orthographic(-1.0, 1.0, -1.0, 1.0, 0.1, 10.0) * view,
        );
        assert!(ortho.h.w.abs() < 1e-9 * ortho.h.length());
        let direction = ortho.h.truncate().normalize();
        assert!(direction.cross(eye.as_dvec3().normalize()).length() < 1e-6, "{direction}");
    }

    /// A cluster of `count` triangles around `centre`, each tilted from `axis` by at
    /// most `spread` radians, with random windings kept counter-clockwise about `axis`.
    fn cluster(rng: &mut Lcg, centre: Vec3, axis: Vec3, spread: f32, count: usize) -> Vec<[Vec3; 3]> {
        let (u, v) = axis.any_orthonormal_pair();
        (0..count)
            .map(|_| {
                let tilt = rng.range(0.0, spread);
                let around = rng.range(0.0, std::f32::consts::TAU);
                let normal = axis * tilt.cos() + (u * around.cos() + v * around.sin()) * tilt.sin();
                let (a, b) = normal.any_orthonormal_pair();
                let p0 = centre + rng.vec(-0.5, 0.5);
                let size = rng.range(0.05, 0.3);
                [p0, p0 + a * size, p0 + b * size]
            })
            .collect()
    }

    #[test]
    fn a_cones_winding_holds_for_every_triangle_it_bounds() {
        let mut rng = Lcg(11);
        let (mut decided, mut undecided) = (0, 0);
        for case in 0..400 {
            let clip_from_world = random_projection(&mut rng, case);
            let centre = ProjectionCentre::of(clip_from_world);
            let axis = rng.vec(-1.0, 1.0).normalize_or(Vec3::Y);
            let spread = rng.range(0.0, 1.2);
            let middle = rng.vec(-2.0, 2.0);
            let triangles = cluster(&mut rng, middle, axis, spread, 24);
            let cone = NormalCone::of_triangles(&triangles).expect("a cone under 90°");
            let bounds = Aabb::from_points(triangles.iter().flatten().copied());
            let Some(winding) = cone.winding(&centre, &bounds) else {
                undecided += 1;
                continue;
            };
            decided += 1;
            for t in &triangles {
                assert_eq!(centre.winding(*t), Some(winding), "case {case}");
                if let Some(area) = projected_area(clip_from_world, *t) {
                    assert_eq!(area > 0.0, winding == Winding::CounterClockwise, "case {case}");
                }
            }
        }
        // Not a vacuous bound: most narrow clusters are decided.
        assert!(decided > undecided / 2, "{decided} decided, {undecided} not");
    }

    #[test]
    fn a_flat_cluster_facing_the_centre_is_decided_and_a_closed_one_is_not() {
        let view = glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y);
        let centre =
            ProjectionCentre::of(glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 100.0) * view);
        let mut rng = Lcg(3);
        let facing = cluster(&mut rng, Vec3::ZERO, Vec3::Z, 0.2, 16);
        let bounds = Aabb::from_points(facing.iter().flatten().copied());
        let cone = NormalCone::of_triangles(&facing).unwrap();
        assert_eq!(cone.winding(&centre, &bounds), Some(Winding::CounterClockwise));
        let away: Vec<[Vec3; 3]> = facing.iter().map(|&[a, b, c]| [a, c, b]).collect();
        let cone = NormalCone::of_triangles(&away).unwrap();
        assert_eq!(cone.winding(&centre, &bounds), Some(Winding::Clockwise));
        // Both sides of a box: no cone.
        let mut both = facing.clone();
        both.extend(away);
        assert_eq!(NormalCone::of_triangles(&both), None);
        assert_eq!(NormalCone::of_triangles(&[[Vec3::ZERO; 3]]), None, "degenerate only");
    }
}
