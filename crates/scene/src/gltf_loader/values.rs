//! What the glTF 2.0 specification requires of a file's values that the gltf crate
//! accepts anyway, refused with its JSON path, and the features Gnomon does not draw,
//! warned of:
//!
//! - a material's `baseColorFactor` in [0, 1] and its `alphaCutoff` finite and not
//!   negative (§5.22, §5.19);
//! - an accessor marked `normalized` only for integer components (§5.1.5: never
//!   FLOAT or UNSIGNED_INT);
//! - a node's `matrix` alone, without `translation`, `rotation` or `scale` (§5.25),
//!   and affine: its last row (0, 0, 0, 1) (§3.5.2: decomposable to TRS);
//! - warned: skins and morph targets, drawn in their bind pose, and orthographic
//!   cameras, which Gnomon does not use.

use gltf::json::{Root, accessor::ComponentType, validation::Checked};

/// Refuses the first value of `json` that the specification does not allow.
pub fn check(json: &Root) -> Result<(), String> {
    materials(json)?;
    accessors(json)?;
    nodes(json)
}

fn materials(json: &Root) -> Result<(), String> {
    for (i, material) in json.materials.iter().enumerate() {
        let factor = material.pbr_metallic_roughness.base_color_factor.0;
        if !factor.iter().all(|c| (0.0..=1.0).contains(c)) {
            return Err(format!(
                "`materials[{i}].pbrMetallicRoughness.baseColorFactor` = {factor:?} is invalid: each of its four \
                 numbers in [0, 1] (glTF 2.0, §5.22)"
            ));
        }
        if let Some(cutoff) = &material.alpha_cutoff
            && !(cutoff.0.is_finite() && cutoff.0 >= 0.0)
        {
            return Err(format!(
                "`materials[{i}].alphaCutoff` = {} is invalid: a finite number, at least 0 (glTF 2.0, §5.19)",
                cutoff.0
            ));
        }
    }
    Ok(())
}

fn accessors(json: &Root) -> Result<(), String> {
    for (i, accessor) in json.accessors.iter().enumerate() {
        let Checked::Valid(kind) = &accessor.component_type else { continue };
        if accessor.normalized && matches!(kind.0, ComponentType::F32 | ComponentType::U32) {
            return Err(format!(
                "`accessors[{i}].normalized` is true for {:?} components: only for 8- and 16-bit integers \
                 (glTF 2.0, §5.1.5)",
                kind.0
            ));
        }
    }
    Ok(())
}

fn nodes(json: &Root) -> Result<(), String> {
    for (i, node) in json.nodes.iter().enumerate() {
        let Some(m) = &node.matrix else { continue };
        if node.translation.is_some() || node.rotation.is_some() || node.scale.is_some() {
            return Err(format!(
                "`nodes[{i}]` has both a `matrix` and `translation`, `rotation` or `scale`: one or the other \
                 (glTF 2.0, §5.25)"
            ));
        }
        // Column-major: the last row is elements 3, 7, 11 and 15.
        if [m[3], m[7], m[11], m[15]] != [0.0, 0.0, 0.0, 1.0] {
            return Err(format!(
                "`nodes[{i}].matrix` is projective (its last row is [{}, {}, {}, {}]): a node's matrix is affine, \
                 its last row [0, 0, 0, 1] (glTF 2.0, §3.5.2)",
                m[3], m[7], m[11], m[15]
            ));
        }
    }
    Ok(())
}

/// The file's features that Gnomon reads but does not draw as the file means them.
pub fn unsupported(json: &Root) -> Vec<String> {
    let mut warnings = Vec::new();
    if !json.skins.is_empty() {
        warnings.push(format!(
            "{} skin(s): skinned meshes are drawn in their bind pose, unanimated",
            json.skins.len()
        ));
    }
    let morphed = json.meshes.iter().flat_map(|m| &m.primitives).filter(|p| p.targets.is_some()).count();
    if morphed > 0 {
        warnings.push(format!("{morphed} primitive(s) with morph targets: drawn with no target applied"));
    }
    let orthographic = json
        .cameras
        .iter()
        .filter(|c| matches!(c.type_, Checked::Valid(gltf::json::camera::Type::Orthographic)))
        .count();
    if orthographic > 0 {
        warnings.push(format!(
            "{orthographic} orthographic camera(s) ignored: Gnomon draws perspective views (the first \
             perspective camera, else a view fitted to the scene)"
        ));
    }
    warnings
}

/// Checks every sparse accessor's indices, which the gltf crate substitutes
/// unchecked: each below the accessor's count, and strictly increasing (glTF 2.0,
/// §3.6.2.3), so none is written twice or outside.
pub fn sparse_indices(document: &gltf::Document, buffers: &[gltf::buffer::Data]) -> Result<(), String> {
    use gltf::accessor::sparse::IndexType;
    for accessor in document.accessors() {
        let Some(sparse) = accessor.sparse() else { continue };
        let at = format!("`accessors[{}].sparse.indices`", accessor.index());
        let indices = sparse.indices();
        let view = indices.view();
        let width = match indices.index_type() {
            IndexType::U8 => 1,
            IndexType::U16 => 2,
            IndexType::U32 => 4,
        };
        let start = view.offset() + indices.offset();
        let bytes = buffers
            .get(view.buffer().index())
            .and_then(|b| b.0.get(start..start.checked_add(sparse.count() * width)?))
            .ok_or_else(|| format!("{at}: its {} indices run past their buffer", sparse.count()))?;
        let mut previous: Option<u64> = None;
        for (k, index) in bytes.chunks_exact(width).enumerate() {
            let index = index.iter().rev().fold(0u64, |v, &b| (v << 8) | u64::from(b));
            if index >= accessor.count() as u64 {
                return Err(format!(
                    "{at}[{k}] = {index} is past the accessor's {} elements",
                    accessor.count()
                ));
            }
            if previous.is_some_and(|p| index <= p) {
                return Err(format!(
                    "{at}[{k}] = {index} does not follow {}: sparse indices strictly increase (glTF 2.0, §3.6.2.3)",
                    previous.unwrap_or_default()
                ));
            }
            previous = Some(index);
        }
    }
    Ok(())
}
