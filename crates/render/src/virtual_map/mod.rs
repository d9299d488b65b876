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
//! [`gnomon_math::virtual_map`]. The frame's use of them (`--partition virtual`) is
//! in `frame/virtual_pages.rs` and `frame/virtual_record.rs`; the lighting passes'
//! lookup in `virtual_visibility.wgsl` (see `docs/virtual-maps.md`).

pub(crate) mod draw;
pub(crate) mod edges;
mod probe;

pub use draw::{POOL_LAYER_ROWS, PoolSize, PoolTile, VirtualPages};
pub(crate) use edges::{EdgeFeedback, EdgeRequests, EdgeTarget};
pub use probe::VirtualProbe;

use bytemuck::{Pod, Zeroable};
use glam::Mat4;
pub use gnomon_math::virtual_map::{AreaSearch, ConeReach};
use gnomon_math::virtual_map::{Clipmap, MAX_LEVELS, MapProjection, PageKey};

use crate::{
    Frame, Gpu, RenderError,
    pool::{Binding, Pool, ViewKey},
};

/// Vectors of two levels' origins in [`PageRequestParams::origins`].
pub(crate) const ORIGIN_VECTORS: usize = (MAX_LEVELS as usize).div_ceil(2);

/// Where a virtual map's levels lie in the world, as every virtual-map pass reads it
/// (`MapSpace` in map_space.wgsl; [`gnomon_math::virtual_map::MapProjection`]).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct MapSpaceGpu {
    pub light_from_world: Mat4,
    pub near: f32,
    pub far: f32,
    /// The tangent of a spot's or each cube face's frustum's half-angle; 0 for a sun.
    pub tan_half_fov: f32,
    /// Its [`MapKindGpu`].
    pub kind: u32,
}

/// How a map space projects, as `MapSpace::kind` says it (`MAP_ORTHOGRAPHIC`,
/// `MAP_PERSPECTIVE` and `MAP_CUBE` in the generated constants).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub(crate) enum MapKindGpu {
    /// A sun's.
    Orthographic = 0,
    /// A spot's.
    Perspective = 1,
    /// A point light's cube faces, side by side.
    Cube = 2,
}

impl MapKindGpu {
    /// Every kind, for the generated constants.
    pub const ALL: [MapKindGpu; 3] = [MapKindGpu::Orthographic, MapKindGpu::Perspective, MapKindGpu::Cube];

    /// Its constant's name in WGSL.
    pub fn wgsl_name(self) -> &'static str {
        match self {
            MapKindGpu::Orthographic => "MAP_ORTHOGRAPHIC",
            MapKindGpu::Perspective => "MAP_PERSPECTIVE",
            MapKindGpu::Cube => "MAP_CUBE",
        }
    }

    fn of(projection: MapProjection) -> MapKindGpu {
        match projection {
            MapProjection::Orthographic => MapKindGpu::Orthographic,
            MapProjection::Perspective { .. } => MapKindGpu::Perspective,
            MapProjection::Cube => MapKindGpu::Cube,
        }
    }
}

impl MapSpaceGpu {
    /// `clipmap`'s map space.
    pub fn of(clipmap: &Clipmap) -> Self {
        MapSpaceGpu {
            light_from_world: clipmap.light_from_world,
            near: clipmap.near,
            far: clipmap.far,
            tan_half_fov: clipmap.tan_half_fov().unwrap_or(0.0),
            kind: MapKindGpu::of(clipmap.projection) as u32,
        }
    }
}

/// The request pass's uniform: see `page_requests.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct PageRequestParams {
    pub map: MapSpaceGpu,
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
    /// Levels finer than its footprint's that a pixel along a shadow edge may ask
    /// for (`edge_requests.wgsl`; the request pass itself reads no such thing).
    pub edge_levels: u32,
    /// Under a light with an area whose penumbrae rays refine: its size
    /// ([`AreaSearch::light_size`]); 0 asks for no search's pages.
    pub area_light_size: f32,
    /// The search's cap in texels ([`AreaSearch::cap_texels`]).
    pub area_cap_texels: f32,
    /// Under a technique that reads the light's cone in coarser levels (PCSS): the
    /// light's size ([`ConeReach::light_size`]); 0 asks for no cone's pages.
    pub cone_light_size: f32,
    /// [`ConeReach::level_cap_texels`].
    pub cone_level_cap_texels: f32,
    /// [`ConeReach::reach_cap_texels`].
    pub cone_reach_cap_texels: f32,
    pub _pad0: u32,
    pub _pad1: u32,
}

