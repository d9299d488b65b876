//! The penumbra metrics against analytic truth: a straight edge under a disk light,
//! whose visibility across the edge is the uncovered share of the disk (a circular
//! segment), seen in an image at an angle to the pixel grid.

use crate::common;

use common::{disk_visible, figures::figure};
use glam::{Vec2, Vec3};
use gnomon_reference::{
    ReferenceImage,
    metrics::{self, PixelClass, RasterView},
    penumbra::{self, edge_band, in_penumbra, penumbra_pixels},
    profile::{self, Field},
};

const W: usize = 240;
const H: usize = 160;
/// The edge's normal makes this angle with the image's x axis, so that profiles are
/// not along the pixel grid.
const EDGE_ANGLE_DEGREES: f32 = 30.0;

/// The analytic 10 %–90 % width of a penumbra whose disk spans `radius_px` pixels
/// either side of the edge: `radius_px · 2u₉₀`, where the segment area is 0.9.
fn analytic_width(radius_px: f32) -> f32 {
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if disk_visible(mid) < profile::HIGH { lo = mid } else { hi = mid }
    }
    radius_px * 2.0 * 0.5 * (lo + hi)
}

/// Signed distance of pixel `i`'s centre from the edge through the image centre, in
/// pixels, positive on the lit side.
fn signed_distance(i: usize) -> f32 {
    let a = EDGE_ANGLE_DEGREES.to_radians();
    let p = Vec2::new((i % W) as f32, (i / W) as f32) - Vec2::new(W as f32 / 2.0, H as f32 / 2.0);
    p.dot(Vec2::new(a.cos(), a.sin()))
}

/// The exact visibility under a disk of `radius_px` (0: a hard step).
fn exact(radius_px: f32) -> Vec<f32> {
    (0..W * H)
        .map(|i| {
            let s = signed_distance(i);
            if radius_px == 0.0 { f32::from(s >= 0.0) } else { disk_visible(s / radius_px) }
        })
        .collect()
}

/// A Monte Carlo estimate of [`exact`] as the reference makes it: eight stratified
/// batches of 32 disk samples, the standard error from the spread of the batch means.
fn monte_carlo(radius_px: f32) -> (Vec<f32>, Vec<f32>) {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        // SplitMix64.
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    };
    let (mut visibility, mut std_error) = (Vec::new(), Vec::new());
    for i in 0..W * H {
        let u = signed_distance(i) / radius_px;
        let means: Vec<f32> = (0..8)
            .map(|_| {
                // 4 × 8 strata of (r², θ): uniform over the disk's area.
                let hits = (0..32)
                    .filter(|s| {
                        let r = (((s / 8) as f32 + next()) / 4.0).sqrt();
                        let theta = ((s % 8) as f32 + next()) / 8.0 * std::f32::consts::TAU;
                        r * theta.cos() < u
                    })
                    .count();
                hits as f32 / 32.0
            })
            .collect();
        let mean = means.iter().sum::<f32>() / 8.0;
        let variance = means.iter().map(|m| (m - mean).powi(2)).sum::<f32>() / 7.0;
        visibility.push(mean);
        std_error.push((variance / 8.0).sqrt());
    }
    (visibility, std_error)
}

/// A reference image of one surface (object 1) that faces the light everywhere.
fn reference(visibility: Vec<f32>, std_error: Vec<f32>) -> ReferenceImage {
    let n = visibility.len();
    ReferenceImage {
        width: W as u32,
        height: (n / W) as u32,
        samples: 256,
        visibility,
        faces_light: vec![true; n],
        std_error,
        object_id: vec![1; n],
        triangle: vec![0; n],
        depth: vec![10.0; n],
        position: vec![Vec3::ZERO; n],
        rays: n as u64,
    }
}

/// `compare`'s metrics of the visibility `v` against `r`.
fn measure(v: &[f32], r: &ReferenceImage) -> metrics::Metrics {
    let (ids, depth) = (vec![1u32; v.len()], vec![10.0f32; v.len()]);
    let raster = RasterView { visibility: v, object_id: &ids, depth: &depth };
    metrics::measure(raster, r, &metrics::classify(raster, r))
}

