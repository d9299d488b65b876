//! Omnidirectional shadow-map parametrizations for point lights: the six 90° faces of
//! a cube map, laid out as WebGPU samples them, and the two hemispheres of a
//! dual-paraboloid map (Brabec, Annen & Seidel, "Shadow mapping for hemispherical and
//! omnidirectional light sources", CGI 2002).
//!
//! Cube sampling picks the face by the direction's major axis and takes the other two
//! coordinates, divided by it, as (s, t) with t growing downward (Vulkan spec,
//! "Cube Map Face Selection", the same table as D3D and OpenGL). A face is rendered
//! with [`cube_face_view`] and [`cube_face_projection`]: a direction lands in the face's
//! NDC exactly where that table sends it, so a lookup reads the texel it was drawn
//! into. Matching the table needs a mirrored view (determinant −1): a face pass must
//! flip its front-face winding.

use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::{LightProjection, ProjectionKind};

/// The six faces in WebGPU's layer order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CubeFace {
    /// The face the +x axis passes through (layer 0).
    PositiveX,
    /// The face the −x axis passes through (layer 1).
    NegativeX,
    /// The face the +y axis (up) passes through (layer 2).
    PositiveY,
    /// The face the −y axis (down) passes through (layer 3).
    NegativeY,
    /// The face the +z axis passes through (layer 4).
    PositiveZ,
    /// The face the −z axis passes through (layer 5).
    NegativeZ,
}

impl CubeFace {
    /// Every face, in layer order: `ALL[i].layer() == i`.
    pub const ALL: [CubeFace; 6] = [
        CubeFace::PositiveX,
        CubeFace::NegativeX,
        CubeFace::PositiveY,
        CubeFace::NegativeY,
        CubeFace::PositiveZ,
        CubeFace::NegativeZ,
    ];

    /// The face's array layer.
    pub fn layer(self) -> u32 {
        self as u32
    }

    /// The face a direction (any length, not zero) is sampled from: its major axis.
    /// Ties go to x, then y, as the spec leaves them to the implementation.
    pub fn of_direction(d: Vec3) -> CubeFace {
        let a = d.abs();
        if a.x >= a.y && a.x >= a.z {
            if d.x >= 0.0 { CubeFace::PositiveX } else { CubeFace::NegativeX }
        } else if a.y >= a.z {
            if d.y >= 0.0 { CubeFace::PositiveY } else { CubeFace::NegativeY }
        } else if d.z >= 0.0 {
            CubeFace::PositiveZ
        } else {
            CubeFace::NegativeZ
        }
    }

    /// The spec's (s axis, t axis, major axis) for this face, as unit vectors:
    /// s = d·s_axis / |m|, t = d·t_axis / |m|, with m = d·major.
    fn axes(self) -> (Vec3, Vec3, Vec3) {
        match self {
            CubeFace::PositiveX => (Vec3::NEG_Z, Vec3::NEG_Y, Vec3::X),
            CubeFace::NegativeX => (Vec3::Z, Vec3::NEG_Y, Vec3::NEG_X),
            CubeFace::PositiveY => (Vec3::X, Vec3::Z, Vec3::Y),
            CubeFace::NegativeY => (Vec3::X, Vec3::NEG_Z, Vec3::NEG_Y),
            CubeFace::PositiveZ => (Vec3::X, Vec3::NEG_Y, Vec3::Z),
            CubeFace::NegativeZ => (Vec3::NEG_X, Vec3::NEG_Y, Vec3::NEG_Z),
        }
    }
}

/// Where a cube lookup along `d` lands: its face and texture coordinates (u right, v
/// down, in [0, 1]).
pub fn cube_face_uv(d: Vec3) -> (CubeFace, Vec2) {
    let face = CubeFace::of_direction(d);
    let (s, t, major) = face.axes();
    let m = d.dot(major);
    (face, Vec2::new(0.5 * (d.dot(s) / m + 1.0), 0.5 * (d.dot(t) / m + 1.0)))
}

/// The view of `face` from a light at `position`: view x along the face's s axis, view
/// y against its t axis (NDC y is up, texture v down), and the view looking down −z
/// along the major axis. The basis is mirrored (determinant −1), see the module docs.
pub fn cube_face_view(face: CubeFace, position: Vec3) -> Mat4 {
    let (s, t, major) = face.axes();
    let rotation = Mat3::from_cols(s, -t, -major).transpose();
    Mat4::from_mat3(rotation) * Mat4::from_translation(-position)
}

