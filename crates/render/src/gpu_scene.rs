//! A scene uploaded to the GPU: every mesh in one vertex and one index buffer, every
//! instance in one storage buffer, so that a draw changes no bind group and no
//! vertex buffer, only the index range and the instance index.

use glam::{Mat3, Mat4, Vec4};
use gnomon_math::Aabb;
use gnomon_scene::{AlphaMode, Scene, Texture, Wrap};
use wgpu::util::DeviceExt;

use crate::{
    Gpu, RenderError,
    gpu_types::{InstanceGpu, VertexGpu},
    passes::Layouts,
};

/// Where one mesh lives in the shared buffers.
#[derive(Clone, Copy, Debug)]
struct MeshRange {
    first_index: u32,
    index_count: u32,
    base_vertex: i32,
}

/// One draw: a mesh range and the instance whose data the shaders read.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Draw {
    pub first_index: u32,
    pub index_count: u32,
    pub base_vertex: i32,
    /// The first instance; the draw covers `instance .. instance + instance_count`.
    pub instance: u32,
    pub instance_count: u32,
    pub casts_shadow: bool,
    /// Alpha-tested (glTF MASK): the shadow pass must sample the texture.
    pub masked: bool,
    /// Both faces cast shadows (glTF `doubleSided`), whatever the cull setting.
    pub double_sided: bool,
    /// Index into [`GpuScene::material_groups`]: the texture this draw samples.
    pub material_group: usize,
}

/// The GPU copy of a [`Scene`]'s geometry, instances and textures.
pub struct GpuScene {
    pub(crate) vertices: wgpu::Buffer,
    pub(crate) indices: wgpu::Buffer,
    pub(crate) instances: wgpu::Buffer,
    /// Draws sorted by material group, so a bind group changes only between groups.
    pub(crate) draws: Vec<Draw>,
    /// One bind group per texture, plus a 1×1 white one (index 0) for untextured draws.
    pub(crate) material_groups: Vec<wgpu::BindGroup>,
    /// Each instance's world-space bounds, for culling casters per light.
    pub(crate) instance_bounds: Vec<Aabb>,
}

impl GpuScene {
    pub(crate) fn upload(gpu: &Gpu, scene: &Scene, layouts: &Layouts) -> Result<Self, RenderError> {
        scene.validate()?;
        if scene.instances.is_empty() || scene.triangle_count() == 0 {
            return Err(RenderError::EmptyScene(scene.name.clone()));
        }
        let mut vertices = Vec::new();
        let mut indices = Vec::new();
        let mut ranges = Vec::with_capacity(scene.meshes.len());
        for mesh in &scene.meshes {
            ranges.push(MeshRange {
                first_index: indices.len() as u32,
                index_count: mesh.indices.len() as u32,
                base_vertex: vertices.len() as i32,
            });
            vertices.extend(mesh.positions.iter().zip(&mesh.normals).zip(&mesh.uvs).map(|((p, n), uv)| {
                VertexGpu { position: p.to_array(), normal: n.to_array(), uv: uv.to_array() }
            }));
            indices.extend_from_slice(&mesh.indices);
        }
        let instance_data: Vec<InstanceGpu> = scene
            .instances
            .iter()
            .enumerate()
            .map(|(i, inst)| {
                let material = &scene.materials[inst.material];
                let normal = Mat3::from_mat4(inst.world_from_object).inverse().transpose();
                let cutoff = match material.alpha_mode {
                    AlphaMode::Mask { cutoff } => cutoff,
                    AlphaMode::Opaque | AlphaMode::Blend => -1.0,
                };
                InstanceGpu {
                    world_from_object: inst.world_from_object,
                    normal_from_object: Mat4::from_mat3(normal),
                    base_color: material.base_color.extend(material.alpha),
                    material: Vec4::new(material.specular, material.shininess, (i + 1) as f32, cutoff),
                    texturing: Vec4::new(
                        f32::from(u8::from(material.base_color_texture.is_some())),
                        0.0,
                        0.0,
                        0.0,
                    ),
                }
            })
            .collect();
        let mut draws: Vec<Draw> = scene
            .instances
            .iter()
            .enumerate()
            .filter(|(_, inst)| !scene.meshes[inst.mesh].indices.is_empty())
            .map(|(i, inst)| {
                let r = ranges[inst.mesh];
                let material = &scene.materials[inst.material];
                Draw {
                    first_index: r.first_index,
                    index_count: r.index_count,
                    base_vertex: r.base_vertex,
                    instance: i as u32,
                    instance_count: 1,
                    casts_shadow: inst.casts_shadow,
                    masked: matches!(material.alpha_mode, AlphaMode::Mask { .. }),
                    double_sided: material.double_sided,
                    material_group: material.base_color_texture.map_or(0, |t| t + 1),
                }
            })
            .collect();
        draws.sort_by_key(|d| (d.material_group, d.instance));
        let draws = coalesce(draws);
        let device = &gpu.device;
        gpu.checked("uploading the scene", || Self {
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene vertices"),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene indices"),
                contents: bytemuck::cast_slice(&indices),
                usage: wgpu::BufferUsages::INDEX,
            }),
            instances: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene instances"),
                contents: bytemuck::cast_slice(&instance_data),
                usage: wgpu::BufferUsages::STORAGE,
            }),
            draws,
            material_groups: material_groups(gpu, scene, layouts),
            instance_bounds: scene
                .instances
                .iter()
                .map(|i| scene.meshes[i.mesh].bounds().transformed(i.world_from_object))
                .collect(),
        })
    }

    /// Binds the shared vertex and index buffers.
    pub(crate) fn bind_geometry(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
    }

    /// Binds the geometry and draws every instance as seen from the camera, each
    /// material's texture bound as group `material_group` when it changes. Returns
    /// (draw calls, bind group changes).
    pub(crate) fn draw_everything(&self, pass: &mut wgpu::RenderPass<'_>, material_group: u32) -> (u32, u32) {
        self.bind_geometry(pass);
        let (mut draws, mut binds) = (0, 0);
        let mut bound = None;
        for d in &self.draws {
            if bound != Some(d.material_group) {
                pass.set_bind_group(material_group, &self.material_groups[d.material_group], &[]);
                bound = Some(d.material_group);
                binds += 1;
            }
            Self::draw_one(pass, d);
            draws += 1;
        }
        (draws, binds)
    }

    /// Issues one draw.
    pub(crate) fn draw_one(pass: &mut wgpu::RenderPass<'_>, d: &Draw) {
        pass.draw_indexed(
            d.first_index..d.first_index + d.index_count,
            d.base_vertex,
            d.instance..d.instance + d.instance_count,
        );
    }
}

