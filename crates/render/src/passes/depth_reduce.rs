//! The sample-distribution passes of SDSM: a compute reduction of the camera's depth
//! buffer to the view depths actually seen, which the cascades then split instead of
//! the frustum's intersection with the scene bounds; and, optionally, a second one to
//! each cascade's light-space x and y bounds of the samples it serves, which the
//! cascades are then fitted to.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

use crate::pool::{Binding, Pool, ViewKey};

/// The reduction pipelines and their bind group layout (both read the depth buffer,
/// fold into a storage buffer and take a uniform).
pub(crate) struct DepthReducePass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    bounds_pipeline: wgpu::ComputePipeline,
}

/// The per-cascade bounds readback, waiting on the submission.
pub(crate) struct PendingSampleBounds {
    buffer: wgpu::Buffer,
    count: usize,
}

/// The bounds pass's uniform: see `sample_bounds.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct BoundsParams {
    pub world_from_clip: Mat4,
    pub light_from_world: Mat4,
    /// The view depths bounding the cascades, four to a vector (a uniform array's
    /// elements are 16 bytes apart): `splits[i / 4][i % 4]`.
    pub splits: [Vec4; 3],
    pub near: f32,
    pub far: f32,
    pub cascade_count: u32,
    pub blend: f32,
}

/// What the bounds pass needs to know of the camera and the cascades.
pub(crate) struct BoundsRequest<'a> {
    pub world_from_clip: Mat4,
    pub light_from_world: Mat4,
    pub near: f32,
    pub far: f32,
    /// The cascades' view-depth splits, count + 1 of them.
    pub splits: &'a [f32],
    /// The lighting pass's blend band, as a fraction of a cascade's depth range.
    pub blend: f32,
}

/// The depth-range readback, waiting on the submission.
pub(crate) struct PendingDepthRange {
    buffer: wgpu::Buffer,
}

/// The camera's planes (`Planes` in `depth_reduce.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct Planes {
    pub near: f32,
    pub far: f32,
    pub _pad0: f32,
    pub _pad1: f32,
}

impl Planes {
    pub fn new(near: f32, far: f32) -> Self {
        Self { near, far, _pad0: 0.0, _pad1: 0.0 }
    }
}

/// One reduction: its pipeline, the depth it reads, the buffer it folds into and its
/// uniform.
struct Dispatch<'a> {
    pipeline: &'a wgpu::ComputePipeline,
    depth: &'a wgpu::Texture,
    output: &'a wgpu::Buffer,
    params: &'a wgpu::Buffer,
}

impl DepthReducePass {
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth reduction"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("depth_reduce.wgsl"),
            source: wgpu::ShaderSource::Wgsl(reduce_wgsl().into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth reduction"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("depth reduction"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("reduce"),
            compilation_options: Default::default(),
            cache: None,
        });
        let bounds_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sample_bounds.wgsl"),
            source: wgpu::ShaderSource::Wgsl(bounds_wgsl().into()),
        });
        let bounds_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("sample bounds"),
            layout: Some(&pipeline_layout),
            module: &bounds_module,
            entry_point: Some("bounds_of_samples"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { layout, pipeline, bounds_pipeline }
    }

    /// Records the per-cascade light-space bounds of `depth`'s samples and the copy of
    /// the result out.
    pub fn record_bounds(
        &self,
        pool: &mut Pool,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        depth: &wgpu::Texture,
        request: &BoundsRequest,
    ) -> PendingSampleBounds {
        let count = request.splits.len().saturating_sub(1).min(MAX_BOUNDS);
        // Minima start at the largest encoding, maxima at the smallest.
        let initial: Vec<u32> = (0..4 * MAX_BOUNDS).map(|i| if i % 4 < 2 { u32::MAX } else { 0 }).collect();
        let bounds = pool.storage(queue, "sample bounds", &initial, wgpu::BufferUsages::COPY_SRC);
        let mut splits = [0.0f32; 12];
        for (slot, z) in splits.iter_mut().zip(request.splits) {
            *slot = z.min(f32::MAX);
        }
        let params = BoundsParams {
            world_from_clip: request.world_from_clip,
            light_from_world: request.light_from_world,
            splits: [
                Vec4::from_slice(&splits[0..4]),
                Vec4::from_slice(&splits[4..8]),
                Vec4::from_slice(&splits[8..12]),
            ],
            near: request.near,
            far: request.far,
            cascade_count: count as u32,
            blend: request.blend,
        };
        let params = pool.uniform(queue, "sample bounds parameters", &params);
        let dispatch = Dispatch { pipeline: &self.bounds_pipeline, depth, output: &bounds, params: &params };
        self.dispatch(pool, encoder, dispatch, "sample bounds");
        let size = (16 * MAX_BOUNDS) as u64;
        let buffer = pool.buffer(
            "sample bounds readback",
            size,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        );
        encoder.copy_buffer_to_buffer(&bounds, 0, &buffer, 0, size);
        PendingSampleBounds { buffer, count }
    }

    /// Binds the dispatch's depth, output and parameters and runs its pipeline over
    /// 16×16 tiles.
    fn dispatch(&self, pool: &mut Pool, encoder: &mut wgpu::CommandEncoder, d: Dispatch, label: &str) {
        let Dispatch { pipeline, depth, output, params } = d;
        let view = pool.view(depth, ViewKey::default());
        let group = pool.bind_group(
            label,
            &self.layout,
            &[Binding::View(view), Binding::Buffer(output.clone()), Binding::Buffer(params.clone())],
        );
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(depth.width().div_ceil(16), depth.height().div_ceil(16), 1);
    }

    /// Records the reduction of `depth` (a camera depth buffer with planes `near`,
    /// `far`) and the copy of its result out.
    pub fn record(
        &self,
        pool: &mut Pool,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        depth: &wgpu::Texture,
        planes: Planes,
    ) -> PendingDepthRange {
        let range = pool.storage(queue, "depth range", &[u32::MAX, 0u32], wgpu::BufferUsages::COPY_SRC);
        let planes = pool.uniform(queue, "camera planes", &planes);
        let dispatch = Dispatch { pipeline: &self.pipeline, depth, output: &range, params: &planes };
        self.dispatch(pool, encoder, dispatch, "depth reduction");
        let buffer = pool.buffer(
            "depth range readback",
            8,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        );
        encoder.copy_buffer_to_buffer(&range, 0, &buffer, 0, 8);
        PendingDepthRange { buffer }
    }
}

