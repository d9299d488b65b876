//! The touched layer of a 2D shadow map (`touched.wgsl`): per texel, the nearness
//! (1 − depth) of the nearest point of any thin opaque caster that touches its square at all, drawn conservatively
//! from the BVH's world-space triangles. The map stores a caster only where it
//! covers a texel's centre; a caster thinner than a texel, or one between the
//! centres, leaves the map's footprint all light, and the footprint test
//! (`refine_footprint.wgsl`) traced no ray there. Where the refinement by rays reads
//! a 2D map under a hard light, it reads this beside it: a touched depth in front of
//! the receiver is a caster, and a footprint with light and a caster is unsure.
//!
//! Cut-out (alpha-tested) triangles are left out: their cards would count as
//! casters whole. What this layer misses of them, the map's texels miss as well.

use gnomon_scene::settings::Refine;

use super::refine::MAX_GROUPS;
use crate::{
    passes::{SHADOW_FORMAT, lighting::MapLookup},
    pool::{Binding, Pool, ViewKey},
    timing::{PassClock, Slot, SlotPart},
};

/// Whether a light refined by `refine` and looked up by `lookup` reads a touched
/// layer where its footprint test runs (`refine_map.wgsl`'s, a 2D map's): where its
/// rays run only where the map is unsure. (Every pixel traced needs no test; a
/// cube's and a virtual map's tests read none yet; the mask pass of a light with an
/// area classifies its penumbrae by the map's pyramid instead, and the frame then
/// draws none for it.)
pub(crate) fn reads_touched(refine: Refine, lookup: MapLookup) -> bool {
    let unsure_only = match refine {
        Refine::Auto | Refine::Rays => true,
        Refine::Off | Refine::EveryPixel => false,
    };
    let map = match lookup {
        MapLookup::Map => true,
        MapLookup::Cube | MapLookup::Paraboloid | MapLookup::Virtual => false,
    };
    unsure_only && map
}

/// What a texel no caster touches holds. The layer stores nearness, 1 − depth (kept
/// by the greatest), so that this is what a new texture holds, and the placeholder
/// bound where a map has none says that nothing touches it.
const UNTOUCHED: f32 = 0.0;

/// The shape of a map's touched layer: the map's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct TouchedLayout {
    /// The map's side, in texels.
    pub resolution: u32,
    /// The map's layers.
    pub layers: u32,
}

impl TouchedLayout {
    /// Its usage: drawn, read by the mask or lighting pass, and copied out by the
    /// tests that check it.
    pub const USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
        .union(wgpu::TextureUsages::TEXTURE_BINDING)
        .union(wgpu::TextureUsages::COPY_SRC);

    /// The texture's size.
    pub fn size(&self) -> wgpu::Extent3d {
        wgpu::Extent3d { width: self.resolution, height: self.resolution, depth_or_array_layers: self.layers }
    }

    /// Its texture.
    pub fn create(&self, device: &wgpu::Device) -> Touched {
        Touched {
            texture: device.create_texture(&wgpu::TextureDescriptor {
                label: Some("touched layer"),
                size: self.size(),
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: SHADOW_FORMAT,
                usage: Self::USAGE,
                view_formats: &[],
            }),
        }
    }
}

/// A map's touched layer: one depth texture with the map's layers.
#[derive(Clone, Debug)]
pub(crate) struct Touched {
    pub texture: wgpu::Texture,
}

/// What a touched layer is drawn from.
pub(crate) struct TouchedInput<'a> {
    /// The light's uniform: its layers' `cascade_clip_from_world` and the map's side.
    pub light: &'a wgpu::Buffer,
    /// The BVH's triangles, world space ([`super::GpuBvh::triangle_buffer`]).
    pub triangles: &'a wgpu::Buffer,
    /// How many it holds.
    pub count: u32,
    /// The map, every layer: the list leaves out the tiny triangles it holds.
    pub map: &'a wgpu::TextureView,
    pub layout: TouchedLayout,
    pub queue: &'a wgpu::Queue,
}

/// One layer's indirect draw (`TouchedDraw` in touched_list.wgsl; wgpu's
/// `DrawIndirectArgs`): the list pass counts 3 vertices a thin triangle into it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct TouchedDrawGpu {
    pub vertex_count: u32,
    pub instance_count: u32,
    pub first_vertex: u32,
    pub first_instance: u32,
}

/// Triangles a workgroup of the list pass takes.
const GROUP_SIZE: u32 = 64;
/// A listed triangle is `layer << LAYER_SHIFT | triangle`: room for 2^28 triangles,
/// more than a device binds, and 16 layers.
const LAYER_SHIFT: u32 = 28;
const _: () = assert!(crate::uniforms::MAX_CASCADES as u32 <= 1 << (32 - LAYER_SHIFT));

/// The touched layer's passes (`touched.wgsl`): the list of each layer's thin
/// triangles, then their draw.
pub(crate) struct TouchedPass {
    list_layout: wgpu::BindGroupLayout,
    draw_layout: wgpu::BindGroupLayout,
    list: wgpu::ComputePipeline,
    draw: wgpu::RenderPipeline,
}

/// A pass's timestamps: its clock and slot.
pub(crate) struct Timed<'a> {
    pub clock: &'a PassClock,
    pub slot: Slot,
}

