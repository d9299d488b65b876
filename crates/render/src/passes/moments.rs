//! The moment pass of the filterable techniques (VSM, ESM, EVSM, MSM, convolution):
//! compute shaders that encode the depth map into the technique's layers of
//! functions of depth, blur them with a separable Gaussian, and build mipmaps.

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use gnomon_scene::settings::MomentSettings;

use super::{LIGHT_WGSL, compose_wgsl};
use crate::{
    pool::{Binding, Pool, ViewKey},
    techniques::{self, FilterableMap, TechniqueRef},
};

const WORKGROUP: u32 = 8;

/// `FilterParams` in `moments_filter.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct FilterParamsGpu {
    pub direction: [i32; 2],
    pub radius: i32,
    pub log_c: f32,
    pub sigma: f32,
    pub _pad0: f32,
    pub _pad1: f32,
    pub _pad2: f32,
}

impl FilterParamsGpu {
    fn new(direction: [i32; 2], radius: i32, log_c: f32, sigma: f32) -> Self {
        Self { direction, radius, log_c, sigma, _pad0: 0.0, _pad1: 0.0, _pad2: 0.0 }
    }
}

/// Pipelines for one storage format (WGSL names the format of a storage texture).
struct FormatPipelines {
    storage_layout: wgpu::BindGroupLayout,
    filter_layout: wgpu::BindGroupLayout,
    blur: wgpu::ComputePipeline,
    downsample: wgpu::ComputePipeline,
    encode: HashMap<TechniqueRef, wgpu::ComputePipeline>,
}

/// The moment pass's pipelines, built on first use per format and technique.
pub(crate) struct MomentPass {
    light_layout: wgpu::BindGroupLayout,
    depth_layout: wgpu::BindGroupLayout,
    formats: HashMap<wgpu::TextureFormat, FormatPipelines>,
    /// Writes the filters' parameters.
    queue: wgpu::Queue,
}

/// What the moment pass filters: a light's depth map and the technique's map.
pub(crate) struct MomentInput<'a> {
    pub technique: TechniqueRef,
    pub map: FilterableMap,
    pub settings: &'a MomentSettings,
    pub format: wgpu::TextureFormat,
    pub resolution: u32,
    pub cascades: u32,
    /// The light's depth map, every layer.
    pub depth_view: &'a wgpu::TextureView,
    pub light_buffer: &'a wgpu::Buffer,
}

/// Where the moment pass writes its map.
#[derive(Clone, Copy, Debug)]
pub(crate) enum MomentTarget<'a> {
    /// A texture of the pool, for this frame.
    Pooled,
    /// A texture kept across frames, of [`MomentLayout::of`] the input.
    Kept(&'a wgpu::Texture),
}

/// The texture a moment map needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct MomentLayout {
    pub size: wgpu::Extent3d,
    pub mip_levels: u32,
    pub format: wgpu::TextureFormat,
}

impl MomentLayout {
    /// The usages a moment map is written and read with.
    pub const USAGE: wgpu::TextureUsages =
        wgpu::TextureUsages::STORAGE_BINDING.union(wgpu::TextureUsages::TEXTURE_BINDING);

    /// The texture `input`'s moment map fills: the technique's layers for every
    /// cascade, with a mip chain where the technique filters through one.
    pub fn of(input: &MomentInput) -> Self {
        let MomentInput { map, settings, format, resolution, cascades, .. } = *input;
        let mip_levels = if settings.mipmaps && map.mipmapped { resolution.ilog2() + 1 } else { 1 };
        let layers = map.layers * cascades;
        let size = wgpu::Extent3d { width: resolution, height: resolution, depth_or_array_layers: layers };
        MomentLayout { size, mip_levels, format }
    }
}

/// A filtered moment map, ready to bind to the lighting pass.
pub(crate) struct MomentMap {
    /// All layers and mip levels (the view keeps the texture alive).
    pub view: wgpu::TextureView,
}

