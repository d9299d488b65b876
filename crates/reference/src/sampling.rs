//! Deterministic stratified sampling: correlated multi-jittered 2D patterns
//! (A. Kensler, "Correlated Multi-Jittered Sampling", Pixar Technical Memo 13-01,
//! 2013), and the maps from the unit square to a disk and to a cone of directions.

use std::f32::consts::{FRAC_PI_4, PI, TAU};

use glam::{Vec2, Vec3};

/// A pseudo-random permutation of [0, len), chosen by `pattern` (Kensler, listing 3).
fn permute(mut i: u32, len: u32, pattern: u32) -> u32 {
    let mut w = len - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    loop {
        i ^= pattern;
        i = i.wrapping_mul(0xe170893d);
        i ^= pattern >> 16;
        i ^= (i & w) >> 4;
        i ^= pattern >> 8;
        i = i.wrapping_mul(0x0929eb3f);
        i ^= pattern >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | (pattern >> 27));
        i = i.wrapping_mul(0x6935fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dcb303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e501cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860a3df);
        i &= w;
        i ^= i >> 5;
        if i < len {
            break;
        }
    }
    (i.wrapping_add(pattern)) % len
}

/// A hashed float in [0, 1) for index `i` of `pattern` (Kensler, listing 4).
fn rand_float(mut i: u32, pattern: u32) -> f32 {
    i ^= pattern;
    i ^= i >> 17;
    i ^= i >> 10;
    i = i.wrapping_mul(0xb36534e5);
    i ^= i >> 12;
    i ^= i >> 21;
    i = i.wrapping_mul(0x93fc4795);
    i ^= 0xdf6e307f;
    i ^= i >> 17;
    i = i.wrapping_mul(1 | (pattern >> 18));
    (i as f64 * (1.0 / 4294967808.0)) as f32
}

/// Sample `s` of `count` of the correlated multi-jittered pattern `pattern`: a point of
/// the unit square. The `count` samples of one pattern are stratified in an m × n grid
/// with m·n = count exactly, and in both 1D projections (Kensler, listing 6). The grid
/// is an exact factorisation (m the largest divisor ≤ √count) because a grid with more
/// cells than samples leaves a stratum of the light unsampled: a bias.
pub fn cmj(s: u32, count: u32, pattern: u32) -> Vec2 {
    let m = (1..=(count as f32).sqrt() as u32).rev().find(|d| count.is_multiple_of(*d)).unwrap_or(1);
    let n = count / m;
    let s = permute(s, count, pattern.wrapping_mul(0x51633e2d));
    let (sx, sy) = (s % m, s / m);
    let px = permute(sx, m, pattern.wrapping_mul(0x68bc21eb));
    let py = permute(sy, n, pattern.wrapping_mul(0x02e5be93));
    let jx = rand_float(s, pattern.wrapping_mul(0x967a889b));
    let jy = rand_float(s, pattern.wrapping_mul(0x368cc8b7));
    Vec2::new(
        (sx as f32 + (py as f32 + jx) / n as f32) / m as f32,
        (sy as f32 + (px as f32 + jy) / m as f32) / n as f32,
    )
    .clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON))
}

/// A 32-bit hash for seeding a pixel's patterns: `gnomon_math::hash::lowbias32`.
pub use gnomon_math::hash::lowbias32 as hash;

/// The unit square to the unit disk, keeping strata compact: P. Shirley and K. Chiu,
/// "A Low Distortion Map Between Disk and Square", JGT 1997.
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let a = 2.0 * u - Vec2::ONE;
    if a == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if a.x.abs() > a.y.abs() {
        (a.x, FRAC_PI_4 * (a.y / a.x))
    } else {
        (a.y, 0.5 * PI - FRAC_PI_4 * (a.x / a.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// The unit square to directions within `half_angle` of `axis`, uniform in solid
/// angle: cos θ = 1 − u (1 − cos θ_max), φ = 2π v.
pub fn cone_direction(u: Vec2, axis: Vec3, half_angle: f32) -> Vec3 {
    let cos_theta = 1.0 - u.x * (1.0 - half_angle.cos());
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = TAU * u.y;
    let (a, b) = axis.any_orthonormal_pair();
    (axis * cos_theta + (a * phi.cos() + b * phi.sin()) * sin_theta).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cmj_is_unbiased_for_counts_that_are_not_squares() {
        // The mean of x and of y over many patterns is 1/2, for any count: no stratum
        // is left out.
        for count in [2u32, 8, 32, 2048] {
            let total = 4096 / count.min(4096);
            let (mut sx, mut sy, mut n) = (0.0f64, 0.0f64, 0.0f64);
            for pattern in 0..total.max(8) {
                for s in 0..count {
                    let p = cmj(s, count, hash(pattern));
                    sx += p.x as f64;
                    sy += p.y as f64;
                    n += 1.0;
                }
            }
            assert!(
                (sx / n - 0.5).abs() < 0.01 && (sy / n - 0.5).abs() < 0.01,
                "{count}: {} {}",
                sx / n,
                sy / n
            );
        }
    }

    #[test]
    fn cmj_is_stratified_in_its_grid_and_its_projections() {
        for (count, pattern) in [(16u32, 7u32), (64, 123), (256, 99)] {
            let m = (count as f32).sqrt() as u32;
            let points: Vec<Vec2> = (0..count).map(|s| cmj(s, count, pattern)).collect();
            let mut cells = vec![0; count as usize];
            let mut columns = vec![0; count as usize];
            for p in &points {
                assert!(p.cmpge(Vec2::ZERO).all() && p.cmplt(Vec2::ONE).all());
                let cell = (p.y * m as f32) as usize * m as usize + (p.x * m as f32) as usize;
                cells[cell] += 1;
                columns[(p.x * count as f32) as usize] += 1;
            }
            assert!(cells.iter().all(|&c| c == 1), "{count}: one sample per cell");
            assert!(columns.iter().all(|&c| c == 1), "{count}: one sample per column");
        }
        // Different patterns differ; the same pattern repeats exactly.
        assert_ne!(cmj(3, 16, 1), cmj(3, 16, 2));
        assert_eq!(cmj(3, 16, 1), cmj(3, 16, 1));
    }

    #[test]
    fn disk_and_cone_maps_stay_inside() {
        for s in 0..64 {
            let u = cmj(s, 64, 5);
            assert!(concentric_disk(u).length() <= 1.0 + 1e-6);
            let axis = Vec3::new(0.3, -1.0, 0.2).normalize();
            let d = cone_direction(u, axis, 0.1);
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert!(d.dot(axis) >= 0.1f32.cos() - 1e-5);
        }
        // The disk map covers area uniformly: mean squared radius of a uniform disk is 1/2.
        let mean_r2: f32 =
            (0..1024).map(|s| concentric_disk(cmj(s, 1024, 11)).length_squared()).sum::<f32>() / 1024.0;
        assert!((mean_r2 - 0.5).abs() < 0.01, "{mean_r2}");
    }
}
