//! The truth at the surfaces a frame drew: for each pixel, the light's visibility
//! from the very point and geometric normal the frame shows there (its position and
//! normal outputs), traced like the reference. The reference through the camera's
//! pixel centres (`visibility.rs`) may see another surface than the frame at an
//! object's outline or a crease, and `compare` had to leave those pixels out; traced
//! from the frame's own surface, every light-facing pixel has an answer, and the
//! error counted is exactly the error the image shows.
//!
//! A pixel is *ambiguous* where the truth itself is not stable: the answer from the
//! point changes when the ray starts a hair higher above the surface
//! ([`DrawnOptions::lift`]). There a caster touches the receiver (a contact, a
//! crease) closer than the frame's point can be trusted; such pixels are counted
//! apart, not as errors.

use glam::Vec3;
use gnomon_scene::Light;
use rayon::prelude::*;
use serde::Serialize;

use crate::{
    Hit, TracedScene,
    emitter::Emitter,
    sampling::hash,
    shade::{BATCHES, LightSampling, shade},
};

/// The surfaces a frame shows, per pixel, row-major: NaN where it shows none.
#[derive(Clone, Copy)]
pub struct DrawnSurfaces<'a> {
    /// Pixels per row.
    pub width: u32,
    /// World-space point of each pixel's surface.
    pub position: &'a [Vec3],
    /// Unit normal of each pixel's triangle's plane, facing the camera.
    pub geometric_normal: &'a [Vec3],
}

/// How the truth at drawn surfaces is traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrawnOptions {
    /// Shadow rays per pixel under an area light (one under a point-like light).
    pub samples: u32,
    /// How far above the surface, along its normal, the second ray of a hard light
    /// starts, to find the ambiguous pixels: `compare` takes 10⁻⁵ of the scene's
    /// extent (1 cm over a 1 km city, 2 µm over the 0.2 m dragon).
    pub lift: f32,
}

/// The truth at each pixel of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct DrawnTruth {
    /// Fraction of the light visible from the pixel's point, in [0, 1]; NaN where
    /// the frame shows no surface, 0 where the surface does not face the light.
    pub visibility: Vec<f32>,
    /// The standard error of each pixel's visibility (the spread of its stratified
    /// batches, as the reference's): 0 under a point-like light, where one ray
    /// decides, and where the whole light is provably in sight.
    pub std_error: Vec<f32>,
    /// The surface faces the light (geometric N·L > 0) inside its cone and range.
    pub faces_light: Vec<bool>,
    /// The answer changes when the ray starts [`DrawnOptions::lift`] higher (hard
    /// lights only).
    pub ambiguous: Vec<bool>,
    /// Samples per pixel used: 1 under a point-like light.
    pub samples: u32,
    /// Rays traced, all pixels together.
    pub rays: u64,
}

