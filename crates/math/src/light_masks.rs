//! A light's area as a fixed set of sample points, and the table of which of them
//! lie on the inner side of any line: what a penumbra beam (the renderer's
//! `rays/penumbra_beam.wgsl`) uses to find, for every caster triangle at once, the
//! set of the light's samples it hides from a receiver. A triangle seen from the
//! receiver and projected onto the light's plane is the intersection of three
//! half-planes, so the samples it hides are the AND of three masks read from the
//! table, and the samples that any caster hides are the OR over the casters: a
//! bitmask of visibility (Schwarz & Stamminger, "Bitmask Soft Shadows", Eurographics
//! 2007; Sintorn, Eisemann & Assarsson, "Sample Based Visibility for Soft Shadows
//! using Alias-free Shadow Maps", EGSR 2008), here over the scene's own triangles
//! rather than a shadow map's texels.
//!
//! The samples lie in the unit disk, spread by Vogel's sunflower spiral (H. Vogel,
//! "A better way to construct the sunflower head", Mathematical Biosciences 44, 1979):
//! sample k at radius √((k + ½)/N), turned by the golden angle each step, so that
//! every sample stands for an equal area and none clumps. A receiver turns the whole
//! set by its own angle, so neighbours' errors are independent.
//!
//! A line is `n(φ)·x = d`, with `n(φ) = (cos φ, sin φ)`; its inner side is
//! `n(φ)·x > d`. The table quantizes φ into [`ANGLE_BINS`] and d ∈ [−1, 1] into
//! [`OFFSET_BINS`]; each entry holds the samples inside the line through its bin's
//! centre. The bins are symmetric (φ + π is `ANGLE_BINS / 2` bins on, −d the mirrored
//! bin), so the two triangles sharing an edge read complementary masks for it, and a
//! mesh's triangles tile the light's samples with no gap along their shared edges.

use glam::Vec2;

/// Samples of the light's area a mask holds: one bit each, four 32-bit words.
pub const SAMPLES: usize = 128;
/// 32-bit words of one mask.
pub const MASK_WORDS: usize = SAMPLES / 32;
/// Bins of a line's normal direction φ over a full turn.
pub const ANGLE_BINS: usize = 256;
/// Bins of a line's offset d over [−1, 1].
pub const OFFSET_BINS: usize = 128;

/// One mask: bit `k % 32` of word `k / 32` is sample k.
pub type Mask = [u32; MASK_WORDS];

/// The golden angle, π(3 − √5), by which Vogel's spiral turns each sample.
const GOLDEN_ANGLE: f32 = 2.399_963_2;

/// The light's samples in the unit disk (Vogel's spiral), [`SAMPLES`] of them.
pub fn samples() -> Vec<Vec2> {
    (0..SAMPLES)
        .map(|k| {
            let radius = ((k as f32 + 0.5) / SAMPLES as f32).sqrt();
            let angle = k as f32 * GOLDEN_ANGLE;
            Vec2::new(angle.cos(), angle.sin()) * radius
        })
        .collect()
}

/// The centre of angle bin `i`, in (−π, π].
pub fn angle_of_bin(i: usize) -> f32 {
    (i as f32 + 0.5) / ANGLE_BINS as f32 * std::f32::consts::TAU - std::f32::consts::PI
}

/// The centre of offset bin `j`, in (−1, 1).
pub fn offset_of_bin(j: usize) -> f32 {
    (j as f32 + 0.5) / OFFSET_BINS as f32 * 2.0 - 1.0
}

/// The bin of a line's normal direction `phi` (radians, any value).
pub fn angle_bin(phi: f32) -> usize {
    let turns = (phi + std::f32::consts::PI) / std::f32::consts::TAU;
    let i = (turns - turns.floor()) * ANGLE_BINS as f32;
    (i as usize).min(ANGLE_BINS - 1)
}

/// The bin of a line's offset `d`, which must lie in (−1, 1): a line outside the
/// disk holds every sample or none, and needs no table.
pub fn offset_bin(d: f32) -> usize {
    (((d + 1.0) * 0.5 * OFFSET_BINS as f32) as usize).min(OFFSET_BINS - 1)
}

/// The samples of `points` on the inner side of the line `n(phi)·x = d`.
pub fn inside(points: &[Vec2], phi: f32, d: f32) -> Mask {
    let n = Vec2::new(phi.cos(), phi.sin());
    let mut mask = [0u32; MASK_WORDS];
    for (k, p) in points.iter().enumerate() {
        if n.dot(*p) > d {
            mask[k / 32] |= 1 << (k % 32);
        }
    }
    mask
}