/// The 90° square projection of every face, from `near` to `far` (WebGPU depth in
/// [0, 1]). A point light's faces share it: near and far come from its range.
pub fn cube_face_projection(near: f32, far: f32) -> Mat4 {
    glam::camera::rh::proj::directx::perspective(std::f32::consts::FRAC_PI_2, 1.0, near, far)
}

/// The six face projections of a point light's cube map at `position`, from `near`
/// to `far`, in layer order. Each is a 90° perspective [`LightProjection`], so the
/// renderer draws and culls a face like any other layer.
pub fn cube_face_projections(position: Vec3, near: f32, far: f32) -> [LightProjection; 6] {
    CubeFace::ALL.map(|face| LightProjection {
        light_from_world: cube_face_view(face, position),
        clip_from_light: cube_face_projection(near, far),
        kind: ProjectionKind::Perspective { fov: std::f32::consts::FRAC_PI_2 },
        near,
        far,
    })
}

/// World size of one cube-map texel across the ray to a receiver `offset` from the
/// light, for faces of `resolution`² texels. A face texel at major-axis distance m is
/// 2m / resolution wide in the face's plane; seen across a ray at angle θ to the
/// major axis it is cos θ = m / |offset| as wide, the smallest it gets (the shader's
/// `cube_texel_world_size`).
pub fn cube_texel_world_size(offset: Vec3, resolution: u32) -> f32 {
    let major = offset.abs().max_element();
    2.0 * major * major / (resolution as f32 * offset.length().max(f32::MIN_POSITIVE))
}

/// The two hemispheres of a point light's dual-paraboloid map at `position`, as
/// layers: each `light_from_world` is the hemisphere's frame (its axis along +z:
/// world −y for layer 0, +y for layer 1, so the lower hemisphere, where most
/// receivers are, is whole), and each `clip_from_light` an orthographic box over the
/// hemisphere out to `far`, a conservative volume for culling casters. The shader
/// maps directions with [`paraboloid_coords`], not with the box.
pub fn paraboloid_projections(position: Vec3, near: f32, far: f32) -> [LightProjection; 2] {
    // Rotations taking world −y, then +y, to +z; both keep world x as x.
    let lower = Mat3::from_cols(Vec3::X, Vec3::Z, -Vec3::Y).transpose();
    let upper = Mat3::from_cols(Vec3::X, -Vec3::Z, Vec3::Y).transpose();
    [lower, upper].map(|rotation| {
        let light_from_world = Mat4::from_mat3(rotation) * Mat4::from_translation(-position);
        // The box looks down its −z: flip z so the hemisphere (z ≥ 0) lies in front.
        let flip = Mat4::from_scale(Vec3::new(1.0, 1.0, -1.0));
        LightProjection {
            light_from_world,
            clip_from_light: glam::camera::rh::proj::directx::orthographic(-far, far, -far, far, 0.0, far)
                * flip,
            kind: ProjectionKind::Orthographic { width: 2.0 * far, height: 2.0 * far },
            near,
            far,
        }
    })
}

/// World size of one dual-paraboloid texel across the ray to a receiver at `offset`
/// in its hemisphere's frame (axis +z), for `resolution`² layers: the map's xy =
/// tan(θ/2) has dxy/dθ = 1 / (1 + cos θ), so a texel (2 / resolution in xy) spans
/// (1 + cos θ)·2/resolution radians, 4/resolution on the axis and half that at the
/// rim (the shader's `paraboloid_texel_world_size`).
pub fn paraboloid_texel_world_size(offset: Vec3, resolution: u32) -> f32 {
    (offset.length() + offset.z) * 2.0 / resolution as f32
}

/// A dual-paraboloid map's coordinates of light-space direction `d` (unit length):
/// the front hemisphere (z ≥ 0) maps to (x, y) / (1 + z), the back one mirrors z. The
/// result lies in the unit disk; the flag says which hemisphere.
pub fn paraboloid_coords(d: Vec3) -> (bool, Vec2) {
    let front = d.z >= 0.0;
    let z = if front { d.z } else { -d.z };
    (front, Vec2::new(d.x, d.y) / (1.0 + z))
}

