//! The render passes and the resources they share: bind group layouts, the WGSL
//! composition, and the pipeline caches.

pub(crate) mod binding_place;
pub(crate) mod blit;
pub(crate) mod depth_baseline;
pub(crate) mod depth_reduce;
pub mod generated;
pub(crate) mod gpu_cull;
pub(crate) mod light_list;
pub(crate) mod lighting;
pub(crate) mod link;
pub(crate) mod map_preview;
pub(crate) mod map_scroll;
pub(crate) mod moments;
pub(crate) mod screen_space;
pub(crate) mod shadow;
pub(crate) mod wgsl_interfaces;

pub(crate) use binding_place::BindingPlace;

#[cfg(test)]
mod gpu_mirrors;
#[cfg(test)]
mod interface_tests;

/// The shadow map's texel format.
pub(crate) const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Begins a depth-only render pass into `target`, starting from `load`: cleared to
/// the far plane (1), or what it holds.
pub(crate) fn begin_depth_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    target: &wgpu::TextureView,
    load: wgpu::LoadOp<f32>,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: target,
            depth_ops: Some(wgpu::Operations { load, store: wgpu::StoreOp::Store }),
            stencil_ops: None,
        }),
        timestamp_writes,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Draws the full-screen triangle (`FULLSCREEN_WGSL`) with `pipeline` and its one
/// bind group into `target`, cleared to black first.
pub(crate) fn draw_fullscreen(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    target: &wgpu::TextureView,
    pipeline: &wgpu::RenderPipeline,
    group: &wgpu::BindGroup,
) {
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, group, &[]);
    pass.draw(0..3, 0..1);
}

/// Links WGSL `parts` into one shader ([`link`]): each part that is a module's text
/// loads that module and what it imports; the others are generated and make up
/// `package::variant`. When the parts name the light uniform's structs
/// ([`LIGHT_WGSL`]) but none types `TechniqueParams` (no technique is composed), the
/// variant types it as `NoParams`.
///
/// A part that does not link (a host's technique WGSL with an error) gives WGSL that
/// names the link error, which the device then refuses by that name: composing never
/// panics, and the shader's creation reports it as any other WGSL error.
pub(crate) fn compose_wgsl(parts: &[&str]) -> String {
    let typed = parts.iter().any(|p| p.starts_with(crate::techniques::TechniqueParams::ALIAS_PREFIX));
    let default_alias = crate::techniques::TechniqueParams::default().wgsl_alias();
    let mut all: Vec<&str> = parts.to_vec();
    if parts.contains(&LIGHT_WGSL) && !typed {
        all.push(&default_alias);
    }
    #[cfg(test)]
    let naming = link::TEST_NAMING.with(std::cell::Cell::get);
    #[cfg(not(test))]
    let naming = link::Naming::AsWritten;
    link::link(&all, naming).unwrap_or_else(|error| {
        let comment: String = error.lines().map(|line| format!("// {line}\n")).collect();
        format!(
            "// WESL could not link this shader:\n{comment}const wesl_link_failed: u32 = wesl_link_error;\n"
        )
    })
}

/// The vertex stage of the passes that cover their whole target.
pub(crate) const FULLSCREEN_WGSL: &str = include_str!("fullscreen.wgsl");

/// The light uniform's struct and depth conventions, shared by every pass. It
/// imports what every light kind does differently (`light_kinds.wgsl`, the only
/// WGSL that reads an emitter's kind), which imports the shapes it samples lights
/// over (`light_shapes.wgsl`).
pub(crate) const LIGHT_WGSL: &str = include_str!("light.wgsl");

/// The WGSL every geometry pass starts with (after [`LIGHT_WGSL`]).
pub(crate) const SCENE_COMMON_WGSL: &str = include_str!("scene_common.wgsl");

/// Gnomon's own passes bind the light uniform at group 0, after the instances.
pub(crate) const OWN_LIGHT_BINDING: BindingPlace = BindingPlace { group: 0, binding: 1 };

/// The passes that shade from the camera bind its uniform first in group 1.
pub(crate) const OWN_CAMERA_BINDING: BindingPlace = BindingPlace { group: 1, binding: 0 };

/// The passes that draw from the camera bind the material texture in group 3.
pub(crate) const CAMERA_MATERIAL_BINDINGS: BindingPlace = BindingPlace { group: 3, binding: 0 };

/// The light uniform (`light_binding.wgsl`, loaded by the modules that import
/// `light`) placed at `place`.
pub(crate) fn light_binding_wgsl(place: BindingPlace) -> String {
    place.declare("LIGHT")
}

