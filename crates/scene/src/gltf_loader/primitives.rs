//! One glTF mesh primitive into a [`Mesh`]: every accessor checked against the data
//! it claims, triangle strips and fans turned into lists, and points and lines
//! counted and skipped (they cast no shadow).

use glam::{Vec2, Vec3};
use gltf::mesh::Mode;

use crate::Mesh;

/// How many primitives of each drawing mode a file has: what was drawn and what was
/// skipped, for the warning and for the "nothing to draw" error.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModeCounts {
    /// Triangle lists, strips and fans: drawn.
    pub triangles: usize,
    /// Points: skipped.
    pub points: usize,
    /// Lines, line loops and line strips: skipped.
    pub lines: usize,
    /// Triangles of zero area, dropped: they cover no pixel and block no ray, and a
    /// file of thousands at one point made the BVH and meshlet builds degenerate.
    pub degenerate_triangles: usize,
    /// The POSITION accessors whose declared `min`/`max` do not bound their data:
    /// Gnomon takes its bounds from the data, and says so.
    pub lying_bounds: std::collections::BTreeSet<usize>,
}

impl ModeCounts {
    /// The skipped primitives in words (`3 point and 2 line primitives`), or `None`.
    pub fn skipped(&self) -> Option<String> {
        let parts: Vec<String> = [(self.points, "point"), (self.lines, "line")]
            .iter()
            .filter(|(n, _)| *n > 0)
            .map(|(n, kind)| format!("{n} {kind}"))
            .collect();
        (!parts.is_empty()).then(|| format!("{} primitive(s)", parts.join(" and ")))
    }
}

/// The triangle list of `indices` drawn in `mode`, or `None` for points and lines.
/// Strips alternate their winding so that every triangle keeps the first one's (glTF
/// 2.0, §3.7.2.1: p_i = {v_i, v_{i+1+i%2}, v_{i+2−i%2}}); fans share vertex 0
/// (p_i = {v_{i+1}, v_{i+2}, v_0}). Degenerate triangles, which strips use to
/// restart, are dropped.
pub fn triangle_list(mode: Mode, indices: &[u32]) -> Option<Vec<u32>> {
    let n = indices.len();
    let triangles: Vec<[u32; 3]> = match mode {
        Mode::Triangles => return Some(indices.to_vec()),
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| [indices[i], indices[i + 1 + i % 2], indices[i + 2 - i % 2]])
            .collect(),
        Mode::TriangleFan => {
            (1..n.saturating_sub(1)).map(|i| [indices[i], indices[i + 1], indices[0]]).collect()
        }
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => return None,
    };
    let distinct = |t: &&[u32; 3]| t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    Some(triangles.iter().filter(distinct).flatten().copied().collect())
}

