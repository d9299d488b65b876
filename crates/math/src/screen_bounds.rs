//! Where a sphere can appear on screen: the tight pixel rectangle of a perspective
//! camera's view of a ball (a light's range), which bounds the pixels a local light
//! can reach (tiled light lists, scissored screen-space passes).
//!
//! Per image axis the problem is two-dimensional: in the plane of that axis and the
//! view axis, the ball is a disk of centre (c, d) (d its depth in front of the eye)
//! and radius r, and its image is bounded by the two tangents from the eye. With
//! L² = c² + d² and t = √(L² − r²) the tangent slopes are
//!
//!   s₋ = (c·t − r·d) / (d·t + c·r),   s₊ = (c·t + r·d) / (d·t − c·r)
//!
//! (tan(θ ± α) with tan θ = c/d and tan α = r/t), as in Mara & McGuire, "2D
//! polyhedral bounds of a clipped, perspective-projected 3D sphere", JCGT 2013. When
//! the ball reaches the near plane (d − r ≤ near) a tangent can pass behind the eye:
//! the bound is then the whole screen, which stays conservative.

use glam::{Mat4, Vec3};

/// A symmetric perspective camera, as [`crate::camera_clip_from_view`] builds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerspectiveCamera {
    /// World to the camera's view space (looking down −z).
    pub view_from_world: Mat4,
    /// The full vertical field of view, radians.
    pub fov_y: f32,
    /// Near-plane distance, > 0.
    pub near: f32,
    /// The image's size in pixels.
    pub viewport: Viewport,
}

/// An image's size in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Viewport {
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
}

/// A rectangle of whole pixels, x to the right and y down from the top-left pixel;
/// never empty.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Columns, ≥ 1.
    pub width: u32,
    /// Rows, ≥ 1.
    pub height: u32,
}

impl PixelRect {
    /// The whole image.
    pub fn whole(viewport: Viewport) -> Self {
        Self { x: 0, y: 0, width: viewport.width.max(1), height: viewport.height.max(1) }
    }

    /// Whether pixel (`x`, `y`) lies inside.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        x >= self.x && y >= self.y && x - self.x < self.width && y - self.y < self.height
    }
}

/// Pixels of margin on each side of a bound: the rasterizer's pixel centres and the
/// f32 evaluation of the slopes may each stray by a fraction of a pixel.
const MARGIN_PIXELS: f32 = 1.0;

impl PerspectiveCamera {
    /// The pixels whose centres can see a point of the closed ball (`centre`,
    /// `radius`), or `None` when no pixel can (the ball lies behind the near plane or
    /// off the screen). Conservative: every point of the ball in front of the near
    /// plane projects into the rectangle.
    pub fn sphere_rect(&self, centre: Vec3, radius: f32) -> Option<PixelRect> {
        let Viewport { width, height } = self.viewport;
        let whole = PixelRect::whole(self.viewport);
        let c = self.view_from_world.transform_point3(centre);
        let depth = -c.z;
        let radius = radius.max(0.0);
        let reaches_past_near = depth + radius > self.near;
        if !reaches_past_near {
            // Wholly behind the near plane (or not a number): nothing is drawn there.
            return None;
        }
        if depth - radius <= self.near {
            return Some(whole);
        }
        let tan_y = (0.5 * self.fov_y).tan();
        let tan_x = tan_y * width as f32 / height as f32;
        // NDC = slope / tan(half field of view), per axis.
        let (x_lo, x_hi) = tangent_slopes(c.x, depth, radius);
        let (y_lo, y_hi) = tangent_slopes(c.y, depth, radius);
        let columns = pixel_span(x_lo / tan_x, x_hi / tan_x, width, false)?;
        // Rows run down while NDC y runs up.
        let rows = pixel_span(y_lo / tan_y, y_hi / tan_y, height, true)?;
        Some(PixelRect { x: columns.0, y: rows.0, width: columns.1 - columns.0, height: rows.1 - rows.0 })
    }
}

/// The slopes (offset / depth) of the two tangents from the eye to the disk of
/// centre (`c`, `depth`) and `radius`, lower first; `depth > radius`.
fn tangent_slopes(c: f32, depth: f32, radius: f32) -> (f32, f32) {
    let t = (c * c + depth * depth - radius * radius).max(0.0).sqrt();
    // Both denominators are positive: every point of the disk lies in front of the eye.
    let lo = (c * t - radius * depth) / (depth * t + c * radius);
    let hi = (c * t + radius * depth) / (depth * t - c * radius);
    (lo, hi)
}

