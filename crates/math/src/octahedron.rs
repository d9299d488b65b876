//! The octahedral encoding of unit vectors (Cigolle et al., "A Survey of Efficient
//! Representations for Independent Unit Vectors", JCGT 2014): a unit vector as two
//! numbers in [−1, 1]. The renderer's prepass and lighting passes store normals this
//! way (render's `passes/octahedron.wgsl`, the same arithmetic); the frame decodes
//! them here.

use glam::{Vec2, Vec3};

/// The encoding of the unit vector `n`: its projection onto the octahedron
/// |x| + |y| + |z| = 1, the lower half folded over the diagonals.
pub fn encode(n: Vec3) -> Vec2 {
    let p = Vec2::new(n.x, n.y) / (n.x.abs() + n.y.abs() + n.z.abs());
    if n.z >= 0.0 {
        p
    } else {
        let sign = Vec2::new(if p.x >= 0.0 { 1.0 } else { -1.0 }, if p.y >= 0.0 { 1.0 } else { -1.0 });
        (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * sign
    }
}

/// The unit vector whose encoding is `e`.
pub fn decode(e: Vec2) -> Vec3 {
    let mut n = Vec3::new(e.x, e.y, 1.0 - e.x.abs() - e.y.abs());
    // The lower hemisphere folds over the diagonals (Cigolle et al., listing 1).
    let t = (-n.z).max(0.0);
    n.x += if n.x >= 0.0 { -t } else { t };
    n.y += if n.y >= 0.0 { -t } else { t };
    n.normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Decoding an encoding gives the unit vector back, over the whole sphere (a
    /// spiral of 2,000 directions), on the axes and on the octahedron's edges, to
    /// float precision.
    #[test]
    fn decode_inverts_encode() {
        let mut directions: Vec<Vec3> = (0..2000)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / 2000.0;
                let phi = i as f32 * 2.399_963;
                let r = (1.0 - z * z).max(0.0).sqrt();
                Vec3::new(r * phi.cos(), r * phi.sin(), z)
            })
            .collect();
        directions.extend([Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]);
        directions.extend(
            [Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0), Vec3::new(1.0, -1.0, -1.0)]
                .map(Vec3::normalize),
        );
        let worst = directions.iter().map(|n| (decode(encode(*n)) - *n).length()).fold(0.0f32, f32::max);
        assert!(worst < 1e-6, "worst error {worst:e}");
        assert!(directions.iter().all(|n| encode(*n).abs().max_element() <= 1.0));
    }
}
