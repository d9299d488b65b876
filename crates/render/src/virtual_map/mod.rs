//! Virtual shadow maps on the GPU (issue 53), the parts built so far:
//! - the page requests: a compute pass reads the prepass's surface (each pixel's
//!   world point and view depth) and marks, one bit per page, the pages of the
//!   clipmap level matching each pixel's footprint that its filter may read
//!   (`page_requests.wgsl`);
//! - the pool of page tiles that draws only the pages new or dirty this frame
//!   ([`VirtualPages`], `draw.rs`);
//! - sampling through the page table (`page_lookup.wgsl`; [`VirtualPages::visibility`]
//!   in `probe.rs`).
//!
//! The clipmap's geometry and the page pool's bookkeeping are CPU-side, in
//! [`gnomon_math::virtual_map`]. Not yet built: culling casters per page, the
//! lighting passes' sampling through the page table, and `--partition virtual` (see
//! `docs/virtual-maps.md`).

pub(crate) mod draw;
mod probe;

pub use draw::{PoolSize, VirtualPages};
pub use probe::VirtualProbe;

use bytemuck::{Pod, Zeroable};
use glam::Mat4;
use gnomon_math::virtual_map::{Clipmap, MAX_LEVELS, PageKey};

use crate::{
    Frame, Gpu, RenderError,
    pool::{Binding, Pool, ViewKey},
};

/// Vectors of two levels' origins in [`PageRequestParams::origins`].
pub(crate) const ORIGIN_VECTORS: usize = (MAX_LEVELS as usize).div_ceil(2);

/// The request pass's uniform: see `page_requests.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct PageRequestParams {
    pub light_from_world: Mat4,
    /// Each level's first page, two levels to a vector.
    pub origins: [[i32; 4]; ORIGIN_VECTORS],
    pub finest_texel: f32,
    pub footprint_per_depth: f32,
    pub reach_texels: f32,
    pub levels: u32,
    pub pages_per_side: u32,
    pub page_texels: u32,
    pub width: u32,
    pub height: u32,
}

/// A virtual map as the sampling shaders read it (`VirtualMap` in
/// `page_lookup.wgsl`): the clipmap's levels and the pool's layout.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct VirtualMapGpu {
    pub light_from_world: Mat4,
    /// Each level's first page, two levels to a vector.
    pub origins: [[i32; 4]; ORIGIN_VECTORS],
    pub finest_texel: f32,
    pub near: f32,
    pub far: f32,
    pub levels: u32,
    pub pages_per_side: u32,
    pub page_texels: u32,
    pub pool_pages_per_side: u32,
    pub _pad0: u32,
}

impl VirtualMapGpu {
    /// `clipmap`'s levels, sampled from a pool of `pool_pages_per_side`² tiles.
    pub fn new(clipmap: &Clipmap, pool_pages_per_side: u32) -> Self {
        VirtualMapGpu {
            light_from_world: clipmap.light_from_world,
            origins: packed_origins(clipmap),
            finest_texel: clipmap.finest_texel,
            near: clipmap.near,
            far: clipmap.far,
            levels: clipmap.shape.levels,
            pages_per_side: clipmap.shape.pages_per_side(),
            page_texels: clipmap.shape.page_size,
            pool_pages_per_side,
            _pad0: 0,
        }
    }
}

/// Each level's first page, two levels to a vector (level 2k in xy, 2k + 1 in zw).
fn packed_origins(clipmap: &Clipmap) -> [[i32; 4]; ORIGIN_VECTORS] {
    let mut origins = [[0i32; 4]; ORIGIN_VECTORS];
    for (level, origin) in clipmap.origins.iter().enumerate().take(MAX_LEVELS as usize) {
        let pair = &mut origins[level / 2];
        pair[2 * (level % 2)] = origin.x;
        pair[2 * (level % 2) + 1] = origin.y;
    }
    origins
}

/// What a pixel's footprint and filter are, for the pages it asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelReach {
    /// A pixel's footprint in world units per unit of view depth: `2 tan(fov / 2) /
    /// height` for a perspective camera.
    pub footprint_per_depth: f32,
    /// Texels of its level that the pixel's filter reaches from its point: the
    /// kernel's radius, the normal offset's and a texel for bilinear taps.
    pub reach_texels: f32,
}

/// The page-request pipeline.
pub struct PageRequests {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    /// Its buffers and bind groups, kept from one request to the next.
    pool: Pool,
}

