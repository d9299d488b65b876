//! The truth's shadow rays, open to another tracer: under a point-like light, the
//! one ray [`crate::drawn::drawn_truth`] traces from each light-facing surface a
//! frame drew (its origin already moved off the surface, its direction and length),
//! with the answer this crate's tracer gave, and the world-space triangles it traced
//! against. An independent tracer (the Python tests' Embree) traces the very same
//! segments against the very same triangles, so that where the two disagree the
//! cause is the tracers' own (a triangle test, an edge rule), not an origin offset
//! or a facing rule.

use glam::{Vec2, Vec3};
use gnomon_scene::Light;

use crate::{Hit, TracedScene, drawn::DrawnSurfaces, emitter::Emitter, offset_ray_origin};

/// One shadow ray per light-facing pixel whose light lies above its surface's
/// horizon, in pixel order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShadowSegments {
    /// The pixel each ray leaves from, as a row-major index.
    pub pixel: Vec<u32>,
    /// Where each ray starts: the drawn point moved off its surface along the
    /// geometric normal ([`offset_ray_origin`]).
    pub origin: Vec<Vec3>,
    /// Unit direction toward the light.
    pub direction: Vec<Vec3>,
    /// How far the ray goes: to the light, infinite under a sun.
    pub length: Vec<f32>,
    /// Whether this crate's tracer found a caster on the segment.
    pub occluded: Vec<bool>,
}

/// Why a light's rays cannot be cross-checked one per pixel.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CrossCheckError {
    /// The light has an area: its truth is a Monte Carlo mean over many rays.
    #[error("the light has an area: a cross-check traces one ray per pixel, under a light of size 0")]
    AreaLight,
}

/// The segments the truth traces from `surfaces` under `light`, and its answers.
pub fn shadow_segments(
    traced: &TracedScene,
    light: &Light,
    surfaces: DrawnSurfaces,
) -> Result<ShadowSegments, CrossCheckError> {
    let emitter = Emitter::new(light);
    if !emitter.is_point() {
        return Err(CrossCheckError::AreaLight);
    }
    let mut segments = ShadowSegments::default();
    for (index, (&position, &normal)) in surfaces.position.iter().zip(surfaces.geometric_normal).enumerate() {
        let hit = Hit { t: 0.0, position, normal, object_id: 0, triangle: 0 };
        if !position.is_finite() || !normal.is_finite() || !emitter.faces(&hit) {
            continue;
        }
        // As `shade` traces a point-like light: its one sample, and no ray where the
        // light lies below the surface's horizon.
        let (direction, length) = emitter.sample(position, Vec2::splat(0.5));
        if direction.dot(normal) <= 0.0 {
            continue;
        }
        let origin = offset_ray_origin(position, normal);
        segments.pixel.push(index as u32);
        segments.origin.push(origin);
        segments.direction.push(direction);
        segments.length.push(length);
        segments.occluded.push(traced.occluded(origin, direction, length));
    }
    Ok(segments)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gnomon_scene::{Settings, builtin};

    #[test]
    fn each_segment_is_the_truths_own_ray_and_answer() {
        let scene = builtin::spheres();
        let settings = Settings::default();
        let light = settings.resolve_light(&scene).unwrap();
        let traced = TracedScene::build(&scene);
        // A grid of points on the ground about the spheres, facing up.
        let position: Vec<Vec3> = (0..32 * 32)
            .map(|i| Vec3::new((i % 32) as f32 * 0.25 - 4.0, 0.0, (i / 32) as f32 * 0.25 - 4.0))
            .collect();
        let normal = vec![Vec3::Y; position.len()];
        let surfaces = DrawnSurfaces { width: 32, position: &position, geometric_normal: &normal };
        let segments = shadow_segments(&traced, &light, surfaces).unwrap();
        assert_eq!(segments.pixel.len(), position.len(), "every point faces the sun");
        let truth = crate::drawn::drawn_truth(
            &traced,
            &light,
            surfaces,
            &crate::drawn::DrawnOptions { samples: 1, lift: 0.0 },
            &|_| {},
        );
        for (k, &pixel) in segments.pixel.iter().enumerate() {
            let lit = truth.visibility[pixel as usize] == 1.0;
            assert_eq!(segments.occluded[k], !lit, "pixel {pixel}");
            assert!(segments.direction[k].dot(Vec3::Y) > 0.0);
        }
        assert!(segments.occluded.iter().any(|&o| o) && segments.occluded.iter().any(|&o| !o));
    }

    #[test]
    fn a_light_with_an_area_is_refused() {
        let scene = builtin::spheres();
        let mut settings = Settings::default();
        settings.light.sun_angular_diameter = Some(2.0);
        let light = settings.resolve_light(&scene).unwrap();
        let traced = TracedScene::build(&scene);
        let surfaces = DrawnSurfaces { width: 0, position: &[], geometric_normal: &[] };
        assert_eq!(shadow_segments(&traced, &light, surfaces), Err(CrossCheckError::AreaLight));
    }
}
