//! Perspective shadow maps (PSM; Stamminger & Drettakis, SIGGRAPH 2002): the sun's map
//! is rendered in the camera's post-perspective space, where what is near the camera
//! is large and what is far is small, so the map's texels follow the screen's pixels.
//!
//! In that space the sun's parallel rays become the lines through one point L, the
//! image of the sun's direction (a point at infinity) under the camera's projection
//! (Kozlov, "Perspective shadow maps: care and feeding", GPU Gems 1, ch. 14):
//! - with the sun in front of the camera, L is an ordinary point light beyond the far
//!   plane, shining back toward the camera;
//! - with the sun behind the camera, L is an *inverted* point light: moving toward the
//!   sun takes a point away from L, so depth must decrease with the distance from L;
//! - with the sun perpendicular to the view direction, L is at infinity and the map is
//!   orthographic in post-perspective space.
//!
//! Casters behind the camera would be turned inside out by the projection, so the
//! virtual camera slides back along its axis until every potential caster is in front
//! of it by at least the receivers' near depth (Stamminger & Drettakis, §4.2). The
//! potential casters are the receivers swept toward the sun to the top of the scene's
//! box, seen from the sun.
//!
//! The whole construction is one projective 4×4 matrix from world space. Geometry that
//! still lies behind the virtual camera maps either to w ≤ 0 or to a depth outside
//! [0, 1], so the rasterizer's clipping discards it instead of drawing it inverted
//! (a test checks this).
//!
//! PSM fails when the sun is in the camera's view: L then sits among the receivers and
//! no single map around it covers them ("dueling frusta"). With the sun behind the
//! camera and close to its axis, L sits just beyond the receivers and the map would
//! need a window of nearly unbounded extent; there is nothing to gain there anyway, as
//! the light's rays follow the view's. The fit returns None in both cases, and when
//! the sun is nearly along the view direction, and the caller falls back.

use glam::{DMat4, DVec3, DVec4, Mat4, Vec3, dcamera};

use crate::{Aabb, LightProjection, ProjectionKind, fitting::directional_light_view};

use super::{MIN_SIN_GAMMA, WarpView, largest_texel_span};

/// L farther than this, relative to the size of the post-perspective point cloud,
/// counts as at infinity: the map is orthographic in post-perspective space.
const INFINITE_LIGHT: f64 = 1e4;
/// A receiver or caster less than this far in front of L's plane (as a cosine) would
/// need a map of unbounded extent: the sun is in view.
const MIN_COS_FROM_AXIS: f64 = 1e-3;

/// The PSM of a sun travelling along `direction` over `receivers` (world points: the
/// view frustum ∩ the scene), or None where PSM cannot work (see the module docs).
pub(super) fn fit_perspective(
    direction: Vec3,
    scene: &Aabb,
    receivers: &[Vec3],
    view: &WarpView,
) -> Option<LightProjection> {
    let light_from_world = directional_light_view(direction, scene);
    let clip_from_world = construct(direction, light_from_world, scene, receivers, view)?.clip_from_world;
    let clip_from_world = clip_from_world.as_mat4();
    // The depth fields describe the light's own view, as for the other warps.
    let casters_box = scene.transformed(light_from_world);
    let margin = 1e-3 * scene.bounding_radius().max(1e-3);
    let receiver_far =
        receivers.iter().map(|p| -light_from_world.transform_point3(*p).z).fold(f32::NEG_INFINITY, f32::max);
    let points: Vec<DVec3> = receivers.iter().map(|p| p.as_dvec3()).collect();
    let span = largest_texel_span(clip_from_world, light_from_world, &points);
    Some(LightProjection {
        light_from_world,
        clip_from_light: clip_from_world * light_from_world.inverse(),
        kind: ProjectionKind::Warped { width: span, height: span },
        near: -casters_box.max.z - margin,
        far: receiver_far + margin,
    })
}

/// A PSM and the virtual camera it was built around.
struct Construction {
    clip_from_world: DMat4,
    /// The camera's eye, slid back so that every potential caster is in front of it.
    #[cfg_attr(not(test), expect(dead_code, reason = "the tests check what lies behind it"))]
    virtual_eye: DVec3,
}