const RADIUS_PX: f32 = 15.0;

/// The helper's width of the exact penumbra is the analytic one: the reference
/// against itself has no width error, and its measured width is the circular
/// segment's.
#[test]
fn the_exact_penumbra_has_the_analytic_width() {
    let expected = analytic_width(RADIUS_PX);
    let truth = reference(exact(RADIUS_PX), vec![0.0; W * H]);
    let m = measure(&truth.visibility, &truth);
    let width = m.penumbra.width;
    eprintln!("exact: {width:?}, analytic width {expected:.3} px");
    assert!(width.profiles > 100, "{width:?}");
    assert_eq!(width.unresolved, 0);
    assert_eq!(width.error_px, Some(0.0));
    let measured = width.reference_px.unwrap();
    figure(
        "penumbra width of the exact disk penumbra (px)",
        format!("{measured:.3}"),
        format!("{expected:.3} ± 0.25"),
    );
    assert!((measured - expected as f64).abs() < 0.25, "{measured} vs {expected}");
}

/// A 256-sample Monte Carlo reference against the exact visibility: the width error
/// is near 0 (Monte Carlo noise moves each crossing by a fraction of a pixel); a
/// visibility blurred to a disk twice as large has the predicted error, the analytic
/// width, and is too wide; a hard step is too sharp by that width, less the pixel
/// its bilinear sampling spreads it over.
#[test]
fn the_width_error_of_a_reference_is_near_zero_and_a_blur_has_the_predicted_one() {
    let w = analytic_width(RADIUS_PX) as f64;
    let (visibility, std_error) = monte_carlo(RADIUS_PX);
    let noisy = reference(visibility, std_error);

    let own = measure(&exact(RADIUS_PX), &noisy).penumbra.width;
    eprintln!("exact against Monte Carlo: {own:?}");
    assert!(own.profiles > 100 && own.unresolved == 0, "{own:?}");
    let own_error = own.error_px.unwrap();
    figure(
        "width error of the exact penumbra against a 256-sample reference (px)",
        format!("{own_error:.3}"),
        format!("< {:.3} (5 % of {w:.2})", 0.05 * w),
    );
    assert!(own_error < 0.05 * w, "{own:?}");

    let blurred = measure(&exact(2.0 * RADIUS_PX), &noisy).penumbra.width;
    eprintln!("twice the disk against Monte Carlo: {blurred:?}, predicted error {w:.3}");
    let (error, bias) = (blurred.error_px.unwrap(), blurred.bias_px.unwrap());
    figure(
        "width error of a penumbra blurred to twice the disk (px)",
        format!("{error:.3}"),
        format!("{w:.3} ± 5 %"),
    );
    assert!((error - w).abs() < 0.05 * w && (bias - w).abs() < 0.05 * w, "{blurred:?}");

    let hard = measure(&exact(0.0), &noisy).penumbra.width;
    eprintln!("a hard step against Monte Carlo: {hard:?}");
    let bias = hard.bias_px.unwrap();
    assert!(
        bias < 0.0 && (bias + w).abs() < 1.5,
        "{hard:?}: the step is w = {w:.2} too sharp, within 1.5 px"
    );
}

