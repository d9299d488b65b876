//! The light's visibility from one surface point: one ray to a point light, or an
//! area light's stratified samples in independent batches (whose spread is the
//! estimate's standard error), skipped where the whole light is provably in sight.
//! Shared by the reference through the camera's pixels (`visibility.rs`) and by the
//! truth at the surfaces a frame drew (`drawn.rs`).

use glam::{Vec2, Vec3};

use crate::{
    Hit, TracedScene,
    emitter::Emitter,
    sampling::{cmj, hash},
    tracer::{RayCone, Receiver, offset_ray_origin},
};

/// Batches of independent stratified patterns a pixel's samples are split into, so
/// that the spread of the batch means gives an honest standard error.
pub(crate) const BATCHES: u32 = 8;

/// How an area light's samples are traced at a pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LightSampling {
    /// Every sample's ray, at every pixel: the definition, kept for the test that the
    /// shortcut changes nothing.
    #[cfg_attr(not(test), expect(dead_code, reason = "only the test that compares the two samples this way"))]
    EveryRay,
    /// None where the whole light is provably in sight (`wholly_in_sight`), every
    /// sample's ray elsewhere.
    SkipWhollyInSight,
}

/// Visibility of the light at `hit` (which [faces](Emitter::faces) it): the share of
/// its samples that arrive, each weighted by [`Emitter::weight`]; the standard error
/// of the estimate; and the number of shadow rays traced.
pub(crate) fn shade(
    traced: &TracedScene,
    emitter: &Emitter,
    hit: &Hit,
    samples: u32,
    seed: u32,
    sampling: LightSampling,
) -> (f32, f32, u64) {
    let origin = offset_ray_origin(hit.position, hit.normal);
    let rays = std::cell::Cell::new(0u64);
    // A sample's weight (`Emitter::weight`) and whether its ray arrives.
    let sample = |u: Vec2| {
        let (d, len) = emitter.sample(hit.position, u);
        let weight = emitter.weight(len);
        // Light samples below the surface's horizon are blocked by the surface itself.
        if d.dot(hit.normal) <= 0.0 {
            return (weight, false);
        }
        rays.set(rays.get() + 1);
        (weight, !traced.occluded(origin, d, len))
    };
    if samples == 1 {
        let v = if sample(Vec2::splat(0.5)).1 { 1.0 } else { 0.0 };
        return (v, 0.0, rays.get());
    }
    if sampling == LightSampling::SkipWhollyInSight && wholly_in_sight(traced, emitter, hit, origin) {
        return (1.0, 0.0, 0);
    }
    // Split the samples into independent stratified batches; the spread of the batch
    // means estimates the standard error of their average.
    let per_batch = samples / BATCHES;
    let means: Vec<f32> = (0..BATCHES)
        .map(|b| {
            let pattern = hash(seed ^ hash(b + 1));
            let (arrived, total) = (0..per_batch).fold((0.0f32, 0.0f32), |(arrived, total), s| {
                let (weight, visible) = sample(cmj(s, per_batch, pattern));
                (arrived + if visible { weight } else { 0.0 }, total + weight)
            });
            arrived / total.max(1e-30)
        })
        .collect();
    let mean = means.iter().sum::<f32>() / BATCHES as f32;
    let variance = means.iter().map(|m| (m - mean).powi(2)).sum::<f32>() / (BATCHES - 1) as f32;
    (mean, (variance / BATCHES as f32).sqrt(), rays.get())
}

/// Whether every shadow ray the sampler could send from `hit` (leaving from `origin`)
/// arrives: the whole light lies above the surface's horizon, and nothing that could
/// block a ray lies in the cone that holds them all (`TracedScene::cone_is_clear`).
/// Then the estimate is exactly 1 with no spread, as tracing each sample would have
/// found, and no ray is traced: most of a soft-shadow reference's pixels are wholly
/// lit, and each cost `samples` rays before.
fn wholly_in_sight(traced: &TracedScene, emitter: &Emitter, hit: &Hit, origin: Vec3) -> bool {
    let Some((axis, half_angle, length)) = emitter.bounding_cone(hit.position) else {
        return false;
    };
    // Every direction within `half_angle` of `axis` climbs away from the surface.
    if axis.dot(hit.normal) <= half_angle.sin() + 1e-4 {
        return false;
    }
    let cone = RayCone { apex: origin, axis, half_angle, length };
    traced.cone_is_clear(&cone, &Receiver { point: hit.position, normal: hit.normal })
}
