//! The ways a scene can be malformed, each naming the scene and the part at fault.

/// A scene that is not well formed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SceneError {
    /// An instance's mesh index is not below the number of meshes.
    #[error("scene `{scene}`: instance `{instance}` refers to mesh {mesh}, but there are {count} meshes")]
    MeshOutOfRange {
        /// Name of the scene at fault.
        scene: String,
        /// Name of the instance with the bad index.
        instance: String,
        /// The mesh index it gives.
        mesh: usize,
        /// The number of meshes in the scene.
        count: usize,
    },
    /// An instance's material index is not below the number of materials.
    #[error(
        "scene `{scene}`: instance `{instance}` refers to material {material}, but there are {count} materials"
    )]
    MaterialOutOfRange {
        /// Name of the scene at fault.
        scene: String,
        /// Name of the instance with the bad index.
        instance: String,
        /// The material index it gives.
        material: usize,
        /// The number of materials in the scene.
        count: usize,
    },
    /// A mesh's positions, normals and texture coordinates differ in number.
    #[error(
        "scene `{scene}`: mesh `{mesh}` has {positions} positions, {normals} normals and {uvs} UVs; all three must match"
    )]
    AttributeCountMismatch {
        /// Name of the scene at fault.
        scene: String,
        /// Name of the mesh at fault.
        mesh: String,
        /// Its number of positions.
        positions: usize,
        /// Its number of normals.
        normals: usize,
        /// Its number of texture coordinates.
        uvs: usize,
    },
    /// A mesh's index reaches past its vertices, or its index count is not a multiple of 3.
    #[error(
        "scene `{scene}`: mesh `{mesh}` has an index {index} beyond its {vertices} vertices, or an index count not a multiple of 3"
    )]
    BadIndices {
        /// Name of the scene at fault.
        scene: String,
        /// Name of the mesh at fault.
        mesh: String,
        /// The first index past the vertices (0 when only the index count is wrong).
        index: u32,
        /// The mesh's number of vertices.
        vertices: usize,
    },
    /// A mesh has a position or normal with an infinite or NaN coordinate.
    #[error("scene `{scene}`: mesh `{mesh}` has a non-finite position or normal")]
    NonFinite {
        /// Name of the scene at fault.
        scene: String,
        /// Name of the mesh at fault.
        mesh: String,
    },
    /// An instance's transform has an infinite or NaN entry.
    #[error("scene `{scene}`: instance `{instance}` has a non-finite transform (world_from_object)")]
    NonFiniteTransform {
        /// Name of the scene at fault.
        scene: String,
        /// Name of the instance at fault.
        instance: String,
    },
    /// A material's base-colour texture index is not below the number of textures.
    #[error(
        "scene `{scene}`: material `{material}` refers to texture {texture}, but there are {count} textures"
    )]
    TextureOutOfRange {
        /// Name of the scene at fault.
        scene: String,
        /// Name of the material with the bad index.
        material: String,
        /// The texture index it gives.
        texture: usize,
        /// The number of textures in the scene.
        count: usize,
    },
    /// A light has a number outside its valid range ([`crate::limits`]).
    #[error("scene `{scene}`: light `{light}`: {problem}")]
    BadLight {
        /// Name of the scene at fault.
        scene: String,
        /// The light: `sun`, `spot`, `point`, or its name in the light list.
        light: String,
        /// The value at fault and its valid range.
        problem: crate::limits::LimitError,
    },
    /// A scene has two defaults of one kind: which one `--light <kind>` draws would be
    /// a matter of order ([`crate::scene_lights`] allows one per kind).
    #[error(
        "scene `{scene}`: two default {kind} lights, `{first}` and `{second}`: a scene has one default per kind (Scene::set_default replaces it)"
    )]
    TwoDefaults {
        /// Name of the scene at fault.
        scene: String,
        /// The kind, as `Light::KIND_NAMES` writes it.
        kind: &'static str,
        /// The first default's name.
        first: String,
        /// The second default's name.
        second: String,
    },
    /// The camera has a number outside its valid range ([`crate::limits`]).
    #[error("scene `{scene}`: camera: {problem}")]
    BadCamera {
        /// Name of the scene at fault.
        scene: String,
        /// The value at fault and its valid range.
        problem: crate::limits::LimitError,
    },
    /// A texture is empty (zero width or height) or its bytes are not 4 per texel.
    #[error(
        "scene `{scene}`: texture `{texture}` is {width}×{height} but holds {bytes} bytes, not 4 per texel"
    )]
    BadTexture {
        /// Name of the scene at fault.
        scene: String,
        /// Name of the texture at fault.
        texture: String,
        /// Its width in texels.
        width: u32,
        /// Its height in texels.
        height: u32,
        /// The number of bytes it holds.
        bytes: usize,
    },
}
