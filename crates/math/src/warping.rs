//! Perspective warps of a directional light's map: perspective shadow maps (PSM;
//! Stamminger & Drettakis 2002, in `psm`), light-space perspective shadow maps
//! (LiSPSM; Wimmer, Scherzer & Purgathofer, EGSR 2004) and trapezoidal shadow maps
//! (TSM; Martin & Tan, EGSR 2004).
//!
//! LiSPSM and TSM apply a perspective transform in the light's view plane, along the camera's
//! view direction projected onto that plane, so that receivers near the camera get
//! more texels than far ones. The transform's centre of projection q lies on the
//! camera's axis, a distance η before the nearest receiver; the map's sides are the
//! lines through q that touch the receivers' hull, and its near and far edges the
//! hull's extent along the axis. The two methods differ only in η:
//! - LiSPSM: η = n_opt = (z_n + √(z_n·z_f)) / sin γ, the distance that spreads the
//!   aliasing error evenly over the view depths z_n to z_f (γ: the angle between the
//!   view and light directions);
//! - TSM: η maps the focus point (here the view depth √(z_n·z_f) on the axis) to 80 %
//!   of the way from the near edge to the far edge of the map (the "80 % rule").
//!
//! The transform keeps the light's rays parallel to its depth axis, so depth
//! comparisons along a ray stay valid; stored depth is linear in light distance
//! divided by the axis coordinate, monotonic along every ray. When the light is nearly
//! parallel to the view direction the warp has nothing to work with and both methods
//! fall back to the orthographic receiver fit (η → ∞ is the orthographic limit).

mod psm;

use glam::{DMat2, DVec3, Mat4, Vec2, Vec3, Vec4};

use crate::{
    Aabb, LightProjection, ProjectionKind,
    fitting::{directional_light_view, fit_directional_to_receivers},
};

/// Which warp to apply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Warp {
    /// Perspective shadow maps: the map drawn in the camera's post-perspective space.
    Perspective,
    /// Light-space perspective shadow maps, with Wimmer's n_opt.
    LightSpacePerspective,
    /// Trapezoidal shadow maps, with the 80 % rule.
    Trapezoidal,
}

/// The camera as the warps see it.
#[derive(Clone, Copy, Debug)]
pub struct WarpView {
    /// Camera position, in world space.
    pub eye: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// View depths bounding the receivers (z_n, z_f), 0 < near < far.
    pub near: f32,
    /// See `near`: the far view depth of the receivers (z_f), in world units along `forward`.
    pub far: f32,
}

/// Below this sin γ the light is treated as parallel to the view direction.
const MIN_SIN_GAMMA: f32 = 0.02;
/// Where TSM's 80 % rule puts the focus point, in the map's NDC y (−1 at the near edge).
const TSM_FOCUS_NDC: f32 = 0.6;

