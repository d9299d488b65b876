//! Cascaded shadow maps for directional lights: where the view frustum is split
//! along its depth, and how each slice's light projection is fitted, tightly to the
//! slice's receivers or stably to its bounding sphere with texel snapping.

use glam::{Mat4, Vec3};

use crate::{
    Aabb, LightProjection,
    fitting::{Hexahedron, directional_light_view, fit_directional_to_receivers, intersection_vertices},
};

/// How the view depth range is divided among the cascades.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SplitScheme {
    /// Equal depth ranges: z_i = n + (f − n)·i/N.
    Uniform,
    /// Equal ratios: z_i = n·(f/n)^(i/N), which matches the perspective texel
    /// density (Lloyd, Tuft, Yoon & Manocha 2006).
    Logarithmic,
    /// Parallel-split shadow maps (Zhang, Sun, Xu & Lo 2006): z_i = λ·log_i +
    /// (1 − λ)·uniform_i. λ = 1 is fully logarithmic, λ = 0 uniform.
    Practical {
        /// Weight of the logarithmic split against the uniform one, in [0, 1].
        lambda: f32,
    },
}

/// The N + 1 view depths bounding N cascades, from `near` to `far` inclusive.
pub fn split_distances(scheme: SplitScheme, count: usize, near: f32, far: f32) -> Vec<f32> {
    let n = count.max(1);
    (0..=n)
        .map(|i| {
            if i == 0 {
                return near;
            }
            if i == n {
                return far;
            }
            let t = i as f32 / n as f32;
            let uniform = near + (far - near) * t;
            let log = near * (far / near).powf(t);
            match scheme {
                SplitScheme::Uniform => uniform,
                SplitScheme::Logarithmic => log,
                SplitScheme::Practical { lambda } => lambda * log + (1.0 - lambda) * uniform,
            }
        })
        .collect()
}

/// The slice of a view frustum (`view_frustum` from near to far, `near`..`far` in view
/// depth) between view depths `from` and `to`. The frustum's edges run linearly in
/// view depth from the near to the far face.
pub fn frustum_slice(view_frustum: &Hexahedron, near: f32, far: f32, from: f32, to: f32) -> Hexahedron {
    let t = |z: f32| (z - near) / (far - near);
    view_frustum.slice(t(from), t(to))
}

/// A perspective view, for [`view_slice`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerspectiveView {
    /// The eye, in world space.
    pub eye: Vec3,
    /// A point it looks at.
    pub target: Vec3,
    /// Up, roughly: the view's y axis is made orthogonal to the view direction.
    pub up: Vec3,
    /// The full vertical field of view, in radians.
    pub fov_y: f32,
    /// Width over height.
    pub aspect: f32,
}

/// The slice of a perspective view between view depths `from` and `to`, with
/// [`Hexahedron`]'s corner order, built from the view's eye, axes and field of view
/// in f64 instead of interpolated between the faces of its frustum. An f32 frustum
/// whose far plane is 10⁴ times its near one has corners off by about 10⁻⁴ of their
/// distance, enough to change a stable cascade's size from one frame to the next.
pub fn view_slice(view: &PerspectiveView, from: f32, to: f32) -> Hexahedron {
    let eye = view.eye.as_dvec3();
    let forward = (view.target.as_dvec3() - eye).normalize();
    let right = forward.cross(view.up.as_dvec3()).normalize();
    let up = right.cross(forward);
    let tan_y = (0.5 * f64::from(view.fov_y)).tan();
    let tan_x = tan_y * f64::from(view.aspect);
    let corners = std::array::from_fn(|k| {
        let depth = f64::from(if k & 4 == 0 { from } else { to });
        let sx = if k & 1 == 0 { -1.0 } else { 1.0 };
        let sy = if k & 2 == 0 { -1.0 } else { 1.0 };
        (eye + depth * (forward + sx * tan_x * right + sy * tan_y * up)).as_vec3()
    });
    Hexahedron { corners }
}

