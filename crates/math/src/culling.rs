//! Frustum culling: the planes of a projection's clip volume, and a conservative test
//! of a bounding box against them, so that a shadow pass skips the casters a light
//! cannot see.

use glam::{Mat4, Vec3, Vec4};

use crate::Aabb;

/// The six planes bounding a clip volume, each `(n, d)` with `n · p + d ≥ 0` inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frustum {
    /// Left, right, bottom, top, near, far.
    pub planes: [Vec4; 6],
}

impl Frustum {
    /// The planes of `clip_from_world`'s volume: −w ≤ x, y ≤ w and 0 ≤ z ≤ w (WebGPU
    /// depth), read off the matrix's rows (Gribb & Hartmann, "Fast extraction of
    /// viewing frustum planes from the world-view-projection matrix", 2001).
    pub fn from_clip_from_world(clip_from_world: Mat4) -> Frustum {
        let m = clip_from_world.transpose();
        let (x, y, z, w) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
        Frustum { planes: [w + x, w - x, w + y, w - y, z, w - z] }
    }

    /// Whether `bounds` may reach inside the volume: false only when the whole box
    /// lies outside one plane (it can say true for a box outside near a corner,
    /// never false for a box inside). `near` includes the near plane; a pass that
    /// clamps depth (pancaking) draws casters in front of it and leaves it out.
    pub fn intersects(&self, bounds: &Aabb, near: bool) -> bool {
        if bounds.is_empty() {
            return false;
        }
        self.planes.iter().enumerate().all(|(i, plane)| {
            if i == 4 && !near {
                return true;
            }
            // The box corner farthest along the plane's normal (the "p-vertex").
            let n = plane.truncate();
            let p = Vec3::select(n.cmpge(Vec3::ZERO), bounds.max, bounds.min);
            n.dot(p) + plane.w >= 0.0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{omni::cube_face_projections, test_rng::Lcg};

    #[test]
    fn boxes_inside_touching_and_outside_a_face() {
        let faces = cube_face_projections(Vec3::ZERO, 0.1, 10.0);
        // Layer 0 looks down +x.
        let frustum = Frustum::from_clip_from_world(faces[0].clip_from_world());
        let cube = |c: Vec3, h: f32| Aabb::new(c - Vec3::splat(h), c + Vec3::splat(h));
        assert!(frustum.intersects(&cube(Vec3::new(5.0, 0.0, 0.0), 0.5), true));
        assert!(!frustum.intersects(&cube(Vec3::new(-5.0, 0.0, 0.0), 0.5), true), "behind the face");
        assert!(!frustum.intersects(&cube(Vec3::new(12.0, 0.0, 0.0), 0.5), true), "beyond the range");
        assert!(!frustum.intersects(&cube(Vec3::new(2.0, 5.0, 0.0), 0.5), true), "beside the 90° cone");
        // Straddling the 45° boundary to the +y face: both faces draw it.
        let up = Frustum::from_clip_from_world(faces[2].clip_from_world());
        let seam = cube(Vec3::new(3.0, 3.0, 0.0), 0.3);
        assert!(frustum.intersects(&seam, true) && up.intersects(&seam, true));
        assert!(!frustum.intersects(&Aabb::EMPTY, true));
    }

    #[test]
    fn no_box_with_a_point_inside_is_culled() {
        // Property: a box holding a point that projects inside the volume is never
        // culled, with or without the near plane.
        let mut rng = Lcg(11);
        let faces = cube_face_projections(Vec3::new(1.0, -2.0, 0.5), 0.05, 20.0);
        for projection in faces {
            let clip_from_world = projection.clip_from_world();
            let frustum = Frustum::from_clip_from_world(clip_from_world);
            let world_from_clip = clip_from_world.inverse();
            for _ in 0..500 {
                let ndc = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(0.0, 1.0));
                let p = world_from_clip.project_point3(ndc);
                let b = Aabb::new(p - rng.vec(0.0, 2.0), p + rng.vec(0.0, 2.0));
                assert!(frustum.intersects(&b, true) && frustum.intersects(&b, false));
            }
        }
    }

    #[test]
    fn leaving_out_the_near_plane_keeps_casters_before_it() {
        let ortho = crate::LightProjection::orthographic(Mat4::IDENTITY, (-1.0, 1.0, -1.0, 1.0), 1.0, 5.0);
        let frustum = Frustum::from_clip_from_world(ortho.clip_from_world());
        // The view looks down −z: z = −0.5 is in front of the near plane at distance 1.
        let before = Aabb::new(Vec3::new(-0.1, -0.1, -0.6), Vec3::new(0.1, 0.1, -0.4));
        assert!(!frustum.intersects(&before, true));
        assert!(frustum.intersects(&before, false));
    }
}