/// Checks that `accessor` holds what the gltf crate's reader will read from it: at
/// least one element, of `dimensions`, with one of `types`. The reader asserts the
/// element size and computes `count − 1` unchecked, both only in debug builds
/// (found by fuzzing); a release build would read garbage instead.
fn check_accessor(
    accessor: &gltf::Accessor,
    what: &str,
    dimensions: gltf::accessor::Dimensions,
    types: &[gltf::accessor::DataType],
    label: &str,
) -> Result<(), String> {
    let sparse_empty = accessor.sparse().is_some_and(|s| s.count() == 0);
    if accessor.count() == 0 || sparse_empty {
        return Err(format!("{label}: its {what} accessor {} has no elements", accessor.index()));
    }
    if accessor.dimensions() != dimensions || !types.contains(&accessor.data_type()) {
        return Err(format!(
            "{label}: its {what} accessor {} holds {:?} of {:?}; glTF requires {dimensions:?} of {types:?}",
            accessor.index(),
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    Ok(())
}

/// Reads `prim` into a mesh with texture coordinates from set `texcoord_set`; `None`
/// for a point or line primitive. `label` names it in errors.
pub fn read(
    prim: &gltf::Primitive,
    buffers: &[gltf::buffer::Data],
    texcoord_set: u32,
    label: String,
) -> Result<Option<Mesh>, String> {
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    use gltf::accessor::{DataType, Dimensions};
    let position_accessor =
        prim.get(&gltf::Semantic::Positions).ok_or_else(|| format!("{label} has no POSITION attribute"))?;
    check_accessor(&position_accessor, "POSITION", Dimensions::Vec3, &[DataType::F32], &label)?;
    if let Some(normals) = prim.get(&gltf::Semantic::Normals) {
        check_accessor(&normals, "NORMAL", Dimensions::Vec3, &[DataType::F32], &label)?;
    }
    if let Some(uvs) = prim.get(&gltf::Semantic::TexCoords(texcoord_set)) {
        let types = [DataType::F32, DataType::U8, DataType::U16];
        check_accessor(&uvs, "TEXCOORD", Dimensions::Vec2, &types, &label)?;
    }
    if let Some(indices) = prim.indices() {
        let types = [DataType::U8, DataType::U16, DataType::U32];
        check_accessor(&indices, "index", Dimensions::Scalar, &types, &label)?;
    }
    let positions: Vec<Vec3> = reader
        .read_positions()
        .ok_or_else(|| {
            format!("{label}: its POSITION accessor {} cannot be read", position_accessor.index())
        })?
        .map(Vec3::from_array)
        .collect();
    if positions.len() != position_accessor.count() {
        return Err(format!(
            "{label}: its POSITION accessor {} claims {} vertices but its buffer holds {}",
            position_accessor.index(),
            position_accessor.count(),
            positions.len()
        ));
    }
    let indices: Vec<u32> = match (prim.indices(), reader.read_indices()) {
        (Some(accessor), Some(read)) => {
            let indices: Vec<u32> = read.into_u32().collect();
            if indices.len() != accessor.count() {
                return Err(format!(
                    "{label}: its index accessor {} claims {} indices but its buffer holds {}",
                    accessor.index(),
                    accessor.count(),
                    indices.len()
                ));
            }
            indices
        }
        (Some(accessor), None) => {
            return Err(format!(
                "{label}: its index accessor {} cannot be read from its buffer",
                accessor.index()
            ));
        }
        (None, _) => (0..positions.len() as u32).collect(),
    };
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
        return Err(format!("{label}: index {bad} is out of range for its {} vertices", positions.len()));
    }
    let Some(indices) = triangle_list(prim.mode(), &indices) else { return Ok(None) };
    if !indices.len().is_multiple_of(3) {
        return Err(format!("{label}: {} indices is not a whole number of triangles", indices.len()));
    }
    if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
        return Err(format!("{label}: a vertex position is not finite ({p})"));
    }
    let normals: Vec<Vec3> = match reader.read_normals() {
        Some(n) => n.map(|n| Vec3::from_array(n).normalize_or_zero()).collect(),
        None => smooth_normals(&positions, &indices),
    };
    if normals.len() != positions.len() {
        return Err(format!("{label}: {} normals for {} positions", normals.len(), positions.len()));
    }
    let uvs: Vec<Vec2> = match reader.read_tex_coords(texcoord_set) {
        Some(t) => t.into_f32().map(Vec2::from_array).collect(),
        None => vec![Vec2::ZERO; positions.len()],
    };
    if uvs.len() != positions.len() {
        return Err(format!("{label}: {} texture coordinates for {} positions", uvs.len(), positions.len()));
    }
    Ok(Some(Mesh { name: label, positions, normals, uvs, indices }))
}

/// The index of `prim`'s POSITION accessor if its declared `min` and `max` do not
/// bound `positions` (the data it was read into), beyond the rounding of a decimal
/// in JSON. glTF 2.0 (§3.6.2.5, accessor bounds) requires them to; a viewer that culls by them would
/// lose the vertices outside.
pub fn lying_bounds(prim: &gltf::Primitive, positions: &[Vec3]) -> Option<usize> {
    let accessor = prim.get(&gltf::Semantic::Positions)?;
    let declared = |value: Option<gltf::json::Value>| -> Option<Vec3> {
        let numbers: Vec<f32> =
            value?.as_array()?.iter().map(|n| n.as_f64().map(|n| n as f32)).collect::<Option<_>>()?;
        <[f32; 3]>::try_from(numbers).ok().map(Vec3::from_array)
    };
    let (min, max) = (declared(accessor.min())?, declared(accessor.max())?);
    // 1e-5 of the bound's magnitude, and at least 1e-5: a decimal's rounding.
    let slack = (min.abs().max(max.abs()) + Vec3::ONE) * 1e-5;
    let outside = |p: &Vec3| p.cmplt(min - slack).any() || p.cmpgt(max + slack).any();
    positions.iter().any(outside).then(|| accessor.index())
}

/// Removes `mesh`'s triangles of zero area (their edges' cross product is exactly 0,
/// which no affine placement changes) and returns how many went.
pub fn drop_degenerate(mesh: &mut Mesh) -> usize {
    let before = mesh.indices.len() / 3;
    let positions = &mesh.positions;
    let kept: Vec<u32> = mesh
        .indices
        .chunks_exact(3)
        .filter(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
            (b - a).cross(c - a) != Vec3::ZERO
        })
        .flatten()
        .copied()
        .collect();
    mesh.indices = kept;
    let dropped = before - mesh.indices.len() / 3;
    if dropped > 0 {
        keep_referenced_vertices(mesh);
    }
    dropped
}

