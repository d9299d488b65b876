//! Error metrics of a technique's visibility V against the reference R, over the
//! pixels the shadow decides: both images see the same surface, and it faces the
//! light and lies inside its cone and range. A surface turned away from the light is
//! dark in both images whatever the shadow map says, so counting it would only
//! dilute the error; the rate over every surface pixel is kept as a second, named
//! figure ([`Metrics::surface_mismatch_rate`]).

use serde::Serialize;

use crate::{
    ReferenceImage,
    penumbra::{self, Penumbra, RegionError},
};

/// A technique's per-pixel output, as the metrics need it.
#[derive(Clone, Copy)]
pub struct RasterView<'a> {
    /// Shadow factor in [0, 1]; NaN for background.
    pub visibility: &'a [f32],
    /// Instance index + 1; 0 for background.
    pub object_id: &'a [u32],
    /// View-space depth; NaN for background.
    pub depth: &'a [f32],
}

/// How a pixel takes part in a comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelClass {
    /// Neither image sees a surface.
    Background,
    /// The two images see different surfaces (an object's outline, or a depth
    /// difference beyond the tolerance): reported, never compared.
    Silhouette,
    /// Both see the same surface, and it faces the light inside its cone and range:
    /// compared.
    Compared,
    /// Both see the same surface, but it faces away from the light or lies outside its
    /// cone or range: no shadow decides it. Counted in
    /// [`Metrics::surface_mismatch_rate`] only.
    Unlit,
}

/// What each rate of [`Metrics`] divides by, as reports print it: (field, denominator).
pub const DENOMINATORS: &[(&str, &str)] = &[
    (
        "compared",
        "light-facing pixels: both images see the same surface, which faces the light (geometric N·L > 0 in the reference) inside its cone and range",
    ),
    (
        "false_shadow_rate, false_lit_rate, mismatch_rate, mae, rmse, p99",
        "the compared (light-facing) pixels",
    ),
    (
        "surface_mismatch_rate",
        "every pixel of a surface both images see, light-facing or not (compared + unlit)",
    ),
    (
        "penumbra.pixels, penumbra.mae, penumbra.rmse",
        "the penumbra: compared pixels where the reference is strictly between 0 and 1 by more than its own standard error (R − SE > 0 and R + SE < 1); none under a point-like light",
    ),
    (
        "penumbra.width.error_px, penumbra.width.bias_px, penumbra.width.reference_px",
        "the resolved edge profiles: lines through penumbra pixels on the reference's 0.5 isoline, along its gradient, where both images' 10 %–90 % transitions were found on one surface (penumbra.width.profiles, less penumbra.width.unresolved)",
    ),
    (
        "edge.pixels, edge.mae, edge.rmse",
        "the edge band: compared pixels within 2 px of the reference's shadow boundary (where it crosses 0.5 between 4-neighbours on one surface)",
    ),
];

/// Relative depth difference under which two hits on the same object are one surface.
pub const DEPTH_TOLERANCE: f32 = 1e-3;

/// Classifies every pixel: the same object at a depth within [`DEPTH_TOLERANCE`] is
/// one surface, compared where the reference says it faces the light.
pub fn classify(raster: RasterView, reference: &ReferenceImage) -> Vec<PixelClass> {
    (0..reference.pixel_count())
        .map(|i| {
            let (a, b) = (raster.object_id[i], reference.object_id[i]);
            match (a, b) {
                (0, 0) => PixelClass::Background,
                _ if a != b => PixelClass::Silhouette,
                _ => {
                    let (da, db) = (raster.depth[i], reference.depth[i]);
                    if (da - db).abs() > DEPTH_TOLERANCE * db.abs().max(1e-6) {
                        PixelClass::Silhouette
                    } else if reference.faces_light[i] {
                        PixelClass::Compared
                    } else {
                        PixelClass::Unlit
                    }
                }
            }
        })
        .collect()
}

