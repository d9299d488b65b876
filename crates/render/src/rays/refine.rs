//! Ray-traced refinement of the shadow mask (hybrid ray-traced shadows, after Story's
//! HFTS): each light's mask pass stores the map's answer and lists the pixels it is
//! unsure of (`refine_classify.wgsl`); then a compute pass, dispatched indirectly
//! over that list alone, casts their rays and darkens those a caster blocks
//! (`refine_trace.wgsl`). Only listed pixels pay for a ray, and a group of the trace
//! pass holds listed pixels only, so no lane waits on a neighbour's ray.

use crate::passes::wgsl_interfaces::{
    AREA_VISIBILITY, DEFER_TO_RAY, FOOTPRINT_RECEIVER, FOOTPRINT_TOUCHED, MAP_UNSURE, RAY_DECIDES,
};
use gnomon_scene::settings::Refine;

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};

use super::Traversal;
use crate::{
    passes::{self, Layouts, compose_wgsl, lighting::MapLookup},
    pool::{Binding, Pool},
};

/// Pixels per workgroup of the trace pass, and per workgroup the mask pass counts.
pub(crate) const GROUP_SIZE: u32 = 64;
/// The most workgroups the trace pass dispatches: the least
/// `max_compute_workgroups_per_dimension` WebGPU allows a device, so every device
/// accepts the dispatch. Listed pixels past them are looped over.
pub(crate) const MAX_GROUPS: u32 = 65_535;
/// Bytes from one light's counters to the next: the largest
/// `min_storage_buffer_offset_alignment` WebGPU allows, so every device accepts the
/// dynamic offset.
pub(crate) const COUNTER_STRIDE: u64 = 256;
/// One light's counters, as the mask pass counts them (`RefineCounters` in
/// refine_append.wgsl, atomics) and the trace, fill and edge passes read them
/// (`ListedPixels` in refine_list.wgsl, its dispatch counts as `vec3<u32>`): the three
/// workgroup counts of the trace pass's indirect dispatch, then the pixels listed;
/// the same for the pixels listed to be filled; then the unsure pixels their penumbra
/// history answered. 48 bytes, as `ListedPixels`' 16-byte alignment rounds it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub(crate) struct RefineCountersGpu {
    pub groups_x: u32,
    pub groups_y: u32,
    pub groups_z: u32,
    pub count: u32,
    pub fill_groups_x: u32,
    pub fill_groups_y: u32,
    pub fill_groups_z: u32,
    pub fill_count: u32,
    pub kept_count: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// Bytes of one light's counters ([`RefineCountersGpu`]).
const COUNTER_BYTES: u64 = std::mem::size_of::<RefineCountersGpu>() as u64;
/// Bytes from a light's counters to those of its fill pass (its indirect dispatch).
const FILL_COUNTERS: u64 = std::mem::offset_of!(RefineCountersGpu, fill_groups_x) as u64;
/// Texels of the ring around a lookup's bilinear 2×2 that the footprint test reads
/// (`refine_footprint.wgsl`): a virtual map's pixels ask for the pages it reaches.
pub(crate) const UNSURE_RING_TEXELS: i32 = 2;
/// One listed pixel (`UnsurePixel` in refine_list.wgsl), which only the GPU writes
/// and reads: its position, its map layer (and penumbra width), and the mean and
/// count of the beams its penumbra history holds. Rust sizes the list by it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct UnsurePixelGpu {
    /// x | y << 16.
    pub pixel: u32,
    pub layer: u32,
    pub mean: f32,
    pub beams: f32,
}

/// Bytes of one listed pixel ([`UnsurePixelGpu`]).
pub(crate) const PIXEL_BYTES: u64 = std::mem::size_of::<UnsurePixelGpu>() as u64;

/// The constants the list (`refine_list.wgsl` and the passes that import it) shares
/// with Rust.
pub(crate) fn list_wgsl() -> String {
    format!("const REFINE_GROUP_SIZE: u32 = {GROUP_SIZE}u;\nconst REFINE_MAX_GROUPS: u32 = {MAX_GROUPS}u;\n")
}