/// The moment pass's encoding WGSL for a technique and storage format, composed.
pub(crate) fn encode_wgsl(technique: TechniqueRef, format: wgpu::TextureFormat) -> String {
    let mut parts: Vec<String> =
        vec![LIGHT_WGSL.to_owned(), super::light_binding_wgsl(super::OWN_LIGHT_BINDING)];
    parts.extend(techniques::shared_wgsl());
    parts.extend(techniques::technique_wgsl(technique.get(), technique.wgsl()));
    parts.push(moment_target_wgsl(format));
    parts.push(include_str!("moments_encode.wgsl").to_owned());
    let refs: Vec<&str> = parts.iter().map(String::as_str).collect();
    compose_wgsl(&refs)
}

/// The blur and downsampling WGSL for a storage format, composed.
pub(crate) fn filter_wgsl(format: wgpu::TextureFormat) -> String {
    compose_wgsl(&[&moment_target_wgsl(format), include_str!("moments_filter.wgsl")])
}

/// The generated type of the storage texture the moment passes write, in `format`:
/// `MomentTarget`, which `moments_encode.wgsl` and `moments_filter.wgsl` import.
fn moment_target_wgsl(format: wgpu::TextureFormat) -> String {
    format!("alias MomentTarget = texture_storage_2d_array<{}, write>;\n", wgsl_format(format))
}

fn wgsl_format(format: wgpu::TextureFormat) -> &'static str {
    match format {
        wgpu::TextureFormat::Rgba16Float => "rgba16float",
        wgpu::TextureFormat::Rgba32Float => "rgba32float",
        // `Renderer::moment_format` picks one of the two; wgpu's enum is open-ended.
        other => unreachable!("a moment map is rgba16float or rgba32float, not {other:?}"),
    }
}

fn compute_entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::COMPUTE, ty, count: None }
}

fn storage_entry(binding: u32, format: wgpu::TextureFormat) -> wgpu::BindGroupLayoutEntry {
    compute_entry(
        binding,
        wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2Array,
        },
    )
}

