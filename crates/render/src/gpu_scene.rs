//! A scene uploaded to the GPU: every mesh in one vertex and one index buffer, every
//! instance in one storage buffer, so that a draw changes no bind group and no
//! vertex buffer, only the index range and the instance range. The instances are
//! grouped into batches (same mesh, material texture and pipeline state), each with a
//! [`CullTree`] and stored in its order, so that culling a batch against a frustum
//! yields runs of consecutive instances: instanced draws, whatever the instance count.

use std::ops::Range;

use gnomon_math::{
    Aabb,
    culling::{CullTree, Frustum},
};
use gnomon_scene::{AlphaMode, Scene, Texture, Wrap};
use rayon::prelude::*;
use wgpu::util::DeviceExt;

use crate::{
    Gpu, RenderError,
    gpu_types::{INSTANCE_SLOT, InstanceGpu, VertexGpu, VertexStream},
    passes::{Layouts, shadow::Sides},
};

/// Instances that share a mesh, a material texture and the state their draws need:
/// `first_instance .. first_instance + tree.len()` in the instance buffer.
#[derive(Debug)]
pub(crate) struct Batch {
    pub first_index: u32,
    pub index_count: u32,
    pub base_vertex: i32,
    pub first_instance: u32,
    pub casts_shadow: bool,
    /// Alpha-tested (glTF MASK): the shadow pass must sample the texture.
    pub masked: bool,
    /// Which faces can block light: a double-sided material, or a closed or an
    /// open mesh (what `cull auto` culls by).
    pub sides: Sides,
    /// Index into [`GpuScene::material_groups`]: the texture this batch samples.
    pub material_group: usize,
    /// The batch's instances, in the order the instance buffer holds them.
    tree: CullTree,
}

/// What a view draws: the runs of instances of each batch that survive culling, in
/// drawing order.
#[derive(Clone, Debug, Default)]
pub(crate) struct Visible {
    /// (batch index, instance range in the instance buffer).
    pub runs: Vec<(u32, Range<u32>)>,
}

impl Visible {
    /// How many instances the runs hold.
    pub fn instances(&self) -> u32 {
        self.runs.iter().map(|(_, r)| r.end - r.start).sum()
    }
}

/// One view to cull for: the casters seen by a shadow-map layer, or every instance
/// seen by the camera.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CullView {
    pub frustum: Frustum,
    /// Whether the frustum's near plane counts (not for a pass that clamps depth).
    pub near: bool,
    pub casters_only: bool,
}

/// The GPU copy of a [`Scene`]'s geometry, instances and textures.
pub struct GpuScene {
    pub(crate) vertices: wgpu::Buffer,
    /// The vertices' positions alone, for the shadow pass's position-only stream.
    pub(crate) positions: wgpu::Buffer,
    pub(crate) indices: wgpu::Buffer,
    pub(crate) instances: wgpu::Buffer,
    /// Batches sorted by material group, so a bind group changes only between groups.
    pub(crate) batches: Vec<Batch>,
    /// The shadow casters' BVH for ray-traced refinement, built on first use
    /// ([`GpuScene::build_rays`]).
    /// Or why the device cannot take it, kept so that it is not built again.
    rays: std::sync::OnceLock<Result<crate::rays::GpuBvh, crate::rays::RaysUnavailable>>,
    /// The batches in shadow-pass order: opaque before alpha-masked, then by cull
    /// state and texture, so that pipelines and bind groups change least.
    shadow_order: Vec<u32>,
    /// One bind group per texture, plus a 1×1 white one (index 0) for untextured draws.
    pub(crate) material_groups: Vec<wgpu::BindGroup>,
    /// The world bounds of every instance: what a light's projection is fitted to.
    pub(crate) bounds: Aabb,
    /// Each scene instance's slot in the instance buffer (None for one without
    /// geometry, which is not uploaded).
    slots: Vec<Option<u32>>,
    /// Each mesh's bounds in its own space, for a moved instance's new box.
    mesh_bounds: Vec<Aabb>,
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
        let positions: Vec<[f32; 3]> = vertices.iter().map(|v| v.position).collect();
        let mesh_bounds: Vec<Aabb> = scene.meshes.iter().map(|m| m.bounds()).collect();

