//! Whether a triangle mesh is closed, for face culling in the shadow pass
//! (`cull auto`). Culling a caster's back (or front) faces is safe only when every
//! ray into the mesh crosses a face that is kept: a closed, consistently wound mesh
//! (a 2-manifold without boundary). Architecture is full of single-sided walls and
//! roofs, through which a culled shadow pass lets the light.
//!
//! A mesh is closed when, once positions that coincide are welded, every edge is
//! shared by exactly two triangles that run along it in opposite directions (the
//! usual test for an oriented closed manifold; see Botsch et al., "Polygon Mesh
//! Processing", 2010, §2.1). Split vertices (the same position with different
//! normals or texture coordinates) are welded first, so that a hard-edged cube counts
//! as closed.

use std::collections::HashMap;

use glam::Vec3;

/// What [`closedness`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Closedness {
    /// Triangles with three distinct welded corners.
    pub triangles: usize,
    /// Triangles left out because two of their corners weld together.
    pub degenerate: usize,
    /// Undirected edges not shared by exactly one triangle each way: a boundary
    /// (one triangle), a flipped neighbour (two the same way) or a non-manifold fin
    /// (three or more).
    pub open_edges: usize,
}

impl Closedness {
    /// Whether the mesh is closed: it has triangles and no open edge.
    pub fn is_closed(&self) -> bool {
        self.triangles > 0 && self.open_edges == 0
    }
}

/// The weld tolerance for a mesh of these positions: a millionth of its bounding
/// box's diagonal, well above float rounding of coordinates written by exporters
/// and well below any real feature.
pub fn weld_tolerance(positions: &[Vec3]) -> f32 {
    let (lo, hi) =
        positions.iter().fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let diagonal = (hi - lo).length();
    if diagonal.is_finite() { (diagonal * 1e-6).max(f32::MIN_POSITIVE) } else { f32::MIN_POSITIVE }
}

/// For each position, the index of the first position within `tolerance` of it
/// (itself if none): a weld. Positions are hashed into cells of the tolerance's size,
/// so each is compared only with those in its own and the 26 neighbouring cells.
pub fn weld(positions: &[Vec3], tolerance: f32) -> Vec<u32> {
    let cell_of = |p: Vec3| (p / tolerance).floor().as_ivec3();
    let mut cells: HashMap<glam::IVec3, Vec<u32>> = HashMap::new();
    let mut welded = Vec::with_capacity(positions.len());
    for (i, &p) in positions.iter().enumerate() {
        let cell = cell_of(p);
        let mut found = None;
        'search: for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let neighbour = cell + glam::IVec3::new(dx, dy, dz);
                    for &j in cells.get(&neighbour).map_or(&[][..], Vec::as_slice) {
                        if positions[j as usize].distance(p) <= tolerance {
                            found = Some(j);
                            break 'search;
                        }
                    }
                }
            }
        }
        let representative = found.unwrap_or(i as u32);
        if found.is_none() {
            cells.entry(cell).or_default().push(i as u32);
        }
        welded.push(representative);
    }
    welded
}

