//! Camera projection and the mapping between NDC and shadow-map texture space.

use glam::{Mat4, Vec2, Vec3};

/// `view_from_world` for a camera or light at `eye` looking at `target`.
///
/// `up` is a hint; when it is nearly parallel to the view direction another axis is
/// used so that the basis never degenerates (a sun straight overhead, say).
pub fn view_from_world_look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    let forward = (target - eye).normalize();
    let up = if forward.cross(up).length_squared() < 1e-6 {
        // Any axis not parallel to `forward` works; z is the usual fallback for y-up worlds.
        if forward.z.abs() < 0.9 { Vec3::Z } else { Vec3::X }
    } else {
        up
    };
    glam::camera::rh::view::look_at_mat4(eye, target, up)
}

/// A right-handed perspective projection to WebGPU clip space (depth 0 at `near`,
/// 1 at `far`, y up). `fov_y` is the full vertical field of view in radians.
pub fn camera_clip_from_view(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    glam::camera::rh::proj::directx::perspective(fov_y, aspect, near, far)
}

/// The affine map from NDC (x, y in [−1, 1], y up; z in [0, 1]) to texture space
/// (u, v in [0, 1], v down; depth unchanged): u = x/2 + 1/2, v = −y/2 + 1/2.
///
/// Because it is affine it commutes with the perspective divide, so
/// `texture_from_ndc() * clip_from_world` may be applied before dividing by w.
pub fn texture_from_ndc() -> Mat4 {
    Mat4::from_cols_array(&[
        0.5, 0.0, 0.0, 0.0, //
        0.0, -0.5, 0.0, 0.0, //
        0.0, 0.0, 1.0, 0.0, //
        0.5, 0.5, 0.0, 1.0,
    ])
}

/// [`texture_from_ndc`] applied to a point: returns (u, v, depth).
pub fn ndc_to_texture(ndc: Vec3) -> Vec3 {
    Vec3::new(0.5 * ndc.x + 0.5, 0.5 - 0.5 * ndc.y, ndc.z)
}

/// The inverse of [`ndc_to_texture`] for the xy part: texture (u, v) to NDC (x, y).
pub fn texture_to_ndc(uv: Vec2) -> Vec2 {
    Vec2::new(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y)
}

/// View-space distance along the view axis for a depth-buffer value `depth` written by
/// [`camera_clip_from_view`] (or any `directx::perspective`) with planes `near`, `far`.
///
/// From z_ndc = f(z − n) / (z (f − n)) solved for z: z = n f / (f − z_ndc (f − n)).
pub fn linearize_perspective_depth(depth: f32, near: f32, far: f32) -> f32 {
    near * far / (far - depth * (far - near))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 1e-5 * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn ndc_corners_map_to_texture_corners_with_y_flip() {
        // NDC top-left (−1, +1) is texel (0, 0); bottom-right (+1, −1) is (1, 1).
        assert_eq!(ndc_to_texture(Vec3::new(-1.0, 1.0, 0.0)), Vec3::new(0.0, 0.0, 0.0));
        assert_eq!(ndc_to_texture(Vec3::new(1.0, -1.0, 1.0)), Vec3::new(1.0, 1.0, 1.0));
        assert_eq!(ndc_to_texture(Vec3::new(0.0, 0.0, 0.25)), Vec3::new(0.5, 0.5, 0.25));
        // NDC y = +0.5 (upper half) is v = 0.25.
        assert_eq!(ndc_to_texture(Vec3::new(0.5, 0.5, 0.5)), Vec3::new(0.75, 0.25, 0.5));
    }

    #[test]
    fn texture_matrix_matches_function_and_commutes_with_divide() {
        let clip = Vec4::new(0.3, -0.8, 0.6, 2.0);
        let via_matrix = texture_from_ndc() * clip;
        let after_divide = via_matrix.truncate() / via_matrix.w;
        let expected = ndc_to_texture(clip.truncate() / clip.w);
        assert!((after_divide - expected).abs().max_element() < 1e-6);
        let uv = Vec2::new(0.2, 0.9);
        let back = ndc_to_texture(texture_to_ndc(uv).extend(0.0));
        assert!((back.truncate() - uv).abs().max_element() < 1e-6);
    }

    #[test]
    fn perspective_maps_near_and_far_to_zero_and_one() {
        let (near, far) = (0.5, 100.0);
        let m = camera_clip_from_view(60f32.to_radians(), 16.0 / 9.0, near, far);
        let at = |z: f32| {
            let c = m * Vec4::new(0.0, 0.0, -z, 1.0);
            c.z / c.w
        };
        assert!(close(at(near), 0.0));
        assert!(close(at(far), 1.0));
        // Hand-computed: z = 1 gives f(z − n)/(z(f − n)) = 100·0.5/99.5.
        assert!(close(at(1.0), 100.0 * 0.5 / 99.5));
        for z in [0.5, 0.7, 3.0, 42.0, 99.0] {
            assert!(close(linearize_perspective_depth(at(z), near, far), z), "z = {z}");
        }
        // y up: a point above the axis lands at positive NDC y, with 60° full fov the
        // top of the frustum at distance 1 is y = tan 30°.
        let top = m * Vec4::new(0.0, 30f32.to_radians().tan(), -1.0, 1.0);
        assert!(close(top.y / top.w, 1.0));
    }

    #[test]
    fn look_at_puts_target_on_negative_z() {
        let v = view_from_world_look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
        assert!((v.transform_point3(Vec3::ZERO) - Vec3::new(0.0, 0.0, -5.0)).length() < 1e-6);
        // Straight down, where the y hint is degenerate: still a valid rotation.
        let v = view_from_world_look_at(Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, Vec3::Y);
        assert!((v.transform_point3(Vec3::ZERO) - Vec3::new(0.0, 0.0, -10.0)).length() < 1e-5);
        assert!((v.determinant() - 1.0).abs() < 1e-5);
    }
}
