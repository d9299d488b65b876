//! Axis-aligned bounding boxes: scene bounds, transformed bounds and corners.

use glam::{Mat4, Vec3};

/// An axis-aligned box. An empty box has `min > max` on every axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Corner with the smallest coordinate on every axis, in the box's space (usually world space).
    pub min: Vec3,
    /// Corner with the largest coordinate on every axis, in the same space as `min`.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box: the identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    /// The box with corners `min` and `max`, taken as given: a `min` above `max` on any axis makes it empty.
    pub fn new(min: Vec3, max: Vec3) -> Self {
        Self { min, max }
    }

    /// The smallest box holding all `points`; [`Aabb::EMPTY`] for none.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.including(p))
    }

    /// Whether the box holds no point at all: `min > max` on at least one axis.
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// This box grown just enough to hold the point `p`.
    pub fn including(self, p: Vec3) -> Self {
        Self { min: self.min.min(p), max: self.max.max(p) }
    }

    /// The smallest box holding both this box and `other`.
    pub fn union(self, other: Aabb) -> Self {
        Self { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    /// The box's midpoint, `(min + max) / 2`; meaningless (NaN for [`Aabb::EMPTY`]) for an empty box.
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// Size along each axis, `max − min`; negative on some axis for an empty box.
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Radius of the bounding sphere centred on [`Aabb::center`].
    pub fn bounding_radius(&self) -> f32 {
        0.5 * self.extent().length()
    }

    /// The eight corners, in the order of the bits of the index (x, y, z).
    pub fn corners(&self) -> [Vec3; 8] {
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// The box around this box's corners after an affine transform.
    pub fn transformed(&self, to_from_this: Mat4) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        Aabb::from_points(self.corners().map(|c| to_from_this.transform_point3(c)))
    }

    /// Whether `p` lies inside the box, boundary included.
    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_with_empty_is_identity() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.0, 4.0));
        assert_eq!(Aabb::EMPTY.union(b), b);
        assert!(Aabb::EMPTY.is_empty());
        assert!(!b.is_empty());
    }

    #[test]
    fn transformed_box_contains_transformed_corners() {
        let b = Aabb::new(Vec3::new(-1.0, -2.0, -3.0), Vec3::new(1.0, 2.0, 3.0));
        let m = Mat4::from_rotation_y(0.7) * Mat4::from_translation(Vec3::new(5.0, 0.0, 1.0));
        let t = b.transformed(m);
        for c in b.corners() {
            let p = m.transform_point3(c);
            assert!(t.contains(p + (t.center() - p) * 1e-5), "{p} not in {t:?}");
        }
        // A 90° turn about y swaps the x and z extents.
        let r = b.transformed(Mat4::from_rotation_y(std::f32::consts::FRAC_PI_2));
        assert!((r.extent() - Vec3::new(6.0, 4.0, 2.0)).abs().max_element() < 1e-5);
    }
}
