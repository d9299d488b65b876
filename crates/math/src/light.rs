//! Light-space projections: an orthographic box fitted to the scene for directional
//! lights, and a perspective frustum built from a spot light's cone.

use glam::{Mat4, Vec3};

use crate::{Aabb, projection::view_from_world_look_at};

/// The shape of a light's shadow projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProjectionKind {
    /// Parallel rays; `width` × `height` world units are covered by the map.
    Orthographic {
        /// Width of the window in light view space (along its x), in world units.
        width: f32,
        /// Height of the window in light view space (along its y), in world units.
        height: f32,
    },
    /// Rays from a point; `fov` is the full (square) field of view in radians.
    Perspective {
        /// Full field of view, the same horizontally and vertically, in radians.
        fov: f32,
    },
    /// Parallel rays through a perspective warp of the light's view plane
    /// ([`crate::warping`]): texels vary in size across the map. `width` × `height` is
    /// the world extent of the warped window's far edge and its depth along the warp's
    /// axis; the true size of a texel is local (see [`LightProjection::texel_world_size`]).
    Warped {
        /// World width of the warped window at its far edge, where its texels are largest.
        width: f32,
        /// World depth of the warped window along the warp's axis.
        height: f32,
    },
}

/// Everything a renderer needs to draw and sample one shadow map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightProjection {
    /// World space to the light's view space, which looks down −z. The transform is rigid (a
    /// cube face's is mirrored), so light-space distances are world units.
    pub light_from_world: Mat4,
    /// The light's view space to the map's clip space (WebGPU depth in [0, 1]): the
    /// orthographic, perspective or warped projection that `kind` describes.
    pub clip_from_light: Mat4,
    /// The projection's shape and size, which give a texel's size in world units.
    pub kind: ProjectionKind,
    /// Distance along the light's view axis of the depth-0 plane.
    pub near: f32,
    /// Distance along the light's view axis of the depth-1 plane.
    pub far: f32,
}

impl LightProjection {
    /// An orthographic projection of the light-space window left..right × bottom..top,
    /// from distance `near` to `far` along the light's view axis.
    pub fn orthographic(
        light_from_world: Mat4,
        (left, right, bottom, top): (f32, f32, f32, f32),
        near: f32,
        far: f32,
    ) -> LightProjection {
        LightProjection {
            light_from_world,
            clip_from_light: glam::camera::rh::proj::directx::orthographic(
                left, right, bottom, top, near, far,
            ),
            kind: ProjectionKind::Orthographic { width: right - left, height: top - bottom },
            near,
            far,
        }
    }

    /// World space to the map's clip space, `clip_from_light · light_from_world`: the matrix a
    /// shadow pass draws casters with, and the lighting pass projects receivers with.
    pub fn clip_from_world(&self) -> Mat4 {
        self.clip_from_light * self.light_from_world
    }

    /// World size of one texel of a `resolution`² map, at `distance` along the light's
    /// view axis (the distance is ignored for orthographic maps).
    pub fn texel_world_size(&self, resolution: u32, distance: f32) -> f32 {
        match self.kind {
            ProjectionKind::Orthographic { width, height } => width.max(height) / resolution as f32,
            ProjectionKind::Perspective { fov } => 2.0 * distance * (0.5 * fov).tan() / resolution as f32,
            // The largest texel, at the far edge: conservative for biases. The shader
            // measures the local size from the projection itself.
            ProjectionKind::Warped { width, height } => width.max(height) / resolution as f32,
        }
    }

    /// An orthographic projection's window in light view space: (left, right,
    /// bottom, top). None for a perspective one.
    pub fn orthographic_window(&self) -> Option<(f32, f32, f32, f32)> {
        let ProjectionKind::Orthographic { .. } = self.kind else { return None };
        let light_from_clip = self.clip_from_light.inverse();
        let low = light_from_clip.project_point3(Vec3::new(-1.0, -1.0, 0.0));
        let high = light_from_clip.project_point3(Vec3::new(1.0, 1.0, 0.0));
        Some((low.x, high.x, low.y, high.y))
    }