impl PageRequestParams {
    /// The parameters of requests from a `width`×`height` image's pixels of
    /// `reach` into `clipmap`, pages along edges down to `edge_levels` finer.
    pub fn new(clipmap: &Clipmap, reach: PixelReach, size: (u32, u32), edge_levels: u32) -> Self {
        PageRequestParams {
            map: MapSpaceGpu::of(clipmap),
            origins: packed_origins(clipmap),
            finest_texel: clipmap.finest_texel,
            footprint_per_depth: reach.footprint_per_depth,
            reach_texels: reach.reach_texels,
            levels: clipmap.shape.levels,
            pages_per_side: clipmap.shape.pages_per_side(),
            page_texels: clipmap.shape.page_size,
            width: size.0,
            height: size.1,
            edge_levels,
            area_light_size: reach.area_search.map_or(0.0, |a| a.light_size),
            area_cap_texels: reach.area_search.map_or(0.0, |a| a.cap_texels),
            cone_light_size: reach.cone.map_or(0.0, |c| c.light_size),
            cone_level_cap_texels: reach.cone.map_or(0.0, |c| c.level_cap_texels),
            cone_reach_cap_texels: reach.cone.map_or(0.0, |c| c.reach_cap_texels),
            _pad0: 0,
            _pad1: 0,
        }
    }
}

/// A virtual map as the sampling shaders read it (`VirtualMap` in
/// `page_lookup.wgsl`): the clipmap's levels and the pool's layout.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct VirtualMapGpu {
    pub map: MapSpaceGpu,
    /// Each level's first page, two levels to a vector.
    pub origins: [[i32; 4]; ORIGIN_VECTORS],
    pub finest_texel: f32,
    pub levels: u32,
    pub pages_per_side: u32,
    pub page_texels: u32,
    pub pool_pages_per_side: u32,
    /// A pixel's footprint in world units per unit of view depth (which level it
    /// reads: [`PixelReach::footprint_per_depth`]).
    pub footprint_per_depth: f32,
    /// Rows of tiles in each layer of the pool ([`PoolSize::rows_per_layer`]).
    pub pool_rows_per_layer: u32,
    /// Levels finer than its footprint's a pixel reads where their pages hold its
    /// whole footprint (`virtual_read_level` in virtual_visibility.wgsl).
    pub edge_levels: u32,
}

impl VirtualMapGpu {
    /// `clipmap`'s levels, sampled from a pool of `pool` by pixels whose footprint is
    /// `footprint_per_depth` per unit of view depth, down to `edge_levels` finer
    /// where their pages hold a pixel's footprint.
    pub fn new(clipmap: &Clipmap, pool: PoolSize, footprint_per_depth: f32, edge_levels: u32) -> Self {
        VirtualMapGpu {
            map: MapSpaceGpu::of(clipmap),
            origins: packed_origins(clipmap),
            finest_texel: clipmap.finest_texel,
            levels: clipmap.shape.levels,
            pages_per_side: clipmap.shape.pages_per_side(),
            page_texels: clipmap.shape.page_size,
            pool_pages_per_side: pool.pages_per_side,
            footprint_per_depth,
            pool_rows_per_layer: pool.rows_per_layer,
            edge_levels,
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
    /// Under a light with a size whose penumbrae rays refine, the search of the
    /// refinement's footprint test over the cone to its area (`virtual_area_unsure`,
    /// refine_virtual.wgsl), whose pages each pixel asks for too.
    pub area_search: Option<AreaSearch>,
    /// Under a technique that reads the light's cone in coarser levels (PCSS), that
    /// cone, whose pages each pixel asks for in every level it may read
    /// ([`gnomon_math::virtual_map::Clipmap::cone_requests`]).
    pub cone: Option<ConeReach>,
}

/// The page-request pipeline, and the pass that unprojects a camera depth prepass
/// into the surface it reads.
pub struct PageRequests {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    surface_layout: wgpu::BindGroupLayout,
    surface_pipeline: wgpu::ComputePipeline,
    /// Its buffers and bind groups, kept from one request to the next.
    pool: Pool,
}

/// The surface pass's uniform: see `surface_from_depth.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct SurfaceParams {
    pub world_from_clip: Mat4,
    pub view_z_from_world: glam::Vec4,
    pub width: u32,
    pub height: u32,
    pub _pad0: u32,
    pub _pad1: u32,
}

/// A camera's depth prepass, for [`PageRequests::request_from_depth`].
pub struct CameraDepth<'a> {
    /// Its depth, `Depth32Float`, 1 where nothing was seen.
    pub depth: &'a wgpu::Texture,
    /// The camera's projection.
    pub clip_from_world: Mat4,
    /// The camera's view.
    pub view_from_world: Mat4,
}

/// A compute entry of `binding` and type `ty`.
fn compute_entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::COMPUTE, ty, count: None }
}

/// A buffer binding of type `ty`.
fn buffer_binding(ty: wgpu::BufferBindingType) -> wgpu::BindingType {
    wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None }
}