/// A cascade's projection fitted tightly: the light's map covers exactly the slice's
/// potential receivers (the slice ∩ the scene). With `depth_clamp` its depth range
/// starts at the nearest of them ([`LightProjection::pancaked`]).
pub fn fit_cascade_tight(
    direction: Vec3,
    scene: &Aabb,
    slice: &Hexahedron,
    depth_clamp: bool,
) -> LightProjection {
    let receivers = intersection_vertices(slice, &Hexahedron::from_aabb(scene));
    let fitted = fit_directional_to_receivers(direction, scene, &receivers);
    if depth_clamp { fitted.pancaked(&receivers) } else { fitted }
}

/// A cascade's projection fitted stably: a square window of the slice's bounding
/// sphere's diameter, whose size does not change as the camera turns, placed on the
/// texel grid of a `resolution`² map, so that moving the camera moves the window by
/// whole texels and the rasterised shadow does not shimmer (Valient, "Stable cascaded
/// shadow maps", ShaderX6 2008).
pub fn fit_cascade_stable(
    direction: Vec3,
    scene: &Aabb,
    slice: &Hexahedron,
    resolution: u32,
) -> LightProjection {
    fit_cascade_stable_with_margin(direction, scene, slice, resolution, 0.0)
}

/// [`fit_cascade_stable`] with its window grown by `margin` on every side before it
/// is placed on the texel grid (a margin that does not follow the camera keeps the
/// cascade still).
pub fn fit_cascade_stable_with_margin(
    direction: Vec3,
    scene: &Aabb,
    slice: &Hexahedron,
    resolution: u32,
    margin: f32,
) -> LightProjection {
    let light_from_world = directional_light_view(direction, scene);
    let centre = slice.corners.iter().copied().sum::<Vec3>() / 8.0;
    let radius = slice.corners.iter().map(|c| c.distance(centre)).fold(0.0f32, f32::max) + margin.max(0.0);
    // Round the radius up to a fixed quantum so float noise in the corners cannot
    // change the window's size from frame to frame.
    let radius = (radius * 16.0).ceil() / 16.0;
    let texel = 2.0 * radius / resolution as f32;
    let c = light_from_world.transform_point3(centre);
    let snapped = Vec3::new((c.x / texel).floor() * texel, (c.y / texel).floor() * texel, c.z);
    // Depth spans the whole scene along the light, whatever the slice: a depth range
    // that followed the camera would change every stored depth a little each frame.
    let casters = scene.transformed(light_from_world);
    let margin = 1e-3 * scene.bounding_radius().max(1e-3);
    let near = -casters.max.z - margin;
    let far = -casters.min.z + margin;
    let (left, right) = (snapped.x - radius, snapped.x + radius);
    let (bottom, top) = (snapped.y - radius, snapped.y + radius);
    LightProjection::orthographic(light_from_world, (left, right, bottom, top), near, far)
}

/// A tight cascade narrowed to the light-space bounds of the samples it serves (SDSM;
/// Lauritzen, Salvi & Lefohn 2011, §3.2): the window becomes `samples` (min x, min y,
/// max x, max y in the light's view space) within the tight window, widened on each
/// side by `margin_texels` texels of the result, so that filter kernels and normal
/// offsets read inside the map. The depth range is the tight fit's.
pub fn fit_cascade_to_samples(
    tight: &LightProjection,
    samples: [f32; 4],
    margin_texels: f32,
    resolution: u32,
) -> LightProjection {
    let Some((left, right, bottom, top)) = tight.orthographic_window() else { return *tight };
    let (x0, x1) = (samples[0].max(left), samples[2].min(right));
    let (y0, y1) = (samples[1].max(bottom), samples[3].min(top));
    let texels = resolution as f32;
    let margin_texels = margin_texels.clamp(0.0, 0.25 * texels);
    if !(x0 <= x1 && y0 <= y1) {
        return *tight;
    }
    // The margin is m texels of the widened window: w' = w + 2m·w'/R.
    let widen = |extent: f32| margin_texels * extent.max(1e-6) / (texels - 2.0 * margin_texels);
    let (mx, my) = (widen(x1 - x0), widen(y1 - y0));
    LightProjection::orthographic(
        tight.light_from_world,
        (x0 - mx, x1 + mx, y0 - my, y1 + my),
        tight.near,
        tight.far,
    )
}