impl PendingDepthRange {
    /// The (nearest, farthest) view depth seen, after the submission; None when the
    /// camera sees no surface.
    pub async fn read(self, gpu: &crate::Gpu) -> Result<Option<(f32, f32)>, crate::RenderError> {
        let bits: Vec<u32> = crate::readback::read_buffer(gpu, &self.buffer).await?;
        let (near, far) = (f32::from_bits(bits[0]), f32::from_bits(bits[1]));
        Ok((bits[0] != u32::MAX && near <= far).then_some((near, far)))
    }
}

/// Cascades the bounds pass serves, as the lighting pass's uniform allows.
const MAX_BOUNDS: usize = crate::uniforms::MAX_CASCADES;

/// Inverts the shader's order-preserving encoding.
fn decode(bits: u32) -> f32 {
    f32::from_bits(if bits & 0x8000_0000 != 0 { bits & 0x7fff_ffff } else { !bits })
}

impl PendingSampleBounds {
    /// Each cascade's (min x, min y, max x, max y) in light view space, after the
    /// submission; None for a cascade that serves no sample.
    pub async fn read(self, gpu: &crate::Gpu) -> Result<Vec<Option<[f32; 4]>>, crate::RenderError> {
        let bits: Vec<u32> = crate::readback::read_buffer(gpu, &self.buffer).await?;
        Ok(bits
            .chunks_exact(4)
            .take(self.count)
            .map(|b| {
                let bounds = [decode(b[0]), decode(b[1]), decode(b[2]), decode(b[3])];
                (b[0] != u32::MAX && bounds[0] <= bounds[2] && bounds[1] <= bounds[3]).then_some(bounds)
            })
            .collect())
    }
}

/// The depth buffer both passes read, at binding 0 of their group.
const DEPTH_BUFFER_BINDING_WGSL: &str = include_str!("depth_buffer_binding.wgsl");

/// `depth_reduce.wgsl`, composed.
pub(crate) fn reduce_wgsl() -> String {
    super::compose_wgsl(&[DEPTH_BUFFER_BINDING_WGSL, include_str!("depth_reduce.wgsl")])
}

/// `sample_bounds.wgsl`, composed.
pub(crate) fn bounds_wgsl() -> String {
    super::compose_wgsl(&[DEPTH_BUFFER_BINDING_WGSL, include_str!("sample_bounds.wgsl")])
}

#[cfg(test)]
mod tests {
    use super::decode;

    /// The shader's encoding, mirrored: it must order like the floats.
    fn encode(f: f32) -> u32 {
        let bits = f.to_bits();
        if bits & 0x8000_0000 != 0 { !bits } else { bits | 0x8000_0000 }
    }

    #[test]
    fn the_bounds_encoding_orders_like_the_floats_and_round_trips() {
        let values = [-1e30f32, -3.5, -1.0, -1e-20, -0.0, 0.0, 1e-20, 0.25, 1.0, 7.0, 1e30];
        for w in values.windows(2) {
            assert!(encode(w[0]) <= encode(w[1]), "{} then {}", w[0], w[1]);
        }
        for v in values {
            assert_eq!(decode(encode(v)).to_bits(), v.to_bits());
        }
    }
}