/// The inverse of [`paraboloid_coords`]: the unit direction at `p` (in the unit disk)
/// of the given hemisphere.
pub fn paraboloid_direction(front: bool, p: Vec2) -> Vec3 {
    // On the paraboloid z = ½ − ½(x² + y²), the normal (x, y, 1) halves the angle
    // between the view axis and the direction: d = (2x, 2y, 1 − r²) / (1 + r²).
    let r2 = p.length_squared();
    let z = (1.0 - r2) / (1.0 + r2);
    let d = Vec3::new(2.0 * p.x / (1.0 + r2), 2.0 * p.y / (1.0 + r2), z);
    if front { d } else { Vec3::new(d.x, d.y, -d.z) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ndc_to_texture, test_rng::Lcg};

    fn random_direction(rng: &mut Lcg) -> Vec3 {
        loop {
            let d = rng.vec(-1.0, 1.0);
            if d.length_squared() > 1e-4 && d.length_squared() <= 1.0 {
                return d.normalize();
            }
        }
    }

    #[test]
    fn a_face_draws_every_direction_where_the_cube_lookup_reads_it() {
        let mut rng = Lcg(3);
        let light = Vec3::new(1.0, 2.0, -3.0);
        let projection = cube_face_projection(0.05, 50.0);
        for _ in 0..2000 {
            let d = random_direction(&mut rng);
            let (face, uv) = cube_face_uv(d);
            let world = light + d * rng.range(0.1, 40.0);
            let clip = projection * cube_face_view(face, light) * world.extend(1.0);
            assert!(clip.w > 0.0, "{d} in front of face {face:?}");
            let ndc = clip.truncate() / clip.w;
            assert!(ndc.x.abs() <= 1.0 + 1e-5 && ndc.y.abs() <= 1.0 + 1e-5 && (0.0..=1.0).contains(&ndc.z));
            let drawn = ndc_to_texture(ndc).truncate();
            assert!((drawn - uv).length() < 1e-4, "{d}: drawn at {drawn}, looked up at {uv} on {face:?}");
        }
    }

    #[test]
    fn face_projections_draw_the_cube_layers_in_order() {
        let light = Vec3::new(-2.0, 1.0, 0.5);
        let faces = cube_face_projections(light, 0.02, 10.0);
        for (layer, projection) in faces.iter().enumerate() {
            let face = CubeFace::ALL[layer];
            assert_eq!(face.layer(), layer as u32);
            // The face's own axis lands at the centre of its layer, in front of the light.
            let (_, _, major) = face.axes();
            let ndc = projection.clip_from_world().project_point3(light + major * 3.0);
            assert!(ndc.truncate().length() < 1e-5 && (0.0..1.0).contains(&ndc.z), "{face:?}: {ndc}");
            assert_eq!(projection.near, 0.02);
            assert_eq!(projection.far, 10.0);
        }
    }

    #[test]
    fn paraboloid_layers_split_the_sphere_at_the_horizon() {
        let light = Vec3::new(1.0, 2.0, -1.0);
        let [lower, upper] = paraboloid_projections(light, 0.01, 10.0);
        let down = lower.light_from_world.transform_point3(light - Vec3::Y);
        let up = upper.light_from_world.transform_point3(light + Vec3::Y);
        assert!(down.abs_diff_eq(Vec3::Z, 1e-6) && up.abs_diff_eq(Vec3::Z, 1e-6), "{down} {up}");
        let mut rng = Lcg(5);
        for _ in 0..500 {
            let d = random_direction(&mut rng);
            let p = light + d * rng.range(0.1, 9.0);
            // Every point within range is in exactly the hemisphere its y says, and that
            // layer's culling box holds it.
            let layer = if d.y <= 0.0 { &lower } else { &upper };
            let z = layer.light_from_world.transform_point3(p).z;
            assert!(z >= -1e-5, "{d}: z {z}");
            let ndc = layer.clip_from_world().project_point3(p);
            assert!(ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0 && (-1e-6..=1.0).contains(&ndc.z), "{d}: {ndc}");
            let (front, xy) = paraboloid_coords(layer.light_from_world.transform_vector3(d));
            assert!(front && xy.length() <= 1.0 + 1e-5);
        }
    }

    #[test]
    fn paraboloid_texels_halve_from_axis_to_rim() {
        // Measured against the mapping itself: one texel step in xy at the axis and at
        // the rim, turned into an angle by paraboloid_direction.
        let res = 256;
        let step = 2.0 / res as f32;
        for (xy, offset) in [(0.0f32, Vec3::Z * 5.0), (1.0 - step, Vec3::X * 5.0)] {
            let a = paraboloid_direction(true, Vec2::new(xy - 0.5 * step, 0.0));
            let b = paraboloid_direction(true, Vec2::new(xy + 0.5 * step, 0.0));
            let measured = 5.0 * a.angle_between(b);
            let size = paraboloid_texel_world_size(offset, res);
            assert!((measured - size).abs() < 0.02 * size, "at xy {xy}: {measured} against {size}");
        }
    }

    #[test]
    fn cube_texels_shrink_toward_face_corners() {
        // On the axis, a texel spans 2d / resolution; toward a corner it is seen at
        // an angle, and spans less across the ray.
        let on_axis = cube_texel_world_size(Vec3::new(0.0, 0.0, -4.0), 512);
        assert!((on_axis - 8.0 / 512.0).abs() < 1e-7);
        let corner = Vec3::new(1.0, 1.0, 1.0) * (4.0 / 3f32.sqrt());
        let at_corner = cube_texel_world_size(corner, 512);
        assert!((at_corner - on_axis / 3.0).abs() < 1e-6, "{at_corner}");
    }

    #[test]
    fn lookups_follow_the_specs_face_selection_table() {
        // Worked from the Vulkan spec's table: s = ½(sc/|ma| + 1), t = ½(tc/|ma| + 1).
        let cases = [
            (Vec3::new(1.0, 0.5, 0.25), CubeFace::PositiveX, Vec2::new(0.375, 0.25)),
            (Vec3::new(-1.0, 0.5, 0.25), CubeFace::NegativeX, Vec2::new(0.625, 0.25)),
            (Vec3::new(0.5, 1.0, 0.25), CubeFace::PositiveY, Vec2::new(0.75, 0.625)),
            (Vec3::new(0.25, -1.0, 0.5), CubeFace::NegativeY, Vec2::new(0.625, 0.25)),
            (Vec3::new(0.25, 0.5, 1.0), CubeFace::PositiveZ, Vec2::new(0.625, 0.25)),
            (Vec3::new(0.25, 0.5, -1.0), CubeFace::NegativeZ, Vec2::new(0.375, 0.25)),
        ];
        for (d, face, uv) in cases {
            for scale in [1.0, 3.0] {
                let (f, got) = cube_face_uv(d * scale);
                assert_eq!(f, face, "{d}");
                assert!((got - uv).length() < 1e-6, "{d}: {got} against {uv}");
            }
        }
    }

    #[test]
    fn faces_meet_along_their_edges_and_their_views_are_mirrored() {
        // A direction on the edge between two faces reaches the same border of both.
        let edge = Vec3::new(1.0, 0.3, 1.0).normalize();
        let (s, t) = (CubeFace::PositiveX.axes(), CubeFace::PositiveZ.axes());
        let uv = |axes: (Vec3, Vec3, Vec3)| {
            let m = edge.dot(axes.2);
            Vec2::new(0.5 * (edge.dot(axes.0) / m + 1.0), 0.5 * (edge.dot(axes.1) / m + 1.0))
        };
        let (on_x, on_z) = (uv(s), uv(t));
        assert!(on_x.x.abs() < 1e-6 && (on_z.x - 1.0).abs() < 1e-6, "{on_x} {on_z}");
        assert!((on_x.y - on_z.y).abs() < 1e-6);
        for face in CubeFace::ALL {
            let det = cube_face_view(face, Vec3::ZERO).determinant();
            assert!((det + 1.0).abs() < 1e-6, "{face:?}: determinant {det}");
            assert_eq!(CubeFace::ALL[face.layer() as usize], face);
        }
    }

    #[test]
    fn paraboloid_coordinates_cover_the_disk_and_invert() {
        let mut rng = Lcg(5);
        for _ in 0..2000 {
            let d = random_direction(&mut rng);
            let (front, p) = paraboloid_coords(d);
            assert!(p.length() <= 1.0 + 1e-6);
            assert_eq!(front, d.z >= 0.0);
            let back = paraboloid_direction(front, p);
            assert!((back - d).length() < 1e-5, "{d} → {p} → {back}");
        }
        // The rim of the disk is the hemisphere's horizon, its centre the axis.
        assert!((paraboloid_coords(Vec3::X).1 - Vec2::X).length() < 1e-6);
        assert_eq!(paraboloid_coords(Vec3::Z).1, Vec2::ZERO);
    }
}