impl PageRequests {
    /// Builds the pipeline on `gpu`.
    pub fn new(gpu: &Gpu) -> Result<PageRequests, RenderError> {
        gpu.checked("building the page-request pass", || {
            let device = &gpu.device;
            let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
                binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty,
                count: None,
            };
            let buffer =
                |ty| wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None };
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("page requests"),
                entries: &[
                    entry(
                        0,
                        wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: false },
                            view_dimension: wgpu::TextureViewDimension::D2,
                            multisampled: false,
                        },
                    ),
                    entry(1, buffer(wgpu::BufferBindingType::Storage { read_only: false })),
                    entry(2, buffer(wgpu::BufferBindingType::Uniform)),
                ],
            });
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("page_requests.wgsl"),
                source: wgpu::ShaderSource::Wgsl(page_requests_wgsl().into()),
            });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("page requests"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("page requests"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some("request_pages"),
                compilation_options: Default::default(),
                cache: None,
            });
            PageRequests { layout, pipeline, pool: Pool::new(device) }
        })
    }

    /// The pages the pixels of `surface` (an `Rgba32Float` texture: world point in
    /// xyz, view depth in w, 0 where no surface is seen) ask for, each once, in
    /// [`PageKey`] order. Submits the pass and waits for it.
    pub async fn request(
        &mut self,
        gpu: &Gpu,
        surface: &wgpu::Texture,
        clipmap: &Clipmap,
        reach: PixelReach,
    ) -> Result<Vec<PageKey>, RenderError> {
        let shape = clipmap.shape;
        if shape.levels == 0 || shape.levels > MAX_LEVELS || clipmap.origins.len() != shape.levels as usize {
            return Err(RenderError::Gpu {
                during: "requesting virtual pages",
                message: format!("a clipmap of {} levels: give 1 to {MAX_LEVELS}", shape.levels),
            });
        }
        let side = shape.pages_per_side();
        let words = (shape.levels as u64 * u64::from(side) * u64::from(side)).div_ceil(32);
        let device = &gpu.device;
        self.pool.end_frame();
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let bits = self.pool.buffer("page request bits", 4 * words, usage);
        let readback_usage = wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ;
        let readback = self.pool.buffer("page request readback", 4 * words, readback_usage);
        let params = PageRequestParams {
            light_from_world: clipmap.light_from_world,
            origins: packed_origins(clipmap),
            finest_texel: clipmap.finest_texel,
            footprint_per_depth: reach.footprint_per_depth,
            reach_texels: reach.reach_texels,
            levels: shape.levels,
            pages_per_side: side,
            page_texels: shape.page_size,
            width: surface.width(),
            height: surface.height(),
        };
        let uniform = self.pool.uniform(&gpu.queue, "page request parameters", &params);
        let view = self.pool.view(surface, ViewKey::default());
        let bindings = [Binding::View(view), Binding::Buffer(bits.clone()), Binding::Buffer(uniform)];
        let group = self.pool.bind_group("page requests", &self.layout, &bindings);
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&bits, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("page requests"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(surface.width().div_ceil(8), surface.height().div_ceil(8), 1);
        }
        encoder.copy_buffer_to_buffer(&bits, 0, &readback, 0, 4 * words);
        gpu.queue.submit([encoder.finish()]);
        let words: Vec<u32> = crate::readback::read_buffer(gpu, &readback).await?;
        Ok(decode(&words, clipmap))
    }
}

impl PageRequests {
    /// [`PageRequests::request`] for the surfaces a rendered `frame` saw: its world
    /// positions and view depths (background pixels ask for nothing).
    pub async fn request_for_frame(
        &mut self,
        gpu: &Gpu,
        frame: &Frame,
        clipmap: &Clipmap,
        reach: PixelReach,
    ) -> Result<Vec<PageKey>, RenderError> {
        let texels: Vec<[f32; 4]> = frame
            .position
            .iter()
            .zip(&frame.depth)
            .map(|(p, &d)| if d.is_finite() && p.is_finite() { [p.x, p.y, p.z, d] } else { [0.0; 4] })
            .collect();
        let size = wgpu::Extent3d { width: frame.width, height: frame.height, depth_or_array_layers: 1 };
        let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
        let surface = self.pool.texture(
            "frame surface for page requests",
            size,
            wgpu::TextureFormat::Rgba32Float,
            usage,
        );
        let layout = wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(16 * frame.width),
            rows_per_image: Some(frame.height),
        };
        gpu.queue.write_texture(surface.as_image_copy(), bytemuck::cast_slice(&texels), layout, size);
        self.request(gpu, &surface, clipmap, reach).await
    }
}

/// The pages whose bits are set in `words` (the request pass's layout), in
/// [`PageKey`] order.
fn decode(words: &[u32], clipmap: &Clipmap) -> Vec<PageKey> {
    let side = clipmap.shape.pages_per_side() as usize;
    let per_level = side * side;
    let mut pages = Vec::new();
    for (w, &word) in words.iter().enumerate() {
        let mut rest = word;
        while rest != 0 {
            let bit = 32 * w + rest.trailing_zeros() as usize;
            rest &= rest - 1;
            let level = bit / per_level;
            let Some(origin) = clipmap.origins.get(level) else { continue };
            let (row, column) = ((bit % per_level) / side, bit % side);
            pages.push(PageKey {
                level: level as u32,
                x: origin.x + column as i32,
                y: origin.y + row as i32,
            });
        }
    }
    pages.sort_unstable();
    pages
}

/// `lookup_probe.wgsl` (with `page_lookup.wgsl`), composed.
pub(crate) fn lookup_probe_wgsl() -> String {
    crate::passes::compose_wgsl(&[include_str!("lookup_probe.wgsl")])
}

/// `page_requests.wgsl`, composed.
pub(crate) fn page_requests_wgsl() -> String {
    crate::passes::compose_wgsl(&[include_str!("page_requests.wgsl")])
}
