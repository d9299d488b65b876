//! The GPU culler (`gpu_cull.wgsl`): one compute dispatch per shadow layer tests
//! every shadow item (`gpu_scene/shadow_items.rs`) against the layer and writes the
//! draws it keeps, bucket by bucket, with their counts: what the layer's
//! `multi_draw_indexed_indirect_count` reads (`DrawSubmission::GpuCulled`).

use bytemuck::{Pod, Zeroable};
use gnomon_math::facing::Winding;

use crate::{
    gpu_scene::{DrawArgs, LayerFaces, shadow_items::ShadowItems},
    pool::{Binding, Pool},
};

/// Threads per workgroup: one item each.
pub(crate) const CULL_WORKGROUP: u32 = 64;

/// How many workgroups cull `items` items.
pub(crate) fn workgroups(items: u32) -> u32 {
    items.div_ceil(CULL_WORKGROUP)
}

/// The winding a bucket's pipeline culls, as `gpu_cull.wgsl` reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub(crate) enum WindingCode {
    /// It culls none: every item in the frustum is kept.
    Kept = 0,
    CounterClockwise = 1,
    Clockwise = 2,
}

impl WindingCode {
    pub const ALL: [WindingCode; 3] =
        [WindingCode::Kept, WindingCode::CounterClockwise, WindingCode::Clockwise];

    fn of(winding: Option<Winding>) -> Self {
        match winding {
            None => WindingCode::Kept,
            Some(Winding::CounterClockwise) => WindingCode::CounterClockwise,
            Some(Winding::Clockwise) => WindingCode::Clockwise,
        }
    }

    /// The constant's name in WGSL.
    pub fn wgsl_name(self) -> &'static str {
        match self {
            WindingCode::Kept => "WINDING_KEPT",
            WindingCode::CounterClockwise => "WINDING_CCW",
            WindingCode::Clockwise => "WINDING_CW",
        }
    }
}

/// The layer a dispatch culls for (`CullView` in `gpu_cull.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct CullViewGpu {
    pub(crate) planes: [[f32; 4]; 6],
    pub(crate) centre: [f32; 4],
    pub(crate) item_count: u32,
    pub(crate) near: u32,
    pub(crate) _pad0: u32,
    pub(crate) _pad1: u32,
}

/// A bucket as the culler reads it (`CullBucket` in `gpu_cull.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct BucketGpu {
    pub(crate) first_slot: u32,
    pub(crate) culled: u32,
}

/// What one layer's culling wrote: its kept draws, bucket by bucket from each
/// bucket's first slot, and each bucket's count.
pub(crate) struct CulledDraws {
    pub draws: wgpu::Buffer,
    pub counts: wgpu::Buffer,
}

impl CulledDraws {
    /// Bytes from the start of `draws` to a slot's arguments.
    pub fn draw_offset(slot: u32) -> u64 {
        u64::from(slot) * DrawArgs::SIZE
    }

    /// Bytes from the start of `counts` to a bucket's count.
    pub fn count_offset(bucket: usize) -> u64 {
        bucket as u64 * std::mem::size_of::<u32>() as u64
    }
}

/// The layer one dispatch culls for.
pub(crate) struct CullTarget<'a> {
    pub frustum: &'a gnomon_math::culling::Frustum,
    /// Whether the near plane counts.
    pub near: bool,
    /// What decides the faces the layer's pass culls; None where no matrix tells.
    pub faces: Option<LayerFaces>,
}

/// The culling pipeline, built on first use.
pub(crate) struct GpuCullPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipeline: Option<wgpu::ComputePipeline>,
}

impl GpuCullPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gpu cull"),
            entries: &[
                super::compute_storage_entry(0, crate::passes::StorageAccess::Read),
                super::uniform_entry(1, wgpu::ShaderStages::COMPUTE),
                super::compute_storage_entry(2, crate::passes::StorageAccess::Read),
                super::compute_storage_entry(3, crate::passes::StorageAccess::ReadWrite),
                super::compute_storage_entry(4, crate::passes::StorageAccess::ReadWrite),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gpu cull"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        Self { layout, pipeline_layout, pipeline: None }
    }

    fn pipeline(&mut self, device: &wgpu::Device) -> &wgpu::ComputePipeline {
        let layout = &self.pipeline_layout;
        self.pipeline.get_or_insert_with(|| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("gpu cull"),
                source: wgpu::ShaderSource::Wgsl(gpu_cull_wgsl().into()),
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("gpu cull"),
                layout: Some(layout),
                module: &module,
                entry_point: Some("cull"),
                compilation_options: Default::default(),
                cache: None,
            })
        })
    }

    /// Records the culling of `items` for `target`, with `timestamp_writes` where
    /// given: returns the buffers the layer's draws read.
    pub fn record(
        &mut self,
        gpu: &crate::Gpu,
        pool: &mut Pool,
        encoder: &mut wgpu::CommandEncoder,
        items: &ShadowItems,
        target: &CullTarget,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites>,
    ) -> CulledDraws {
        // The centre is taken to unit length: any positive multiple answers the same.
        let centre = target.faces.map_or(glam::DVec4::ZERO, |f| f.centre().homogeneous());
        let centre = centre.try_normalize().unwrap_or_default().as_vec4();
        let view = CullViewGpu {
            planes: target.frustum.planes.map(|p| p.to_array()),
            centre: centre.to_array(),
            item_count: items.count,
            near: target.near.into(),
            _pad0: 0,
            _pad1: 0,
        };
        let buckets: Vec<BucketGpu> = items
            .buckets
            .iter()
            .map(|b| {
                let culled = target.faces.and_then(|f| f.culls(b.class.sides)).map(|c| c.culled);
                BucketGpu { first_slot: b.first_slot, culled: WindingCode::of(culled) as u32 }
            })
            .collect();
        let view_buffer = pool.uniform(&gpu.queue, "gpu cull view", &view);
        let bucket_buffer =
            pool.storage(&gpu.queue, "gpu cull buckets", &buckets, wgpu::BufferUsages::empty());
        // Copied out by the tests, which read what the culler kept.
        let indirect =
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_SRC;
        let counts = pool.buffer(
            "gpu cull counts",
            CulledDraws::count_offset(items.buckets.len()),
            indirect | wgpu::BufferUsages::COPY_DST,
        );
        let draws = pool.buffer("gpu cull draws", CulledDraws::draw_offset(items.count), indirect);
        encoder.clear_buffer(&counts, 0, None);
        let group = pool.bind_group(
            "gpu cull",
            &self.layout,
            &[
                Binding::Buffer(items.buffer.clone()),
                Binding::Buffer(view_buffer),
                Binding::Buffer(bucket_buffer),
                Binding::Buffer(counts.clone()),
                Binding::Buffer(draws.clone()),
            ],
        );
        let pipeline = self.pipeline(&gpu.device);
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("gpu cull"), timestamp_writes });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(workgroups(items.count), 1, 1);
        drop(pass);
        CulledDraws { draws, counts }
    }
}

