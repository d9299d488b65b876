//! Error pictures: where a technique is wrongly shadowed or wrongly lit (hard
//! shadows), or how far off it is (soft shadows), with the colours their legends use.

use crate::{ReferenceImage, metrics::PixelClass};

/// Hard-shadow heat-map colours, with their legend labels.
///
/// This one: a compared pixel that the technique shadows but the reference lights (red).
pub const FALSE_SHADOW: [u8; 3] = [235, 60, 50];
/// Compared pixel that the technique lights but the reference shadows (blue).
pub const FALSE_LIT: [u8; 3] = [40, 140, 255];
/// Pixel where the two images see different surfaces, never compared (yellow).
pub const SILHOUETTE: [u8; 3] = [230, 190, 30];
/// Pixel of a surface that faces away from the light or lies outside its cone or
/// range: no shadow decides it, never compared (dark blue-grey).
pub const UNLIT: [u8; 3] = [52, 56, 72];
/// Pixel where neither image sees a surface (near-black).
pub const BACKGROUND: [u8; 3] = [28, 28, 34];
/// Compared pixel lit in both images (light grey).
pub const CORRECT_LIT: [u8; 3] = [190, 190, 190];
/// Compared pixel shadowed in both images (dark grey).
pub const CORRECT_SHADOW: [u8; 3] = [85, 85, 85];

/// The legend of [`hard`]'s picture: each label with its colour (the background is left out).
pub const HARD_LEGEND: &[(&str, [u8; 3])] = &[
    ("false shadow", FALSE_SHADOW),
    ("false lit", FALSE_LIT),
    ("silhouette", SILHOUETTE),
    ("faces away", UNLIT),
    ("correct lit", CORRECT_LIT),
    ("correct shadow", CORRECT_SHADOW),
];

/// RGBA8 pixels: background, silhouette and unlit colours, and `compared(i)` elsewhere.
fn paint(classes: &[PixelClass], compared: impl Fn(usize) -> [u8; 3]) -> Vec<u8> {
    classes
        .iter()
        .enumerate()
        .flat_map(|(i, class)| {
            let [r, g, b] = match class {
                PixelClass::Background => BACKGROUND,
                PixelClass::Silhouette => SILHOUETTE,
                PixelClass::Unlit => UNLIT,
                PixelClass::Compared => compared(i),
            };
            [r, g, b, 255]
        })
        .collect()
}

/// RGBA8 image of the hard-shadow errors of `visibility` (thresholded at 0.5).
pub fn hard(visibility: &[f32], reference: &ReferenceImage, classes: &[PixelClass]) -> Vec<u8> {
    paint(classes, |i| match (reference.visibility[i] >= 0.5, visibility[i] >= 0.5) {
        (true, false) => FALSE_SHADOW,
        (false, true) => FALSE_LIT,
        (true, true) => CORRECT_LIT,
        (false, false) => CORRECT_SHADOW,
    })
}

/// RGBA8 image of the hard-shadow errors of `visibility` against the truth at its
/// own surfaces ([`crate::drawn`]): every light-facing pixel is compared, ambiguous
/// ones painted as the silhouette colour (counted apart, as the metric does).
pub fn drawn(visibility: &[f32], truth: &crate::drawn::DrawnTruth) -> Vec<u8> {
    visibility
        .iter()
        .enumerate()
        .flat_map(|(i, &v)| {
            let [r, g, b] = if !v.is_finite() || !truth.visibility[i].is_finite() {
                BACKGROUND
            } else if !truth.faces_light[i] {
                UNLIT
            } else if truth.ambiguous[i] {
                SILHOUETTE
            } else {
                match (truth.visibility[i] >= 0.5, v >= 0.5) {
                    (true, false) => FALSE_SHADOW,
                    (false, true) => FALSE_LIT,
                    (true, true) => CORRECT_LIT,
                    (false, false) => CORRECT_SHADOW,
                }
            };
            [r, g, b, 255]
        })
        .collect()
}

/// The soft-error colour ramp for |V − R| in [0, 1]: black, violet, orange, yellow
/// (a coarse approximation of matplotlib's "inferno").
pub fn ramp(e: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 5] =
        [[0.0, 0.0, 0.02], [0.34, 0.06, 0.43], [0.73, 0.21, 0.33], [0.98, 0.55, 0.04], [0.99, 1.0, 0.64]];
    let x = e.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let k = (x.floor() as usize).min(STOPS.len() - 2);
    let t = x - k as f32;
    std::array::from_fn(|c| ((STOPS[k][c] * (1.0 - t) + STOPS[k + 1][c] * t) * 255.0).round() as u8)
}

/// RGBA8 image of |V − R| through [`ramp`].
pub fn soft(visibility: &[f32], reference: &ReferenceImage, classes: &[PixelClass]) -> Vec<u8> {
    paint(classes, |i| ramp((visibility[i] - reference.visibility[i]).abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each pixel of the drawn heat-map is painted by its class against the truth.
    #[test]
    fn drawn_paints_each_class_its_colour() {
        let truth = crate::drawn::DrawnTruth {
            visibility: vec![1.0, 0.0, 1.0, 0.0, 0.0, 1.0, f32::NAN],
            std_error: vec![0.0; 7],
            faces_light: vec![true, true, true, true, false, true, false],
            ambiguous: vec![false, false, false, false, false, true, false],
            samples: 1,
            rays: 0,
        };
        let frame = [0.0, 1.0, 1.0, 0.0, 0.0, 1.0, f32::NAN];
        let painted: Vec<[u8; 3]> = drawn(&frame, &truth).chunks(4).map(|p| [p[0], p[1], p[2]]).collect();
        let expected = [FALSE_SHADOW, FALSE_LIT, CORRECT_LIT, CORRECT_SHADOW, UNLIT, SILHOUETTE, BACKGROUND];
        assert_eq!(painted, expected);
    }

    #[test]
    fn ramp_runs_dark_to_bright() {
        let luma = |c: [u8; 3]| c[0] as u32 * 3 + c[1] as u32 * 6 + c[2] as u32;
        let mut last = 0;
        for k in 0..=10 {
            let l = luma(ramp(k as f32 / 10.0));
            assert!(l >= last, "ramp must brighten monotonically");
            last = l;
        }
        assert_eq!(ramp(0.0), [0, 0, 5]);
    }
}