/// A compute pipeline of one bind group `layout`, running `entry` of `wgsl`.
fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    wgsl: String,
    entry: &str,
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::ComputePipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(wgsl.into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts.iter().map(|&layout| Some(layout)).collect::<Vec<_>>(),
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

impl PageRequests {
    /// Builds the pipelines on `gpu`.
    pub fn new(gpu: &Gpu) -> Result<PageRequests, RenderError> {
        gpu.checked("building the page-request pass", || {
            let device = &gpu.device;
            let float_texture = wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            };
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("page requests"),
                entries: &[
                    compute_entry(0, float_texture),
                    compute_entry(1, buffer_binding(wgpu::BufferBindingType::Storage { read_only: false })),
                    compute_entry(2, buffer_binding(wgpu::BufferBindingType::Uniform)),
                ],
            });
            let surface_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("surface from depth"),
                entries: &[
                    compute_entry(
                        0,
                        wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Depth,
                            view_dimension: wgpu::TextureViewDimension::D2,
                            multisampled: false,
                        },
                    ),
                    compute_entry(
                        1,
                        wgpu::BindingType::StorageTexture {
                            access: wgpu::StorageTextureAccess::WriteOnly,
                            format: wgpu::TextureFormat::Rgba32Float,
                            view_dimension: wgpu::TextureViewDimension::D2,
                        },
                    ),
                    compute_entry(2, buffer_binding(wgpu::BufferBindingType::Uniform)),
                ],
            });
            PageRequests {
                pipeline: compute_pipeline(
                    device,
                    "page requests",
                    page_requests_wgsl(),
                    "request_pages",
                    &[&layout],
                ),
                surface_pipeline: compute_pipeline(
                    device,
                    "surface from depth",
                    surface_from_depth_wgsl(),
                    "surface_from_depth",
                    &[&surface_layout],
                ),
                layout,
                surface_layout,
                pool: Pool::new(device),
            }
        })
    }

    /// [`PageRequests::request`] for the surface a camera's depth prepass saw, each
    /// pixel unprojected into its world point and view depth on the GPU first.
    pub async fn request_from_depth(
        &mut self,
        gpu: &Gpu,
        camera: CameraDepth<'_>,
        clipmap: &Clipmap,
        reach: PixelReach,
    ) -> Result<Vec<PageKey>, RenderError> {
        self.pool.end_frame();
        let size = camera.depth.size();
        let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING;
        let surface = self.pool.texture("camera surface", size, wgpu::TextureFormat::Rgba32Float, usage);
        let params = SurfaceParams {
            // In f64: an f32 inverse of a perspective matrix bends rays by parts in 10⁵.
            world_from_clip: camera.clip_from_world.as_dmat4().inverse().as_mat4(),
            view_z_from_world: camera.view_from_world.row(2),
            width: size.width,
            height: size.height,
            _pad0: 0,
            _pad1: 0,
        };
        let uniform = self.pool.uniform(&gpu.queue, "surface parameters", &params);
        let depth = self.pool.view(camera.depth, ViewKey::default());
        let out = self.pool.view(&surface, ViewKey::default());
        let bindings = [Binding::View(depth), Binding::View(out), Binding::Buffer(uniform)];
        let group = self.pool.bind_group("surface from depth", &self.surface_layout, &bindings);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("surface from depth"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.surface_pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(size.width.div_ceil(8), size.height.div_ceil(8), 1);
        }
        gpu.queue.submit([encoder.finish()]);
        self.requests_of(gpu, &surface, clipmap, reach).await
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
        self.pool.end_frame();
        self.requests_of(gpu, surface, clipmap, reach).await
    }

    /// [`PageRequests::request`], in the pool's current frame.
    async fn requests_of(
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
        let words = page_words(clipmap);
        let device = &gpu.device;
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let bits = self.pool.buffer("page request bits", 4 * words, usage);
        let readback_usage = wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ;
        let readback = self.pool.buffer("page request readback", 4 * words, readback_usage);
        let params = PageRequestParams::new(clipmap, reach, (surface.width(), surface.height()), 0);
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

/// Words of one bit per page of every level of `clipmap` (the request pass's layout).
fn page_words(clipmap: &Clipmap) -> u64 {
    let side = u64::from(clipmap.shape.pages_per_side());
    (u64::from(clipmap.shape.levels) * side * side).div_ceil(32)
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

/// `lookup_probe.wgsl` (with `page_lookup.wgsl`), composed, with the shadow
/// resources in group 0 from binding 0.
pub(crate) fn lookup_probe_wgsl() -> String {
    let place = crate::passes::BindingPlace { group: 0, binding: 0 };
    let bindings = crate::techniques::shadow_bindings_wgsl(place);
    crate::passes::compose_wgsl(&[&bindings, include_str!("lookup_probe.wgsl")])
}

/// `surface_from_depth.wgsl`, composed.
pub(crate) fn surface_from_depth_wgsl() -> String {
    crate::passes::compose_wgsl(&[include_str!("surface_from_depth.wgsl")])
}

/// `page_requests.wgsl`, composed.
pub(crate) fn page_requests_wgsl() -> String {
    crate::passes::compose_wgsl(&[include_str!("page_requests.wgsl")])
}
