//! Plain-old-data mirrors of the vertex and instance data in `passes/*.wgsl`; the
//! uniforms are in [`crate::uniforms`].

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

/// One entry of the instance buffer (`Instance` in `scene_common.wgsl`). The buffer is
/// bound twice: as a storage buffer, where fragment stages read the material, and as
/// vertex buffer [`INSTANCE_SLOT`], where vertex stages read `world_from_object`
/// ([`InstanceGpu::transform_layout`]).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct InstanceGpu {
    pub world_from_object: Mat4,
    /// rgb: base colour (linear); a: base alpha.
    pub base_color: Vec4,
    /// Specular weight and Blinn-Phong exponent.
    pub specular: f32,
    pub shininess: f32,
    /// The scene's instance index + 1 (0 marks the background).
    pub object_id: u32,
    /// Alpha cutoff of a MASK material; −1 for none.
    pub alpha_cutoff: f32,
    /// 1 when the base colour is multiplied by the bound texture.
    pub textured: u32,
    /// Which of its faces the camera's passes draw: a [`SeenFaces`].
    pub seen_faces: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// Which faces of an instance the camera's passes draw (`InstanceGpu::seen_faces`;
/// `hidden_face` in scene_common.wgsl).
///
/// A closed mesh's inside is never seen from outside it, so the camera draws only
/// its outer faces, by the winding they have on screen, as glTF asks of a
/// single-sided material (glTF 2.0, "Double Sided"). Where snapping the vertices of
/// a sliver a fraction of a pixel wide (a 4 mm wire across 300 pixels) opens gaps
/// in its near faces, the rasterizer showed its far faces through them, from
/// inside, where every shadow ray is blocked: the truth there is shadow and the
/// map's answer light. An open mesh's faces are both drawn, as before: a wall or a
/// card seen from behind shows its back.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SeenFaces {
    /// A double-sided material, or an open mesh (or a closed one of no volume).
    Both = 0,
    /// A closed mesh whose outer faces wind counter-clockwise on screen.
    CounterClockwise = 1,
    /// A closed mesh whose outer faces wind clockwise: one wound inside out, or
    /// placed by a mirroring transform.
    Clockwise = 2,
}

impl SeenFaces {
    pub const ALL: [SeenFaces; 3] = [SeenFaces::Both, SeenFaces::CounterClockwise, SeenFaces::Clockwise];

    /// The WGSL constant's name (`package::constants`).
    pub fn wgsl_name(self) -> &'static str {
        match self {
            SeenFaces::Both => "SEEN_BOTH",
            SeenFaces::CounterClockwise => "SEEN_CCW",
            SeenFaces::Clockwise => "SEEN_CW",
        }
    }

    /// The faces seen of a mesh placed by `world_from_object`, whose winding
    /// `outward` says (None: open, or double-sided; Some(true): its outer faces wind
    /// counter-clockwise seen from outside, a positive signed volume).
    pub fn of(outward: Option<bool>, world_from_object: Mat4) -> SeenFaces {
        match outward {
            None => SeenFaces::Both,
            // A transform of negative determinant mirrors the mesh and its winding.
            Some(ccw) if ccw == (world_from_object.determinant() > 0.0) => SeenFaces::CounterClockwise,
            Some(_) => SeenFaces::Clockwise,
        }
    }
}

/// The vertex-buffer slot of the instance transforms, after the vertices (slot 0).
pub const INSTANCE_SLOT: u32 = 1;

impl InstanceGpu {
    /// `world_from_object`'s four columns as per-instance vertex attributes, locations
    /// 3 to 6 (`InstanceTransform` in `scene_common.wgsl`), at the start of each entry.
    ///
    /// Why not read the matrix from the storage buffer by `instance_index`: that is a
    /// gather in every vertex invocation, and a CPU rasterizer pays it per vertex
    /// (lavapipe: Sponza's shadow pass took 1.6–1.8× a depth-only pass that reads no
    /// instance data, and 0.94× once the matrix came as an attribute). Per-instance
    /// attributes are fetched once per instance on every kind of device.
    pub const TRANSFORM_ATTRIBUTES: [wgpu::VertexAttribute; 4] = wgpu::vertex_attr_array![
        3 => Float32x4, 4 => Float32x4, 5 => Float32x4, 6 => Float32x4
    ];

    pub const fn transform_layout() -> wgpu::VertexBufferLayout<'static> {
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<InstanceGpu>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &Self::TRANSFORM_ATTRIBUTES,
        }
    }
}

/// Which vertex stream a geometry pass reads from slot 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VertexStream {
    /// Position, normal and texture coordinate ([`VertexGpu`]).
    Full,
    /// Positions alone (12 bytes a vertex): what opaque casters drawn into a projected
    /// map need, and a third of the bytes fetched.
    PositionsOnly,
}

impl VertexStream {
    /// The vertex buffers a pipeline drawing scene geometry declares: the stream in
    /// slot 0, the instance transforms in slot [`INSTANCE_SLOT`].
    pub const fn buffers(self) -> [Option<wgpu::VertexBufferLayout<'static>>; 2] {
        let vertices = match self {
            VertexStream::Full => VertexGpu::layout(),
            VertexStream::PositionsOnly => wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &POSITION_ATTRIBUTES,
            },
        };
        [Some(vertices), Some(InstanceGpu::transform_layout())]
    }
}

const POSITION_ATTRIBUTES: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x3];

/// One vertex: position, normal, texture coordinate (locations 0, 1, 2).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct VertexGpu {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
}

impl VertexGpu {
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 3] =
        wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2];

    pub const fn layout() -> wgpu::VertexBufferLayout<'static> {
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<VertexGpu>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &Self::ATTRIBUTES,
        }
    }
}
