//! CPU texture lookups that match the GPU's at mip 0: WebGPU's nearest and bilinear
//! filtering with repeat, mirrored-repeat and clamp-to-edge addressing, for the
//! alpha test of cut-out casters.

use glam::Vec2;
use gnomon_scene::{Texture, Wrap};

fn wrap(i: i64, n: i64, mode: Wrap) -> usize {
    (match mode {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::ClampToEdge => i.clamp(0, n - 1),
        Wrap::MirroredRepeat => {
            let m = i.rem_euclid(2 * n);
            if m >= n { 2 * n - 1 - m } else { m }
        }
    }) as usize
}

fn alpha_at(t: &Texture, x: i64, y: i64) -> f32 {
    let (w, h) = (t.width as i64, t.height as i64);
    let (x, y) = (wrap(x, w, t.wrap_u), wrap(y, h, t.wrap_v));
    t.rgba8[4 * (y * t.width as usize + x) + 3] as f32 / 255.0
}

/// The alpha channel of `t` at `uv`, filtered as its sampler asks.
pub fn sample_alpha(t: &Texture, uv: Vec2) -> f32 {
    let size = Vec2::new(t.width as f32, t.height as f32);
    if t.nearest {
        let p = (uv * size).floor();
        return alpha_at(t, p.x as i64, p.y as i64);
    }
    // Texel centres sit at half-integers: the bilinear footprint starts at uv·size − ½.
    let p = uv * size - Vec2::splat(0.5);
    let base = p.floor();
    let f = p - base;
    let (x, y) = (base.x as i64, base.y as i64);
    let top = alpha_at(t, x, y) * (1.0 - f.x) + alpha_at(t, x + 1, y) * f.x;
    let bottom = alpha_at(t, x, y + 1) * (1.0 - f.x) + alpha_at(t, x + 1, y + 1) * f.x;
    top * (1.0 - f.y) + bottom * f.y
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker(nearest: bool, wrap: Wrap) -> Texture {
        // 2×2: alpha 0 and 255 in a checkerboard.
        let rgba8 = [0u8, 255, 255, 0].iter().flat_map(|&a| [255, 255, 255, a]).collect();
        Texture { name: "c".into(), width: 2, height: 2, rgba8, wrap_u: wrap, wrap_v: wrap, nearest }
    }

    #[test]
    fn nearest_and_bilinear_match_hand_computed_values() {
        let t = checker(true, Wrap::Repeat);
        assert_eq!(sample_alpha(&t, Vec2::new(0.25, 0.25)), 0.0);
        assert_eq!(sample_alpha(&t, Vec2::new(0.75, 0.25)), 1.0);
        assert_eq!(sample_alpha(&t, Vec2::new(1.25, 0.25)), 0.0, "repeat");
        let t = checker(false, Wrap::Repeat);
        // At a texel centre bilinear equals the texel; halfway between two it averages.
        assert!((sample_alpha(&t, Vec2::new(0.75, 0.25)) - 1.0).abs() < 1e-6);
        assert!((sample_alpha(&t, Vec2::new(0.5, 0.25)) - 0.5).abs() < 1e-6);
        let t = checker(false, Wrap::ClampToEdge);
        assert!((sample_alpha(&t, Vec2::new(0.99, 0.25)) - 1.0).abs() < 1e-6, "clamped at the edge");
        let t = checker(true, Wrap::MirroredRepeat);
        assert_eq!(sample_alpha(&t, Vec2::new(1.25, 0.25)), 1.0, "mirrored: texel 2 is texel 1");
    }
}
