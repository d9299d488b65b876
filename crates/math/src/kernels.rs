//! Filter kernels the shadow shaders use, computed on the CPU: a progressive Poisson
//! disk, Gaussian blur weights, and the Fourier coefficients of the depth test used
//! by convolution shadow maps.

use glam::Vec2;

/// A Poisson-disk sample set in the unit disk, in progressive order: every prefix of
/// it is itself well spread, so a shader can take the first N points for any N.
///
/// Built with Mitchell's best-candidate algorithm (D. Mitchell, "Spectrally optimal
/// sampling for distribution ray tracing", SIGGRAPH 1991): each new point is the one
/// of k·n uniform candidates farthest from the points chosen so far. A fixed seed
/// makes it the same on every run.
pub fn poisson_disk(count: usize) -> Vec<Vec2> {
    let mut rng = SplitMix64(0x05EE_D0F6_E0E0);
    let mut points: Vec<Vec2> = Vec::with_capacity(count);
    while points.len() < count {
        let candidates = 16 * (points.len() + 1);
        let mut best = Vec2::ZERO;
        let mut best_distance = -1.0f32;
        for _ in 0..candidates {
            let c = rng.in_unit_disk();
            let nearest = points.iter().map(|p| p.distance_squared(c)).fold(f32::INFINITY, f32::min);
            // Also keep away from the disk's rim by treating it as a neighbour, so
            // taps are not wasted on the kernel's very edge.
            let rim = (1.0 - c.length()).powi(2) * 4.0;
            let d = nearest.min(rim.max(1e-6));
            if d > best_distance {
                best_distance = d;
                best = c;
            }
        }
        points.push(best);
    }
    points
}

/// Normalised weights of a Gaussian of standard deviation `sigma` at integer offsets
/// −radius..=radius. A radius of 0 gives the single weight 1.
pub fn gaussian_weights(radius: u32, sigma: f32) -> Vec<f32> {
    let r = radius as i32;
    let raw: Vec<f32> = (-r..=r)
        .map(|i| if sigma > 0.0 { (-0.5 * (i as f32 / sigma).powi(2)).exp() } else { (i == 0) as u8 as f32 })
        .collect();
    let sum: f32 = raw.iter().sum();
    raw.into_iter().map(|w| w / sum).collect()
}

/// Frequencies c_k = π(2k − 1), k = 1..=terms, of the Fourier series of the depth
/// test used by convolution shadow maps (Annen et al., "Convolution shadow maps",
/// EGSR 2007): for x = d − z in (−1, 1),
///
///   H(x) ≈ ½ + 2 Σ_k sin(c_k x) / c_k,
///
/// the odd square wave of period 2. Depths d, z ∈ [0, 1] keep x in [−1, 1]; only a
/// receiver at the far plane behind an occluder at the near plane meets the wave's
/// next jump at x = −1 (a period of 4 would avoid it at the cost of halving the
/// sharpness everywhere). sin(c_k (d − z)) splits into sin(c_k d)·cos(c_k z) −
/// cos(c_k d)·sin(c_k z), so the map stores sin and cos of c_k·d, which filter linearly.
pub fn convolution_frequencies(terms: u32) -> Vec<f32> {
    (1..=terms).map(|k| std::f32::consts::PI * (2 * k - 1) as f32).collect()
}

/// The truncated, attenuated series of [`convolution_frequencies`] evaluated at
/// x = d − z: ½ + 2 Σ_k exp(−α (k/M)²) sin(c_k x) / c_k.
pub fn convolution_step(x: f32, terms: u32, attenuation: f32) -> f32 {
    let m = terms as f32;
    0.5 + convolution_frequencies(terms)
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let k = (i + 1) as f32;
            2.0 * (-attenuation * (k / m).powi(2)).exp() * (c * x).sin() / c
        })
        .sum::<f32>()
}

/// A small deterministic generator (Steele, Lea & Flood's SplitMix64).
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 40) as f32 / (1u64 << 24) as f32
    }

    fn in_unit_disk(&mut self) -> Vec2 {
        loop {
            let p = Vec2::new(self.next_f32(), self.next_f32()) * 2.0 - Vec2::ONE;
            if p.length_squared() <= 1.0 {
                return p;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn min_spacing(points: &[Vec2]) -> f32 {
        let mut best = f32::INFINITY;
        for (i, a) in points.iter().enumerate() {
            for b in &points[i + 1..] {
                best = best.min(a.distance(*b));
            }
        }
        best
    }

    #[test]
    fn poisson_disk_is_inside_deterministic_and_spread_at_every_prefix() {
        let disk = poisson_disk(64);
        assert_eq!(disk, poisson_disk(64), "deterministic");
        assert!(disk.iter().all(|p| p.length() <= 1.0));
        // A random set of n points in the unit disk has a minimum spacing of order
        // 1/n; a Poisson disk keeps it of order 1/√n. The bound is ~half the spacing
        // of a hexagonal packing of n points in the disk, √(2π/(√3 n)).
        for n in [8, 16, 32, 64] {
            let hex = (2.0 * std::f32::consts::PI / (3f32.sqrt() * n as f32)).sqrt();
            let spacing = min_spacing(&disk[..n]);
            assert!(spacing > 0.45 * hex, "prefix {n}: spacing {spacing} vs hexagonal {hex}");
        }
        // And it is centred: the mean of the points is near the origin.
        let mean = disk.iter().copied().sum::<Vec2>() / 64.0;
        assert!(mean.length() < 0.1, "{mean}");
    }

    #[test]
    fn gaussian_weights_are_normalised_and_symmetric() {
        let w = gaussian_weights(4, 2.0);
        assert_eq!(w.len(), 9);
        assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        for i in 0..4 {
            assert!((w[i] - w[8 - i]).abs() < 1e-7);
            assert!(w[i] < w[i + 1]);
        }
        assert_eq!(gaussian_weights(0, 0.0), vec![1.0]);
    }

    #[test]
    fn convolution_series_converges_to_the_step() {
        // Away from the discontinuity the truncated series approaches H(x).
        for &x in &[-0.7f32, -0.3, 0.3, 0.7] {
            let want = if x > 0.0 { 1.0 } else { 0.0 };
            let e4 = (convolution_step(x, 4, 0.0) - want).abs();
            let e16 = (convolution_step(x, 16, 0.0) - want).abs();
            assert!(e16 < 0.03, "x = {x}: error {e16} with 16 terms");
            assert!(e16 <= e4 + 1e-6, "x = {x}: more terms, no worse");
        }
        // At the discontinuity every partial sum is exactly ½.
        assert!((convolution_step(0.0, 8, 0.0) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn attenuation_reduces_ringing() {
        // Gibbs overshoot: the raw series exceeds 1 just after the step by ~9% of
        // the jump; the attenuation exp(−α (k/M)²) damps it.
        let overshoot = |alpha: f32| {
            (1..200).map(|i| convolution_step(i as f32 / 200.0, 8, alpha) - 1.0).fold(f32::MIN, f32::max)
        };
        let raw = overshoot(0.0);
        assert!(raw > 0.05, "raw overshoot {raw}");
        assert!(overshoot(2.0) < 0.5 * raw, "damped {} vs raw {raw}", overshoot(2.0));
    }
}