        let closed = scene.closed_meshes();
        let (batches, order) = batch_instances(scene, &ranges, &mesh_bounds, &closed);
        let mut shadow_order: Vec<u32> = (0..batches.len() as u32).collect();
        shadow_order.sort_by_key(|&b| {
            let b = &batches[b as usize];
            (b.masked, b.sides, b.material_group)
        });
        let bounds = batches.iter().map(|b| b.tree.bounds()).fold(Aabb::EMPTY, Aabb::union);

        let mut slots = vec![None; scene.instances.len()];
        for (slot, &index) in order.iter().enumerate() {
            slots[index] = Some(slot as u32);
        }
        let instance_data: Vec<InstanceGpu> = order.iter().map(|&i| instance_gpu(scene, i)).collect();
        let instance_bytes = std::mem::size_of_val(instance_data.as_slice()) as u64;
        let limit = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
        if instance_bytes > limit {
            return Err(RenderError::SceneTooLarge {
                scene: scene.name.clone(),
                instances: instance_data.len(),
                bytes: instance_bytes,
                limit,
                max_instances: limit / std::mem::size_of_val(&instance_data[0]) as u64,
            });
        }
        let device = &gpu.device;
        let buffer = |label: &str, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        gpu.checked("uploading the scene", || Self {
            vertices: buffer("scene vertices", bytemuck::cast_slice(&vertices), wgpu::BufferUsages::VERTEX),
            positions: buffer(
                "scene positions",
                bytemuck::cast_slice(&positions),
                wgpu::BufferUsages::VERTEX,
            ),
            indices: buffer("scene indices", bytemuck::cast_slice(&indices), wgpu::BufferUsages::INDEX),
            // Vertex stages read the matrices as per-instance attributes, fragment
            // stages the materials from storage (`InstanceGpu`).
            instances: buffer(
                "scene instances",
                bytemuck::cast_slice(&instance_data),
                // Moving an instance rewrites its record in place.
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            ),
            batches,
            rays: std::sync::OnceLock::new(),
            shadow_order,
            material_groups: material_groups(gpu, scene, layouts),
            bounds,
            slots,
            mesh_bounds,
        })
    }

    /// Follows instances that moved: `scene` (the one this was uploaded from) holds
    /// the new transforms of the instances numbered in `moved`. Rewrites their
    /// transforms on the GPU, refits the culling trees and the scene's bounds, and
    /// refits the casters' BVH if one was built for rays, all without a rebuild.
    /// Refuses an index that is not the scene's, or a non-finite transform, before
    /// changing anything.
    pub(crate) fn move_instances(
        &mut self,
        gpu: &Gpu,
        scene: &Scene,
        moved: &[usize],
    ) -> Result<(), RenderError> {
        check_moved(scene, self.slots.len(), moved)?;
        let size = std::mem::size_of::<InstanceGpu>() as u64;
        let mut refits: Vec<Vec<(u32, Aabb)>> = vec![Vec::new(); self.batches.len()];
        gpu.checked("moving instances", || {
            for &index in moved {
                let Some(slot) = self.slots[index] else { continue };
                gpu.queue.write_buffer(
                    &self.instances,
                    slot as u64 * size,
                    bytemuck::bytes_of(&instance_gpu(scene, index)),
                );
                // The batches hold consecutive slots, in order.
                let batch = self.batches.partition_point(|b| b.first_instance <= slot) - 1;
                let inst = &scene.instances[index];
                let bounds = self.mesh_bounds[inst.mesh].transformed(inst.world_from_object);
                refits[batch].push((slot - self.batches[batch].first_instance, bounds));
            }
        })?;
        for (batch, moved) in self.batches.iter_mut().zip(refits) {
            if !moved.is_empty() {
                batch.tree.refit(moved);
            }
        }
        self.bounds = self.batches.iter().map(|b| b.tree.bounds()).fold(Aabb::EMPTY, Aabb::union);
        if let Some(Ok(bvh)) = self.rays.get_mut() {
            bvh.refit(gpu, scene, moved)?;
        }
        Ok(())
    }

    /// Builds and uploads the shadow casters' BVH for ray-traced refinement, once:
    /// `scene` must be the one this was uploaded from. Ok(Err) says why this device
    /// cannot trace it (the same answer every time); Err is a failure of the device.
    pub(crate) fn build_rays(
        &self,
        gpu: &Gpu,
        scene: &Scene,
        layout: &wgpu::BindGroupLayout,
    ) -> Result<Result<&crate::rays::GpuBvh, crate::rays::RaysUnavailable>, RenderError> {
        if self.rays.get().is_none() {
            let built = match crate::rays::GpuBvh::upload(gpu, scene, layout) {
                Ok(bvh) => Ok(bvh),
                Err(RenderError::RaysUnavailable(why)) => Err(why),
                Err(failure) => return Err(failure),
            };
            // Another thread may have built it meanwhile: either answer is the same.
            let _ = self.rays.set(built);
        }
        let built = self.rays.get().expect("set above");
        Ok(built.as_ref().map_err(Clone::clone))
    }

    /// The casters' BVH, if [`GpuScene::build_rays`] has built it.
    pub(crate) fn rays(&self) -> Option<&crate::rays::GpuBvh> {
        self.rays.get().and_then(|built| built.as_ref().ok())
    }

    /// How many instances were uploaded (those with geometry).
    pub fn instance_count(&self) -> usize {
        self.batches.iter().map(|b| b.tree.len()).sum()
    }

    /// Culls every view, in parallel: the runs each one draws.
    pub(crate) fn cull(&self, views: &[CullView]) -> Vec<Visible> {
        views.par_iter().map(|view| self.cull_one(view)).collect()
    }

    fn cull_one(&self, view: &CullView) -> Visible {
        let mut visible = Visible::default();
        let mut runs = Vec::new();
        let order: Box<dyn Iterator<Item = u32>> = if view.casters_only {
            Box::new(self.shadow_order.iter().copied())
        } else {
            Box::new(0..self.batches.len() as u32)
        };
        for index in order {
            let batch = &self.batches[index as usize];
            if view.casters_only && !batch.casts_shadow {
                continue;
            }
            runs.clear();
            batch.tree.cull(&view.frustum, view.near, &mut runs);
            let first = batch.first_instance;
            visible.runs.extend(runs.iter().map(|r| (index, first + r.start..first + r.end)));
        }
        visible
    }

    /// Binds the shared index buffer, the instance transforms and `stream`: what
    /// every pipeline declaring [`VertexStream::buffers`] reads.
    pub(crate) fn bind_geometry(&self, pass: &mut wgpu::RenderPass<'_>, stream: VertexStream) {
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_vertex_buffer(INSTANCE_SLOT, self.instances.slice(..));
        self.bind_stream(pass, stream);
    }

    /// Binds `stream` alone, for a pass that changes streams between pipelines.
    pub(crate) fn bind_stream(&self, pass: &mut wgpu::RenderPass<'_>, stream: VertexStream) {
        let vertices = match stream {
            VertexStream::Full => &self.vertices,
            VertexStream::PositionsOnly => &self.positions,
        };
        pass.set_vertex_buffer(0, vertices.slice(..));
    }

    /// Binds the geometry and draws `visible`, each material's texture bound as group
    /// `material_group` when it changes. Returns (draw calls, bind group changes).
    pub(crate) fn draw_visible(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        visible: &Visible,
        material_group: u32,
    ) -> (u32, u32) {
        self.bind_geometry(pass, VertexStream::Full);
        let (mut draws, mut binds) = (0, 0);
        let mut bound = None;
        for (batch, run) in &visible.runs {
            let batch = &self.batches[*batch as usize];
            if bound != Some(batch.material_group) {
                pass.set_bind_group(material_group, &self.material_groups[batch.material_group], &[]);
                bound = Some(batch.material_group);
                binds += 1;
            }
            Self::draw_run(pass, batch, run.clone());
            draws += 1;
        }
        (draws, binds)
    }

    /// Issues one instanced draw of a batch's mesh.
    pub(crate) fn draw_run(pass: &mut wgpu::RenderPass<'_>, batch: &Batch, instances: Range<u32>) {
        pass.draw_indexed(
            batch.first_index..batch.first_index + batch.index_count,
            batch.base_vertex,
            instances,
        );
    }
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