    /// The same orthographic projection with its depth range replaced: cascades share
    /// one range so that every layer stores depth with the same convention.
    /// Perspective projections are returned unchanged.
    pub fn with_depth_range(&self, near: f32, far: f32) -> LightProjection {
        let Some((left, right, bottom, top)) = self.orthographic_window() else { return *self };
        LightProjection {
            clip_from_light: glam::camera::rh::proj::directx::orthographic(
                left, right, bottom, top, near, far,
            ),
            near,
            far,
            ..*self
        }
    }

    /// The same orthographic projection with its window grown by `margin` light-space
    /// units on every side (its depth range kept). Perspective projections are
    /// returned unchanged.
    pub fn widened(&self, margin: f32) -> LightProjection {
        let Some((left, right, bottom, top)) = self.orthographic_window() else { return *self };
        let window = (left - margin, right + margin, bottom - margin, top + margin);
        LightProjection::orthographic(self.light_from_world, window, self.near, self.far)
    }

    /// The same orthographic projection with its near plane moved up to the nearest of
    /// `receivers` (world points), for a map drawn with depth clamping: casters in
    /// front of the plane are clamped onto it ("pancaking") and still shadow every
    /// receiver behind them, and the depth range spans only the receivers. Returned
    /// unchanged when that would not move the plane forward, and for other kinds.
    pub fn pancaked(&self, receivers: &[Vec3]) -> LightProjection {
        if !matches!(self.kind, ProjectionKind::Orthographic { .. }) || receivers.is_empty() {
            return *self;
        }
        let nearest = receivers
            .iter()
            .map(|p| -self.light_from_world.transform_point3(*p).z)
            .fold(f32::INFINITY, f32::min);
        let margin = 1e-3 * (self.far - self.near).abs().max(1e-6);
        let near = nearest - margin;
        if near > self.near && near < self.far { self.with_depth_range(near, self.far) } else { *self }
    }

    /// For a perspective map, the factor k such that a texel at view distance d spans
    /// k·d world units; for an orthographic map, the constant texel size. The shader
    /// uses `texel = k_ortho + k_persp · d`.
    pub fn texel_size_coefficients(&self, resolution: u32) -> (f32, f32) {
        match self.kind {
            ProjectionKind::Orthographic { .. } | ProjectionKind::Warped { .. } => {
                (self.texel_world_size(resolution, 0.0), 0.0)
            }
            ProjectionKind::Perspective { .. } => (0.0, self.texel_world_size(resolution, 1.0)),
        }
    }
}

/// An orthographic projection for a directional light travelling along `direction`,
/// fitted tightly to `bounds`: the box's corners, seen from the light, fill the map
/// in x and y, and span the depth range in z.
///
/// The fit is in light view space, so the map's texels are square in world units
/// only when the fitted width and height are equal; the shader uses the larger one
/// for the texel size, so biases stay conservative.
pub fn directional_light_projection(direction: Vec3, bounds: &Aabb) -> LightProjection {
    crate::fitting::fit_directional_to_receivers(direction, bounds, &[])
}