/// The WGSL of `ray_decides` and `defer_to_ray`, which the shadow-mask pass calls
/// with each pixel's map answer: never, when `refine` is off; otherwise the
/// classification ([`classify_wgsl`]) and the list it appends to.
pub(crate) fn mask_refine_wgsl(refine: Refine, lookup: MapLookup, size: LightSize) -> Vec<String> {
    let classified = classifies_penumbrae(refine, lookup, size).then(|| {
        // The lookup classified the pixel already (`penumbra_map_lookup`): what it
        // left unsure it said by its visibility.
        vec![
            "const REFINE_EVERY_PIXEL: bool = false;\nconst REFINE_PENUMBRAE: bool = true;\n".to_owned(),
            include_str!("refine_classify.wgsl").to_owned(),
            RAY_DECIDES.bind("classified_ray_decides"),
            MAP_UNSURE.bind("classified_map_unsure"),
        ]
    });
    let Some(mut parts) = classified.or_else(|| classify_wgsl(refine, lookup, size)) else {
        return vec![
            include_str!("refine_off.wgsl").to_owned(),
            RAY_DECIDES.bind("unrefined_ray_decides"),
            DEFER_TO_RAY.bind("unrefined_defer_to_ray"),
        ];
    };
    parts.push(list_wgsl());
    parts.push(include_str!("refine_append.wgsl").to_owned());
    parts.push(DEFER_TO_RAY.bind("listed_defer_to_ray"));
    parts
}

/// Whether a light has an area whose penumbrae its rays trace: what its
/// classification looks for, built into its shaders. (A uniform can say it too, but
/// on lavapipe a branch on a uniform still runs both sides: the area's 6 × 6 search,
/// left in the mask pass of a hard sun, cost Florence's frame 15–35 ms.)
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum LightSize {
    /// A sun without angular diameter, a spot or point light without radius.
    Hard,
    /// A light with an area: its refined pixels trace its penumbrae.
    Area,
}

impl LightSize {
    pub fn of(light: &gnomon_scene::Light) -> Self {
        if light.is_hard() { LightSize::Hard } else { LightSize::Area }
    }
}

/// Whether the mask pass of a light of `size` refined by `refine` and looked up by
/// `lookup` classifies its penumbrae by the map's min-max pyramid
/// (`penumbra_classify.wgsl`): a light with an area whose rays run where the map is
/// unsure, on a 2D map or a point light's cube. Its lookup is then the
/// classification alone, lit, umbra or unsure, and no technique's estimate.
pub(crate) fn classifies_penumbrae(refine: Refine, lookup: MapLookup, size: LightSize) -> bool {
    let traced = match refine {
        Refine::Auto | Refine::Rays => true,
        Refine::Off | Refine::EveryPixel => false,
    };
    let pyramid = match lookup {
        MapLookup::Map | MapLookup::Cube => true,
        MapLookup::Paraboloid | MapLookup::Virtual => false,
    };
    traced && pyramid && size == LightSize::Area
}

/// The WGSL of `ray_decides`, which says whether a ray decides a pixel: the
/// classification (refine_classify.wgsl) with the footprint test of the light's kind
/// of map, and for a light with an area its penumbrae's. `None` when `refine` is off.
pub(crate) fn classify_wgsl(refine: Refine, lookup: MapLookup, size: LightSize) -> Option<Vec<String>> {
    let every_pixel = match refine {
        Refine::Off => return None,
        // The frame's plan resolves `auto` to `rays` (`super::light_refine`).
        Refine::Auto | Refine::Rays => false,
        Refine::EveryPixel => true,
    };
    let footprint = match lookup {
        MapLookup::Map => vec![
            include_str!("refine_footprint.wgsl").to_owned(),
            include_str!("refine_map.wgsl").to_owned(),
            FOOTPRINT_RECEIVER.bind("projected_footprint_receiver"),
            FOOTPRINT_TOUCHED.bind("projected_footprint_touched"),
            MAP_UNSURE.bind("projected_map_unsure"),
        ],
        MapLookup::Cube => vec![
            include_str!("refine_footprint.wgsl").to_owned(),
            include_str!("refine_cube.wgsl").to_owned(),
            FOOTPRINT_RECEIVER.bind("cube_footprint_receiver"),
            FOOTPRINT_TOUCHED.bind("untouched_footprint"),
            MAP_UNSURE.bind("cube_map_unsure"),
        ],
        MapLookup::Paraboloid => {
            vec![include_str!("refine_omni.wgsl").to_owned(), MAP_UNSURE.bind("paraboloid_map_unsure")]
        }
        MapLookup::Virtual => vec![
            include_str!("refine_footprint.wgsl").to_owned(),
            include_str!("refine_virtual.wgsl").to_owned(),
            // refine_footprint.wgsl's own test, which a virtual map does not call, reads
            // a 2D map's plane.
            include_str!("refine_map.wgsl").to_owned(),
            FOOTPRINT_RECEIVER.bind("projected_footprint_receiver"),
            FOOTPRINT_TOUCHED.bind("untouched_footprint"),
            MAP_UNSURE.bind("virtual_map_unsure"),
        ],
    };
    let penumbrae = size == LightSize::Area;
    let mut parts = vec![
        format!(
            "const REFINE_EVERY_PIXEL: bool = {every_pixel};\nconst REFINE_PENUMBRAE: bool = {penumbrae};\n"
        ),
        include_str!("refine_classify.wgsl").to_owned(),
        RAY_DECIDES.bind("classified_ray_decides"),
    ];
    parts.extend(footprint);
    Some(parts)
}

