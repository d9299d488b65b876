//! Procedural mesh builders: planes, boxes, spheres and cylinders, with normals and UVs.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3};

use crate::Mesh;

impl Mesh {
    fn push_vertex(&mut self, p: Vec3, n: Vec3, uv: Vec2) -> u32 {
        self.positions.push(p);
        self.normals.push(n);
        self.uvs.push(uv);
        (self.positions.len() - 1) as u32
    }

    /// A rectangle facing `normal`, centred at `center`, spanned by the half-edges `u`
    /// and `v` (with u × v pointing along `normal`, so it is counter-clockwise).
    fn push_quad(&mut self, center: Vec3, u: Vec3, v: Vec3) {
        let n = u.cross(v).normalize();
        let a = self.push_vertex(center - u - v, n, Vec2::new(0.0, 1.0));
        let b = self.push_vertex(center + u - v, n, Vec2::new(1.0, 1.0));
        let c = self.push_vertex(center + u + v, n, Vec2::new(1.0, 0.0));
        let d = self.push_vertex(center - u + v, n, Vec2::new(0.0, 0.0));
        self.indices.extend([a, b, c, a, c, d]);
    }
}

/// A horizontal rectangle of `size_x` × `size_z` at y = 0 facing +y (one-sided).
pub fn plane(size_x: f32, size_z: f32) -> Mesh {
    let mut m = Mesh { name: "plane".into(), ..Default::default() };
    m.push_quad(Vec3::ZERO, Vec3::new(0.5 * size_x, 0.0, 0.0), Vec3::new(0.0, 0.0, -0.5 * size_z));
    m
}

/// A closed box with the given half-extents, centred at the origin, flat-shaded.
pub fn cuboid(half: Vec3) -> Mesh {
    let mut m = Mesh { name: "box".into(), ..Default::default() };
    let (x, y, z) = (Vec3::X * half.x, Vec3::Y * half.y, Vec3::Z * half.z);
    m.push_quad(x, -z, y); // +x
    m.push_quad(-x, z, y); // −x
    m.push_quad(y, x, -z); // +y
    m.push_quad(-y, x, z); // −y
    m.push_quad(z, x, y); // +z
    m.push_quad(-z, -x, y); // −z
    m
}

/// A UV sphere of `radius` centred at the origin, with smooth normals.
pub fn uv_sphere(radius: f32, segments: u32, rings: u32) -> Mesh {
    let mut m = Mesh { name: "sphere".into(), ..Default::default() };
    for r in 0..=rings {
        let theta = PI * r as f32 / rings as f32; // from the north pole
        for s in 0..=segments {
            let phi = TAU * s as f32 / segments as f32;
            let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin());
            m.push_vertex(radius * n, n, Vec2::new(s as f32 / segments as f32, r as f32 / rings as f32));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            // Skip the degenerate triangles at the poles.
            if r != 0 {
                m.indices.extend([a, b, a + 1]);
            }
            if r != rings - 1 {
                m.indices.extend([a + 1, b, b + 1]);
            }
        }
    }
    m
}

/// A closed cylinder along y from 0 to `height`, smooth sides and flat caps.
pub fn cylinder(radius: f32, height: f32, segments: u32) -> Mesh {
    let mut m = Mesh { name: "cylinder".into(), ..Default::default() };
    let ring = |s: u32| {
        let phi = TAU * s as f32 / segments as f32;
        Vec3::new(phi.cos(), 0.0, -phi.sin())
    };
    for s in 0..=segments {
        let n = ring(s);
        let u = s as f32 / segments as f32;
        m.push_vertex(radius * n, n, Vec2::new(u, 1.0));
        m.push_vertex(radius * n + Vec3::Y * height, n, Vec2::new(u, 0.0));
    }
    for s in 0..segments {
        let (a, b, c, d) = (2 * s, 2 * s + 2, 2 * s + 3, 2 * s + 1);
        m.indices.extend([a, b, c, a, c, d]);
    }
    for (y, n) in [(height, Vec3::Y), (0.0, Vec3::NEG_Y)] {
        let centre = m.push_vertex(Vec3::Y * y, n, Vec2::splat(0.5));
        let first = centre + 1;
        for s in 0..=segments {
            let p = ring(s);
            m.push_vertex(radius * p + Vec3::Y * y, n, Vec2::new(0.5 + 0.5 * p.x, 0.5 - 0.5 * p.z));
        }
        for s in 0..segments {
            let (a, b) = (first + s, first + s + 1);
            if n.y > 0.0 {
                m.indices.extend([centre, a, b]);
            } else {
                m.indices.extend([centre, b, a]);
            }
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle's winding agrees with its vertex normals (counter-clockwise seen
    /// from outside), which back-face culling in the shadow pass relies on.
    fn assert_outward_winding(m: &Mesh) {
        for t in m.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            let face = (b - a).cross(c - a);
            if face.length_squared() < 1e-12 {
                continue;
            }
            let n = m.normals[t[0] as usize] + m.normals[t[1] as usize] + m.normals[t[2] as usize];
            assert!(face.dot(n) > 0.0, "{}: triangle {t:?} winds against its normals", m.name);
        }
    }

    #[test]
    fn builders_wind_counter_clockwise_outward() {
        for m in
            [plane(2.0, 3.0), cuboid(Vec3::new(1.0, 2.0, 0.5)), uv_sphere(1.0, 16, 8), cylinder(0.5, 2.0, 12)]
        {
            assert_outward_winding(&m);
            assert_eq!(m.positions.len(), m.normals.len());
            assert_eq!(m.positions.len(), m.uvs.len());
            assert!(m.indices.iter().all(|&i| (i as usize) < m.positions.len()));
        }
    }

    /// `cull auto` culls only closed meshes: the solids must weld into closed
    /// surfaces (a sphere's poles and seam, a box's split corners), the plane not.
    #[test]
    fn solids_are_closed_and_the_plane_is_open() {
        for m in [cuboid(Vec3::new(1.0, 2.0, 0.5)), uv_sphere(1.0, 16, 8), cylinder(0.5, 2.0, 12)] {
            let c = m.closedness();
            assert!(c.is_closed(), "{}: {c:?}", m.name);
        }
        let plane = plane(2.0, 3.0).closedness();
        assert_eq!((plane.is_closed(), plane.open_edges), (false, 4));
    }

    #[test]
    fn builders_have_the_requested_size() {
        let b = cuboid(Vec3::new(1.0, 2.0, 0.5)).bounds();
        assert_eq!(b.min, Vec3::new(-1.0, -2.0, -0.5));
        let s = uv_sphere(2.0, 32, 16);
        assert!(s.positions.iter().all(|p| (p.length() - 2.0).abs() < 1e-5));
        let c = cylinder(0.5, 3.0, 16).bounds();
        assert!((c.max.y - 3.0).abs() < 1e-6 && c.min.y == 0.0);
    }
}