/// Everything measured for one technique. Every count, rate and error is over the
/// compared (light-facing) pixels, except [`Metrics::surface_mismatch_rate`], and
/// [`Metrics::penumbra`] and [`Metrics::edge`], over subsets of them.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Metrics {
    /// Light-facing pixels compared: the denominator of the rates.
    pub compared: usize,
    /// Pixels of a surface both images see that faces away from the light or lies
    /// outside its cone or range (not compared).
    pub unlit: usize,
    /// Pixels where the two images see different surfaces (not compared).
    pub silhouette: usize,
    /// Reference lit (R ≥ 0.5), technique shadowed (V < 0.5): acne, over-darkening.
    pub false_shadow: usize,
    /// Reference shadowed (R < 0.5), technique lit (V ≥ 0.5): leaks, peter-panning.
    pub false_lit: usize,
    /// `false_shadow / compared`.
    pub false_shadow_rate: f64,
    /// `false_lit / compared`.
    pub false_lit_rate: f64,
    /// `(false_shadow + false_lit) / compared`.
    pub mismatch_rate: f64,
    /// Mean |V − R|.
    pub mae: f64,
    /// √mean (V − R)².
    pub rmse: f64,
    /// 99th percentile of |V − R|.
    pub p99: f64,
    /// Mismatches over every pixel of a surface both images see, facing the light or
    /// not (`compared + unlit`): the all-surface rate Gnomon reported before it
    /// counted only light-facing pixels. Lower than [`Metrics::mismatch_rate`] by
    /// about the share of unlit pixels.
    pub surface_mismatch_rate: f64,
    /// Over the reference's penumbra: its pixel count, MAE, RMSE and the width error
    /// of its transitions. Empty under a point-like light.
    pub penumbra: Penumbra,
    /// Over the band of ±[`EDGE_BAND_PX`](crate::penumbra::EDGE_BAND_PX) pixels around
    /// the reference's shadow boundary: where a hard shadow's filtering shows.
    pub edge: RegionError,
}

impl Metrics {
    /// Pixels of a surface both images see, facing the light or not.
    pub fn surface(&self) -> usize {
        self.compared + self.unlit
    }
}