fn construct(
    direction: Vec3,
    light_from_world: Mat4,
    scene: &Aabb,
    receivers: &[Vec3],
    view: &WarpView,
) -> Option<Construction> {
    let to_light = -direction.as_dvec3().normalize();
    let forward = view.forward.as_dvec3().normalize();
    if receivers.len() < 3 || to_light.cross(forward).length() < MIN_SIN_GAMMA as f64 {
        return None;
    }
    let receivers: Vec<DVec3> = receivers.iter().map(|p| p.as_dvec3()).collect();
    let casters = potential_casters(light_from_world, scene, &receivers);

    // Slide the virtual camera back until everything is at least z_n in front of it.
    let eye = view.eye.as_dvec3();
    let depth = |p: &DVec3| (*p - eye).dot(forward);
    let nearest = receivers.iter().chain(&casters).map(depth).fold(f64::INFINITY, f64::min);
    let z_n = view.near as f64;
    let slide_back = (z_n - nearest).max(0.0);
    let virtual_eye = eye - forward * slide_back;
    let up = if forward.y.abs() < 0.9 { DVec3::Y } else { DVec3::X };
    let virtual_depths = receivers.iter().chain(&casters).map(|p| depth(p) + slide_back);
    let (near, far) = virtual_depths.fold((f64::INFINITY, 0.0f64), |(lo, hi), d| (lo.min(d), hi.max(d)));
    // A square 90° projection: its field of view only scales x and y, which the fit
    // below absorbs.
    let post_from_world = dcamera::rh::proj::directx::perspective(
        std::f64::consts::FRAC_PI_2,
        1.0,
        near,
        far.max(near * 1.001),
    ) * dcamera::rh::view::look_to_mat4(virtual_eye, forward, up);

    let post = |p: &DVec3| post_from_world.project_point3(*p);
    let receivers_post: Vec<DVec3> = receivers.iter().map(post).collect();
    let casters_post: Vec<DVec3> = casters.iter().map(post).collect();
    let light_h = post_from_world * to_light.extend(0.0);
    let extent = receivers_post.iter().chain(&casters_post).map(|p| p.length()).fold(1e-9, f64::max);
    let clip_from_post = if light_h.w.abs() * INFINITE_LIGHT <= light_h.truncate().length() / extent {
        fit_orthographic(light_h.truncate().normalize(), &receivers_post, &casters_post)
    } else {
        let light = light_h.truncate() / light_h.w;
        fit_point(light, light_h.w < 0.0, &receivers_post, &casters_post)?
    };
    Some(Construction { clip_from_world: clip_from_post * post_from_world, virtual_eye })
}

/// Each receiver moved toward the sun to the top of the scene's box as the sun sees it:
/// their hull holds every point that can shadow a receiver.
fn potential_casters(light_from_world: Mat4, scene: &Aabb, receivers: &[DVec3]) -> Vec<DVec3> {
    let light_from_world = light_from_world.as_dmat4();
    let top = scene.transformed(light_from_world.as_mat4()).max.z as f64;
    let world_from_light = light_from_world.inverse();
    receivers
        .iter()
        .map(|&p| {
            let mut light = light_from_world.transform_point3(p);
            light.z = light.z.max(top);
            world_from_light.transform_point3(light)
        })
        .collect()
}

/// Two unit vectors completing `axis` to an orthonormal frame, square to
/// post-perspective x (the screen's horizontal) unless the axis lies along it. The
/// window is a rectangle in this frame, so keeping it aligned with the screen's axes
/// keeps it tight around the receivers, which fill the screen: an arbitrary rotation
/// (glam's `any_orthonormal_pair`) measured mean m 2.72 instead of 0.66 on `columns`.
fn frame_around(axis: DVec3) -> (DVec3, DVec3) {
    let helper = if axis.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let across = axis.cross(helper).normalize();
    (across, axis.cross(across))
}

