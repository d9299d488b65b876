//! Perspective aliasing, measured: for every pixel, how many screen pixels one shadow
//! texel spans there (Lloyd, Tuft, Yoon & Manocha, "Warping and partitioning for low
//! error shadow maps", EGSR 2006, §3: the aliasing error m). m = 1 is ideal; above 1 a
//! texel is smeared over several pixels (blocky, undersampled shadows), below 1 several
//! texels fall in one pixel (oversampled: texels wasted).
//!
//! Lloyd et al. factor m into a perspective term, which fitting, partitioning and
//! warping change, and a projection term cos φ_eye / cos φ_light, set by the receiver's
//! orientation alone, which none of them can change and which grows without bound at
//! receivers grazed by the light. This is the perspective term: the largest world
//! extent of a texel measured across the light's rays, over the world size of a pixel
//! measured across the camera's ray, both at the receiver. The texel extent comes from
//! the Jacobian of the layer's projection across the light's rays (1 / σ_min), so it
//! is exact for warped (projective) maps as well as for orthographic ones.

use glam::{Mat4, Vec2, Vec3, Vec4Swizzles};
use gnomon_math::virtual_map::Clipmap;
use gnomon_scene::{
    Camera, Light,
    lights::{Origin, ShadowView},
};

/// A frame's geometry and shadow layout, as the aliasing measure needs them.
#[derive(Clone, Copy)]
pub struct AliasingInput<'a> {
    /// Image width in pixels; every per-pixel slice is `width × height` long, row-major, top row first.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// World position of the visible surface; NaN for background.
    pub position: &'a [Vec3],
    /// World unit normal of the visible surface; NaN for background.
    pub normal: &'a [Vec3],
    /// View depth of the visible surface; NaN for background.
    pub depth: &'a [f32],
    /// The camera the frame was rendered with, for the world size of a pixel at each surface.
    pub camera: &'a Camera,
    /// The light, for the direction of its rays.
    pub light: &'a Light,
    /// Every shadow-map layer's clip_from_world (one per cascade, or per virtual level).
    pub layers: &'a [Mat4],
    /// Which layer shades each pixel.
    pub choice: LayerChoice<'a>,
    /// Texels along a side of each layer.
    pub resolution: u32,
}

/// How a frame picks the layer that shades a pixel.
#[derive(Clone, Copy)]
pub enum LayerChoice<'a> {
    /// By view depth, between these splits (one more than the layers): cascades.
    Splits(&'a [f32]),
    /// The first layer whose projection holds the point: cascades chosen by projection.
    Projection,
    /// A virtual map's level, as its page requests and lookup choose it
    /// ([`Clipmap::level_for_point`] of the pixel's footprint, `footprint_per_depth`
    /// times its view depth): the layers are its levels' windows, or for a point
    /// light each level's faces ([`Clipmap::layer_of`]).
    Clipmap {
        /// The frame's clipmap.
        clipmap: &'a Clipmap,
        /// A pixel's footprint in world units per unit of view depth.
        footprint_per_depth: f32,
    },
}

/// m per pixel, and its summary over the pixels where it is defined.
#[derive(Clone, Debug)]
pub struct AliasingImage {
    /// Image width in pixels, as in the input.
    pub width: u32,
    /// Image height in pixels, as in the input.
    pub height: u32,
    /// Pixels spanned by one shadow texel in its longest direction (the perspective
    /// term); NaN for background and outside every layer.
    pub m: Vec<f32>,
    /// Mean of m over the pixels where it is defined.
    pub mean: f32,
    /// The largest m.
    pub max: f32,
    /// Pixels where m is defined.
    pub measured: usize,
}

