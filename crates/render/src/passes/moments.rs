//! The moment pass of the filterable techniques (VSM, ESM, EVSM, MSM, convolution):
//! compute shaders that encode the depth map into the technique's layers of
//! functions of depth, blur them with a separable Gaussian, and build mipmaps.

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use gnomon_scene::settings::{MomentSettings, Technique};
use wgpu::util::DeviceExt;

use super::{LIGHT_WGSL, compose_wgsl};
use crate::techniques::{self, FilterableMap};

const WORKGROUP: u32 = 8;

/// `FilterParams` in `moments_filter.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct FilterParamsGpu {
    direction: [i32; 2],
    radius: i32,
    log_c: f32,
    sigma: f32,
    _pad: [f32; 3],
}

/// Pipelines for one storage format (WGSL names the format of a storage texture).
struct FormatPipelines {
    storage_layout: wgpu::BindGroupLayout,
    filter_layout: wgpu::BindGroupLayout,
    blur: wgpu::ComputePipeline,
    downsample: wgpu::ComputePipeline,
    encode: HashMap<Technique, wgpu::ComputePipeline>,
}

/// The moment pass's pipelines, built on first use per format and technique.
pub(crate) struct MomentPass {
    light_layout: wgpu::BindGroupLayout,
    depth_layout: wgpu::BindGroupLayout,
    formats: HashMap<wgpu::TextureFormat, FormatPipelines>,
}

/// A filtered moment map, ready to bind to the lighting pass.
pub(crate) struct MomentMap {
    /// All layers and mip levels (the view keeps the texture alive).
    pub view: wgpu::TextureView,
}

fn wgsl_format(format: wgpu::TextureFormat) -> &'static str {
    match format {
        wgpu::TextureFormat::Rgba16Float => "rgba16float",
        _ => "rgba32float",
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
    pub fn new(device: &wgpu::Device) -> Self {
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
        Self { light_layout, depth_layout, formats: HashMap::new() }
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
            let source = include_str!("moments_filter.wgsl").replace("MOMENT_FORMAT", wgsl_format(format));
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("moments: filter"),
                source: wgpu::ShaderSource::Wgsl(source.into()),
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
        technique: Technique,
        format: wgpu::TextureFormat,
    ) -> &wgpu::ComputePipeline {
        let (light_layout, depth_layout) = (&self.light_layout, &self.depth_layout);
        let pipelines = self.formats.get_mut(&format).expect("format pipelines are built first");
        let storage_layout = &pipelines.storage_layout;
        pipelines.encode.entry(technique).or_insert_with(|| {
            let mut parts: Vec<String> = vec![LIGHT_WGSL.to_owned()];
            parts.extend(techniques::shared_wgsl());
            parts.extend(techniques::lookup(technique).wgsl().iter().map(|s| s.to_string()));
            parts.push(include_str!("moments_encode.wgsl").replace("MOMENT_FORMAT", wgsl_format(format)));
            let refs: Vec<&str> = parts.iter().map(String::as_str).collect();
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("moments: encode"),
                source: wgpu::ShaderSource::Wgsl(compose_wgsl(&refs).into()),
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

    /// Records the encoding, blur and mipmaps of `technique`'s map from the depth
    /// map `depth_view` into a new texture, in one compute pass.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        technique: Technique,
        map: FilterableMap,
        settings: &MomentSettings,
        format: wgpu::TextureFormat,
        resolution: u32,
        cascades: u32,
        depth_view: &wgpu::TextureView,
        light_buffer: &wgpu::Buffer,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites>,
    ) -> MomentMap {
        self.format_pipelines(device, format);
        self.encode_pipeline(device, technique, format);
        let pipelines = &self.formats[&format];
        let mip_levels = if settings.mipmaps && map.mipmapped { resolution.ilog2() + 1 } else { 1 };
        // The technique's layers, for every cascade in turn.
        let layers = map.layers * cascades;
        let texture = |label, mips| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: resolution, height: resolution, depth_or_array_layers: layers },
                mip_level_count: mips,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        let moments = texture("moment map", mip_levels);
        let level_view = |t: &wgpu::Texture, level: u32| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                base_mip_level: level,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let log_c = map.log_space_exponent.unwrap_or(0.0);
        let filter_group = |source: &wgpu::TextureView,
                            target: &wgpu::TextureView,
                            params: FilterParamsGpu| {
            let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("moments: filter parameters"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("moments: filter"),
                layout: &pipelines.filter_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(source) },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(target) },
                    wgpu::BindGroupEntry { binding: 2, resource: buffer.as_entire_binding() },
                ],
            })
        };
        let light_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("moments: light"),
            layout: &self.light_layout,
            entries: &[wgpu::BindGroupEntry { binding: 1, resource: light_buffer.as_entire_binding() }],
        });
        let depth_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("moments: depth map"),
            layout: &self.depth_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(depth_view),
            }],
        });
        let top = level_view(&moments, 0);
        let encode_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("moments: encode target"),
            layout: &pipelines.storage_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&top),
            }],
        });
        let groups = |size: u32| size.div_ceil(WORKGROUP);

        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("moments"), timestamp_writes });
        pass.set_pipeline(&pipelines.encode[&technique]);
        pass.set_bind_group(0, &light_group, &[]);
        pass.set_bind_group(1, &encode_group, &[]);
        pass.set_bind_group(2, &depth_group, &[]);
        pass.dispatch_workgroups(groups(resolution), groups(resolution), layers);

        if settings.blur_radius > 0 {
            let scratch = texture("moment map blur scratch", 1);
            let scratch_view = level_view(&scratch, 0);
            let radius = settings.blur_radius as i32;
            let params = |direction| FilterParamsGpu {
                direction,
                radius,
                log_c,
                sigma: 0.5 * settings.blur_radius as f32,
                _pad: [0.0; 3],
            };
            // Horizontal into the scratch texture, vertical back.
            let horizontal = filter_group(&top, &scratch_view, params([1, 0]));
            let vertical = filter_group(&scratch_view, &top, params([0, 1]));
            pass.set_pipeline(&pipelines.blur);
            for group in [&horizontal, &vertical] {
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(groups(resolution), groups(resolution), layers);
            }
        }

        if mip_levels > 1 {
            pass.set_pipeline(&pipelines.downsample);
            for level in 1..mip_levels {
                let size = (resolution >> level).max(1);
                let params =
                    FilterParamsGpu { direction: [0, 0], radius: 0, log_c, sigma: 1.0, _pad: [0.0; 3] };
                let group =
                    filter_group(&level_view(&moments, level - 1), &level_view(&moments, level), params);
                pass.set_bind_group(0, &group, &[]);
                pass.dispatch_workgroups(groups(size), groups(size), layers);
            }
        }
        drop(pass);
        let view = moments.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        MomentMap { view }
    }
}