/// The camera uniform (`camera_binding.wgsl`) placed at `place`.
pub(crate) fn camera_binding_wgsl(place: BindingPlace) -> String {
    place.declare("CAMERA")
}

/// The material texture that [`SCENE_COMMON_WGSL`]'s helpers sample
/// (`material_bindings.wgsl`) placed from `place`.
pub(crate) fn material_bindings_wgsl(place: BindingPlace) -> String {
    place.declare("MATERIAL")
}

/// The camera uniform's struct.
pub(crate) const CAMERA_STRUCT_WGSL: &str = include_str!("camera.wgsl");

/// The octahedral encoding of the prepass's normals, for the passes that write or read
/// them.
pub(crate) const OCTAHEDRON_WGSL: &str = include_str!("octahedron.wgsl");

/// The prepass's bindings and `world_at`, for the passes that read the prepass.
pub(crate) const SCREEN_COMMON_WGSL: &str = include_str!("screen_common.wgsl");

/// The shadow receiver: a host's shader reads a light's shadows through it.
pub(crate) mod receiver;

/// What the lighting and shadow-mask passes share about a point and its light.
pub(crate) const SHADING_WGSL: &str = include_str!("shading.wgsl");

/// The binding of the shadow group that holds a 2D map's touched layer
/// (`rays/touched.rs`; `touched_map` in refine_map.wgsl).
pub(crate) const TOUCHED_BINDING: u32 = 12;

/// Bind group layouts shared by the passes.
pub(crate) struct Layouts {
    /// Group 0: instances (storage) and the light (uniform); the trace pass's
    /// compute stage reads the light too.
    pub scene: wgpu::BindGroupLayout,
    /// Group 1 of the lighting pass and the prepass: the camera.
    pub camera: wgpu::BindGroupLayout,
    /// Group 1 of a forward lighting pass that refines by rays: the camera and the
    /// tracer's resources, for each traversal ([`crate::rays::forward_layouts`]).
    pub forward_rays: crate::rays::TracerLayouts,
    /// Group 1 of the shadow-mask pass and of the lighting passes on the mask path:
    /// the camera and the prepass's surface, normals and object.
    pub screen: wgpu::BindGroupLayout,
    /// Group 2 of the lighting pass: the shadow map and its comparison sampler, the
    /// filterable techniques' moment map and its sampler, a point light's cube with
    /// its nearest comparison and gathering samplers, on the mask path the light's
    /// layer of the shadow mask, and in the mask pass of a light whose penumbrae it
    /// classifies the map's min-max pyramid (`rays/pyramid.rs`), then where its
    /// rays refine a 2D map under the footprint test the map's touched layer
    /// ([`TOUCHED_BINDING`]).
    pub shadow: wgpu::BindGroupLayout,
    /// The shadow receiver's one group, in the host's shader: the light's and the
    /// camera's uniforms, then the shadow resources in the order of `shadow`.
    pub receiver: wgpu::BindGroupLayout,
    /// A material's base-colour texture and sampler: group 3 of the lighting pass,
    /// group 1 of the alpha-masked shadow pass.
    pub material: wgpu::BindGroupLayout,
    /// The tracer's resources ([`crate::rays`]), for each traversal: group 3 of the
    /// trace pass.
    pub rays: crate::rays::TracerLayouts,
    /// Group 1 of a shadow-mask pass that refines with rays: `screen`'s bindings,
    /// the list of unsure pixels and the light's counters, written.
    pub refine_screen: wgpu::BindGroupLayout,
    /// Group 1 of the trace pass: the same, read.
    pub trace_screen: wgpu::BindGroupLayout,
    /// Group 2 of the trace pass: the light's layer of the mask, written.
    pub refined_mask: wgpu::BindGroupLayout,
    /// Group 3 of the mask pass of a light whose penumbrae it classifies: its
    /// penumbra history, read and written.
    pub penumbra_history: wgpu::BindGroupLayout,
}