/// Measures `raster` against `reference` over the pixels `classes` marks compared.
pub fn measure(raster: RasterView, reference: &ReferenceImage, classes: &[PixelClass]) -> Metrics {
    let mut m = Metrics {
        compared: 0,
        unlit: 0,
        silhouette: 0,
        false_shadow: 0,
        false_lit: 0,
        false_shadow_rate: 0.0,
        false_lit_rate: 0.0,
        mismatch_rate: 0.0,
        mae: 0.0,
        rmse: 0.0,
        p99: 0.0,
        surface_mismatch_rate: 0.0,
        penumbra: penumbra::measure_penumbra(raster, reference, classes),
        edge: penumbra::measure_edge(raster, reference, classes),
    };
    // Mismatches on unlit pixels: both images should be dark there, but their tests
    // of which way a surface faces can differ at the terminator.
    let mut unlit_mismatches = 0usize;
    let mismatch = |v: f32, r: f32| (r >= 0.5) != (v >= 0.5);
    let mut errors = Vec::new();
    let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
    for (i, class) in classes.iter().enumerate() {
        match class {
            PixelClass::Background => {}
            PixelClass::Silhouette => m.silhouette += 1,
            PixelClass::Unlit => {
                m.unlit += 1;
                unlit_mismatches += usize::from(mismatch(raster.visibility[i], reference.visibility[i]));
            }
            PixelClass::Compared => {
                let (v, r) = (raster.visibility[i], reference.visibility[i]);
                m.compared += 1;
                match (r >= 0.5, v >= 0.5) {
                    (true, false) => m.false_shadow += 1,
                    (false, true) => m.false_lit += 1,
                    _ => {}
                }
                let e = (v - r).abs() as f64;
                sum += e;
                sum_sq += e * e;
                errors.push(e);
            }
        }
    }
    if m.compared > 0 {
        let n = m.compared as f64;
        m.false_shadow_rate = m.false_shadow as f64 / n;
        m.false_lit_rate = m.false_lit as f64 / n;
        m.mismatch_rate = (m.false_shadow + m.false_lit) as f64 / n;
        m.mae = sum / n;
        m.rmse = (sum_sq / n).sqrt();
        errors.sort_by(f64::total_cmp);
        // Nearest-rank percentile.
        let rank = ((0.99 * n).ceil() as usize).clamp(1, errors.len());
        m.p99 = errors[rank - 1];
    }
    if m.surface() > 0 {
        m.surface_mismatch_rate =
            (m.false_shadow + m.false_lit + unlit_mismatches) as f64 / m.surface() as f64;
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference(visibility: Vec<f32>, object_id: Vec<u32>) -> ReferenceImage {
        let n = visibility.len();
        ReferenceImage {
            width: n as u32,
            height: 1,
            samples: 1,
            depth: object_id.iter().map(|&i| if i == 0 { f32::NAN } else { 10.0 }).collect(),
            faces_light: object_id.iter().map(|&i| i != 0).collect(),
            visibility,
            std_error: vec![0.0; n],
            object_id,
            triangle: vec![0; n],
            position: vec![glam::Vec3::ZERO; n],
            rays: n as u64,
        }
    }

    #[test]
    fn counts_false_shadow_false_lit_and_silhouettes() {
        let r = reference(vec![1.0, 1.0, 0.0, 0.0, 1.0, f32::NAN, 0.5], vec![1, 1, 1, 1, 2, 0, 1]);
        let v = [1.0, 0.0, 0.0, 1.0, 1.0, f32::NAN, 0.4];
        let ids = [1, 1, 1, 1, 1, 0, 1];
        let depth = [10.0, 10.0, 10.0, 10.0005, 10.0, f32::NAN, 10.0];
        let raster = RasterView { visibility: &v, object_id: &ids, depth: &depth };
        let classes = classify(raster, &r);
        assert_eq!(classes[4], PixelClass::Silhouette, "different objects");
        assert_eq!(classes[5], PixelClass::Background);
        assert_eq!(classes[3], PixelClass::Compared, "depth within tolerance");
        let m = measure(raster, &r, &classes);
        assert_eq!((m.compared, m.silhouette, m.false_shadow, m.false_lit), (5, 1, 2, 1));
        assert!((m.mismatch_rate - 0.6).abs() < 1e-12);
        assert!((m.mae - (1.0 + 1.0 + 0.1) / 5.0).abs() < 1e-6);
        assert!((m.p99 - 1.0).abs() < 1e-12);
        // A depth far off on the same object is a silhouette too.
        let depth = [10.0, 10.0, 10.0, 12.0, 10.0, f32::NAN, 10.0];
        let classes = classify(RasterView { visibility: &v, object_id: &ids, depth: &depth }, &r);
        assert_eq!(classes[3], PixelClass::Silhouette);
    }

    /// A pixel whose surface faces away from the light is never counted in the
    /// light-facing figures, however the two images disagree there; the all-surface
    /// rate still counts it.
    #[test]
    fn the_metric_counts_no_back_facing_pixel() {
        let mut r = reference(vec![1.0, 0.0, 0.0, 0.0], vec![1, 1, 1, 1]);
        // Pixels 1 to 3 face away from the light: the reference is dark there.
        r.faces_light = vec![true, false, false, false];
        let v = [1.0, 1.0, 0.0, 0.0];
        let (ids, depth) = ([1; 4], [10.0; 4]);
        let raster = RasterView { visibility: &v, object_id: &ids, depth: &depth };
        let classes = classify(raster, &r);
        assert_eq!(classes, [PixelClass::Compared, PixelClass::Unlit, PixelClass::Unlit, PixelClass::Unlit]);
        let m = measure(raster, &r, &classes);
        assert_eq!((m.compared, m.unlit, m.false_shadow, m.false_lit), (1, 3, 0, 0));
        assert_eq!((m.mismatch_rate, m.mae), (0.0, 0.0));
        assert!((m.surface_mismatch_rate - 0.25).abs() < 1e-12, "{m:?}");
        // Turned toward the light, the same pixel 1 is a false lit.
        r.faces_light[1] = true;
        let m = measure(raster, &r, &classify(raster, &r));
        assert_eq!((m.compared, m.false_lit), (2, 1));
        assert!((m.mismatch_rate - 0.5).abs() < 1e-12);
    }
}