/// Traces the truth of `light` at every surface the frame drew, in parallel over
/// rows; `progress` is called with the number of rows finished so far. The result
/// depends only on the inputs.
pub fn drawn_truth(
    traced: &TracedScene,
    light: &Light,
    surfaces: DrawnSurfaces,
    options: &DrawnOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> DrawnTruth {
    let emitter = Emitter::new(light);
    let samples = if emitter.is_point() { 1 } else { options.samples.max(BATCHES) };
    let width = surfaces.width.max(1) as usize;
    let done = std::sync::atomic::AtomicU64::new(0);
    let rows: Vec<Vec<DrawnPixel>> = surfaces
        .position
        .par_chunks(width)
        .zip(surfaces.geometric_normal.par_chunks(width))
        .enumerate()
        .map(|(y, (positions, normals))| {
            let row = positions
                .iter()
                .zip(normals)
                .enumerate()
                .map(|(x, (&position, &normal))| {
                    let seed = hash((y * width + x) as u32);
                    drawn_pixel(
                        traced,
                        &emitter,
                        Hit { t: 0.0, position, normal, object_id: 0, triangle: 0 },
                        samples,
                        seed,
                        options.lift,
                    )
                })
                .collect();
            progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
            row
        })
        .collect();
    let pixels: Vec<DrawnPixel> = rows.into_iter().flatten().collect();
    DrawnTruth {
        visibility: pixels.iter().map(|p| p.visibility).collect(),
        std_error: pixels.iter().map(|p| p.std_error).collect(),
        faces_light: pixels.iter().map(|p| p.faces_light).collect(),
        ambiguous: pixels.iter().map(|p| p.ambiguous).collect(),
        samples,
        rays: pixels.iter().map(|p| p.rays).sum(),
    }
}

/// Whether each surface the frame shows faces `light` (geometric N·L > 0 toward its
/// centre) inside its cone and range: the pixels whose visibility a shadow decides,
/// as [`drawn_truth`] finds them. With the visibility of a frame that traced every
/// pixel (the GPU's `raytraced`), this makes a [`DrawnTruth`] without the CPU
/// tracer: the browser's truth view does so.
pub fn faces_light(light: &Light, surfaces: DrawnSurfaces) -> Vec<bool> {
    let emitter = Emitter::new(light);
    surfaces
        .position
        .iter()
        .zip(surfaces.geometric_normal)
        .map(|(&position, &normal)| {
            position.is_finite()
                && normal.is_finite()
                && emitter.faces(&Hit { t: 0.0, position, normal, object_id: 0, triangle: 0 })
        })
        .collect()
}

impl DrawnTruth {
    /// The truth at a frame's surfaces from the visibility of the same view drawn with
    /// every pixel traced (the GPU's `raytraced`), without the CPU tracer: how a
    /// browser, which has no threads for it, measures a frame. Ambiguity is not
    /// traced, so no pixel is set apart as ambiguous.
    pub fn from_traced(light: &Light, surfaces: DrawnSurfaces, traced_visibility: Vec<f32>) -> DrawnTruth {
        let pixels = traced_visibility.len();
        DrawnTruth {
            visibility: traced_visibility,
            std_error: vec![0.0; pixels],
            faces_light: faces_light(light, surfaces),
            ambiguous: vec![false; pixels],
            samples: 1,
            rays: 0,
        }
    }
}

struct DrawnPixel {
    visibility: f32,
    std_error: f32,
    faces_light: bool,
    ambiguous: bool,
    rays: u64,
}

/// The truth at one drawn surface point (`hit`'s position and normal).
fn drawn_pixel(
    traced: &TracedScene,
    emitter: &Emitter,
    hit: Hit,
    samples: u32,
    seed: u32,
    lift: f32,
) -> DrawnPixel {
    if !hit.position.is_finite() || !hit.normal.is_finite() {
        return DrawnPixel {
            visibility: f32::NAN,
            std_error: f32::NAN,
            faces_light: false,
            ambiguous: false,
            rays: 0,
        };
    }
    if !emitter.faces(&hit) {
        return DrawnPixel { visibility: 0.0, std_error: 0.0, faces_light: false, ambiguous: false, rays: 0 };
    }
    let sampling = LightSampling::SkipWhollyInSight;
    let (visibility, std_error, rays) = shade(traced, emitter, &hit, samples, seed, sampling);
    if samples > 1 {
        return DrawnPixel { visibility, std_error, faces_light: true, ambiguous: false, rays };
    }
    // The same ray from a hair higher: where its answer differs, the truth depends
    // on where exactly the point lies, closer than it can be known.
    let lifted = Hit { position: hit.position + hit.normal * lift, ..hit };
    let (again, _, more) = shade(traced, emitter, &lifted, samples, seed, sampling);
    DrawnPixel {
        visibility,
        std_error: 0.0,
        faces_light: true,
        ambiguous: again != visibility,
        rays: rays + more,
    }
}

/// A frame's visibility against the truth at its own surfaces, over every
/// light-facing pixel it shows.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DrawnMetrics {
    /// Light-facing pixels the frame shows, ambiguous ones left out: the
    /// denominator of the rates.
    pub compared: usize,
    /// Light-facing pixels whose truth is ambiguous (counted apart).
    pub ambiguous: usize,
    /// `ambiguous / (compared + ambiguous)`.
    pub ambiguous_rate: f64,
    /// Truth lit (≥ 0.5), frame shadowed.
    pub false_shadow: usize,
    /// Truth shadowed, frame lit.
    pub false_lit: usize,
    /// `false_shadow / compared`.
    pub false_shadow_rate: f64,
    /// `false_lit / compared`.
    pub false_lit_rate: f64,
    /// `(false_shadow + false_lit) / compared`.
    pub mismatch_rate: f64,
    /// Mean |V − R| over the compared pixels.
    pub mae: f64,
}