/// The shadow rays from surface points (surface_rays.wgsl) with what they need: the
/// tracer of `traversal`, its bindings in `group`, and the light's samples.
pub(crate) fn surface_rays_wgsl(group: u32, traversal: Traversal) -> Vec<String> {
    let mut parts = vec![
        super::trace_wgsl(group, traversal),
        include_str!("light_sample.wgsl").to_owned(),
        include_str!("surface_rays.wgsl").to_owned(),
    ];
    match traversal {
        Traversal::Shader => {
            parts.push(include_str!("penumbra_beam.wgsl").to_owned());
            parts.push(AREA_VISIBILITY.bind("beam_area_visibility"));
        }
        Traversal::RayQuery => parts.push(AREA_VISIBILITY.bind("ray_area_visibility")),
    }
    parts
}

/// The trace pass's WGSL for `traversal` and a light of `size`, composed.
pub(crate) fn trace_pass_wgsl(traversal: Traversal, size: LightSize) -> String {
    let penumbrae = size == LightSize::Area;
    let mut parts = passes::lighting::camera_shading_wgsl();
    parts.push(format!("const REFINE_PENUMBRAE: bool = {penumbrae};"));
    parts.push(passes::OCTAHEDRON_WGSL.to_owned());
    parts.push(passes::SCREEN_COMMON_WGSL.to_owned());
    parts.push(list_wgsl());
    parts.extend(surface_rays_wgsl(super::GROUP, traversal));
    parts.push(include_str!("refine_trace.wgsl").to_owned());
    let refs: Vec<&str> = parts.iter().map(String::as_str).collect();
    compose_wgsl(&refs)
}

/// Who uses a group 1 of [`screen_layout`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ListAccess {
    /// The refining mask pass, which appends to the list and counts.
    Append,
    /// The trace pass, which reads them (writing only each entry's penumbra width),
    /// and dispatches by the counters: they must be read-only there.
    Read,
}

/// Group 1 of a refining mask pass (`Append`) or of the trace pass (`Read`): the
/// camera and the prepass (bindings 0–2, as `Layouts::screen`), the list (3) and the
/// light's counters (4, at a dynamic offset of [`COUNTER_STRIDE`] per light).
pub(crate) fn screen_layout(device: &wgpu::Device, access: ListAccess) -> wgpu::BindGroupLayout {
    let (stages, read_only, label) = match access {
        ListAccess::Append => (wgpu::ShaderStages::FRAGMENT, false, "screen, listing unsure pixels"),
        ListAccess::Read => (wgpu::ShaderStages::COMPUTE, true, "screen, tracing unsure pixels"),
    };
    let entry = |binding, ty| wgpu::BindGroupLayoutEntry { binding, visibility: stages, ty, count: None };
    let texture = wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: false },
        view_dimension: wgpu::TextureViewDimension::D2,
        multisampled: false,
    };
    let buffer =
        |ty, has_dynamic_offset| wgpu::BindingType::Buffer { ty, has_dynamic_offset, min_binding_size: None };
    // The trace pass writes each listed pixel's penumbra width into its entry
    // (refine_list.wgsl); the counters stay read-only there, as the dispatch's
    // arguments.
    let list = wgpu::BufferBindingType::Storage { read_only: false };
    let counters = wgpu::BufferBindingType::Storage { read_only };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            entry(0, buffer(wgpu::BufferBindingType::Uniform, false)),
            entry(1, texture),
            entry(2, texture),
            entry(3, buffer(list, false)),
            entry(4, buffer(counters, true)),
        ],
    })
}

/// Group 2 of the trace and fill passes: the light's layer of the mask, written (0),
/// a copy of it as the trace pass left it, read by the fill pass (1), and the light's
/// penumbra history as this frame leaves it, written (2).
pub(crate) fn refined_mask_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    };
    let written = |format| wgpu::BindingType::StorageTexture {
        access: wgpu::StorageTextureAccess::WriteOnly,
        format,
        view_dimension: wgpu::TextureViewDimension::D2,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("refined shadow mask"),
        entries: &[
            entry(0, written(passes::screen_space::MASK_FORMAT)),
            entry(
                1,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
            ),
            entry(2, written(HISTORY_FORMAT)),
        ],
    })
}