impl Layouts {
    pub fn new(device: &wgpu::Device) -> Self {
        let vf = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let vfc = vf | wgpu::ShaderStages::COMPUTE;
        let layout = |label: &str, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries })
        };
        let instances = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let filterable =
            texture(wgpu::TextureSampleType::Float { filterable: true }, wgpu::TextureViewDimension::D2);
        let filtering = wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering);
        let fragment = wgpu::ShaderStages::FRAGMENT;
        Self {
            scene: layout(
                "scene",
                &[
                    wgpu::BindGroupLayoutEntry { binding: 0, visibility: vfc, ty: instances, count: None },
                    uniform_entry(1, vfc),
                ],
            ),
            camera: layout("camera", &[uniform_entry(0, vf)]),
            forward_rays: crate::rays::forward_layouts(device),
            shadow: layout(
                "shadow map",
                &[
                    shadow_entries(0),
                    vec![unfilterable_texture_entry(9)],
                    (10..12)
                        .map(|binding| {
                            let unfiltered = wgpu::TextureSampleType::Float { filterable: false };
                            fragment_entry(binding, texture(unfiltered, wgpu::TextureViewDimension::D2Array))
                        })
                        .collect(),
                    vec![fragment_entry(
                        TOUCHED_BINDING,
                        texture(wgpu::TextureSampleType::Depth, wgpu::TextureViewDimension::D2Array),
                    )],
                ]
                .concat(),
            ),
            receiver: layout(
                "shadow receiver",
                &[vec![uniform_entry(0, fragment), uniform_entry(1, fragment)], shadow_entries(2)].concat(),
            ),
            screen: layout(
                "screen",
                &[
                    uniform_entry(0, vf),
                    unfilterable_texture_entry(1),
                    unfilterable_texture_entry(2),
                    fragment_entry(3, texture(wgpu::TextureSampleType::Uint, wgpu::TextureViewDimension::D2)),
                ],
            ),
            material: layout("material", &[fragment_entry(0, filterable), fragment_entry(1, filtering)]),
            rays: crate::rays::layouts(device),
            refine_screen: crate::rays::refine_screen_layout(device, crate::rays::ListAccess::Append),
            trace_screen: crate::rays::refine_screen_layout(device, crate::rays::ListAccess::Read),
            refined_mask: crate::rays::refined_mask_layout(device),
            penumbra_history: crate::rays::history_layout(device),
        }
    }
}

/// The shadow resources a light's lookup reads, from binding `first` on: its depth
/// map and comparison sampler, the moment map and its sampler, the cube with its
/// nearest comparison and gathering samplers (the declarations of
/// techniques/bindings.wgsl and receiver.wgsl), then a virtual map's uniform and
/// page table (virtual_map/page_lookup.wgsl), whose pool is the depth map.
fn shadow_entries(first: u32) -> Vec<wgpu::BindGroupLayoutEntry> {
    use wgpu::{SamplerBindingType as S, TextureViewDimension as D};
    let depth = |dimension| texture(wgpu::TextureSampleType::Depth, dimension);
    let filterable = texture(wgpu::TextureSampleType::Float { filterable: true }, D::D2Array);
    let buffer = |ty| wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None };
    [
        depth(D::D2Array),
        wgpu::BindingType::Sampler(S::Comparison),
        filterable,
        wgpu::BindingType::Sampler(S::Filtering),
        depth(D::Cube),
        wgpu::BindingType::Sampler(S::Comparison),
        wgpu::BindingType::Sampler(S::NonFiltering),
        buffer(wgpu::BufferBindingType::Uniform),
        buffer(wgpu::BufferBindingType::Storage { read_only: true }),
    ]
    .into_iter()
    .zip(first..)
    .map(|(ty, binding)| fragment_entry(binding, ty))
    .collect()
}

/// A texture binding of one sample, read by fragment stages.
fn texture(
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindingType {
    wgpu::BindingType::Texture { sample_type, view_dimension, multisampled: false }
}

fn fragment_entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::FRAGMENT, ty, count: None }
}

/// The layout and pipeline layout of a full-screen pass that reads a depth texture
/// of `dimension` (binding 0) and a uniform (binding 1) in its fragment stage: the map
/// preview and the map scroll.
fn depth_reader_layouts(
    device: &wgpu::Device,
    label: &str,
    dimension: wgpu::TextureViewDimension,
) -> (wgpu::BindGroupLayout, wgpu::PipelineLayout) {
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            fragment_entry(0, texture(wgpu::TextureSampleType::Depth, dimension)),
            uniform_entry(1, wgpu::ShaderStages::FRAGMENT),
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    (layout, pipeline_layout)
}

/// Whether a shader may write a storage buffer it binds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum StorageAccess {
    Read,
    ReadWrite,
}

/// A storage buffer a compute stage reads, or reads and writes.
pub(crate) fn compute_storage_entry(binding: u32, access: StorageAccess) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: access == StorageAccess::Read },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A 2D float texture read with `textureLoad` by a fragment stage.
fn unfilterable_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}