/// The warped projection of a sun travelling along `direction` over `receivers` (world
/// points: the view frustum ∩ the scene), with casters anywhere in `scene`.
pub fn fit_warped(
    warp: Warp,
    direction: Vec3,
    scene: &Aabb,
    receivers: &[Vec3],
    view: &WarpView,
) -> LightProjection {
    let fallback = || fit_directional_to_receivers(direction, scene, receivers);
    if warp == Warp::Perspective {
        return psm::fit_perspective(direction, scene, receivers, view).unwrap_or_else(fallback);
    }
    let light_from_world = directional_light_view(direction, scene);
    // The view direction in the light's view plane: its length is sin γ.
    let forward_light = light_from_world.transform_vector3(view.forward);
    let axis = Vec2::new(forward_light.x, forward_light.y);
    let sin_gamma = axis.length();
    if receivers.len() < 3 || sin_gamma < MIN_SIN_GAMMA {
        return fallback();
    }
    let axis = axis / sin_gamma;
    let across = Vec2::new(-axis.y, axis.x);
    let points: Vec<Vec3> = receivers.iter().map(|&p| light_from_world.transform_point3(p)).collect();
    // Coordinates along the axis (t) and across it (b).
    let tb = |p: Vec3| Vec2::new(p.truncate().dot(axis), p.truncate().dot(across));
    let (t_near, t_far) = points.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &p| {
        let t = tb(p).x;
        (lo.min(t), hi.max(t))
    });
    let depth = t_far - t_near;
    if depth <= 1e-6 * scene.bounding_radius().max(1e-6) {
        return fallback();
    }
    let (z_n, z_f) = (view.near, view.far.max(view.near * (1.0 + 1e-4)));
    let eta = match warp {
        Warp::Perspective => unreachable!("PSM is fitted above"),
        Warp::LightSpacePerspective => (z_n + (z_n * z_f).sqrt()) / sin_gamma,
        Warp::Trapezoidal => {
            // The focus point on the camera's axis, at the view depth √(z_n·z_f).
            let focus = light_from_world.transform_point3(view.eye + view.forward * (z_n * z_f).sqrt());
            let delta = (tb(focus).x - t_near).clamp(0.0, depth);
            // y(t') = A + B/t' maps t' = η to −1 and η + λ to +1; solving
            // y(η + δ) = ξ for η gives η = λδ(1 − ξ) / ((1 + ξ)λ − 2δ).
            let denominator = (1.0 + TSM_FOCUS_NDC) * depth - 2.0 * delta;
            if denominator <= 0.0 {
                f32::INFINITY
            } else {
                depth * delta * (1.0 - TSM_FOCUS_NDC) / denominator
            }
        }
    };
    // Beyond this the warp is numerically an orthographic map anyway.
    if !eta.is_finite() || eta > 100.0 * depth || eta <= 0.0 {
        return fallback();
    }
    // The centre of projection q, on the camera's axis, η before the nearest receiver.
    let eye = tb(light_from_world.transform_point3(view.eye));
    let q = Vec2::new(t_near - eta, eye.y);
    // The map's sides: the extreme slopes, seen from q, of the receivers.
    let (slope_min, slope_max) = points.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &p| {
        let d = tb(p) - q;
        let s = d.y / d.x;
        (lo.min(s), hi.max(s))
    });
    let slope_span = (slope_max - slope_min).max(1e-9);
    // Depth spans every caster toward the light and every receiver away from it.
    let casters = scene.transformed(light_from_world);
    let margin = 1e-3 * scene.bounding_radius().max(1e-3);
    let near = -casters.max.z - margin;
    let far = points.iter().map(|p| -p.z).fold(f32::NEG_INFINITY, f32::max) + margin;

    // Rows of clip_from_light, acting on light view space (x, y, z, 1):
    //   w = t' = t − q_t                        (t = axis · (x, y))
    //   x = (2b' − (s_min + s_max)·t') / (s_max − s_min), so x/w = ±1 on the sides
    //   y = A·t' + B with A = 1 + 2η/λ, B = −2η(η + λ)/λ: y/w = −1 at t' = η, +1 at η + λ
    //   z = η·(−z_light − near)/(far − near): z/w in [0, 1] inside the map, since t' ≥ η
    let t_row = Vec4::new(axis.x, axis.y, 0.0, -q.x);
    let b_row = Vec4::new(across.x, across.y, 0.0, -q.y);
    let x_row = (2.0 * b_row - (slope_min + slope_max) * t_row) / slope_span;
    let a = 1.0 + 2.0 * eta / depth;
    let b = -2.0 * eta * (eta + depth) / depth;
    let y_row = a * t_row + Vec4::new(0.0, 0.0, 0.0, b);
    let z_row = Vec4::new(0.0, 0.0, -eta / (far - near), -eta * near / (far - near));
    let clip_from_light = Mat4::from_cols(x_row, y_row, z_row, t_row).transpose();
    LightProjection {
        light_from_world,
        clip_from_light,
        kind: ProjectionKind::Warped { width: slope_span * (eta + depth), height: depth },
        near,
        far,
    }
}

