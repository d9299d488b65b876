//! The bind groups a frame builds from its resources: the camera, each light's scene
//! group (instances and uniform), and the shadow group of the lighting and mask
//! passes, with the samplers and the placeholders bound where a light has no moment
//! map, cube map, virtual map or mask. Made once with the renderer; the groups come from the pool.

use crate::{
    gpu_scene::GpuScene,
    passes::{Layouts, SHADOW_FORMAT, screen_space},
    pool::{Binding, Pool},
};

/// Samplers and placeholder textures, made once.
pub(crate) struct FixedBindings {
    compare_sampler: wgpu::Sampler,
    compare_nearest_sampler: wgpu::Sampler,
    gather_sampler: wgpu::Sampler,
    moment_sampler: wgpu::Sampler,
    /// Bound in place of a moment map for the depth-comparison techniques.
    placeholder_moments: wgpu::TextureView,
    /// Bound in place of a cube map for the lights that are not point lights.
    placeholder_cube: wgpu::TextureView,
    /// Bound in place of the shadow mask on the forward path and in the mask pass.
    pub placeholder_mask: wgpu::TextureView,
    /// Bound in place of a virtual map's uniform and page table for the lights
    /// without one.
    placeholder_virtual: VirtualBuffers,
    /// Bound in place of a depth pyramid's planes and ranges where the mask pass
    /// reads none.
    placeholder_pyramid: [wgpu::TextureView; 2],
    /// Bound in place of a touched layer where a light has none: its zeros say that
    /// nothing touches a texel (`rays/touched.rs`).
    placeholder_touched: wgpu::TextureView,
}

/// A virtual map's uniform and page table, as a light's shadow group binds them.
#[derive(Clone)]
pub(crate) struct VirtualBuffers {
    pub uniform: wgpu::Buffer,
    pub page_table: wgpu::Buffer,
}

/// The textures of a light's shadow group.
pub(crate) struct ShadowViews<'a> {
    /// The depth map, every layer (a 2D array).
    pub map: &'a wgpu::TextureView,
    pub moments: Option<&'a wgpu::TextureView>,
    /// A point light's map as a cube.
    pub cube: Option<&'a wgpu::TextureView>,
    /// The light's layer of the shadow mask, on the mask path's lighting pass.
    pub mask: Option<&'a wgpu::TextureView>,
    /// A sun's virtual map (whose page pool is `map`).
    pub virtual_map: Option<&'a VirtualBuffers>,
    /// The depth map's pyramid, for the mask pass of a light whose penumbrae it
    /// classifies.
    pub pyramid: Option<&'a super::recording::PyramidViews>,
    /// The depth map's touched layer, where its rays refine it under the footprint
    /// test.
    pub touched: Option<&'a wgpu::TextureView>,
}

fn placeholder(
    device: &wgpu::Device,
    label: &str,
    format: wgpu::TextureFormat,
    layers: u32,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: layers },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    })
}

/// A zeroed buffer of `size` bytes, bound where a light has no virtual map.
fn placeholder_buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage,
        mapped_at_creation: false,
    })
}

