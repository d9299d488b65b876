//! Temporal flicker along a camera path, with the scene and light still.
//!
//! Two measures:
//! - per pixel, as issue 6 defines it: how often a pixel's shadow state flips between
//!   consecutive frames, for the technique and for the reference. The reference's
//!   flips are real changes (surfaces sliding under the pixel grid); the excess is
//!   the technique's rate minus the reference's. It is small and noisy, because a
//!   blocky but still shadow edge flips about as often as the true edge when the
//!   pixels slide across it;
//! - at the same surface point (shimmer): each pixel is reprojected into the previous
//!   frame, and where it lands within [`REPROJECTION_TOLERANCE`] of a pixel centre on
//!   the same surface, the two states belong to one world point, whose true
//!   visibility cannot change. A flip there that the reference does not share is the
//!   shadow map's texel grid crawling: shimmer. This is the measure that separates
//!   stable cascades from tight ones.

use glam::{Mat4, Vec3, Vec4Swizzles};
use serde::Serialize;

use gnomon_scene::Camera;

use crate::{
    ReferenceImage,
    metrics::{self, DEPTH_TOLERANCE, PixelClass, RasterView},
};

/// Largest distance, in pixels along each axis, between a reprojected point and the
/// centre of the pixel it lands in, for the pair to count as one surface point. Small,
/// so that a still edge between the two points is rare; it keeps about 1 % of pixels.
pub const REPROJECTION_TOLERANCE: f32 = 0.05;

/// Per pixel: Some(shadowed) where the pixel is compared, None elsewhere.
pub fn shadow_states(visibility: &[f32], classes: &[PixelClass]) -> Vec<Option<bool>> {
    visibility.iter().zip(classes).map(|(&v, &c)| (c == PixelClass::Compared).then_some(v < 0.5)).collect()
}

/// One frame of a path: its camera, its geometry, and the technique's and the
/// reference's shadow states ([`shadow_states`]).
#[derive(Clone, Debug)]
pub struct PathFrame {
    /// Image width in pixels; every per-pixel vector is `width × height` long, row-major, top row first.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The frame's camera, world space to clip space: reprojects the next frame's surface points
    /// into this frame's pixels.
    pub clip_from_world: Mat4,
    /// The frame's camera, world space to view space: gives a reprojected point's view depth, to
    /// tell the same surface from one in front of it.
    pub view_from_world: Mat4,
    /// World position of the visible surface; NaN for background.
    pub position: Vec<Vec3>,
    /// Instance index + 1; 0 for background.
    pub object_id: Vec<u32>,
    /// View depth; NaN for background.
    pub depth: Vec<f32>,
    /// The technique's shadow state per pixel ([`shadow_states`]): `Some(true)` shadowed,
    /// `Some(false)` lit, `None` where the pixel is not compared.
    pub technique: Vec<Option<bool>>,
    /// The reference's shadow state per pixel, over the same pixels as `technique`.
    pub reference: Vec<Option<bool>>,
}

impl PathFrame {
    /// A frame of `width` × `height` pixels seen by `camera`: the technique's output
    /// (`raster`, with its world positions) classified against its frame's reference.
    pub fn new(
        camera: &Camera,
        width: u32,
        height: u32,
        raster: RasterView,
        position: Vec<Vec3>,
        reference: &ReferenceImage,
    ) -> PathFrame {
        let classes = metrics::classify(raster, reference);
        PathFrame {
            width,
            height,
            clip_from_world: camera.clip_from_world(width as f32 / height as f32),
            view_from_world: camera.view_from_world(),
            position,
            object_id: raster.object_id.to_vec(),
            depth: raster.depth.to_vec(),
            technique: shadow_states(raster.visibility, &classes),
            reference: shadow_states(&reference.visibility, &classes),
        }
    }

    /// The pixel of this frame that sees `world` within the tolerance of its centre,
    /// on the surface `object_id`, if any.
    fn pixel_seeing(&self, world: Vec3, object_id: u32) -> Option<usize> {
        let clip = self.clip_from_world * world.extend(1.0);
        if clip.w <= 0.0 {
            return None;
        }
        let ndc = clip.xyz() / clip.w;
        let x = (0.5 + 0.5 * ndc.x) * self.width as f32;
        let y = (0.5 - 0.5 * ndc.y) * self.height as f32;
        if !(x >= 0.0 && y >= 0.0 && x < self.width as f32 && y < self.height as f32) {
            return None;
        }
        let (fx, fy) = (x.floor(), y.floor());
        if (x - fx - 0.5).abs() > REPROJECTION_TOLERANCE || (y - fy - 0.5).abs() > REPROJECTION_TOLERANCE {
            return None;
        }
        let j = fy as usize * self.width as usize + fx as usize;
        let depth = -self.view_from_world.transform_point3(world).z;
        // The same surface, not one in front of it.
        let same = self.object_id[j] == object_id
            && (self.depth[j] - depth).abs() <= DEPTH_TOLERANCE * depth.abs().max(1e-6);
        same.then_some(j)
    }
}

/// Flip counts accumulated over the consecutive frame pairs of a path.
#[derive(Clone, Debug, Default)]
pub struct FlickerCounter {
    pairs: usize,
    compared: u64,
    technique_flips: u64,
    reference_flips: u64,
    reprojected: u64,
    shimmer_flips: u64,
}