/// Exact visibility (0 or 1 everywhere, no standard error) has no penumbra: no
/// penumbra pixels and no profiles, while the edge band is the two boundary columns
/// and two more on each side.
#[test]
fn a_hard_shadow_has_no_penumbra_pixels_and_an_edge_band() {
    let step: Vec<f32> = (0..W * H).map(|i| f32::from(i % W >= W / 2)).collect();
    let truth = reference(step.clone(), vec![0.0; W * H]);
    let classes = vec![PixelClass::Compared; W * H];
    assert!(penumbra_pixels(&truth, &classes).is_empty());
    let band = edge_band(&truth, &classes);
    assert_eq!(band.len(), 6 * H, "columns W/2 − 3 to W/2 + 2");
    assert!(band.iter().all(|&i| (W / 2 - 3..W / 2 + 3).contains(&(i % W))));
    // One column of the technique's shadow shifted into the light: an error of 1 on a
    // sixth of the band.
    let shifted: Vec<f32> = (0..W * H).map(|i| f32::from(i % W > W / 2)).collect();
    let m = measure(&shifted, &truth);
    assert_eq!((m.penumbra.error.pixels, m.penumbra.width.profiles), (0, 0));
    assert_eq!(m.edge.pixels, 6 * H);
    assert!((m.edge.mae - 1.0 / 6.0).abs() < 1e-9, "{:?}", m.edge);
    assert!((m.mae - 1.0 / W as f64).abs() < 1e-9, "all pixels dilute the same error 40 times");
}

/// A reference pixel is in the penumbra only when its estimate lies more than one
/// standard error from both 0 and 1: a pixel whose error bar straddles either end is
/// not, and its error counts in the all-pixel MAE only.
#[test]
fn the_penumbra_mae_ignores_pixels_whose_standard_error_straddles_0_or_1() {
    assert!(!in_penumbra(0.0, 0.0) && !in_penumbra(1.0, 0.0));
    assert!(!in_penumbra(0.01, 0.02) && !in_penumbra(0.99, 0.02) && !in_penumbra(0.02, 0.02));
    assert!(in_penumbra(0.5, 0.01) && in_penumbra(0.03, 0.02) && in_penumbra(0.5, 0.0));
    // One row: R = 0.01 ± 0.02 and 0.99 ± 0.02 straddle; 0.5 ± 0.01 and 0.2 ± 0.05 do not.
    let mut truth = reference(vec![0.01, 0.99, 0.5, 0.2], vec![0.02, 0.02, 0.01, 0.05]);
    (truth.width, truth.height) = (4, 1);
    let v = [1.0, 0.0, 0.6, 0.0];
    let classes = vec![PixelClass::Compared; 4];
    assert_eq!(penumbra_pixels(&truth, &classes), vec![2, 3]);
    let (ids, depth) = ([1u32; 4], [10.0f32; 4]);
    let raster = RasterView { visibility: &v, object_id: &ids, depth: &depth };
    let p = penumbra::measure_penumbra(raster, &truth, &classes);
    assert_eq!(p.error.pixels, 2);
    assert!((p.error.mae - (0.1 + 0.2) / 2.0).abs() < 1e-6, "{p:?}");
    assert!((p.error.rmse - ((0.01 + 0.04) / 2.0f64).sqrt()).abs() < 1e-6, "{p:?}");
}

/// Along one line, a linear ramp from 0 to 1 over 10 pixels rises through 10 % and
/// 90 % 8 pixels apart; a line that leaves the region first measures nothing.
#[test]
fn a_transition_along_a_ramp_is_eight_tenths_of_it() {
    let values: Vec<f32> = (0..W).map(|x| ((x as f32 - 100.0) / 10.0).clamp(0.0, 1.0)).collect();
    let values: Vec<f32> = values.iter().cycle().take(W * 4).copied().collect();
    let mut label = vec![1u32; W * 4];
    let field = Field { width: W, height: 4, values: &values, label: &label };
    let t = profile::transition(&field, 1, Vec2::new(105.0, 1.5), Vec2::X, -50.0..=50.0).unwrap();
    assert!((t.width() - 8.0).abs() < 1e-4 && t.middle.abs() < 1e-4, "{t:?}");
    // The 0.5 crossing must lie in the window.
    assert!(profile::transition(&field, 1, Vec2::new(105.0, 1.5), Vec2::X, 1.0..=50.0).is_none());
    // A gap in the region at x = 102 cuts the line before it reaches 10 %.
    for y in 0..4 {
        label[y * W + 102] = 0;
    }
    let field = Field { width: W, height: 4, values: &values, label: &label };
    assert!(profile::transition(&field, 1, Vec2::new(105.0, 1.5), Vec2::X, -50.0..=50.0).is_none());
}