/// `gpu_cull.wgsl`, composed.
pub(crate) fn gpu_cull_wgsl() -> String {
    super::compose_wgsl(&[include_str!("gpu_cull.wgsl")])
}

#[cfg(test)]
mod tests {
    //! Equal maps (`render/tests/gpu/gpu_culling.rs`) would not notice a culler that kept
    //! everything: here the draws it keeps are read back and held to the CPU's.

    use glam::Vec3;
    use gnomon_math::culling::Frustum;
    use gnomon_scene::{builtin, settings::CullMode};

    use super::*;
    use crate::{
        Gpu, GpuScene,
        gpu_scene::{CullView, Granularity},
        passes::{Layouts, shadow::DepthTarget},
    };

    /// The triangles of the draws the GPU kept for `view`, read back.
    fn gpu_triangles(gpu: &Gpu, pool: &mut Pool, items: &ShadowItems, view: &CullView) -> u64 {
        let faces = match view.granularity {
            Granularity::Clusters { faces } => faces,
            Granularity::Instances => None,
        };
        let target = CullTarget { frustum: &view.frustum, near: view.near, faces };
        let mut pass = GpuCullPass::new(&gpu.device);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let culled = pass.record(gpu, pool, &mut encoder, items, &target, None);
        let read = wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST;
        let counts = pool.buffer("test counts", culled.counts.size(), read);
        let draws = pool.buffer("test draws", culled.draws.size(), read);
        encoder.copy_buffer_to_buffer(&culled.counts, 0, &counts, 0, None);
        encoder.copy_buffer_to_buffer(&culled.draws, 0, &draws, 0, None);
        gpu.queue.submit([encoder.finish()]);
        let counts: Vec<u32> = pollster::block_on(crate::readback::read_buffer(gpu, &counts)).unwrap();
        let draws: Vec<DrawArgs> = pollster::block_on(crate::readback::read_buffer(gpu, &draws)).unwrap();
        let mut triangles = 0;
        for (bucket, &count) in items.buckets.iter().zip(&counts) {
            assert!(count <= bucket.capacity, "{count} draws kept in a bucket of {}", bucket.capacity);
            let kept = &draws[bucket.first_slot as usize..(bucket.first_slot + count) as usize];
            triangles += kept.iter().map(|d| u64::from(d.index_count / 3 * d.instance_count)).sum::<u64>();
        }
        triangles
    }

    #[test]
    fn the_gpu_keeps_the_triangles_the_cpu_keeps() {
        let gpu = Gpu::new_headless().expect("a GPU adapter (install mesa-vulkan-drivers for lavapipe)");
        let scene = builtin::spheres();
        let uploaded = GpuScene::upload(&gpu, &scene, &Layouts::new(&gpu.device)).unwrap();
        let items = uploaded.shadow_items(&gpu).unwrap().expect("the device takes the items");
        let mut pool = Pool::new(&gpu.device);
        let look = |eye: Vec3, target: Vec3| gnomon_math::view_from_world_look_at(eye, target, Vec3::Z);
        let ortho =
            |half: f32| glam::camera::rh::proj::directx::orthographic(-half, half, -half, half, 0.1, 40.0);
        let views = [
            ("all of it, from above", ortho(20.0) * look(Vec3::new(0.0, 20.0, 0.0), Vec3::ZERO)),
            ("a corner", ortho(1.5) * look(Vec3::new(1.0, 20.0, 1.0), Vec3::new(1.0, 0.0, 1.0))),
            ("nothing", ortho(1.0) * look(Vec3::new(500.0, 20.0, 0.0), Vec3::new(500.0, 0.0, 0.0))),
        ];
        let total: u64 = scene.meshes.iter().map(|m| m.triangle_count() as u64).sum();
        for (name, clip_from_world) in views {
            for mode in [CullMode::None, CullMode::Back] {
                let view = CullView {
                    frustum: Frustum::from_clip_from_world(clip_from_world),
                    near: true,
                    casters_only: true,
                    granularity: Granularity::Clusters {
                        faces: LayerFaces::of(clip_from_world, DepthTarget::Projected, mode),
                    },
                };
                let cpu = uploaded.cull(&[view])[0].triangles();
                let on_gpu = gpu_triangles(&gpu, &mut pool, items, &view);
                println!("{name}, cull {mode:?}: CPU {cpu}, GPU {on_gpu} of {total} triangles");
                assert_eq!(on_gpu, cpu, "{name}, cull {mode:?}");
            }
        }
    }
}