/// Flicker over a path.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Flicker {
    /// Consecutive frame pairs measured.
    pub pairs: usize,
    /// Of the pixels compared in both frames of a pair, those whose technique state
    /// flips.
    pub technique_flip_rate: f64,
    /// The same for the reference: real changes.
    pub reference_flip_rate: f64,
    /// technique_flip_rate − reference_flip_rate (may be negative).
    pub excess_flip_rate: f64,
    /// Of the pixels that reproject onto the same surface point of the previous
    /// frame, those whose technique state flips while the reference's does not.
    pub shimmer_rate: f64,
    /// How many pixel pairs the shimmer rate was measured over.
    pub reprojected: u64,
}

impl FlickerCounter {
    /// Adds the pair (`before`, `after`) of consecutive frames.
    pub fn add_pair(&mut self, before: &PathFrame, after: &PathFrame) {
        self.pairs += 1;
        for i in 0..after.technique.len() {
            if let (Some(t0), Some(t1), Some(r0), Some(r1)) =
                (before.technique[i], after.technique[i], before.reference[i], after.reference[i])
            {
                self.compared += 1;
                self.technique_flips += u64::from(t0 != t1);
                self.reference_flips += u64::from(r0 != r1);
            }
            let (Some(t1), Some(r1)) = (after.technique[i], after.reference[i]) else { continue };
            let Some(j) = before.pixel_seeing(after.position[i], after.object_id[i]) else { continue };
            let (Some(t0), Some(r0)) = (before.technique[j], before.reference[j]) else { continue };
            self.reprojected += 1;
            self.shimmer_flips += u64::from(t0 != t1 && r0 == r1);
        }
    }

    /// The flicker measured over the pairs added so far; a rate with nothing to measure is 0.
    pub fn result(&self) -> Flicker {
        let rate = |n: u64, of: u64| n as f64 / of.max(1) as f64;
        let technique_flip_rate = rate(self.technique_flips, self.compared);
        let reference_flip_rate = rate(self.reference_flips, self.compared);
        Flicker {
            pairs: self.pairs,
            technique_flip_rate,
            reference_flip_rate,
            excess_flip_rate: technique_flip_rate - reference_flip_rate,
            shimmer_rate: rate(self.shimmer_flips, self.reprojected),
            reprojected: self.reprojected,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4×1 strip seen by an orthographic camera: pixel x sees world x + 0.5 − 2,
    /// shifted by `shift` world units (one unit per pixel).
    fn frame(shift: f32, technique: [Option<bool>; 4], reference: [Option<bool>; 4]) -> PathFrame {
        let view_from_world = Mat4::from_translation(Vec3::new(-shift, 0.0, -5.0));
        let clip_from_view = glam::camera::rh::proj::directx::orthographic(-2.0, 2.0, -0.5, 0.5, 0.1, 10.0);
        PathFrame {
            width: 4,
            height: 1,
            clip_from_world: clip_from_view * view_from_world,
            view_from_world,
            position: (0..4).map(|x| Vec3::new(x as f32 + 0.5 - 2.0 + shift, 0.0, 0.0)).collect(),
            object_id: vec![1; 4],
            depth: vec![5.0; 4],
            technique: technique.to_vec(),
            reference: reference.to_vec(),
        }
    }

    #[test]
    fn per_pixel_flips_count_against_the_reference() {
        let s = |v: [bool; 4]| v.map(Some);
        let before = frame(0.0, s([true, true, false, false]), s([true, true, false, true]));
        let after = frame(0.3, s([false, true, true, false]), s([false, true, false, false]));
        let mut counter = FlickerCounter::default();
        counter.add_pair(&before, &after);
        let f = counter.result();
        assert_eq!(f.pairs, 1);
        assert!((f.technique_flip_rate - 0.5).abs() < 1e-12);
        assert!((f.reference_flip_rate - 0.5).abs() < 1e-12);
        assert!(f.excess_flip_rate.abs() < 1e-12);
        // A shift of 0.3 pixel lands no reprojection near a pixel centre.
        assert_eq!(f.reprojected, 0);
    }

    #[test]
    fn shimmer_is_a_flip_at_the_same_surface_point_the_reference_does_not_share() {
        let s = |v: [bool; 4]| v.map(Some);
        // A whole-pixel shift: after's pixel x sees before's pixel x + 1.
        let before = frame(0.0, s([false, true, true, false]), s([false, true, true, true]));
        // Pixel 0 (before's 1) keeps its state; pixel 1 (before's 2) flips while the
        // reference does not: shimmer; at pixel 2 (before's 3) only the reference
        // flips, which is not the technique's doing.
        let after = frame(1.0, s([true, false, false, false]), s([true, true, false, false]));
        let mut counter = FlickerCounter::default();
        counter.add_pair(&before, &after);
        let f = counter.result();
        // Pixel 3 reprojects outside the strip.
        assert_eq!(f.reprojected, 3);
        assert!((f.shimmer_rate - 1.0 / 3.0).abs() < 1e-12, "{f:?}");
    }

    #[test]
    fn only_compared_pixels_have_a_state() {
        let classes = [PixelClass::Compared, PixelClass::Silhouette, PixelClass::Compared];
        assert_eq!(shadow_states(&[0.2, 0.2, 0.9], &classes), vec![Some(true), None, Some(false)]);
    }
}
