//! Plain-old-data mirrors of the WGSL structs in `passes/*.wgsl`.

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
    /// x: specular weight, y: Blinn-Phong exponent, z: object id (instance index + 1),
    /// w: alpha cutoff for MASK materials, −1 for none.
    pub material: Vec4,
    /// x: 1 when the base colour is multiplied by the bound texture.
    pub texturing: Vec4,
}

/// The light uniform (`Light` in `scene_common.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Default)]
pub struct LightGpu {
    pub clip_from_world: Mat4,
    pub light_from_world: Mat4,
    /// rgb: colour × intensity.
    pub radiance: Vec4,
    /// xyz: the sun's travel direction or the spot's axis; w: 0 for a sun, 1 for a
    /// spot, 2 for a point light.
    pub direction: Vec4,
    /// xyz: spot or point light position; w: its range.
    pub position: Vec4,
    /// x: cos(inner angle), y: cos(outer angle), z: map near plane, w: map far plane.
    pub cone: Vec4,
    /// x: texel world size of an orthographic map; y: texel world size per unit of
    /// distance for a perspective map; z: normal offset in texels; w: map resolution.
    pub texel: Vec4,
    /// The PCF kernel: x: width, y: 1 when the width is in world units, z: Poisson
    /// taps, w: 1 for receiver-plane depth bias.
    pub kernel: Vec4,
    /// PCSS: x: light size (spot disk radius in world units, or tan of the sun's
    /// angular radius), y: blocker-search taps, z: largest radius in texels.
    pub pcss: Vec4,
    /// Technique parameters, defined by each technique module.
    pub params: [Vec4; 2],
    /// rgb: ambient light.
    pub ambient: Vec4,
    /// Each layer's (cascade's) clip_from_world; layer 0 equals `clip_from_world`.
    pub cascade_clip_from_world: [Mat4; MAX_CASCADES],
    /// x: each layer's texel world size (orthographic; the largest for a warped map;
    /// 0 for a perspective map); y: 1 for a warped layer, whose texel size the shader
    /// measures locally; z: the world step of that measurement.
    pub cascade_texel: [Vec4; MAX_CASCADES],
    /// The view depths where the cascades start and end, packed four to a vector:
    /// cascade i spans split i to split i + 1.
    pub cascade_splits: [Vec4; 3],
    /// x: layer count, y: 1 to select cascades by projection, z: blend band as a
    /// fraction of a cascade's depth range, w: moment-map layers per cascade.
    pub cascades: Vec4,
    /// The rasterizer's depth bias, for the passes that write their own depth (a
    /// point light's distance cube): x: constant bias in units of the depth's last
    /// mantissa bit, y: slope-scaled bias.
    pub raster_bias: Vec4,
    /// Contact shadows: x: ray length in world units, y: steps (0 when off), z:
    /// thickness as a fraction of view depth, w: the ray's start offset along the
    /// normal in world units.
    pub contact: Vec4,
    /// x: the view depth where contact shadows end.
    pub contact_range: Vec4,
}

/// The most cascades a light may have (the size of the uniform arrays).
pub const MAX_CASCADES: usize = 8;

/// The camera uniform (`Camera` in `camera.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct CameraGpu {
    pub clip_from_world: Mat4,
    pub view_from_world: Mat4,
    pub world_from_view: Mat4,
    pub eye: Vec4,
    /// x: 1 to tint pixels by their cascade.
    pub debug: Vec4,
    /// x: clip_from_view's x scale, y: its y scale (a symmetric perspective), z: the
    /// near plane, w: the far plane.
    pub projection: Vec4,
    /// x, y: the image's width and height in pixels; z, w: their inverses.
    pub viewport: Vec4,
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