/// Whether the mesh of `positions` and `triangles` (counter-clockwise or clockwise,
/// consistently) is closed, once positions within `tolerance` are welded
/// ([`weld_tolerance`] is a good choice).
pub fn closedness(positions: &[Vec3], triangles: &[[u32; 3]], tolerance: f32) -> Closedness {
    let welded = weld(positions, tolerance);
    // Directed edge counts, keyed by the undirected edge (low, high): how many
    // triangles run low → high, and how many high → low.
    let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    let mut result = Closedness { triangles: 0, degenerate: 0, open_edges: 0 };
    for t in triangles {
        let [a, b, c] = t.map(|i| welded.get(i as usize).copied().unwrap_or(i));
        if a == b || b == c || c == a {
            result.degenerate += 1;
            continue;
        }
        result.triangles += 1;
        for (from, to) in [(a, b), (b, c), (c, a)] {
            let counts = edges.entry((from.min(to), from.max(to))).or_default();
            if from < to {
                counts.0 += 1;
            } else {
                counts.1 += 1;
            }
        }
    }
    result.open_edges = edges.values().filter(|&&counts| counts != (1, 1)).count();
    result
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::*;
    use crate::test_rng::Lcg;

    /// A unit cube as most exporters write it: 24 vertices (4 per face, split for
    /// their normals), 12 triangles wound counter-clockwise seen from outside.
    fn cube() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let faces = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];
        let (mut positions, mut triangles) = (Vec::new(), Vec::new());
        for n in faces {
            let u = if n.x.abs() > 0.5 { Vec3::Y } else { Vec3::X };
            let v = n.cross(u);
            let base = positions.len() as u32;
            for (s, t) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                positions.push(0.5 * (n + s * u + t * v));
            }
            triangles.push([base, base + 1, base + 2]);
            triangles.push([base, base + 2, base + 3]);
        }
        (positions, triangles)
    }

    fn check(positions: &[Vec3], triangles: &[[u32; 3]]) -> Closedness {
        closedness(positions, triangles, weld_tolerance(positions))
    }

    #[test]
    fn a_cube_is_closed_and_consistently_wound() {
        let (positions, triangles) = cube();
        let c = check(&positions, &triangles);
        assert_eq!(c, Closedness { triangles: 12, degenerate: 0, open_edges: 0 });
        assert!(c.is_closed());
        // Every face's normal, from its winding, points out.
        for t in &triangles {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let centre = (a + b + c) / 3.0;
            assert!((b - a).cross(c - a).dot(centre) > 0.0, "outward winding");
        }
    }

    #[test]
    fn a_cube_missing_a_face_a_plane_and_a_flipped_face_are_open() {
        let (positions, triangles) = cube();
        let missing = check(&positions, &triangles[2..]);
        assert_eq!(missing.open_edges, 4, "the missing face's rim");
        assert!(!missing.is_closed());

        let plane = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, 1.0), Vec3::Z];
        let c = check(&plane, &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!((c.triangles, c.open_edges), (2, 4));

        let mut flipped = triangles.clone();
        for t in &mut flipped[..2] {
            t.swap(1, 2);
        }
        let c = check(&positions, &flipped);
        assert_eq!(c.open_edges, 4, "the flipped face's rim runs the same way as its neighbours'");
        assert!(!c.is_closed());
    }

    #[test]
    fn a_fin_and_an_empty_mesh_are_not_closed() {
        let (mut positions, mut triangles) = cube();
        // A third triangle on one of the cube's edges: non-manifold.
        let (a, b) = (triangles[0][0], triangles[0][1]);
        positions.push(Vec3::new(3.0, 3.0, 3.0));
        triangles.push([a, b, positions.len() as u32 - 1]);
        assert!(!check(&positions, &triangles).is_closed());
        assert!(!check(&[], &[]).is_closed());
    }

    #[test]
    fn degenerate_triangles_are_left_out() {
        let (mut positions, mut triangles) = cube();
        let first = positions[0];
        positions.push(first + Vec3::splat(1e-8));
        triangles.push([0, positions.len() as u32 - 1, 5]);
        let c = check(&positions, &triangles);
        assert_eq!((c.degenerate, c.open_edges), (1, 0));
    }

    /// Property: welding, vertex order, triangle order and rigid motion do not change
    /// the answer; removing any one triangle of a closed mesh opens it.
    #[test]
    fn closedness_is_a_property_of_the_surface_not_of_its_encoding() {
        let mut rng = Lcg(7);
        let (positions, triangles) = cube();
        for _ in 0..50 {
            let rotation = Quat::from_axis_angle(
                rng.vec(-1.0, 1.0).normalize_or(Vec3::Y),
                rng.range(0.0, std::f32::consts::TAU),
            );
            let offset = rng.vec(-100.0, 100.0);
            let scale = rng.range(0.01, 50.0);
            let moved: Vec<Vec3> = positions.iter().map(|p| rotation * (*p * scale) + offset).collect();
            // Rotate each triangle's corners (same winding) and shuffle the triangles.
            let mut shuffled: Vec<[u32; 3]> =
                triangles.iter().map(|t| if rng.next() < 0.5 { [t[1], t[2], t[0]] } else { *t }).collect();
            for i in (1..shuffled.len()).rev() {
                let j = (rng.next() * (i + 1) as f32) as usize;
                shuffled.swap(i, j.min(i));
            }
            assert!(check(&moved, &shuffled).is_closed());
            let removed = (rng.next() * shuffled.len() as f32) as usize;
            let mut holed = shuffled.clone();
            holed.remove(removed.min(holed.len() - 1));
            assert!(!check(&moved, &holed).is_closed());
        }
    }
}