/// Where a mesh lies in the shared vertex and index buffers.
#[derive(Clone, Copy, Debug)]
struct MeshRange {
    first_index: u32,
    index_count: u32,
    base_vertex: i32,
}

/// What the instances of one batch share: one draw covers them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct BatchKey {
    /// The base-colour texture's bind group (0 for none).
    material_group: usize,
    masked: bool,
    sides: Sides,
    casts_shadow: bool,
    mesh: usize,
}

/// Groups the instances into batches by everything a draw of them shares, each with
/// its culling tree; returns the batches and the instances in buffer order.
/// `closed` says, per mesh, whether it is closed ([`Scene::closed_meshes`]).
fn batch_instances(
    scene: &Scene,
    ranges: &[MeshRange],
    mesh_bounds: &[Aabb],
    closed: &[bool],
) -> (Vec<Batch>, Vec<usize>) {
    let key_of = |i: usize| {
        let inst = &scene.instances[i];
        let material = &scene.materials[inst.material];
        BatchKey {
            material_group: material.base_color_texture.map_or(0, |t| t + 1),
            masked: matches!(material.alpha_mode, AlphaMode::Mask { .. }),
            sides: Sides::of(scene, inst, closed),
            casts_shadow: inst.casts_shadow,
            mesh: inst.mesh,
        }
    };
    let mut members: Vec<usize> = (0..scene.instances.len())
        .filter(|&i| !scene.meshes[scene.instances[i].mesh].indices.is_empty())
        .collect();
    members.sort_by_key(|&i| (key_of(i), i));
    let mut order: Vec<usize> = Vec::with_capacity(members.len());
    let mut batches = Vec::new();
    for group in members.chunk_by(|&a, &b| key_of(a) == key_of(b)) {
        let BatchKey { material_group, masked, sides, casts_shadow, mesh } = key_of(group[0]);
        let bounds: Vec<Aabb> = group
            .iter()
            .map(|&i| mesh_bounds[mesh].transformed(scene.instances[i].world_from_object))
            .collect();
        let (tree, tree_order) = CullTree::build(&bounds);
        let MeshRange { first_index, index_count, base_vertex } = ranges[mesh];
        batches.push(Batch {
            first_index,
            index_count,
            base_vertex,
            first_instance: order.len() as u32,
            casts_shadow,
            masked,
            sides,
            material_group,
            tree,
        });
        order.extend(tree_order.iter().map(|&k| group[k as usize]));
    }
    (batches, order)
}