/// The table, `ANGLE_BINS × OFFSET_BINS` masks, angle-major: entry `i × OFFSET_BINS +
/// j` holds the samples inside the line through the centres of angle bin i and
/// offset bin j.
pub fn half_plane_table() -> Vec<Mask> {
    let points = samples();
    let mut table = Vec::with_capacity(ANGLE_BINS * OFFSET_BINS);
    for i in 0..ANGLE_BINS {
        for j in 0..OFFSET_BINS {
            table.push(inside(&points, angle_of_bin(i), offset_of_bin(j)));
        }
    }
    table
}

/// The mask the table gives the half-plane `n·x > d` (`n` any non-zero vector, `d`
/// in its units): every sample when the line passes outside the disk on the far
/// side, none when on the near side.
pub fn half_plane(table: &[Mask], n: Vec2, d: f32) -> Mask {
    let length = n.length();
    let d = d / length;
    if d <= -1.0 {
        return [u32::MAX; MASK_WORDS];
    }
    if d >= 1.0 {
        return [0; MASK_WORDS];
    }
    table[angle_bin(n.y.atan2(n.x)) * OFFSET_BINS + offset_bin(d)]
}

/// Samples in a mask.
pub fn count(mask: &Mask) -> u32 {
    mask.iter().map(|w| w.count_ones()).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Lcg;

    #[test]
    fn the_samples_fill_the_disk_evenly() {
        let points = samples();
        assert_eq!(points.len(), SAMPLES);
        assert!(points.iter().all(|p| p.length() < 1.0));
        // Every sample stands for an equal area: the share inside radius r is r².
        for r in [0.25f32, 0.5, 0.75, 0.9] {
            let share = points.iter().filter(|p| p.length() < r).count() as f32 / SAMPLES as f32;
            assert!((share - r * r).abs() < 1.5 / SAMPLES as f32, "r {r}: {share}");
        }
        // And every half of the disk holds half of them, within a few samples.
        for half in [Vec2::X, Vec2::Y, -Vec2::X, Vec2::new(1.0, 1.0)] {
            let share = points.iter().filter(|p| p.dot(half) > 0.0).count() as f32 / SAMPLES as f32;
            assert!((share - 0.5).abs() < 3.0 / SAMPLES as f32, "{half}: {share}");
        }
        let mean = points.iter().copied().sum::<Vec2>() / SAMPLES as f32;
        assert!(mean.length() < 0.02, "{mean}");
    }

    #[test]
    fn opposite_sides_of_a_line_read_complementary_masks() {
        let table = half_plane_table();
        let mut rng = Lcg(7);
        for _ in 0..2000 {
            let phi = rng.range(-3.2, 3.2);
            let d = rng.range(-0.99, 0.99);
            let n = Vec2::new(phi.cos(), phi.sin());
            let a = half_plane(&table, n, d);
            let b = half_plane(&table, -n, -d);
            for w in 0..MASK_WORDS {
                assert_eq!(a[w] & b[w], 0, "phi {phi} d {d}: overlap");
                assert_eq!(a[w] | b[w], u32::MAX, "phi {phi} d {d}: gap");
            }
        }
    }

    #[test]
    fn a_quantized_half_plane_differs_from_the_exact_one_only_near_its_line() {
        let table = half_plane_table();
        let points = samples();
        let mut rng = Lcg(11);
        // A line moves by at most half a bin of offset plus half a bin of angle
        // times the disk's radius.
        let slack = 1.0 / OFFSET_BINS as f32 + std::f32::consts::PI / ANGLE_BINS as f32;
        let mut differing = 0u32;
        for _ in 0..2000 {
            let phi = rng.range(-3.2, 3.2);
            let d = rng.range(-1.2, 1.2);
            let n = Vec2::new(phi.cos(), phi.sin());
            let quantized = half_plane(&table, n, d);
            let exact = inside(&points, phi, d);
            for (k, p) in points.iter().enumerate() {
                let bit = |m: &Mask| m[k / 32] >> (k % 32) & 1;
                if bit(&quantized) != bit(&exact) {
                    differing += 1;
                    assert!((n.dot(*p) - d).abs() <= slack * 1.01, "sample {k} at {}", n.dot(*p) - d);
                }
            }
        }
        // About the share of samples within the slack of a chord: a few per line.
        assert!(differing < 2000 * 3, "{differing}");
    }
}
