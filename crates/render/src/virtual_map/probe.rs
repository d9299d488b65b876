//! Sampling a virtual map at given world points, through its page table, with the
//! shaders' own lookup (`page_lookup.wgsl`, `lookup_probe.wgsl`): a 2×2
//! percentage-closer filter at a chosen level. What the tests hold the lookup to, and
//! a way for a host to ask what the map says at a point.

use bytemuck::{Pod, Zeroable};
use gnomon_math::virtual_map::Clipmap;

use super::{VirtualMapGpu, VirtualPages};
use crate::{
    Gpu, RenderError,
    pool::{Binding, ViewKey},
};

/// A world point to sample a virtual map at, and the level to read there.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct VirtualProbe {
    /// The receiver, in world space.
    pub world: [f32; 3],
    /// The clipmap level its filter reads (its pixel's, `Clipmap::level_for_footprint`).
    pub level: u32,
}

/// The probe's pipeline and the sampler its lookup gathers with, built on a pool's
/// first probe ([`VirtualPages::visibility`]).
#[derive(Clone)]
pub(crate) struct ProbePass {
    pipeline: wgpu::ComputePipeline,
    /// The lookup gathers a 2×2 within one page (`virtual_tile_gather`).
    gather: wgpu::Sampler,
}

impl ProbePass {
    fn new(gpu: &Gpu) -> Result<ProbePass, RenderError> {
        let device = &gpu.device;
        gpu.checked("building the virtual map's lookup probe", || {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("lookup_probe.wgsl"),
                source: wgpu::ShaderSource::Wgsl(super::lookup_probe_wgsl().into()),
            });
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("virtual lookup probe"),
                layout: None,
                module: &module,
                entry_point: Some("probe_virtual_map"),
                compilation_options: Default::default(),
                cache: None,
            });
            let gather = device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("virtual probe gather"),
                ..Default::default()
            });
            ProbePass { pipeline, gather }
        })
    }
}

impl VirtualPages {
    /// The probe's pass, built on the first call.
    fn probe_pass(&mut self, gpu: &Gpu) -> Result<&ProbePass, RenderError> {
        if self.probe.is_none() {
            self.probe = Some(ProbePass::new(gpu)?);
        }
        Ok(self.probe.as_ref().expect("built above"))
    }

    /// The fraction of a 2×2 bilinear footprint that sees the light at each probe,
    /// read through the page table of `clipmap` as the pool now stands: a tap whose
    /// page is not resident reads the coarser page standing in for it, and a tap
    /// under no page reads the far plane (lit). Submits and waits.
    pub async fn visibility(
        &mut self,
        gpu: &Gpu,
        clipmap: &Clipmap,
        probes: &[VirtualProbe],
    ) -> Result<Vec<f32>, RenderError> {
        if probes.is_empty() {
            return Ok(Vec::new());
        }
        let device = &gpu.device;
        let words: Vec<u32> = self.page_table(clipmap).iter().map(|e| e.0).collect();
        let uniform = VirtualMapGpu::new(clipmap, self.size(), 0.0, 0);
        let bytes = 4 * probes.len() as u64;
        let ProbePass { pipeline, gather } = self.probe_pass(gpu)?.clone();
        let texture = self.texture().clone();
        let pool = self.frame_pool();
        let uniform = pool.uniform(&gpu.queue, "virtual map", &uniform);
        let table = pool.storage(&gpu.queue, "page table", &words, wgpu::BufferUsages::empty());
        let probes_buffer = pool.storage(&gpu.queue, "probes", probes, wgpu::BufferUsages::empty());
        let out = pool.buffer(
            "probe visibility",
            bytes,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        );
        let read =
            pool.buffer("probe readback", bytes, wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ);
        let view = pool.view(&texture, ViewKey::whole(wgpu::TextureViewDimension::D2Array));
        // The places `lookup_probe.wgsl` declares: the shadow resources' from 0.
        let bindings = vec![
            (0, Binding::View(view)),
            (6, Binding::Sampler(gather)),
            (7, Binding::Buffer(uniform)),
            (8, Binding::Buffer(table)),
            (10, Binding::Buffer(probes_buffer)),
            (11, Binding::Buffer(out.clone())),
        ];
        let layout = pipeline.get_bind_group_layout(0);
        let group = pool.bind_group_numbered("virtual lookup probe", &layout, bindings);
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups((probes.len() as u32).div_ceil(64), 1, 1);
        }
        encoder.copy_buffer_to_buffer(&out, 0, &read, 0, bytes);
        gpu.queue.submit([encoder.finish()]);
        crate::readback::read_buffer(gpu, &read).await
    }
}