/// The layer that shades a point, chosen as the lighting pass does (see
/// `select_cascade` in the renderer's `map_visibility.wgsl`; the normal offset is
/// ignored): for a point light's 2D maps, the cube face its direction falls on (or
/// the paraboloid); for a virtual map, its level's layer.
pub fn shading_layer(input: &AliasingInput, world: Vec3, view_depth: f32) -> usize {
    let count = input.layers.len();
    match (input.choice, omni_layer(input, world)) {
        (LayerChoice::Clipmap { clipmap, footprint_per_depth }, _) => {
            let footprint = clipmap.map_footprint(world, view_depth * footprint_per_depth);
            let level = clipmap.level_for_point(clipmap.map_xy(world), footprint);
            level.map_or(count - 1, |l| clipmap.layer_of(l, world))
        }
        (LayerChoice::Splits(_) | LayerChoice::Projection, Some(layer)) => layer,
        (LayerChoice::Splits(splits), None) => (1..count).rfind(|&i| view_depth > splits[i]).unwrap_or(0),
        (LayerChoice::Projection, None) => {
            let margin = 4.0 / input.resolution as f32;
            (0..count.saturating_sub(1))
                .find(|&i| {
                    texture_coords(input.layers[i], world).is_some_and(|(uv, z)| {
                        uv.cmpgt(Vec2::splat(margin)).all()
                            && uv.cmplt(Vec2::splat(1.0 - margin)).all()
                            && (0.0..=1.0).contains(&z)
                    })
                })
                .unwrap_or(count - 1)
        }
    }
}

/// A point light's 2D maps' layer for `world`: the cube face its direction falls on,
/// or of dual paraboloids (two layers) the lower hemisphere's 0; None for a sun or a
/// spot.
fn omni_layer(input: &AliasingInput, world: Vec3) -> Option<usize> {
    let ShadowView::Omni { position, .. } = input.light.shadow_view() else {
        return None;
    };
    let d = world - position;
    Some(match input.layers.len() {
        2 => usize::from(d.y > 0.0),
        _ => gnomon_math::omni::CubeFace::of_direction(d).layer() as usize,
    })
}

/// Shadow-map texture coordinates (u right, v down, both in [0, 1] inside the map) and
/// depth of `world` under `clip_from_world`; None behind a perspective projection.
fn texture_coords(clip_from_world: Mat4, world: Vec3) -> Option<(Vec2, f32)> {
    let clip = clip_from_world * world.extend(1.0);
    if clip.w <= 0.0 {
        return None;
    }
    let ndc = clip.xyz() / clip.w;
    Some((Vec2::new(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y), ndc.z))
}

/// The largest stretch of J⁻¹, 1 / σ_min(J), for the 2×2 Jacobian J with columns `dx`
/// and `dy`: with J in texels per unit, how many units one texel spans at most.
pub fn footprint_from_jacobian(dx: Vec2, dy: Vec2) -> f32 {
    let squares = dx.length_squared() + dy.length_squared();
    let det = (dx.x * dy.y - dy.x * dx.y).abs();
    // σ_max² = (S + √(S² − 4 det²)) / 2, and σ_min = det / σ_max.
    let sigma_max = (0.5 * (squares + (squares * squares - 4.0 * det * det).max(0.0).sqrt())).sqrt();
    if det <= f32::MIN_POSITIVE { f32::INFINITY } else { sigma_max / det }
}