/// The format of a light's penumbra history (penumbra_mask.wgsl): per pixel, its
/// value and the beams behind it.
pub(crate) const HISTORY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Float;

/// Group 3 of the mask pass of a light whose penumbrae it classifies: its penumbra
/// history as the last frame left it, read (0), and as this frame leaves it, written
/// (1).
pub(crate) fn history_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let fragment = wgpu::ShaderStages::FRAGMENT;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("penumbra history"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: fragment,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: fragment,
                ty: wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: HISTORY_FORMAT,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
                count: None,
            },
        ],
    })
}

/// The trace passes of each traversal and light size, built on first use.
#[derive(Default)]
pub(crate) struct TracePasses {
    passes: HashMap<(Traversal, LightSize), TracePass>,
}

impl TracePasses {
    /// The passes of `traversal` (which the device must run) for a light of `size`.
    pub fn get(
        &mut self,
        device: &wgpu::Device,
        layouts: &Layouts,
        traversal: Traversal,
        size: LightSize,
    ) -> &TracePass {
        self.passes
            .entry((traversal, size))
            .or_insert_with(|| TracePass::new(device, layouts, traversal, size))
    }
}

/// The trace pass's pipeline, and the penumbra fill's that follows it under a light
/// with an area (`cs_fill_penumbra` in refine_trace.wgsl).
pub(crate) struct TracePass {
    trace: wgpu::ComputePipeline,
    fill: wgpu::ComputePipeline,
}

impl TracePass {
    fn new(device: &wgpu::Device, layouts: &Layouts, traversal: Traversal, size: LightSize) -> Self {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow mask ray trace"),
            bind_group_layouts: &[
                Some(&layouts.scene),
                Some(&layouts.trace_screen),
                Some(&layouts.refined_mask),
                Some(layouts.rays.get(traversal)),
            ],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("shadow mask ray trace"),
            source: wgpu::ShaderSource::Wgsl(trace_pass_wgsl(traversal, size).into()),
        });
        let pipeline = |entry_point: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry_point),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(entry_point),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        Self { trace: pipeline("cs_trace"), fill: pipeline("cs_fill_penumbra") }
    }

    /// Records `stage` of light `light` over its listed pixels.
    pub fn record(&self, pass: &mut wgpu::ComputePass, stage: TraceStage, groups: &TraceGroups, light: u32) {
        let (pipeline, arguments) = match stage {
            TraceStage::Trace => (&self.trace, 0),
            TraceStage::PenumbraFill => (&self.fill, FILL_COUNTERS),
        };
        let counters = RefineLists::counter_offset(light);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, groups.scene, &[]);
        pass.set_bind_group(1, groups.screen, &[counters]);
        pass.set_bind_group(2, groups.mask, &[]);
        pass.set_bind_group(super::GROUP, groups.bvh, &[]);
        pass.dispatch_workgroups_indirect(groups.counters, u64::from(counters) + arguments);
    }
}

/// The two compute passes over a light's list of pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TraceStage {
    /// The listed pixels' rays, written into the light's layer of the mask
    /// (`groups.mask`).
    Trace,
    /// After the trace and a copy of the light's layer of the mask into the group's
    /// `traced_mask`, under a light with an area: each unsure pixel no beam answered
    /// takes the mean of its answered neighbours.
    PenumbraFill,
}

impl TraceStage {
    /// The pass's label.
    pub fn label(self) -> &'static str {
        match self {
            TraceStage::Trace => "shadow mask ray trace",
            TraceStage::PenumbraFill => "penumbra fill",
        }
    }
}

/// The groups one light's trace pass binds.
pub(crate) struct TraceGroups<'a> {
    /// The instances and the light's uniform.
    pub scene: &'a wgpu::BindGroup,
    /// The camera, the prepass, the list (whose entries the trace pass completes
    /// with their penumbra width) and the counters, read only ([`RefineLists::group`]
    /// with [`ListAccess::Read`]).
    pub screen: &'a wgpu::BindGroup,
    /// The light's layer of the mask, written, and the copy the filter reads
    /// ([`RefineLists::mask_group`]).
    pub mask: &'a wgpu::BindGroup,
    /// The tracer's resources, for `traversal`.
    pub bvh: &'a wgpu::BindGroup,
    /// How the rays traverse the casters, and whether they trace penumbrae: which
    /// trace pipeline runs.
    pub traversal: Traversal,
    pub size: LightSize,
    /// The counters, whose first three words at the light's offset are the dispatch.
    pub counters: &'a wgpu::Buffer,
}