impl TouchedPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let entry =
            |binding, visibility, ty| wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None };
        let storage = |read_only| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let uniform = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries })
        };
        let compute = wgpu::ShaderStages::COMPUTE;
        let list_layout = layout(
            "touched layer, list",
            &[
                entry(0, compute, storage(true)),
                entry(1, compute, uniform),
                entry(2, compute, storage(false)),
                entry(3, compute, storage(false)),
                entry(
                    4,
                    compute,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                ),
            ],
        );
        let vertex = wgpu::ShaderStages::VERTEX;
        let draw_layout = layout(
            "touched layer, draw",
            &[
                entry(0, vertex, storage(true)),
                entry(1, vertex | wgpu::ShaderStages::FRAGMENT, uniform),
                entry(3, vertex, storage(true)),
            ],
        );
        let module = |label, source: String| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            })
        };
        let pipeline_layout = |label, group: &wgpu::BindGroupLayout| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[Some(group)],
                immediate_size: 0,
            })
        };
        let list_module = module("touched layer, list", touched_list_wgsl());
        let list = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("touched layer, list"),
            layout: Some(&pipeline_layout("touched layer, list", &list_layout)),
            module: &list_module,
            entry_point: Some("cs_touched_list"),
            compilation_options: Default::default(),
            cache: None,
        });
        let draw_module = module("touched layer, draw", touched_draw_wgsl());
        let draw = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("touched layer, draw"),
            layout: Some(&pipeline_layout("touched layer, draw", &draw_layout)),
            vertex: wgpu::VertexState {
                module: &draw_module,
                entry_point: Some("vs_touched"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &draw_module,
                entry_point: Some("fs_touched"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            // Both windings: the list drops a closed mesh's faces turned from the
            // light, and keeps an open mesh's.
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: SHADOW_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        Self { list_layout, draw_layout, list, draw }
    }

    /// Lists every layer's thin triangles of `input` in one compute pass, then draws
    /// each layer of `touched` from its list, one render pass a layer, with the
    /// timestamps of `timed`'s slot round them all.
    pub fn record(
        &self,
        pool: &mut Pool,
        encoder: &mut wgpu::CommandEncoder,
        input: TouchedInput,
        touched: &Touched,
        timed: Option<Timed>,
    ) {
        let TouchedInput { light, triangles, count, map, layout, queue } = input;
        let draws: Vec<TouchedDrawGpu> = (0..layout.layers)
            .map(|layer| TouchedDrawGpu {
                instance_count: 1,
                first_vertex: 3 * layer * count,
                ..Default::default()
            })
            .collect();
        let draws = pool.storage(queue, "touched layer, draws", &draws, wgpu::BufferUsages::INDIRECT);
        let list_bytes = (u64::from(layout.layers) * u64::from(count) * 4).max(4);
        let list = pool.buffer("touched layer, list", list_bytes, wgpu::BufferUsages::STORAGE);
        let (triangles, light) = (Binding::Buffer(triangles.clone()), Binding::Buffer(light.clone()));
        let list_group = pool.bind_group(
            "touched layer, list",
            &self.list_layout,
            &[
                triangles.clone(),
                light.clone(),
                Binding::Buffer(draws.clone()),
                Binding::Buffer(list.clone()),
                Binding::View(map.clone()),
            ],
        );
        let draw_group = pool.bind_group_numbered(
            "touched layer, draw",
            &self.draw_layout,
            vec![(0, triangles), (1, light), (3, Binding::Buffer(list))],
        );
        let part = |part: SlotPart| timed.as_ref().and_then(|t| t.clock.compute_part(t.slot, part));
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("touched layer, list"),
                timestamp_writes: part(SlotPart::Opening),
            });
            pass.set_pipeline(&self.list);
            pass.set_bind_group(0, &list_group, &[]);
            let groups = count.div_ceil(GROUP_SIZE).max(1);
            let x = groups.min(MAX_GROUPS);
            pass.dispatch_workgroups(x, groups.div_ceil(x), layout.layers);
        }
        for layer in 0..layout.layers {
            let view = pool.view(&touched.texture, ViewKey::layer(layer));
            let closing = (layer + 1 == layout.layers).then_some(SlotPart::Closing);
            let timestamp_writes =
                closing.and_then(|part| timed.as_ref().and_then(|t| t.clock.render_part(t.slot, part)));
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("touched layer, draw"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(UNTOUCHED),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.draw);
            pass.set_bind_group(0, &draw_group, &[]);
            pass.draw_indirect(&draws, u64::from(layer) * std::mem::size_of::<TouchedDrawGpu>() as u64);
        }
    }
}

/// The generated constants both passes read, and the light's uniform at group 0
/// binding 1.
fn touched_variant() -> [String; 2] {
    use crate::passes::{OWN_LIGHT_BINDING, light_binding_wgsl};
    let constants = format!(
        "const NO_ALPHA: u32 = {}u;\nconst TOUCHED_GROUP_SIZE: u32 = {GROUP_SIZE}u;\n\
         const LAYER_SHIFT: u32 = {LAYER_SHIFT}u;\nconst TRIANGLE_MASK: u32 = {}u;\n",
        super::bvh::NO_ALPHA,
        (1u32 << LAYER_SHIFT) - 1,
    );
    [light_binding_wgsl(OWN_LIGHT_BINDING), constants]
}

/// `touched_list.wgsl`, composed.
pub(crate) fn touched_list_wgsl() -> String {
    let [light, constants] = touched_variant();
    crate::passes::compose_wgsl(&[
        crate::passes::LIGHT_WGSL,
        &light,
        &constants,
        include_str!("touched_list.wgsl"),
    ])
}

/// `touched_draw.wgsl`, composed.
pub(crate) fn touched_draw_wgsl() -> String {
    let [light, constants] = touched_variant();
    crate::passes::compose_wgsl(&[
        crate::passes::LIGHT_WGSL,
        &light,
        &constants,
        include_str!("touched_draw.wgsl"),
    ])
}