/// Rows (x, y) that map `lo..hi` along `row` onto −1..1, for coordinates divided by w.
fn window_row(row: DVec4, w_row: DVec4, (lo, hi): (f64, f64)) -> DVec4 {
    (2.0 * row - (lo + hi) * w_row) / (hi - lo).max(1e-12)
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

/// L at infinity: the light travels along −`toward_light` through post-perspective
/// space, and the map is an orthographic box there.
fn fit_orthographic(toward_light: DVec3, receivers: &[DVec3], casters: &[DVec3]) -> DMat4 {
    let axis = -toward_light;
    let (across, up) = frame_around(axis);
    let row = |v: DVec3| v.extend(0.0);
    let w_row = DVec4::W;
    let x_row = window_row(row(across), w_row, range(receivers.iter().map(|p| p.dot(across))));
    let y_row = window_row(row(up), w_row, range(receivers.iter().map(|p| p.dot(up))));
    let (start, _) = range(receivers.iter().chain(casters).map(|p| p.dot(axis)));
    let (_, end) = range(receivers.iter().map(|p| p.dot(axis)));
    let pad = 1e-4 * (end - start).abs().max(1e-9);
    let (start, end) = (start - pad, end + pad);
    let z_row = (row(axis) - start * w_row) / (end - start);
    DMat4::from_cols(x_row, y_row, z_row, w_row).transpose()
}

/// L a point (an inverted one when the sun is behind the camera): a frustum from L
/// around the receivers, its depth increasing toward the receivers for an ordinary
/// light and away from them for an inverted one. None when some receiver or caster is
/// (nearly) beside or behind L.
fn fit_point(light: DVec3, inverted: bool, receivers: &[DVec3], casters: &[DVec3]) -> Option<DMat4> {
    let axis = receivers.iter().map(|p| (*p - light).normalize()).sum::<DVec3>().normalize();
    if !axis.is_finite()
        || receivers
            .iter()
            .chain(casters)
            .any(|p| (*p - light).dot(axis) < MIN_COS_FROM_AXIS * (*p - light).length())
    {
        return None;
    }
    let (across, up) = frame_around(axis);
    // Rows acting on homogeneous post-perspective points (p, 1): w is the distance
    // along the axis from L, and x/w, y/w the slopes of the ray from L.
    let row = |v: DVec3| v.extend(-v.dot(light));
    let w_row = row(axis);
    let slopes =
        |v: DVec3| range(receivers.iter().map(move |p| (*p - light).dot(v) / (*p - light).dot(axis)));
    let x_row = window_row(row(across), w_row, slopes(across));
    let y_row = window_row(row(up), w_row, slopes(up));
    // Depth z/w = A + B/w is 0 at w0, the end nearest the sun, and 1 at w1, the farthest
    // receiver from it (Kozlov's inverted projection when the sun is behind).
    let w_of = |p: &DVec3| (*p - light).dot(axis);
    let (all_lo, all_hi) = range(receivers.iter().chain(casters).map(w_of));
    let (receivers_lo, receivers_hi) = range(receivers.iter().map(w_of));
    let (w0, w1) = if inverted {
        (all_hi * (1.0 + 1e-4), receivers_lo * (1.0 - 1e-4))
    } else {
        (all_lo * (1.0 - 1e-4), receivers_hi * (1.0 + 1e-4))
    };
    let b = 1.0 / (1.0 / w1 - 1.0 / w0);
    let a = -b / w0;
    let z_row = a * w_row + DVec4::new(0.0, 0.0, 0.0, b);
    Some(DMat4::from_cols(x_row, y_row, z_row, w_row).transpose())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Lcg;
    use crate::warping::tests::scene;

    /// Sun directions (of travel) around the sky: in front of the camera, behind it,
    /// beside it, high and low.
    fn suns() -> Vec<Vec3> {
        let mut rng = Lcg(7);
        (0..64)
            .map(|_| {
                let azimuth = rng.range(0.0, std::f32::consts::TAU);
                let elevation = rng.range(0.1, 1.45);
                -Vec3::new(elevation.cos() * azimuth.cos(), elevation.sin(), elevation.cos() * azimuth.sin())
            })
            .collect()
    }

    #[test]
    fn nothing_behind_the_virtual_camera_reaches_the_map() {
        // The rasterizer keeps a point only where w > 0, |x|, |y| ≤ w and 0 ≤ z ≤ w:
        // a point behind the virtual camera must fail one of them, or it would be
        // drawn inverted as a false caster.
        let (bounds, receivers, view) = scene();
        let mut rng = Lcg(11);
        let (mut built, mut behind) = (0, 0);
        for direction in suns() {
            let light_from_world = directional_light_view(direction, &bounds);
            let Some(psm) = construct(direction, light_from_world, &bounds, &receivers, &view) else {
                continue;
            };
            built += 1;
            let forward = view.forward.as_dvec3();
            for _ in 0..2000 {
                let t = rng.vec(0.0, 1.0).as_dvec3();
                let p = DVec3::new(-150.0, -20.0, -200.0) + t * DVec3::new(300.0, 60.0, 400.0);
                let clip = psm.clip_from_world * p.extend(1.0);
                let kept = clip.w > 0.0
                    && clip.x.abs() <= clip.w
                    && clip.y.abs() <= clip.w
                    && (0.0..=clip.w).contains(&clip.z);
                if (p - psm.virtual_eye).dot(forward) <= 0.0 {
                    behind += 1;
                    assert!(!kept, "sun {direction}: {p} behind the virtual eye is drawn at {clip}");
                }
            }
        }
        assert!(built > 20 && behind > 1000, "{built} maps built, {behind} points behind");
    }

    #[test]
    fn receivers_fill_the_map_and_casters_fit_its_depth() {
        let (bounds, receivers, view) = scene();
        let mut built = 0;
        for direction in suns() {
            let light_from_world = directional_light_view(direction, &bounds);
            let Some(psm) = construct(direction, light_from_world, &bounds, &receivers, &view) else {
                continue;
            };
            built += 1;
            let points: Vec<DVec3> = receivers.iter().map(|p| p.as_dvec3()).collect();
            let casters = potential_casters(light_from_world, &bounds, &points);
            let ndc = |p: DVec3| {
                let c = psm.clip_from_world * p.extend(1.0);
                assert!(c.w > 0.0, "sun {direction}: {p} has w {}", c.w);
                c.truncate() / c.w
            };
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for &r in &points {
                let n = ndc(r);
                (lo, hi) = (lo.min(n), hi.max(n));
                assert!(n.x.abs() <= 1.0 + 1e-6 && n.y.abs() <= 1.0 + 1e-6, "sun {direction}: {n}");
            }
            // Each receiver's highest potential caster lies on its light ray: the same
            // place in the map, nearer the sun, and within the depth range.
            for (&r, c) in points.iter().zip(casters) {
                let (r, c) = (ndc(r), ndc(c));
                assert!((r.truncate() - c.truncate()).length() < 1e-4, "sun {direction}: {c} over {r}");
                assert!(c.z <= r.z + 1e-9, "sun {direction}: caster depth {} beyond {}", c.z, r.z);
                assert!((-1e-6..=1.0 + 1e-6).contains(&c.z), "sun {direction}: caster depth {}", c.z);
            }
            // The window is tight: the receivers reach each side.
            assert!(lo.x < -0.999 && hi.x > 0.999 && lo.y < -0.999 && hi.y > 0.999, "{lo} {hi}");
        }
        // The others are in view or nearly along it. Without the slide-back, casters
        // behind the camera would leave only about half of them a PSM.
        assert!(built >= 56, "only {built} of 64 suns gave a PSM");
    }

    #[test]
    fn a_sun_in_view_gets_no_psm() {
        // Dueling frusta: the sun's image sits among the receivers.
        let (bounds, receivers, view) = scene();
        let toward_sun = (view.forward + Vec3::new(0.1, 0.15, 0.0)).normalize();
        let direction = -toward_sun;
        let light_from_world = directional_light_view(direction, &bounds);
        assert!(construct(direction, light_from_world, &bounds, &receivers, &view).is_none());
        // A sun behind the camera and above it gets one.
        let direction = -(Vec3::new(0.3, 1.0, 1.0)).normalize();
        let light_from_world = directional_light_view(direction, &bounds);
        assert!(construct(direction, light_from_world, &bounds, &receivers, &view).is_some());
    }
}