impl FixedBindings {
    pub fn new(device: &wgpu::Device) -> Self {
        let linear_clamped = wgpu::SamplerDescriptor {
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        };
        let view_as = |texture: wgpu::Texture, dimension| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(dimension),
                ..Default::default()
            })
        };
        Self {
            compare_sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("shadow compare"),
                // Lit when the receiver's depth ≤ the stored occluder depth.
                compare: Some(wgpu::CompareFunction::LessEqual),
                ..linear_clamped.clone()
            }),
            compare_nearest_sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("shadow compare, nearest"),
                compare: Some(wgpu::CompareFunction::LessEqual),
                ..Default::default()
            }),
            gather_sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("shadow gather"),
                ..Default::default()
            }),
            moment_sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("moment map"),
                mipmap_filter: wgpu::MipmapFilterMode::Linear,
                ..linear_clamped
            }),
            placeholder_moments: view_as(
                placeholder(device, "no moment map", wgpu::TextureFormat::Rgba16Float, 1),
                wgpu::TextureViewDimension::D2Array,
            ),
            placeholder_cube: view_as(
                placeholder(device, "no cube map", SHADOW_FORMAT, 6),
                wgpu::TextureViewDimension::Cube,
            ),
            placeholder_mask: view_as(
                placeholder(device, "no shadow mask", screen_space::MASK_FORMAT, 1),
                wgpu::TextureViewDimension::D2,
            ),
            placeholder_pyramid: [crate::rays::PLANES_FORMAT, crate::rays::RANGES_FORMAT].map(|format| {
                view_as(
                    placeholder(device, "no depth pyramid", format, 1),
                    wgpu::TextureViewDimension::D2Array,
                )
            }),
            placeholder_touched: view_as(
                placeholder(device, "no touched layer", SHADOW_FORMAT, 1),
                wgpu::TextureViewDimension::D2Array,
            ),
            placeholder_virtual: VirtualBuffers {
                uniform: placeholder_buffer(
                    device,
                    "no virtual map",
                    size_of::<crate::virtual_map::VirtualMapGpu>() as u64,
                    wgpu::BufferUsages::UNIFORM,
                ),
                page_table: placeholder_buffer(device, "no page table", 4, wgpu::BufferUsages::STORAGE),
            },
        }
    }

    /// Group 2 of the lighting and mask passes: a light's maps and their samplers.
    pub fn shadow_group(&self, pool: &mut Pool, layouts: &Layouts, views: ShadowViews) -> wgpu::BindGroup {
        let mask = Binding::View(views.mask.unwrap_or(&self.placeholder_mask).clone());
        let [planes, ranges] = match views.pyramid {
            Some(pyramid) => [&pyramid.planes, &pyramid.ranges],
            None => [&self.placeholder_pyramid[0], &self.placeholder_pyramid[1]],
        }
        .map(|view| Binding::View(view.clone()));
        let touched = Binding::View(views.touched.unwrap_or(&self.placeholder_touched).clone());
        // The mask, the pyramid and the touched layer after the shadow resources
        // (`passes::Layouts::shadow`).
        let bindings = [self.map_bindings(&views), vec![mask, planes, ranges, touched]].concat();
        pool.bind_group("shadow map", &layouts.shadow, &bindings)
    }

    /// The shadow receiver's group: the light's and camera's uniforms and the light's
    /// maps, for a host's shader.
    pub fn receiver_group(
        &self,
        pool: &mut Pool,
        layouts: &Layouts,
        uniforms: ReceiverUniforms,
        views: ShadowViews,
    ) -> wgpu::BindGroup {
        let buffers = vec![Binding::Buffer(uniforms.light.clone()), Binding::Buffer(uniforms.camera.clone())];
        let bindings = [buffers, self.map_bindings(&views)].concat();
        pool.bind_group("shadow receiver", &layouts.receiver, &bindings)
    }

    /// A light's maps and their samplers, in the order of `passes::shadow_entries`,
    /// with the placeholders where the light has no moment map or cube.
    fn map_bindings(&self, views: &ShadowViews) -> Vec<Binding> {
        vec![
            Binding::View(views.map.clone()),
            Binding::Sampler(self.compare_sampler.clone()),
            Binding::View(views.moments.unwrap_or(&self.placeholder_moments).clone()),
            Binding::Sampler(self.moment_sampler.clone()),
            Binding::View(views.cube.unwrap_or(&self.placeholder_cube).clone()),
            Binding::Sampler(self.compare_nearest_sampler.clone()),
            Binding::Sampler(self.gather_sampler.clone()),
            Binding::Buffer(views.virtual_map.unwrap_or(&self.placeholder_virtual).uniform.clone()),
            Binding::Buffer(views.virtual_map.unwrap_or(&self.placeholder_virtual).page_table.clone()),
        ]
    }
}

/// The uniforms of a receiver's group.
pub(crate) struct ReceiverUniforms<'a> {
    pub light: &'a wgpu::Buffer,
    pub camera: &'a wgpu::Buffer,
}

/// Group 0 of the geometry passes: the instances and the light's uniform `light`.
pub(crate) fn scene_group(
    pool: &mut Pool,
    layouts: &Layouts,
    uploaded: &GpuScene,
    light: &wgpu::Buffer,
) -> wgpu::BindGroup {
    pool.bind_group(
        "scene",
        &layouts.scene,
        &[Binding::Buffer(uploaded.instances.clone()), Binding::Buffer(light.clone())],
    )
}

/// What the camera sees, and the arguments its passes draw it from where they draw
/// indirectly ([`camera_arguments`]).
pub(crate) struct CameraDraws<'a> {
    pub visible: &'a crate::gpu_scene::Visible,
    pub arguments: Option<wgpu::Buffer>,
}

/// The draw arguments of what the camera sees (`visible`), for its passes (prepass,
/// lighting) to draw each texture's runs as one multi-draw; None where they draw one
/// by one: a device without first instances in indirect draws, or `submission`
/// `direct`, the baseline.
pub(crate) fn camera_arguments(
    pool: &mut Pool,
    gpu: &crate::Gpu,
    uploaded: &GpuScene,
    visible: &crate::gpu_scene::Visible,
    submission: gnomon_scene::settings::DrawSubmission,
) -> Option<wgpu::Buffer> {
    use gnomon_scene::settings::DrawSubmission;
    let indirect = match submission {
        DrawSubmission::GpuCulled | DrawSubmission::Indirect => gpu.indirect_draws,
        DrawSubmission::Direct => false,
    };
    if !indirect || visible.runs.is_empty() {
        return None;
    }
    let mut args = uploaded.visible_arguments(visible);
    args.resize(argument_slots(args.len()), Default::default());
    Some(pool.storage(&gpu.queue, "camera draw arguments", &args, wgpu::BufferUsages::INDIRECT))
}

/// How many draw arguments an arguments buffer holds for `draws`: the next power of
/// two (at least 64), so that the pool keeps reusing a buffer while the count moves.
pub(crate) fn argument_slots(draws: usize) -> usize {
    draws.next_power_of_two().max(64)
}