/// The pixels [first, end) that NDC span [`lo`, `hi`] covers on an axis of `pixels`,
/// widened by the margin; `flip` for an axis whose pixels run against NDC. `None`
/// when the span misses the screen.
fn pixel_span(lo: f32, hi: f32, pixels: u32, flip: bool) -> Option<(u32, u32)> {
    let (lo, hi) = if flip { (-hi, -lo) } else { (lo, hi) };
    let n = pixels as f32;
    let first = ((lo + 1.0) * 0.5 * n - MARGIN_PIXELS).floor();
    let end = ((hi + 1.0) * 0.5 * n + MARGIN_PIXELS).ceil();
    let on_screen = end > 0.0 && first < n;
    if !on_screen {
        return None;
    }
    let first = first.max(0.0) as u32;
    let end = (end.min(n) as u32).max(first + 1);
    Some((first, end))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{camera_clip_from_view, test_rng::Lcg, view_from_world_look_at};

    fn camera(rng: &mut Lcg) -> PerspectiveCamera {
        let eye = rng.vec(-10.0, 10.0);
        let target = eye + rng.vec(-1.0, 1.0) + Vec3::new(0.0, 0.0, 0.01);
        PerspectiveCamera {
            view_from_world: view_from_world_look_at(eye, target, Vec3::Y),
            fov_y: rng.range(0.3, 2.2),
            near: rng.range(0.01, 1.0),
            viewport: Viewport {
                width: 64 + (rng.next() * 1200.0) as u32,
                height: 64 + (rng.next() * 700.0) as u32,
            },
        }
    }

    /// The pixel (column, row) a world point lands in, as the rasterizer maps it, or
    /// `None` off the screen or before the near plane.
    fn pixel_of(cam: &PerspectiveCamera, p: Vec3) -> Option<(u32, u32)> {
        let Viewport { width, height } = cam.viewport;
        let clip_from_view = camera_clip_from_view(cam.fov_y, width as f32 / height as f32, cam.near, 1e4);
        let clip = clip_from_view * cam.view_from_world * p.extend(1.0);
        if clip.w <= cam.near {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        let x = (ndc.x + 1.0) * 0.5 * width as f32;
        let y = (1.0 - ndc.y) * 0.5 * height as f32;
        ((0.0..width as f32).contains(&x) && (0.0..height as f32).contains(&y))
            .then_some((x as u32, y as u32))
    }

    #[test]
    fn every_point_of_the_ball_on_screen_lands_in_its_rect() {
        let mut rng = Lcg(17);
        let (mut bounded, mut nowhere) = (0, 0);
        for _ in 0..800 {
            let cam = camera(&mut rng);
            let centre = rng.vec(-20.0, 20.0);
            let radius = rng.range(0.05, 6.0);
            let rect = cam.sphere_rect(centre, radius);
            if rect.is_some_and(|r| r != PixelRect::whole(cam.viewport)) {
                bounded += 1;
            }
            nowhere += usize::from(rect.is_none());
            for _ in 0..200 {
                // Points inside the ball and on its surface.
                let dir = (rng.vec(-1.0, 1.0) + Vec3::splat(1e-3)).normalize();
                let p = centre + dir * radius * if rng.next() < 0.5 { 1.0 } else { rng.next() };
                if let Some((x, y)) = pixel_of(&cam, p) {
                    let rect =
                        rect.unwrap_or_else(|| panic!("{p} lands in ({x}, {y}) but the ball has no rect"));
                    assert!(rect.contains(x, y), "{p} lands in ({x}, {y}), outside {rect:?}");
                }
            }
        }
        // Both kinds of answer are exercised, not only the whole screen.
        assert!(
            bounded > 80 && nowhere > 80,
            "of 800 balls, {bounded} bounded tighter than the screen, {nowhere} nowhere"
        );
    }

    #[test]
    fn a_small_ball_ahead_is_tight_and_one_behind_is_nowhere() {
        let cam = PerspectiveCamera {
            view_from_world: Mat4::IDENTITY,
            fov_y: 90f32.to_radians(),
            near: 0.1,
            viewport: Viewport { width: 100, height: 100 },
        };
        // A ball of radius 1 at depth 10 subtends ±asin(0.1): ~±0.1 in NDC, ~±5 pixels.
        let rect = cam.sphere_rect(Vec3::new(0.0, 0.0, -10.0), 1.0).unwrap();
        assert!((43..=45).contains(&rect.x) && (10..=14).contains(&rect.width), "{rect:?}");
        assert_eq!((rect.x, rect.width), (rect.y, rect.height), "symmetric on both axes");
        assert_eq!(cam.sphere_rect(Vec3::new(0.0, 0.0, 10.0), 1.0), None, "behind the eye");
        assert_eq!(cam.sphere_rect(Vec3::new(100.0, 0.0, -10.0), 1.0), None, "off to the right");
        let around = cam.sphere_rect(Vec3::new(0.0, 0.0, -0.5), 1.0);
        assert_eq!(around, Some(PixelRect::whole(cam.viewport)), "the eye inside the ball");
    }
}