impl MomentPass {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let light_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("moments: light"),
            entries: &[compute_entry(
                1,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
            )],
        });
        let depth_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("moments: depth map"),
            entries: &[compute_entry(
                0,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2Array,
                    multisampled: false,
                },
            )],
        });
        Self { light_layout, depth_layout, formats: HashMap::new(), queue: queue.clone() }
    }

    fn format_pipelines(
        &mut self,
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
    ) -> &mut FormatPipelines {
        self.formats.entry(format).or_insert_with(|| {
            let storage_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("moments: target"),
                entries: &[storage_entry(0, format)],
            });
            let filter_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("moments: filter"),
                entries: &[
                    compute_entry(
                        0,
                        wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: false },
                            view_dimension: wgpu::TextureViewDimension::D2Array,
                            multisampled: false,
                        },
                    ),
                    storage_entry(1, format),
                    compute_entry(
                        2,
                        wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                    ),
                ],
            });
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("moments: filter"),
                source: wgpu::ShaderSource::Wgsl(filter_wgsl(format).into()),
            });
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("moments: filter"),
                bind_group_layouts: &[Some(&filter_layout)],
                immediate_size: 0,
            });
            let pipeline = |entry: &str| {
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&layout),
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                })
            };
            FormatPipelines {
                blur: pipeline("blur_main"),
                downsample: pipeline("downsample_main"),
                storage_layout,
                filter_layout,
                encode: HashMap::new(),
            }
        })
    }

    fn encode_pipeline(
        &mut self,
        device: &wgpu::Device,
        technique: TechniqueRef,
        format: wgpu::TextureFormat,
    ) -> &wgpu::ComputePipeline {
        let (light_layout, depth_layout) = (&self.light_layout, &self.depth_layout);
        let pipelines = self.formats.get_mut(&format).expect("format pipelines are built first");
        let storage_layout = &pipelines.storage_layout;
        pipelines.encode.entry(technique).or_insert_with(|| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("moments: encode"),
                source: wgpu::ShaderSource::Wgsl(encode_wgsl(technique, format).into()),
            });
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("moments: encode"),
                bind_group_layouts: &[Some(light_layout), Some(storage_layout), Some(depth_layout)],
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("moments: encode"),
                layout: Some(&layout),
                module: &module,
                entry_point: Some("encode_main"),
                compilation_options: Default::default(),
                cache: None,
            })
        })
    }

    /// Records the encoding, blur and mipmaps of `input.technique`'s map from the
    /// depth map into `target`, in one compute pass.
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        pool: &mut Pool,
        encoder: &mut wgpu::CommandEncoder,
        input: &MomentInput,
        target: MomentTarget,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites>,
    ) -> MomentMap {
        let MomentInput { technique, map, settings, format, resolution, .. } = *input;
        self.format_pipelines(device, format);
        self.encode_pipeline(device, technique, format);
        let pipelines = &self.formats[&format];
        let MomentLayout { size, mip_levels, .. } = MomentLayout::of(input);
        // The technique's layers, for every cascade in turn.
        let layers = size.depth_or_array_layers;
        let usage = MomentLayout::USAGE;
        let moments = match target {
            MomentTarget::Pooled => pool.texture_with_mips("moment map", size, mip_levels, format, usage),
            MomentTarget::Kept(texture) => texture.clone(),
        };
        let level = |level: u32| ViewKey {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            base_mip: level,
            mips: Some(1),
            ..Default::default()
        };
        let log_c = map.log_space_exponent.unwrap_or(0.0);
        let filter_group = |pool: &mut Pool,
                            source: &wgpu::TextureView,
                            target: &wgpu::TextureView,
                            params: FilterParamsGpu| {
            let buffer = pool.uniform(&self.queue, "moments: filter parameters", &params);
            pool.bind_group(
                "moments: filter",
                &pipelines.filter_layout,
                &[Binding::View(source.clone()), Binding::View(target.clone()), Binding::Buffer(buffer)],
            )
        };
        let light_group = pool.bind_group_numbered(
            "moments: light",
            &self.light_layout,
            vec![(1, Binding::Buffer(input.light_buffer.clone()))],
        );
        let depth_group = pool.bind_group(
            "moments: depth map",
            &self.depth_layout,
            &[Binding::View(input.depth_view.clone())],
        );
        let top = pool.view(&moments, level(0));
        let encode_group = pool.bind_group(
            "moments: encode target",
            &pipelines.storage_layout,
            &[Binding::View(top.clone())],
        );
        let groups = |size: u32| size.div_ceil(WORKGROUP);

        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("moments"), timestamp_writes });
        pass.set_pipeline(&pipelines.encode[&technique]);
        pass.set_bind_group(0, &light_group, &[]);
        pass.set_bind_group(1, &encode_group, &[]);
        pass.set_bind_group(2, &depth_group, &[]);
        pass.dispatch_workgroups(groups(resolution), groups(resolution), layers);

        if settings.blur_radius > 0 {
            let scratch = pool.texture("moment map blur scratch", size, format, usage);
            let scratch_view = pool.view(&scratch, level(0));
            let radius = settings.blur_radius as i32;
            let params =
                |direction| FilterParamsGpu::new(direction, radius, log_c, 0.5 * settings.blur_radius as f32);
            // Horizontal into the scratch texture, vertical back.
            let horizontal = filter_group(pool, &top, &scratch_view, params([1, 0]));
            let vertical = filter_group(pool, &scratch_view, &top, params([0, 1]));
            pass.set_pipeline(&pipelines.blur);
            for group in [&horizontal, &vertical] {
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(groups(resolution), groups(resolution), layers);
            }
        }

        if mip_levels > 1 {
            pass.set_pipeline(&pipelines.downsample);
            for mip in 1..mip_levels {
                let size = (resolution >> mip).max(1);
                let params = FilterParamsGpu::new([0, 0], 0, log_c, 1.0);
                let (source, target) = (pool.view(&moments, level(mip - 1)), pool.view(&moments, level(mip)));
                let group = filter_group(pool, &source, &target, params);
                pass.set_bind_group(0, &group, &[]);
                pass.dispatch_workgroups(groups(size), groups(size), layers);
            }
        }
        drop(pass);
        let view = pool.view(&moments, ViewKey::whole(wgpu::TextureViewDimension::D2Array));
        MomentMap { view }
    }
}
