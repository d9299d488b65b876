//! Penumbra widths: the 10 %–90 % transition of a visibility image, measured along
//! lines that follow the reference's gradient across its penumbra.
//!
//! A penumbra's width is the one thing a soft-shadow technique is built to get right
//! (PCSS estimates it from the blocker distance; a fixed filter assumes one), and a
//! per-pixel error hides it: a penumbra twice too wide and one shifted by half its
//! width can have the same MAE. So an *edge profile* starts at a pixel on the
//! reference's 0.5 isoline, goes both ways along the reference's gradient there, and
//! finds where each image's rising transition crosses 10 % and 90 %. The difference of
//! the two distances, in pixels, is the profile's width error.

use glam::Vec2;

/// The transition's low and high levels: its width is the distance between them.
pub const LOW: f32 = 0.1;
/// See [`LOW`].
pub const HIGH: f32 = 0.9;
/// Step along a profile, in pixels: a quarter pixel, so that the interpolated
/// crossings are not quantised to the pixel grid.
const STEP_PX: f32 = 0.25;
/// The longest a profile reaches on each side of its seed, in pixels: wider
/// penumbrae than this (rare below 4K) are not measured.
pub const MAX_REACH_PX: f32 = 512.0;
/// How far beyond the reference's transition the technique's own transition may lie
/// and still be the same edge, in pixels; farther, the profile counts as unresolved.
pub const MATCH_MARGIN_PX: f32 = 4.0;
/// Radius of the box filter, applied twice, that smooths the reference before its
/// isoline and gradient are taken: a 256-sample Monte Carlo estimate has a standard
/// error up to 0.03, more than its gradient across a 100-pixel penumbra.
pub const SMOOTHING_RADIUS_PX: usize = 3;

/// A single-channel image in which only the pixels of one region count: its pixels
/// are row-major, top row first, and `label` is 0 outside every region.
#[derive(Clone, Copy)]
pub struct Field<'a> {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// One value per pixel.
    pub values: &'a [f32],
    /// The region of each pixel (for the metrics: the reference's object id on a
    /// compared pixel), 0 where no profile may pass.
    pub label: &'a [u32],
}

impl Field<'_> {
    /// Bilinear value at `p`, in pixel units with pixel (x, y)'s centre at (x, y), when
    /// its four taps all lie in region `label`; `None` otherwise.
    pub fn sample(&self, p: Vec2, label: u32) -> Option<f32> {
        let (x0, y0) = (p.x.floor(), p.y.floor());
        if x0 < 0.0 || y0 < 0.0 || x0 + 1.0 >= self.width as f32 || y0 + 1.0 >= self.height as f32 {
            return None;
        }
        let (fx, fy) = (p.x - x0, p.y - y0);
        let i = y0 as usize * self.width + x0 as usize;
        let taps = [i, i + 1, i + self.width, i + self.width + 1];
        if taps.iter().any(|&t| self.label[t] != label) {
            return None;
        }
        let v = taps.map(|t| self.values[t]);
        Some((v[0] * (1.0 - fx) + v[1] * fx) * (1.0 - fy) + (v[2] * (1.0 - fx) + v[3] * fx) * fy)
    }
}

/// A rising transition found along a line: where it crosses [`LOW`], 0.5 and
/// [`HIGH`], in pixels from the line's origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transition {
    /// Where the values rise through [`LOW`].
    pub low: f32,
    /// Where they rise through 0.5.
    pub middle: f32,
    /// Where they rise through [`HIGH`].
    pub high: f32,
}

impl Transition {
    /// The 10 %–90 % width, in pixels.
    pub fn width(&self) -> f32 {
        self.high - self.low
    }
}

/// The rising transition of `field` (region `label`) along `origin + t·direction`
/// whose 0.5 crossing lies in `window` (pixels from the origin) and is nearest the
/// origin. From that crossing the line is followed backward to the first value at or
/// below [`LOW`] and forward to the first at or above [`HIGH`]; the crossings are
/// interpolated between quarter-pixel steps. `None` when there is no such crossing,
/// or the line leaves the region (or [`MAX_REACH_PX`]) before reaching either level.
pub fn transition(
    field: &Field,
    label: u32,
    origin: Vec2,
    direction: Vec2,
    window: std::ops::RangeInclusive<f32>,
) -> Option<Transition> {
    let at = |k: i32| field.sample(origin + direction * (k as f32 * STEP_PX), label);
    let reach = (MAX_REACH_PX / STEP_PX) as i32;
    // The samples along the line, contiguous in the region around the origin.
    let mut backward = Vec::new();
    for k in (-reach..0).rev() {
        match at(k) {
            Some(v) => backward.push(v),
            None => break,
        }
    }
    let first = -(backward.len() as i32);
    let mut values: Vec<f32> = backward.into_iter().rev().collect();
    for k in 0..=reach {
        match at(k) {
            Some(v) => values.push(v),
            None => break,
        }
    }
    // Where the values cross `level` between samples `index` and `index + 1`.
    let t_of = |index: usize, level: f32| {
        let (a, b) = (values[index], values[index + 1]);
        let fraction = if b == a { 0.0 } else { (level - a) / (b - a) };
        ((first + index as i32) as f32 + fraction) * STEP_PX
    };
    // The upward 0.5 crossing in the window nearest the origin.
    let middle_index = (0..values.len().saturating_sub(1))
        .filter(|&k| values[k] < 0.5 && values[k + 1] >= 0.5)
        .map(|k| (k, t_of(k, 0.5)))
        .filter(|(_, t)| window.contains(t))
        .min_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?;
    let (k, middle) = middle_index;
    // values[k] < 0.5 ≤ values[k + 1], so the last sample at or below LOW up to k has
    // a successor above it, and the first at or above HIGH from k + 1 a predecessor below.
    let low_k = (0..=k).rev().find(|&j| values[j] <= LOW)?;
    let high_k = (k + 1..values.len()).find(|&j| values[j] >= HIGH)?;
    let (low, high) = (t_of(low_k, LOW), t_of(high_k - 1, HIGH));
    Some(Transition { low, middle, high })
}