/// Measures m over a frame.
pub fn measure(input: &AliasingInput) -> AliasingImage {
    let (w, h) = (input.width as usize, input.height as usize);
    let aspect = input.width as f32 / input.height as f32;
    let world_from_clip = input.camera.clip_from_world(aspect).inverse();
    let eye = input.camera.eye;
    // The direction of the camera ray through a (fractional) pixel position.
    let ray = |x: f32, y: f32| {
        let ndc = Vec3::new(2.0 * x / w as f32 - 1.0, 1.0 - 2.0 * y / h as f32, 1.0);
        (world_from_clip.project_point3(ndc) - eye).normalize()
    };
    let texels = input.resolution as f32;
    let origin = input.light.emission().origin;
    let m: Vec<f32> = (0..w * h)
        .map(|i| {
            let p = input.position[i];
            if !p.is_finite() {
                return f32::NAN;
            }
            let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            // A pixel's world size across the camera ray: the distance times the angle
            // between neighbouring rays (the larger of the two axes).
            let centre = ray(x, y);
            let angle = |d: Vec3| centre.angle_between(d);
            let pixel = p.distance(eye) * angle(ray(x + 1.0, y)).max(angle(ray(x, y + 1.0)));
            let travel = match origin {
                Origin::Infinite { travel } => travel,
                Origin::Local { position, .. } => (p - position).normalize(),
            };
            let (across_u, across_v) = travel.any_orthonormal_pair();
            let layer = input.layers[shading_layer(input, p, input.depth[i])];
            // Texels per world unit across the light's rays, by finite differences a
            // pixel wide (exact for orthographic maps, first order for warped ones).
            let (Some((t, _)), Some((tu, _)), Some((tv, _))) = (
                texture_coords(layer, p),
                texture_coords(layer, p + across_u * pixel),
                texture_coords(layer, p + across_v * pixel),
            ) else {
                return f32::NAN;
            };
            let inside = t.cmpge(Vec2::ZERO).all() && t.cmple(Vec2::ONE).all();
            if !inside {
                return f32::NAN;
            }
            let texel = footprint_from_jacobian((tu - t) * texels / pixel, (tv - t) * texels / pixel);
            texel / pixel
        })
        .collect();
    let finite: Vec<f32> = m.iter().copied().filter(|v| v.is_finite()).collect();
    let mean = finite.iter().map(|&v| v as f64).sum::<f64>() / finite.len().max(1) as f64;
    AliasingImage {
        width: input.width,
        height: input.height,
        mean: mean as f32,
        max: finite.iter().copied().fold(0.0, f32::max),
        measured: finite.len(),
        m,
    }
}

/// The colour of m in the heat-map: log2 m from −4 (16× oversampled) to +4 (16×
/// undersampled) on the error ramp, so m = 1 sits in the middle.
pub fn heatmap(image: &AliasingImage) -> Vec<u8> {
    image
        .m
        .iter()
        .flat_map(|&m| {
            if m.is_nan() {
                let [r, g, b] = crate::heatmap::BACKGROUND;
                [r, g, b, 255]
            } else {
                let [r, g, b] = crate::heatmap::ramp(((m.log2() + 4.0) / 8.0).clamp(0.0, 1.0));
                [r, g, b, 255]
            }
        })
        .collect()
}