/// The GPU record of the scene's instance `i`.
fn instance_gpu(scene: &Scene, i: usize) -> InstanceGpu {
    let inst = &scene.instances[i];
    let material = &scene.materials[inst.material];
    let cutoff = match material.alpha_mode {
        AlphaMode::Mask { cutoff } => cutoff,
        AlphaMode::Opaque | AlphaMode::Blend => -1.0,
    };
    InstanceGpu {
        world_from_object: inst.world_from_object,
        base_color: material.base_color.extend(material.alpha),
        // The object id is the scene's instance index + 1, whatever the buffer's order.
        specular: material.specular,
        shininess: material.shininess,
        object_id: (i + 1) as u32,
        alpha_cutoff: cutoff,
        textured: material.base_color_texture.is_some().into(),
        _pad0: 0,
        _pad1: 0,
        _pad2: 0,
    }
}

/// Refuses a move in a scene whose instance list is no longer the `uploaded` one's
/// length, a moved instance that is not `scene`'s, or one whose new transform is not
/// finite: what [`GpuScene::move_instances`] and [`crate::rays::ShadowRays`] check
/// before they change anything.
pub(crate) fn check_moved(scene: &Scene, uploaded: usize, moved: &[usize]) -> Result<(), RenderError> {
    let count = scene.instances.len();
    if count != uploaded {
        return Err(RenderError::InstancesChanged { scene: scene.name.clone(), uploaded, now: count });
    }
    for &index in moved {
        let Some(inst) = scene.instances.get(index) else {
            return Err(RenderError::UnknownInstance { scene: scene.name.clone(), index, count });
        };
        if !inst.world_from_object.is_finite() {
            return Err(gnomon_scene::SceneError::NonFiniteTransform {
                scene: scene.name.clone(),
                instance: inst.name.clone(),
            }
            .into());
        }
    }
    Ok(())
}