/// What a light's counters say of its pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Listed {
    /// Traced this frame: a ray (or a penumbra beam) each.
    pub traced: u32,
    /// Decided by rays, this frame or before: the traced, the filled and those their
    /// penumbra history answered.
    pub unsure: u32,
}

/// A frame's list of unsure pixels (room for every pixel of the screen, reused by
/// each light in turn) and each light's counters.
pub(crate) struct RefineLists {
    pub pixels: wgpu::Buffer,
    pub counters: wgpu::Buffer,
}

impl RefineLists {
    /// Bytes of the list for a `width` × `height` screen: a pixel lists itself at most
    /// once per light.
    pub fn list_bytes(width: u32, height: u32) -> u64 {
        u64::from(width) * u64::from(height) * PIXEL_BYTES
    }

    /// The lists of a frame of `lights` lights on a `width` × `height` screen, from
    /// `pool`. The counters must be cleared before the first mask pass.
    pub fn new(pool: &mut Pool, width: u32, height: u32, lights: usize) -> Self {
        let pixels =
            pool.buffer("unsure pixels", Self::list_bytes(width, height), wgpu::BufferUsages::STORAGE);
        Self { pixels, counters: Self::counters(pool, lights) }
    }

    /// The counters of `lights` lights, [`COUNTER_STRIDE`] apart, from `pool`.
    pub fn counters(pool: &mut Pool, lights: usize) -> wgpu::Buffer {
        pool.buffer(
            "refinement counters",
            COUNTER_STRIDE * lights as u64,
            wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::INDIRECT
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        )
    }

    /// The dynamic offset of light `light`'s counters.
    pub fn counter_offset(light: u32) -> u32 {
        light * COUNTER_STRIDE as u32
    }

    /// Group 1 of the refining mask pass (`Append`) or the trace pass (`Read`), with
    /// the camera and the prepass's `surface` and `normals`.
    pub fn group(
        &self,
        pool: &mut Pool,
        layouts: &Layouts,
        access: ListAccess,
        camera: &wgpu::Buffer,
        [surface, normals]: [&wgpu::TextureView; 2],
    ) -> wgpu::BindGroup {
        let layout = match access {
            ListAccess::Append => &layouts.refine_screen,
            ListAccess::Read => &layouts.trace_screen,
        };
        pool.bind_group(
            "screen, refined by rays",
            layout,
            &[
                Binding::Buffer(camera.clone()),
                Binding::View(surface.clone()),
                Binding::View(normals.clone()),
                Binding::Buffer(self.pixels.clone()),
                Binding::BufferWindow { buffer: self.counters.clone(), size: COUNTER_BYTES },
            ],
        )
    }

    /// The trace and fill passes' group 2: `mask_layer`, written, `traced`, the copy
    /// of it that the fill reads, and `history`, the light's penumbra history as this
    /// frame leaves it.
    pub fn mask_group(
        pool: &mut Pool,
        layouts: &Layouts,
        mask_layer: &wgpu::TextureView,
        traced: &wgpu::TextureView,
        history: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        pool.bind_group(
            "refined shadow mask",
            &layouts.refined_mask,
            &[
                Binding::View(mask_layer.clone()),
                Binding::View(traced.clone()),
                Binding::View(history.clone()),
            ],
        )
    }

    /// Records a copy of `counters` (the mask path's or the forward path's) into a
    /// mappable buffer, to read back.
    pub fn copy_counters(
        counters: &wgpu::Buffer,
        pool: &mut Pool,
        encoder: &mut wgpu::CommandEncoder,
    ) -> wgpu::Buffer {
        let size = counters.size();
        let usage = wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ;
        let copy = pool.buffer("refinement counters, read back", size, usage);
        encoder.copy_buffer_to_buffer(counters, 0, &copy, 0, size);
        copy
    }

    /// Pixels each light listed, from a copy of the counters read back: beamed (or
    /// traced) this frame, and unsure in all (beamed, filled, or answered by their
    /// penumbra history).
    pub fn listed(counters: &[u32], lights: usize) -> Vec<Listed> {
        let bytes: &[u8] = bytemuck::cast_slice(counters);
        let light_counters = |light: usize| {
            let start = light * COUNTER_STRIDE as usize;
            bytes
                .get(start..start + COUNTER_BYTES as usize)
                .map(bytemuck::pod_read_unaligned::<RefineCountersGpu>)
                .unwrap_or_default()
        };
        (0..lights)
            .map(|light| {
                let c = light_counters(light);
                Listed { traced: c.count, unsure: c.count + c.fill_count + c.kept_count }
            })
            .collect()
    }
}
