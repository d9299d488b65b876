//! Error where a shadow's edge is: over the reference's penumbra for an area light,
//! and over a band around its shadow boundary for a point-like one.
//!
//! Most compared pixels are fully lit or fully shadowed, where every technique is
//! right, so an error averaged over all of them is diluted by the ratio of the image
//! to its edges, many times over. These figures divide
//! by the edge alone: the [penumbra](in_penumbra) (pixel count, MAE, RMSE and the
//! [width error](WidthError) of its 10 %–90 % transition) and the [edge
//! band](EDGE_BAND_PX) (pixel count, MAE, RMSE).

use serde::Serialize;

use crate::{
    ReferenceImage,
    metrics::{PixelClass, RasterView},
    profile::{self, Field},
};

/// How many of the reference's own standard errors a penumbra pixel must lie above 0
/// and below 1: a Monte Carlo estimate of 1/256 with a standard error as large is not
/// known to be in the penumbra at all.
pub const PENUMBRA_STD_ERRORS: f32 = 1.0;

/// Half-width of the edge band, in pixels: a compared pixel is in the band when it
/// lies within this Euclidean distance of a boundary pixel, one whose reference
/// visibility is on the other side of 0.5 from a 4-neighbour on the same surface.
/// Two pixels hold a 5-tap filter's reach and a pixel of misplacement either way.
pub const EDGE_BAND_PX: i64 = 2;

/// Pixel count, MAE and RMSE of |V − R| over one set of compared pixels.
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct RegionError {
    /// Pixels in the set: the denominator.
    pub pixels: usize,
    /// Mean |V − R| over them (0 for an empty set).
    pub mae: f64,
    /// √mean (V − R)² over them (0 for an empty set).
    pub rmse: f64,
}

impl RegionError {
    fn over(pixels: &[usize], raster: RasterView, reference: &ReferenceImage) -> RegionError {
        let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
        for &i in pixels {
            let e = (raster.visibility[i] - reference.visibility[i]).abs() as f64;
            sum += e;
            sum_sq += e * e;
        }
        let n = pixels.len().max(1) as f64;
        RegionError { pixels: pixels.len(), mae: sum / n, rmse: (sum_sq / n).sqrt() }
    }
}

/// How far a technique's penumbra is from the reference's in width, over the edge
/// profiles ([`crate::profile`]): lines through the reference's 0.5 isoline along its
/// gradient, where each image's 10 %–90 % transition is measured in pixels.
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct WidthError {
    /// Profiles whose reference transition lies wholly on one surface: the denominator.
    pub profiles: usize,
    /// Of those, the profiles along which the technique has no rising transition
    /// within [`profile::MATCH_MARGIN_PX`] of the reference's (a leak, a missing or a
    /// displaced shadow), or one that runs off the surface before reaching 10 % or
    /// 90 % (a penumbra far too wide): counted here, left out of the means.
    pub unresolved: usize,
    /// Mean 10 %–90 % width of the reference over the resolved profiles, in pixels.
    pub reference_px: Option<f64>,
    /// Mean |w_V − w_R| over the resolved profiles, in pixels: the penumbra width error.
    pub error_px: Option<f64>,
    /// Mean w_V − w_R over the resolved profiles, in pixels: positive when the
    /// technique's penumbrae are too wide, negative when too sharp.
    pub bias_px: Option<f64>,
}

/// The error over the reference's penumbra.
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct Penumbra {
    /// Pixel count, MAE and RMSE over the penumbra pixels.
    #[serde(flatten)]
    pub error: RegionError,
    /// The width error, over the edge profiles.
    pub width: WidthError,
}

/// Whether a reference pixel of visibility `r` and standard error `std_error` is in
/// the penumbra: strictly between 0 and 1 by more than [`PENUMBRA_STD_ERRORS`]
/// standard errors. Exact (hard) visibility, 0 or 1, never is.
pub fn in_penumbra(r: f32, std_error: f32) -> bool {
    let margin = PENUMBRA_STD_ERRORS * std_error;
    r - margin > 0.0 && r + margin < 1.0
}