/// The legend of [`heatmap`]: m at five points of the ramp.
pub fn legend() -> Vec<(String, [u8; 3])> {
    [-4.0f32, -2.0, 0.0, 2.0, 4.0]
        .iter()
        .map(|&e| (format!("m {}", 2f32.powf(e)), crate::heatmap::ramp((e + 4.0) / 8.0)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 0.0, 10.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_degrees: 60.0,
            near: 0.1,
            far: 100.0,
        }
    }

    #[test]
    fn the_footprint_is_the_inverse_of_the_smallest_stretch() {
        // Two texels per pixel in x, half a texel per pixel in y: a texel covers two
        // pixels in y, the worse direction.
        assert!((footprint_from_jacobian(Vec2::new(2.0, 0.0), Vec2::new(0.0, 0.5)) - 2.0).abs() < 1e-5);
        // A rotation does not change it.
        let r = glam::Mat2::from_angle(0.7);
        let m = footprint_from_jacobian(r * Vec2::new(2.0, 0.0), r * Vec2::new(0.0, 0.5));
        assert!((m - 2.0).abs() < 1e-4, "{m}");
        assert!(footprint_from_jacobian(Vec2::X, Vec2::X).is_infinite(), "degenerate");
    }

    fn sun_along(direction: Vec3) -> Light {
        Light::Directional(gnomon_scene::DirectionalLight {
            direction,
            color: Vec3::ONE,
            intensity: 1.0,
            angular_diameter_degrees: 0.5,
        })
    }

    /// A plane facing the camera, under an orthographic map whose texels are exactly
    /// the size of the pixels there: m = 1 at the centre of the image.
    #[test]
    fn a_map_matched_to_the_pixels_gives_m_one() {
        let camera = camera();
        let (w, h) = (64u32, 64u32);
        // The plane z = 0 is 10 away: the image spans 2·10·tan 30° vertically.
        let span = 2.0 * 10.0 * (30f32.to_radians()).tan();
        let pixel = span / h as f32;
        let resolution = 256u32;
        let half = 0.5 * pixel * resolution as f32;
        // Looking down −z from the camera side, like the camera.
        let light_from_world =
            gnomon_math::view_from_world_look_at(Vec3::new(0.0, 0.0, 20.0), Vec3::ZERO, Vec3::Y);
        let map = gnomon_math::LightProjection::orthographic(
            light_from_world,
            (-half, half, -half, half),
            1.0,
            40.0,
        );
        let world_from_clip = camera.clip_from_world(1.0).inverse();
        let (mut position, mut normal, mut depth) = (vec![], vec![], vec![]);
        for y in 0..h {
            for x in 0..w {
                let ndc = Vec3::new(
                    2.0 * (x as f32 + 0.5) / w as f32 - 1.0,
                    1.0 - 2.0 * (y as f32 + 0.5) / h as f32,
                    1.0,
                );
                let d = (world_from_clip.project_point3(ndc) - camera.eye).normalize();
                position.push(camera.eye + d * (10.0 / -d.z));
                normal.push(Vec3::Z);
                depth.push(10.0);
            }
        }
        let layers = [map.clip_from_world()];
        let input = AliasingInput {
            width: w,
            height: h,
            position: &position,
            normal: &normal,
            depth: &depth,
            camera: &camera,
            light: &sun_along(-Vec3::Z),
            layers: &layers,
            choice: LayerChoice::Splits(&[0.0, f32::INFINITY]),
            resolution,
        };
        let image = measure(&input);
        let centre = image.m[(h / 2 * w + w / 2) as usize];
        assert!((centre - 1.0).abs() < 0.03, "m at the centre {centre}");
        // Off-centre rays subtend smaller angles (the pinhole's cos² against the
        // distance's 1 / cos): smaller pixels across the ray, so a texel spans more.
        assert!(
            image.max > centre && image.max < 1.25 && image.mean > centre,
            "{} {}",
            image.max,
            image.mean
        );
        assert_eq!(image.measured, (w * h) as usize);
        // Twice the texels over the same window: half the footprint.
        let image2 = measure(&AliasingInput { resolution: 2 * resolution, ..input });
        assert!(
            (image2.mean - 0.5 * image.mean).abs() < 1e-3 * image.mean,
            "{} vs {}",
            image2.mean,
            image.mean
        );
    }

    #[test]
    fn cascades_are_chosen_by_depth_or_by_projection() {
        let camera = camera();
        let light_from_world =
            gnomon_math::view_from_world_look_at(Vec3::new(0.0, 0.0, 20.0), Vec3::ZERO, Vec3::Y);
        let small =
            gnomon_math::LightProjection::orthographic(light_from_world, (-1.0, 1.0, -1.0, 1.0), 1.0, 40.0);
        let large =
            gnomon_math::LightProjection::orthographic(light_from_world, (-8.0, 8.0, -8.0, 8.0), 1.0, 40.0);
        let layers = [small.clip_from_world(), large.clip_from_world()];
        let input = AliasingInput {
            width: 1,
            height: 1,
            position: &[],
            normal: &[],
            depth: &[],
            camera: &camera,
            light: &sun_along(-Vec3::Z),
            layers: &layers,
            choice: LayerChoice::Splits(&[0.1, 5.0, 100.0]),
            resolution: 64,
        };
        assert_eq!(shading_layer(&input, Vec3::ZERO, 4.0), 0);
        assert_eq!(shading_layer(&input, Vec3::ZERO, 6.0), 1);
        let by_projection = AliasingInput { choice: LayerChoice::Projection, ..input };
        assert_eq!(shading_layer(&by_projection, Vec3::ZERO, 6.0), 0, "inside the small map");
        assert_eq!(shading_layer(&by_projection, Vec3::new(3.0, 0.0, 0.0), 4.0), 1, "outside it");
    }
}
