//! A host application's renderer, as a program that embeds Gnomon for its shadows
//! would write it: its own vertex buffer, camera uniform, pipeline and WGSL
//! (`host.wgsl`), with Gnomon's receiver module prepended and Gnomon's bind group in
//! its group 1. The winit example draws with it, and the tests check that it sees
//! exactly the shadows Gnomon's own lighting pass draws.

use std::collections::HashMap;

use glam::{Mat4, Vec3};
use gnomon_render::{LightShadows, ReceiverVariant, Renderer, wgpu};
use gnomon_scene::Scene;
use wgpu::util::DeviceExt;

/// The colour target's format.
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// The per-pixel visibility of the light, written beside the colour: −1 where
/// nothing is drawn.
pub const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// The depth buffer's format.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The visibility target's value where no surface is drawn.
const NOTHING_DRAWN: wgpu::Color = wgpu::Color { r: -1.0, g: 0.0, b: 0.0, a: 0.0 };

/// Where the host's pipeline binds Gnomon's receiver group.
const RECEIVER_GROUP: u32 = 1;

/// One vertex of the host's own layout: world position, normal and colour.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct HostVertex {
    /// World-space position.
    pub position: [f32; 3],
    /// World-space normal.
    pub normal: [f32; 3],
    /// Linear RGB albedo.
    pub albedo: [f32; 3],
}

/// The host's mesh: one world-space triangle list.
pub struct HostMesh {
    vertices: wgpu::Buffer,
    count: u32,
}

impl HostMesh {
    /// Uploads a triangle list.
    pub fn new(device: &wgpu::Device, vertices: &[HostVertex]) -> Self {
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("host mesh"),
            contents: bytemuck::cast_slice(vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        Self { vertices: buffer, count: vertices.len() as u32 }
    }

    /// A Gnomon scene's instances, baked into the host's layout: what the host would
    /// draw if it kept its geometry in a Gnomon scene too.
    pub fn from_scene(device: &wgpu::Device, scene: &Scene) -> Self {
        let mut vertices = Vec::new();
        for instance in &scene.instances {
            let mesh = &scene.meshes[instance.mesh];
            let albedo = scene.materials[instance.material].base_color.to_array();
            let m = instance.world_from_object;
            // Normals go through the inverse transpose.
            let normal_from_object = glam::Mat3::from_mat4(m).inverse().transpose();
            for &index in &mesh.indices {
                let i = index as usize;
                let normal = mesh.normals.get(i).copied().unwrap_or(Vec3::Y);
                vertices.push(HostVertex {
                    position: m.transform_point3(mesh.positions[i]).to_array(),
                    normal: (normal_from_object * normal).normalize_or_zero().to_array(),
                    albedo,
                });
            }
        }
        Self::new(device, &vertices)
    }
}

/// The views a host frame draws into, all of one size.
pub struct HostTargets<'a> {
    /// Colour, in the format the renderer was made for.
    pub color: &'a wgpu::TextureView,
    /// [`VISIBILITY_FORMAT`].
    pub visibility: &'a wgpu::TextureView,
    /// [`DEPTH_FORMAT`].
    pub depth: &'a wgpu::TextureView,
}

/// The host's pipelines (one per receiver variant), camera uniform and layouts.
pub struct HostRenderer {
    color_format: wgpu::TextureFormat,
    layout: wgpu::PipelineLayout,
    camera: wgpu::Buffer,
    camera_group: wgpu::BindGroup,
    pipelines: HashMap<ReceiverVariant, wgpu::RenderPipeline>,
}

impl HostRenderer {
    /// A host renderer drawing into `color_format`, reading shadows through
    /// `gnomon`'s receiver layout.
    pub fn new(device: &wgpu::Device, gnomon: &Renderer, color_format: wgpu::TextureFormat) -> Self {
        let camera_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("host camera"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("host"),
            // Group 0 is the host's; Gnomon's receiver is group 1 (RECEIVER_GROUP).
            bind_group_layouts: &[Some(&camera_layout), Some(gnomon.receiver_layout())],
            immediate_size: 0,
        });
        let camera = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("host camera"),
            size: size_of::<Mat4>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let camera_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("host camera"),
            layout: &camera_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: camera.as_entire_binding() }],
        });
        Self { color_format, layout, camera, camera_group, pipelines: HashMap::new() }
    }

    /// Sets the camera the next draws see the scene from.
    pub fn set_camera(&self, queue: &wgpu::Queue, clip_from_world: Mat4) {
        queue.write_buffer(&self.camera, 0, bytemuck::bytes_of(&clip_from_world));
    }

    /// Draws `mesh`, lit by one light and shadowed by it, into `targets`, cleared first.
    pub fn draw(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        targets: &HostTargets,
        light: &LightShadows,
        mesh: &HostMesh,
    ) {
        let pipeline = self.pipeline(device, light.variant);
        let color = |view, clear| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
            })
        };
        let sky = wgpu::Color { r: 0.42, g: 0.55, b: 0.72, a: 1.0 };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("host"),
            color_attachments: &[color(targets.color, sky), color(targets.visibility, NOTHING_DRAWN)],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: targets.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.camera_group, &[]);
        pass.set_bind_group(RECEIVER_GROUP, &light.bind_group, &[]);
        pass.set_vertex_buffer(0, mesh.vertices.slice(..));
        pass.draw(0..mesh.count, 0..1);
    }

    /// The pipeline of a receiver variant: Gnomon's receiver module, then the host's.
    fn pipeline(&mut self, device: &wgpu::Device, variant: ReceiverVariant) -> &wgpu::RenderPipeline {
        let Self { color_format, layout, pipelines, .. } = self;
        pipelines.entry(variant).or_insert_with(|| {
            let source = variant.wgsl(RECEIVER_GROUP) + include_str!("host.wgsl");
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("host"),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("host"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("host_vs"),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: size_of::<HostVertex>() as u64,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3],
                    })],
                },
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("host_fs"),
                    compilation_options: Default::default(),
                    targets: &[Some((*color_format).into()), Some(VISIBILITY_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        })
    }
}