/// Removes the vertices no triangle of `mesh` uses any more (a file of millions of
/// vertices at one point keeps none of them), renumbering the indices.
fn keep_referenced_vertices(mesh: &mut Mesh) {
    const UNUSED: u32 = u32::MAX;
    let mut new_index = vec![UNUSED; mesh.positions.len()];
    let mut order = Vec::new();
    for i in &mut mesh.indices {
        let slot = &mut new_index[*i as usize];
        if *slot == UNUSED {
            *slot = order.len() as u32;
            order.push(*i as usize);
        }
        *i = *slot;
    }
    mesh.positions = order.iter().map(|&v| mesh.positions[v]).collect();
    mesh.normals = order.iter().map(|&v| mesh.normals[v]).collect();
    mesh.uvs = order.iter().map(|&v| mesh.uvs[v]).collect();
}

/// Area-weighted vertex normals, for meshes that come without them.
fn smooth_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
        let n = (positions[b] - positions[a]).cross(positions[c] - positions[a]);
        for i in [a, b, c] {
            normals[i] += n;
        }
    }
    normals.iter().map(|n| n.try_normalize().unwrap_or(Vec3::Y)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_become_lists_with_the_first_triangles_winding() {
        // A quad 0-1-2-3 as a strip (0,1,2),(1,3,2) and as a fan around 0.
        assert_eq!(triangle_list(Mode::TriangleStrip, &[0, 1, 2, 3]).unwrap(), [0, 1, 2, 1, 3, 2]);
        assert_eq!(triangle_list(Mode::TriangleFan, &[0, 1, 2, 3]).unwrap(), [1, 2, 0, 2, 3, 0]);
        // A restart by repeated indices leaves no degenerate triangle.
        let restarted = triangle_list(Mode::TriangleStrip, &[0, 1, 2, 2, 5, 5, 6, 7]).unwrap();
        assert!(restarted.chunks(3).all(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]), "{restarted:?}");
        assert!(triangle_list(Mode::TriangleStrip, &[0, 1]).unwrap().is_empty());
        assert!(triangle_list(Mode::Lines, &[0, 1]).is_none() && triangle_list(Mode::Points, &[0]).is_none());
    }

    #[test]
    fn every_strip_triangle_faces_the_same_way_as_the_first() {
        // A zig-zag strip in the z = 0 plane: every triangle's normal must be +z.
        let p: Vec<Vec3> = (0..8).map(|i| Vec3::new((i / 2) as f32, (i % 2) as f32, 0.0)).collect();
        let list = triangle_list(Mode::TriangleStrip, &(0..8).collect::<Vec<u32>>()).unwrap();
        let first = {
            let t = &list[0..3];
            (p[t[1] as usize] - p[t[0] as usize]).cross(p[t[2] as usize] - p[t[0] as usize]).z.signum()
        };
        for t in list.chunks(3) {
            let n = (p[t[1] as usize] - p[t[0] as usize]).cross(p[t[2] as usize] - p[t[0] as usize]);
            assert_eq!(n.z.signum(), first, "{t:?}");
        }
    }
}