/// A view depth range widened to steps of 2^(1/4): `near` down and `far` up to the
/// nearest step. Stable cascades split this range, so that the splits (and with them
/// the slices' bounding spheres) stay put while the camera moves, and jump only when
/// the seen range crosses a step, instead of shimmering every frame.
pub fn quantized_depth_range(near: f32, far: f32) -> (f32, f32) {
    const STEPS_PER_OCTAVE: f32 = 4.0;
    let down = |z: f32| (z.log2() * STEPS_PER_OCTAVE).floor() / STEPS_PER_OCTAVE;
    let up = |z: f32| (z.log2() * STEPS_PER_OCTAVE).ceil() / STEPS_PER_OCTAVE;
    (2f32.powf(down(near)), 2f32.powf(up(far)))
}

/// The light-space x and y of an orthographic window's left-bottom corner, which
/// stable fitting keeps on the texel grid.
pub fn window_origin(projection: &LightProjection) -> (f32, f32) {
    // orthographic(l, r, b, t): x_ndc = 2x/(r − l) − (r + l)/(r − l), so −1 at x = l.
    let m: Mat4 = projection.clip_from_light;
    let inverse = m.inverse();
    let corner = inverse.project_point3(Vec3::new(-1.0, -1.0, 0.0));
    (corner.x, corner.y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ProjectionKind, projection::view_from_world_look_at, test_rng::Lcg};

    #[test]
    fn quantized_depth_ranges_contain_the_range_and_snap_to_steps() {
        let mut rng = Lcg(7);
        for _ in 0..500 {
            let near = rng.range(0.01, 10.0);
            let far = near + rng.range(0.1, 500.0);
            let (n, f) = quantized_depth_range(near, far);
            assert!(n <= near && f >= far, "{near}..{far} → {n}..{f}");
            assert!(n > near / 2f32.powf(0.26) && f < far * 2f32.powf(0.26), "within one step");
            // A small move of the range keeps the same steps, mostly.
            let steps = |z: f32| z.log2() * 4.0;
            assert!((steps(n) - steps(n).round()).abs() < 1e-3 && (steps(f) - steps(f).round()).abs() < 1e-3);
        }
        assert_eq!(quantized_depth_range(1.0, 2.0), (1.0, 2.0));
    }

    const SCHEMES: [SplitScheme; 5] = [
        SplitScheme::Uniform,
        SplitScheme::Logarithmic,
        SplitScheme::Practical { lambda: 0.0 },
        SplitScheme::Practical { lambda: 0.5 },
        SplitScheme::Practical { lambda: 0.8 },
    ];

    #[test]
    fn every_split_scheme_is_monotonic_and_covers_near_to_far() {
        let mut rng = Lcg(3);
        for _ in 0..500 {
            let near = rng.range(0.01, 5.0);
            let far = near * rng.range(1.5, 1e4);
            let count = 1 + (rng.next() * 8.0) as usize % 8;
            for scheme in SCHEMES {
                let z = split_distances(scheme, count, near, far);
                assert_eq!(z.len(), count + 1);
                assert_eq!((z[0], z[count]), (near, far), "{scheme:?}");
                assert!(z.windows(2).all(|w| w[1] > w[0]), "{scheme:?}: {z:?}");
            }
        }
    }

    #[test]
    fn splits_match_their_formulas() {
        let u = split_distances(SplitScheme::Uniform, 4, 1.0, 101.0);
        assert_eq!(u, vec![1.0, 26.0, 51.0, 76.0, 101.0]);
        let l = split_distances(SplitScheme::Logarithmic, 2, 1.0, 100.0);
        assert!((l[1] - 10.0).abs() < 1e-4);
        // λ = 1 is fully logarithmic, λ = 0 uniform.
        let p1 = split_distances(SplitScheme::Practical { lambda: 1.0 }, 2, 1.0, 100.0);
        let p0 = split_distances(SplitScheme::Practical { lambda: 0.0 }, 2, 1.0, 100.0);
        assert!((p1[1] - 10.0).abs() < 1e-4 && (p0[1] - 50.5).abs() < 1e-4);
    }

    fn random_view(rng: &mut Lcg) -> (Mat4, Mat4, f32, f32) {
        let eye = Vec3::new(rng.range(-8.0, 8.0), rng.range(0.5, 6.0), rng.range(-8.0, 8.0));
        let target = Vec3::new(rng.range(-4.0, 4.0), 0.0, rng.range(-4.0, 4.0));
        let view = view_from_world_look_at(eye, target, Vec3::Y);
        let (near, far) = (rng.range(0.05, 0.5), rng.range(10.0, 60.0));
        let clip = crate::camera_clip_from_view(rng.range(0.5, 1.5), rng.range(1.0, 2.0), near, far) * view;
        (view, clip, near, far)
    }

    #[test]
    fn every_fitted_cascade_contains_every_receiver_of_its_slice() {
        let mut rng = Lcg(5);
        let scene = Aabb::new(Vec3::new(-20.0, 0.0, -20.0), Vec3::new(20.0, 4.0, 20.0));
        for _ in 0..60 {
            let (view, clip, near, far) = random_view(&mut rng);
            let direction = Vec3::new(rng.range(-1.0, 1.0), -rng.range(0.2, 1.0), rng.range(-1.0, 1.0));
            let frustum = Hexahedron::from_clip_from_world(clip);
            let splits = split_distances(SplitScheme::Practical { lambda: 0.8 }, 4, near, far);
            for w in splits.windows(2) {
                let slice = frustum_slice(&frustum, near, far, w[0], w[1]);
                // Tight, tight with its depth range pancaked onto the receivers, stable.
                for fit in 0..3 {
                    let p = match fit {
                        0 => fit_cascade_tight(direction, &scene, &slice, false),
                        1 => fit_cascade_tight(direction, &scene, &slice, true),
                        _ => fit_cascade_stable(direction, &scene, &slice, 1024),
                    };
                    let m = p.clip_from_world();
                    for _ in 0..200 {
                        // A random point of the slice: random NDC x, y and a view depth
                        // inside the slice, taken back to world space.
                        let z_view = rng.range(w[0], w[1]);
                        let (a, b) = (rng.next(), rng.next());
                        let t = (z_view - w[0]) / (w[1] - w[0]);
                        let at = |i: usize| slice.corners[i].lerp(slice.corners[i | 4], t);
                        let x0 = at(0).lerp(at(1), a);
                        let x1 = at(2).lerp(at(3), a);
                        let p_world = x0.lerp(x1, b);
                        if !scene.contains(p_world) {
                            continue;
                        }
                        let depth = -view.transform_point3(p_world).z;
                        assert!((depth - z_view).abs() < 1e-2 * z_view, "slice parametrisation");
                        let ndc = m.project_point3(p_world);
                        assert!(
                            ndc.x.abs() <= 1.0001
                                && ndc.y.abs() <= 1.0001
                                && (-1e-4..=1.0001).contains(&ndc.z),
                            "fit {fit}: receiver {p_world} of slice {w:?} maps to {ndc}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_view_slice_is_the_frustum_slice() {
        let eye = Vec3::new(3.0, 2.0, -1.0);
        let target = Vec3::new(-2.0, 0.5, 4.0);
        let view = PerspectiveView { eye, target, up: Vec3::Y, fov_y: 0.9, aspect: 1.7 };
        let clip =
            crate::camera_clip_from_view(0.9, 1.7, 0.1, 50.0) * view_from_world_look_at(eye, target, Vec3::Y);
        let frustum = Hexahedron::from_clip_from_world(clip);
        let (a, b) = (frustum_slice(&frustum, 0.1, 50.0, 2.0, 9.0), view_slice(&view, 2.0, 9.0));
        for (p, q) in a.corners.iter().zip(&b.corners) {
            assert!(p.distance(*q) < 1e-3, "{p} vs {q}");
        }
    }

    #[test]
    fn stable_cascades_move_by_whole_texels_and_keep_their_size() {
        let mut rng = Lcg(9);
        let scene = Aabb::new(Vec3::new(-20.0, 0.0, -20.0), Vec3::new(20.0, 4.0, 20.0));
        let direction = Vec3::new(0.3, -0.8, 0.2);
        let resolution = 1024;
        for _ in 0..100 {
            let eye = Vec3::new(rng.range(-5.0, 5.0), 2.0, rng.range(-5.0, 5.0));
            let step = Vec3::new(rng.range(-0.3, 0.3), 0.0, rng.range(-0.3, 0.3));
            let yaw = rng.range(0.0, std::f32::consts::TAU);
            let fit = |eye: Vec3, yaw: f32| {
                let target = eye + Vec3::new(yaw.cos(), -0.3, yaw.sin());
                let clip = crate::camera_clip_from_view(1.0, 1.6, 0.1, 40.0)
                    * view_from_world_look_at(eye, target, Vec3::Y);
                let frustum = Hexahedron::from_clip_from_world(clip);
                fit_cascade_stable(
                    direction,
                    &scene,
                    &frustum_slice(&frustum, 0.1, 40.0, 2.0, 8.0),
                    resolution,
                )
            };
            let a = fit(eye, yaw);
            // Translating and turning the camera moves the window by whole texels and
            // never changes its size.
            let b = fit(eye + step, yaw + rng.range(-0.5, 0.5));
            let (
                ProjectionKind::Orthographic { width: wa, .. },
                ProjectionKind::Orthographic { width: wb, .. },
            ) = (a.kind, b.kind)
            else {
                unreachable!()
            };
            assert!((wa - wb).abs() < 1e-5 * wa, "window size changed: {wa} → {wb}");
            let texel = wa / resolution as f32;
            let (ax, ay) = window_origin(&a);
            let (bx, by) = window_origin(&b);
            for d in [(bx - ax) / texel, (by - ay) / texel] {
                assert!((d - d.round()).abs() < 1e-2, "moved by {d} texels");
            }
        }
    }

    #[test]
    fn sample_fitted_cascades_hold_their_samples_with_the_margin_inside_the_tight_window() {
        let scene = Aabb::new(Vec3::new(-20.0, 0.0, -20.0), Vec3::new(20.0, 5.0, 20.0));
        let direction = Vec3::new(0.4, -1.0, 0.3).normalize();
        let tight = crate::fitting::fit_directional_to_receivers(direction, &scene, &scene.corners());
        let (l, r, b, t) = tight.orthographic_window().unwrap();
        // Samples filling the left half, bottom quarter.
        let samples = [l, b, 0.5 * (l + r), b + 0.25 * (t - b)];
        let fitted = fit_cascade_to_samples(&tight, samples, 4.0, 1024);
        let (fl, fr, fb, ft) = fitted.orthographic_window().unwrap();
        let texel_x = (fr - fl) / 1024.0;
        let texel_y = (ft - fb) / 1024.0;
        assert!((samples[0] - fl - 4.0 * texel_x).abs() < 1e-3 * texel_x, "left margin");
        assert!((fr - samples[2] - 4.0 * texel_x).abs() < 1e-3 * texel_x, "right margin");
        assert!((ft - samples[3] - 4.0 * texel_y).abs() < 1e-3 * texel_y, "top margin");
        assert!(fr - fl < 0.51 * (r - l) && ft - fb < 0.26 * (t - b), "narrower than the tight window");
        assert_eq!((fitted.near, fitted.far), (tight.near, tight.far));
        // Samples beyond the tight window (reconstruction noise) are clipped to it.
        let wide = fit_cascade_to_samples(&tight, [l - 10.0, b - 10.0, r + 10.0, t + 10.0], 0.0, 1024);
        let (wl, wr, wb, wt) = wide.orthographic_window().unwrap();
        for (a, e) in [(wl, l), (wr, r), (wb, b), (wt, t)] {
            assert!((a - e).abs() < 1e-4 * (r - l), "{a} against {e}");
        }
    }
}