/// A perspective projection for a spot light at `position` pointing along
/// `direction`, whose full field of view covers the outer cone (half-angle
/// `outer_angle` radians), from `near` to `far` (usually the light's range).
pub fn spot_light_projection(
    position: Vec3,
    direction: Vec3,
    outer_angle: f32,
    near: f32,
    far: f32,
) -> LightProjection {
    let light_from_world = view_from_world_look_at(position, position + direction, Vec3::Y);
    let fov = 2.0 * outer_angle;
    LightProjection {
        light_from_world,
        clip_from_light: glam::camera::rh::proj::directx::perspective(fov, 1.0, near, far),
        kind: ProjectionKind::Perspective { fov },
        near,
        far,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ndc_to_texture;
    use glam::Vec4;

    fn project(m: Mat4, p: Vec3) -> Vec3 {
        let c = m * p.extend(1.0);
        c.truncate() / c.w
    }

    #[test]
    fn replacing_the_depth_range_keeps_the_window() {
        let bounds = Aabb::new(Vec3::new(-2.0, 0.0, -3.0), Vec3::new(2.0, 1.0, 3.0));
        let p = directional_light_projection(Vec3::new(0.3, -1.0, 0.1), &bounds);
        let q = p.with_depth_range(p.near - 5.0, p.far + 7.0);
        let (a, b) = (p.orthographic_window().unwrap(), q.orthographic_window().unwrap());
        assert!(
            (a.0 - b.0).abs() < 1e-4
                && (a.1 - b.1).abs() < 1e-4
                && (a.2 - b.2).abs() < 1e-4
                && (a.3 - b.3).abs() < 1e-4
        );
        for c in bounds.corners() {
            let (x, y) = (project(p.clip_from_world(), c), project(q.clip_from_world(), c));
            assert!((x.truncate() - y.truncate()).length() < 1e-4);
            assert!(y.z > 0.0 && y.z < 1.0 && (q.far - q.near - (p.far - p.near) - 12.0).abs() < 1e-3);
        }
    }

    #[test]
    fn widening_grows_the_window_on_every_side_and_keeps_depth() {
        let bounds = Aabb::new(Vec3::new(-2.0, 0.0, -3.0), Vec3::new(2.0, 1.0, 3.0));
        let p = directional_light_projection(Vec3::new(0.3, -1.0, 0.1), &bounds);
        let q = p.widened(0.5);
        let (a, b) = (p.orthographic_window().unwrap(), q.orthographic_window().unwrap());
        let grown = [a.0 - b.0, b.1 - a.1, a.2 - b.2, b.3 - a.3];
        assert!(grown.iter().all(|g| (g - 0.5).abs() < 1e-4), "{grown:?}");
        assert_eq!((q.near, q.far), (p.near, p.far));
        // A point keeps its depth, and the window's centre stays put.
        for c in bounds.corners() {
            let (x, y) = (project(p.clip_from_world(), c), project(q.clip_from_world(), c));
            assert!((x.z - y.z).abs() < 1e-5 && y.x.abs() < x.x.abs() + 1e-6 && y.y.abs() < x.y.abs() + 1e-6);
        }
        let spot = spot_light_projection(Vec3::ZERO, Vec3::NEG_Z, 0.5, 0.1, 10.0);
        assert_eq!(spot.widened(1.0).clip_from_light, spot.clip_from_light);
    }

    #[test]
    fn directional_light_straight_down_matches_hand_computed_box() {
        // Sun straight down onto the box [−2, 2] × [0, 1] × [−3, 3].
        let bounds = Aabb::new(Vec3::new(-2.0, 0.0, -3.0), Vec3::new(2.0, 1.0, 3.0));
        let p = directional_light_projection(Vec3::NEG_Y, &bounds);
        let m = p.clip_from_world();
        // The top of the box is nearest to the light, the bottom farthest. The fit adds
        // a margin of 1e-3 × the bounding radius (√53 / 2) on every side, so over the
        // depth range 1 + 2·margin the top sits at margin / (1 + 2·margin).
        let margin = 1e-3 * 53f32.sqrt() / 2.0;
        let top = project(m, Vec3::new(0.0, 1.0, 0.0));
        let bottom = project(m, Vec3::new(0.0, 0.0, 0.0));
        assert!((top.z - margin / (1.0 + 2.0 * margin)).abs() < 1e-6, "{top}");
        assert!((bottom.z - (1.0 + margin) / (1.0 + 2.0 * margin)).abs() < 1e-6, "{bottom}");
        // Looking down with the z-axis fallback up vector, the fitted extents are the
        // box's 4 × 6 footprint (plus the small margin).
        let ProjectionKind::Orthographic { width, height } = p.kind else { panic!() };
        let (w, h) = (width.min(height), width.max(height));
        assert!((w - 4.0).abs() < 0.02 && (h - 6.0).abs() < 0.02, "{w} × {h}");
        // Every corner lands inside the map.
        for c in bounds.corners() {
            let t = ndc_to_texture(project(m, c));
            assert!(t.cmpge(Vec3::splat(-1e-6)).all() && t.cmple(Vec3::splat(1.0 + 1e-6)).all());
        }
        // Texel size: the larger extent over the resolution.
        assert!((p.texel_world_size(1024, 0.0) - h / 1024.0).abs() < 1e-7);
    }

    #[test]
    fn directional_light_maps_parallel_rays_to_one_texel() {
        let bounds = Aabb::new(Vec3::splat(-5.0), Vec3::splat(5.0));
        let dir = Vec3::new(1.0, -2.0, 0.5).normalize();
        let m = directional_light_projection(dir, &bounds).clip_from_world();
        let a = project(m, Vec3::new(0.3, 1.0, -0.2));
        let b = project(m, Vec3::new(0.3, 1.0, -0.2) + 3.0 * dir);
        assert!((a.truncate() - b.truncate()).length() < 1e-5, "same ray, same xy");
        assert!(b.z > a.z, "farther along the light is deeper");
    }

    #[test]
    fn spot_light_matches_hand_computed_frustum() {
        // Spot at (0, 10, 0) pointing down, outer half-angle 45°: fov 90°, so the cone's
        // edge at the ground (distance 10) is 10 units from the axis and lands on the
        // map's edge.
        let p = spot_light_projection(Vec3::new(0.0, 10.0, 0.0), Vec3::NEG_Y, 45f32.to_radians(), 0.5, 20.0);
        let m = p.clip_from_world();
        let centre = project(m, Vec3::ZERO);
        assert!(centre.truncate().length() < 1e-5);
        // Hand-computed depth at distance 10: f(z − n)/(z(f − n)) = 20·9.5/(10·19.5).
        assert!((centre.z - 20.0 * 9.5 / (10.0 * 19.5)).abs() < 1e-5);
        let edge = project(m, Vec3::new(10.0, 0.0, 0.0));
        assert!((edge.x.abs().max(edge.y.abs()) - 1.0).abs() < 1e-5, "{edge}");
        // Texel size grows linearly with distance: 2·d·tan(45°)/res.
        assert!((p.texel_world_size(1000, 10.0) - 0.02).abs() < 1e-6);
        let (k0, k1) = p.texel_size_coefficients(1000);
        assert!(k0 == 0.0 && (k1 - 0.002).abs() < 1e-8);
        // Behind the light: w < 0.
        assert!((m * Vec4::new(0.0, 11.0, 0.0, 1.0)).w < 0.0);
    }

    #[test]
    fn pancaking_moves_the_near_plane_to_the_receivers_and_clamps_casters_onto_it() {
        let scene = Aabb::new(Vec3::new(-10.0, 0.0, -10.0), Vec3::new(10.0, 20.0, 10.0));
        let direction = Vec3::new(0.2, -1.0, 0.1).normalize();
        let full = directional_light_projection(direction, &scene);
        // Receivers on the ground; a caster high above them.
        let receivers = [Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, 5.0), Vec3::new(5.0, 1.0, -5.0)];
        let pancaked = full.pancaked(&receivers);
        assert!(pancaked.near > full.near + 10.0, "near {} against {}", pancaked.near, full.near);
        assert_eq!(pancaked.far, full.far);
        let depth = |p: &LightProjection, w: Vec3| project(p.clip_from_world(), w).z;
        for r in receivers {
            let z = depth(&pancaked, r);
            assert!((0.0..=1.0).contains(&z), "receiver depth {z}");
        }
        // The caster lies before the near plane: a clamping rasterizer stores 0 there,
        // still in front of the receiver below it, which keeps its shadow.
        let caster = Vec3::new(0.0, 15.0, 0.0);
        let below = caster + direction * (15.0 / -direction.y);
        assert!(depth(&pancaked, caster) < 0.0);
        assert!(depth(&pancaked, below) > 0.0);
        // Depth resolution over the receivers improves by the ratio of the ranges.
        let gain = (depth(&pancaked, receivers[2]) - depth(&pancaked, receivers[0]))
            / (depth(&full, receivers[2]) - depth(&full, receivers[0]));
        assert!(gain > 3.0, "gain {gain}");
        // Perspective projections are left alone.
        let spot = spot_light_projection(Vec3::Y * 10.0, Vec3::NEG_Y, 0.5, 0.1, 30.0);
        assert_eq!(spot.pancaked(&receivers), spot);
    }
}