/// Merges runs of draws of the same mesh with consecutive instances and the same
/// state into one instanced draw: a row of identical columns is one draw call.
fn coalesce(draws: Vec<Draw>) -> Vec<Draw> {
    let mut out: Vec<Draw> = Vec::with_capacity(draws.len());
    for d in draws {
        if let Some(last) = out.last_mut()
            && last.first_index == d.first_index
            && last.index_count == d.index_count
            && last.base_vertex == d.base_vertex
            && last.instance + last.instance_count == d.instance
            && (last.casts_shadow, last.masked, last.double_sided, last.material_group)
                == (d.casts_shadow, d.masked, d.double_sided, d.material_group)
        {
            last.instance_count += 1;
            continue;
        }
        out.push(d);
    }
    out
}

/// A bind group per texture (after a white 1×1 default at index 0), each texture
/// with the sampler its glTF sampler asks for.
fn material_groups(gpu: &Gpu, scene: &Scene, layouts: &Layouts) -> Vec<wgpu::BindGroup> {
    let device = &gpu.device;
    let white = Texture {
        name: "white".into(),
        width: 1,
        height: 1,
        rgba8: vec![255; 4],
        wrap_u: Wrap::Repeat,
        wrap_v: Wrap::Repeat,
        nearest: true,
    };
    std::iter::once(&white)
        .chain(&scene.textures)
        .map(|t| {
            let texture = device.create_texture_with_data(
                &gpu.queue,
                &wgpu::TextureDescriptor {
                    label: Some(&t.name),
                    size: wgpu::Extent3d { width: t.width, height: t.height, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: wgpu::TextureFormat::Rgba8UnormSrgb,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                },
                wgpu::util::TextureDataOrder::LayerMajor,
                &t.rgba8,
            );
            let address = |w: Wrap| match w {
                Wrap::Repeat => wgpu::AddressMode::Repeat,
                Wrap::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
                Wrap::ClampToEdge => wgpu::AddressMode::ClampToEdge,
            };
            let filter = if t.nearest { wgpu::FilterMode::Nearest } else { wgpu::FilterMode::Linear };
            let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(&t.name),
                address_mode_u: address(t.wrap_u),
                address_mode_v: address(t.wrap_v),
                mag_filter: filter,
                min_filter: filter,
                ..Default::default()
            });
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&t.name),
                layout: &layouts.material,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(
                            &texture.create_view(&Default::default()),
                        ),
                    },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&sampler) },
                ],
            })
        })
        .collect()
}