/// The compared pixels in the reference's penumbra.
pub fn penumbra_pixels(reference: &ReferenceImage, classes: &[PixelClass]) -> Vec<usize> {
    (0..classes.len())
        .filter(|&i| {
            classes[i] == PixelClass::Compared && in_penumbra(reference.visibility[i], reference.std_error[i])
        })
        .collect()
}

/// The compared pixels within [`EDGE_BAND_PX`] of the reference's shadow boundary.
pub fn edge_band(reference: &ReferenceImage, classes: &[PixelClass]) -> Vec<usize> {
    let (w, h) = (reference.width as i64, reference.height as i64);
    let label = labels(reference, classes);
    let lit = |i: usize| reference.visibility[i] >= 0.5;
    let boundary: Vec<bool> = (0..label.len())
        .map(|i| {
            let (x, y) = (i as i64 % w, i as i64 / w);
            label[i] != 0
                && [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)].iter().any(|&(nx, ny)| {
                    let j = (ny * w + nx) as usize;
                    nx >= 0 && ny >= 0 && nx < w && ny < h && label[j] == label[i] && lit(j) != lit(i)
                })
        })
        .collect();
    let b = EDGE_BAND_PX;
    (0..label.len())
        .filter(|&i| {
            let (x, y) = (i as i64 % w, i as i64 / w);
            label[i] != 0
                && (-b..=b).any(|dy| {
                    (-b..=b).any(|dx| {
                        let (nx, ny) = (x + dx, y + dy);
                        dx * dx + dy * dy <= b * b
                            && nx >= 0
                            && ny >= 0
                            && nx < w
                            && ny < h
                            && boundary[(ny * w + nx) as usize]
                    })
                })
        })
        .collect()
}

/// The error over the edge band ([`edge_band`]).
pub fn measure_edge(raster: RasterView, reference: &ReferenceImage, classes: &[PixelClass]) -> RegionError {
    RegionError::over(&edge_band(reference, classes), raster, reference)
}

/// The error over the reference's penumbra: its pixels' MAE and RMSE, and the width
/// error along the edge profiles seeded on them.
pub fn measure_penumbra(raster: RasterView, reference: &ReferenceImage, classes: &[PixelClass]) -> Penumbra {
    let pixels = penumbra_pixels(reference, classes);
    let error = RegionError::over(&pixels, raster, reference);
    if pixels.is_empty() {
        return Penumbra { error, width: WidthError::default() };
    }
    let mut seed = vec![false; classes.len()];
    for &i in &pixels {
        seed[i] = true;
    }
    let label = labels(reference, classes);
    let field = |values| Field {
        width: reference.width as usize,
        height: reference.height as usize,
        values,
        label: &label,
    };
    let (reference_field, technique_field) = (field(&reference.visibility), field(raster.visibility));
    let profiles = profile::profiles(&reference_field, |i| seed[i]);
    Penumbra { error, width: width_error(&reference_field, &technique_field, &profiles) }
}

/// The width error of `technique` against `reference` over `profiles`.
pub fn width_error(reference: &Field, technique: &Field, profiles: &[profile::Profile]) -> WidthError {
    let mut out = WidthError::default();
    let (mut reference_sum, mut abs_sum, mut signed_sum, mut resolved) = (0.0f64, 0.0f64, 0.0f64, 0usize);
    for p in profiles {
        let Some((r, v)) = profile::measure_profile(reference, technique, p) else {
            continue;
        };
        out.profiles += 1;
        let Some(v) = v else {
            out.unresolved += 1;
            continue;
        };
        let difference = (v.width() - r.width()) as f64;
        reference_sum += r.width() as f64;
        abs_sum += difference.abs();
        signed_sum += difference;
        resolved += 1;
    }
    if resolved > 0 {
        let n = resolved as f64;
        out.reference_px = Some(reference_sum / n);
        out.error_px = Some(abs_sum / n);
        out.bias_px = Some(signed_sum / n);
    }
    out
}

/// Each compared pixel's reference object id, 0 elsewhere: the regions a profile and
/// the boundary stay within.
fn labels(reference: &ReferenceImage, classes: &[PixelClass]) -> Vec<u32> {
    classes
        .iter()
        .zip(&reference.object_id)
        .map(|(c, &id)| if *c == PixelClass::Compared { id } else { 0 })
        .collect()
}