/// Measures a frame's `visibility` against the truth at its own surfaces.
pub fn measure_drawn(visibility: &[f32], truth: &DrawnTruth) -> DrawnMetrics {
    let mut m = DrawnMetrics::default();
    let mut sum = 0.0f64;
    for (i, &v) in visibility.iter().enumerate() {
        if !truth.faces_light[i] || !v.is_finite() {
            continue;
        }
        if truth.ambiguous[i] {
            m.ambiguous += 1;
            continue;
        }
        let r = truth.visibility[i];
        m.compared += 1;
        match (r >= 0.5, v >= 0.5) {
            (true, false) => m.false_shadow += 1,
            (false, true) => m.false_lit += 1,
            (true, true) | (false, false) => {}
        }
        sum += f64::from((v - r).abs());
    }
    if m.compared > 0 {
        let n = m.compared as f64;
        m.false_shadow_rate = m.false_shadow as f64 / n;
        m.false_lit_rate = m.false_lit as f64 / n;
        m.mismatch_rate = (m.false_shadow + m.false_lit) as f64 / n;
        m.mae = sum / n;
    }
    if m.compared + m.ambiguous > 0 {
        m.ambiguous_rate = m.ambiguous as f64 / (m.compared + m.ambiguous) as f64;
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn truth(visibility: Vec<f32>, ambiguous: Vec<bool>) -> DrawnTruth {
        let n = visibility.len();
        DrawnTruth {
            faces_light: visibility.iter().map(|v| v.is_finite()).collect(),
            std_error: vec![0.0; n],
            visibility,
            ambiguous,
            samples: 1,
            rays: n as u64,
        }
    }

    /// A sun's light-facing surfaces are those whose normal has a component toward
    /// it; background (NaN) faces nothing.
    #[test]
    fn faces_light_is_the_side_of_the_surface_the_light_is_on() {
        let sun = Light::Directional(gnomon_scene::DirectionalLight {
            direction: -Vec3::Y,
            color: Vec3::ONE,
            intensity: 1.0,
            angular_diameter_degrees: 0.0,
        });
        let position = [Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, Vec3::NAN];
        let geometric_normal = [Vec3::Y, -Vec3::Y, Vec3::X, Vec3::Y];
        let surfaces = DrawnSurfaces { width: 4, position: &position, geometric_normal: &geometric_normal };
        assert_eq!(faces_light(&sun, surfaces), [true, false, false, false]);
    }

    /// False shadow, false lit and ambiguous pixels are counted apart; background
    /// and pixels facing away from the light are not counted at all.
    #[test]
    fn counts_every_light_facing_pixel_and_the_ambiguous_apart() {
        let mut t = truth(
            vec![1.0, 1.0, 0.0, 0.0, 1.0, f32::NAN, 0.0],
            vec![false, false, false, false, true, false, false],
        );
        t.faces_light[6] = false;
        let m = measure_drawn(&[1.0, 0.0, 0.0, 1.0, 0.0, f32::NAN, 1.0], &t);
        assert_eq!((m.compared, m.ambiguous, m.false_shadow, m.false_lit), (4, 1, 1, 1));
        assert_eq!(m.mismatch_rate, 0.5);
        assert_eq!(m.ambiguous_rate, 0.2);
    }
}