/// The world extent of the whole map at its coarsest among `points`: 2 / σ_min of the
/// Jacobian of NDC x and y along the light's x and y axes, the largest over the points.
/// A texel there spans this over the map's resolution.
fn largest_texel_span(clip_from_world: Mat4, light_from_world: Mat4, points: &[DVec3]) -> f32 {
    let clip_from_world = clip_from_world.as_dmat4();
    let world_from_light = light_from_world.as_dmat4().inverse();
    let (axis_x, axis_y) = (world_from_light.x_axis.truncate(), world_from_light.y_axis.truncate());
    let span = |p: &DVec3| {
        let clip = clip_from_world * p.extend(1.0);
        // d(xy/w)/dv = ((M v).xy·w − xy·(M v).w) / w².
        let along = |v: DVec3| {
            let dv = clip_from_world * v.extend(0.0);
            (dv.truncate().truncate() * clip.w - clip.truncate().truncate() * dv.w) / (clip.w * clip.w)
        };
        let jacobian = DMat2::from_cols(along(axis_x), along(axis_y));
        // σ_min² is the smaller eigenvalue of JᵀJ.
        let gram = jacobian.transpose() * jacobian;
        let (trace, det) = (gram.x_axis.x + gram.y_axis.y, gram.determinant());
        let sigma_min = (0.5 * (trace - (trace * trace - 4.0 * det).max(0.0).sqrt())).max(0.0).sqrt();
        2.0 / sigma_min.max(1e-30)
    };
    points.iter().map(span).fold(0.0f64, f64::max) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fitting::{Hexahedron, intersection_vertices};
    use glam::Vec4Swizzles;

    fn ndc(p: &LightProjection, world: Vec3) -> Vec3 {
        let c = p.clip_from_world() * world.extend(1.0);
        assert!(c.w > 0.0, "in front of the warp's centre");
        c.xyz() / c.w
    }

    pub(super) fn scene() -> (Aabb, Vec<Vec3>, WarpView) {
        let scene = Aabb::new(Vec3::new(-50.0, 0.0, -100.0), Vec3::new(50.0, 10.0, 0.0));
        let eye = Vec3::new(0.0, 2.0, 2.0);
        let view_from_world = crate::view_from_world_look_at(eye, Vec3::new(0.0, 1.0, -50.0), Vec3::Y);
        let clip = crate::camera_clip_from_view(1.0, 1.5, 0.5, 150.0) * view_from_world;
        let receivers =
            intersection_vertices(&Hexahedron::from_clip_from_world(clip), &Hexahedron::from_aabb(&scene));
        let forward = (Vec3::new(0.0, 1.0, -50.0) - eye).normalize();
        (scene, receivers, WarpView { eye, forward, near: 0.5, far: 120.0 })
    }

    #[test]
    fn every_receiver_lands_in_the_map_and_near_ones_get_more_texels() {
        let (bounds, receivers, view) = scene();
        // A sun from the side, well off the view direction.
        let direction = Vec3::new(1.0, -1.0, 0.2).normalize();
        for warp in [Warp::Perspective, Warp::LightSpacePerspective, Warp::Trapezoidal] {
            let p = fit_warped(warp, direction, &bounds, &receivers, &view);
            assert!(matches!(p.kind, ProjectionKind::Warped { .. }), "{warp:?} warps");
            for &r in &receivers {
                let n = ndc(&p, r);
                assert!(n.x.abs() <= 1.0 + 1e-3 && n.y.abs() <= 1.0 + 1e-3, "{warp:?}: {r} → {n}");
                assert!((-1e-3..=1.0 + 1e-3).contains(&n.z), "{warp:?}: depth {}", n.z);
            }
            // One world unit across the light near the camera spans more of the map
            // than the same unit far away.
            let span = |at: Vec3| (ndc(&p, at + Vec3::X) - ndc(&p, at)).truncate().length();
            let (near, far) = (span(Vec3::new(0.0, 0.0, -2.0)), span(Vec3::new(0.0, 0.0, -90.0)));
            assert!(near > 3.0 * far, "{warp:?}: near {near} far {far}");
        }
    }

    #[test]
    fn depth_increases_along_every_light_ray() {
        let (bounds, receivers, view) = scene();
        let direction = Vec3::new(0.3, -1.0, 0.5).normalize();
        for warp in [Warp::Perspective, Warp::LightSpacePerspective, Warp::Trapezoidal] {
            let p = fit_warped(warp, direction, &bounds, &receivers, &view);
            for &r in &receivers {
                let (a, b) = (ndc(&p, r - direction * 3.0), ndc(&p, r));
                assert!(b.z > a.z, "{warp:?}: farther from the light must be deeper");
                assert!((a.truncate() - b.truncate()).length() < 1e-3, "{warp:?}: a ray stays on one texel");
            }
        }
    }

    #[test]
    fn a_light_along_the_view_falls_back_to_the_orthographic_fit() {
        let (bounds, receivers, view) = scene();
        for warp in [Warp::Perspective, Warp::LightSpacePerspective, Warp::Trapezoidal] {
            for direction in [view.forward, -view.forward] {
                let p = fit_warped(warp, direction, &bounds, &receivers, &view);
                let expected = fit_directional_to_receivers(direction, &bounds, &receivers);
                assert_eq!(p, expected, "{warp:?}");
            }
        }
    }

    #[test]
    fn psm_warps_harder_than_lispsm() {
        // PSM's warp is set by the camera's own near plane; LiSPSM moves the centre of
        // projection back to n_opt to spread the error evenly, so its near texels are
        // less dense and its far ones less sparse (here 30 against 10).
        let (bounds, receivers, view) = scene();
        let direction = Vec3::new(1.0, -1.0, 0.2).normalize();
        let density_ratio = |warp| {
            let p = fit_warped(warp, direction, &bounds, &receivers, &view);
            let span = |at: Vec3| (ndc(&p, at + Vec3::X * 0.1) - ndc(&p, at)).truncate().length();
            span(Vec3::new(0.0, 0.0, -1.0)) / span(Vec3::new(0.0, 0.0, -90.0))
        };
        let (psm, lispsm) = (density_ratio(Warp::Perspective), density_ratio(Warp::LightSpacePerspective));
        assert!(psm > 2.0 * lispsm, "near/far texel density: PSM {psm}, LiSPSM {lispsm}");
    }

    #[test]
    fn lispsm_uses_wimmers_n_opt() {
        // With the light perpendicular to the view (sin γ = 1), the centre of projection
        // sits z_n + √(z_n·z_f) before the nearest receiver along the axis: a receiver at
        // the near edge maps to y = −1, and w there equals n_opt.
        let (bounds, receivers, view) = scene();
        let direction = Vec3::new(1.0, 0.0, 0.0);
        let p = fit_warped(Warp::LightSpacePerspective, direction, &bounds, &receivers, &view);
        let n_opt = view.near + (view.near * view.far).sqrt();
        let ws: Vec<f32> = receivers.iter().map(|&r| (p.clip_from_world() * r.extend(1.0)).w).collect();
        let w_min = ws.iter().copied().fold(f32::INFINITY, f32::min);
        // sin γ is that of the view direction, slightly tilted down: within 1 %.
        assert!((w_min - n_opt).abs() < 0.01 * n_opt, "w at the near edge {w_min}, n_opt {n_opt}");
    }
}