/// One edge profile: a point on the reference's 0.5 isoline and the direction in
/// which the reference rises there, both in pixels (x right, y down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    /// The seed pixel's centre.
    pub origin: Vec2,
    /// Unit direction of the smoothed reference's gradient at the seed.
    pub direction: Vec2,
    /// The seed's region.
    pub label: u32,
}

/// The edge profiles of `reference`: one per pixel that `seeds` allows, at or above
/// 0.5 in the smoothed reference with a 4-neighbour of its region below it, oriented
/// along the smoothed gradient. Smoothing ([`SMOOTHING_RADIUS_PX`]) keeps Monte Carlo
/// noise from scattering seeds through a wide penumbra and turning its gradient.
pub fn profiles(reference: &Field, seeds: impl Fn(usize) -> bool) -> Vec<Profile> {
    let smooth = smoothed(reference);
    let (w, h) = (reference.width, reference.height);
    let label = reference.label;
    let value = |x: usize, y: usize, l: u32| {
        let i = y * w + x;
        (label[i] == l).then_some(smooth[i])
    };
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let l = label[i];
            if l == 0 || smooth[i] < 0.5 || !seeds(i) {
                continue;
            }
            let neighbours = [
                (x > 0).then(|| (x - 1, y)),
                (x + 1 < w).then_some((x + 1, y)),
                (y > 0).then(|| (x, y - 1)),
                (y + 1 < h).then_some((x, y + 1)),
            ];
            let n = neighbours.map(|p| p.and_then(|(nx, ny)| value(nx, ny, l)));
            if !n.iter().flatten().any(|&v| v < 0.5) {
                continue;
            }
            // Central differences where both sides lie in the region, one-sided otherwise.
            let centre = smooth[i];
            let derivative = |minus: Option<f32>, plus: Option<f32>| match (minus, plus) {
                (Some(a), Some(b)) => 0.5 * (b - a),
                (Some(a), None) => centre - a,
                (None, Some(b)) => b - centre,
                (None, None) => 0.0,
            };
            let gradient = Vec2::new(derivative(n[0], n[1]), derivative(n[2], n[3]));
            if let Some(direction) = gradient.try_normalize() {
                out.push(Profile { origin: Vec2::new(x as f32, y as f32), direction, label: l });
            }
        }
    }
    out
}

/// Width error of one profile: the technique's and the reference's transitions
/// along it. `None` when the reference's own transition leaves its region (the
/// profile is not measured); the technique's is `None` when it has no rising
/// transition within [`MATCH_MARGIN_PX`] of the reference's.
pub fn measure_profile(
    reference: &Field,
    technique: &Field,
    profile: &Profile,
) -> Option<(Transition, Option<Transition>)> {
    let Profile { origin, direction, label } = *profile;
    let r = transition(reference, label, origin, direction, -MAX_REACH_PX..=MAX_REACH_PX)?;
    let window = r.low - MATCH_MARGIN_PX..=r.high + MATCH_MARGIN_PX;
    Some((r, transition(technique, label, origin, direction, window)))
}

/// `field` smoothed within each region by a box of radius [`SMOOTHING_RADIUS_PX`],
/// applied twice in each direction (a tent, close to a Gaussian of σ ≈ 2.8 px).
fn smoothed(field: &Field) -> Vec<f32> {
    let mut values = field.values.to_vec();
    for _ in 0..2 {
        values = box_pass(field, &values, 1);
        values = box_pass(field, &values, field.width);
    }
    values
}

/// One box pass along rows (`stride` 1) or columns (`stride` = width), averaging the
/// taps of the centre's region.
fn box_pass(field: &Field, values: &[f32], stride: usize) -> Vec<f32> {
    let (w, h) = (field.width as i64, field.height as i64);
    let r = SMOOTHING_RADIUS_PX as i64;
    (0..values.len())
        .map(|i| {
            let l = field.label[i];
            if l == 0 {
                return values[i];
            }
            let (x, y) = ((i as i64) % w, (i as i64) / w);
            let (mut sum, mut count) = (0.0f32, 0u32);
            for d in -r..=r {
                let (nx, ny) = if stride == 1 { (x + d, y) } else { (x, y + d) };
                if nx < 0 || ny < 0 || nx >= w || ny >= h {
                    continue;
                }
                let j = (ny * w + nx) as usize;
                if field.label[j] == l {
                    sum += values[j];
                    count += 1;
                }
            }
            sum / count as f32
        })
        .collect()
}
