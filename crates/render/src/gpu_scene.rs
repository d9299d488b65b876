//! A scene uploaded to the GPU: every mesh in one vertex and one index buffer, every
//! instance in one storage buffer, so that a draw changes no bind group and no
//! vertex buffer, only the index range and the instance index.

use glam::{Mat3, Mat4, Vec4};
use gnomon_scene::Scene;
use wgpu::util::DeviceExt;

use crate::{
    Gpu, RenderError,
    gpu_types::{InstanceGpu, VertexGpu},
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
    pub instance: u32,
    pub casts_shadow: bool,
}

/// The GPU copy of a [`Scene`]'s geometry and instances.
pub struct GpuScene {
    pub(crate) vertices: wgpu::Buffer,
    pub(crate) indices: wgpu::Buffer,
    pub(crate) instances: wgpu::Buffer,
    pub(crate) draws: Vec<Draw>,
}

impl GpuScene {
    pub fn upload(gpu: &Gpu, scene: &Scene) -> Result<Self, RenderError> {
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
                InstanceGpu {
                    world_from_object: inst.world_from_object,
                    normal_from_object: Mat4::from_mat3(normal),
                    base_color: material.base_color.extend(1.0),
                    material: Vec4::new(material.specular, material.shininess, (i + 1) as f32, 0.0),
                }
            })
            .collect();
        let draws = scene
            .instances
            .iter()
            .enumerate()
            .filter(|(_, inst)| !scene.meshes[inst.mesh].indices.is_empty())
            .map(|(i, inst)| {
                let r = ranges[inst.mesh];
                Draw {
                    first_index: r.first_index,
                    index_count: r.index_count,
                    base_vertex: r.base_vertex,
                    instance: i as u32,
                    casts_shadow: inst.casts_shadow,
                }
            })
            .collect();
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
        })
    }

    /// Issues every draw (or only the shadow casters) into `pass`, whose pipeline and
    /// bind groups are already set.
    pub(crate) fn draw(&self, pass: &mut wgpu::RenderPass<'_>, casters_only: bool) {
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        for d in self.draws.iter().filter(|d| d.casts_shadow || !casters_only) {
            pass.draw_indexed(
                d.first_index..d.first_index + d.index_count,
                d.base_vertex,
                d.instance..d.instance + 1,
            );
        }
    }
}
