//! A scene uploaded to the GPU: every mesh in one vertex and one index buffer, every
//! instance in one storage buffer, so that a draw changes no bind group and no
//! vertex buffer, only the index range and the instance range. The instances are
//! grouped into batches (same mesh, material texture and pipeline state), each with a
//! [`CullTree`] and stored in its order, so that culling a batch against a frustum
//! yields runs of consecutive instances: instanced draws, whatever the instance count.

mod batches;
mod materials;
pub(crate) mod shadow_items;

use gnomon_math::Aabb;
use gnomon_scene::{AlphaMode, Motion, Scene};
use rayon::prelude::*;
use wgpu::util::DeviceExt;

pub(crate) use batches::{Batch, CullView, Granularity, LayerFaces, Run, Visible};
use batches::{MeshRange, batch_instances};
pub use shadow_items::GpuCullUnavailable;
use shadow_items::ShadowItems;

use crate::{
    Gpu, RenderError,
    clusters::{MeshClusters, cluster_mesh, place_clusters},
    gpu_types::{INSTANCE_SLOT, InstanceGpu, SeenFaces, VertexGpu, VertexStream},
    passes::Layouts,
};

/// Which index buffer a pass draws from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum IndexOrder {
    /// The meshes' own triangle order: the passes from the camera.
    Scene,
    /// Large meshes in cluster order (`crate::clusters`): the shadow passes.
    Clusters,
}

/// The GPU copy of a [`Scene`]'s geometry, instances and textures.
pub struct GpuScene {
    pub(crate) vertices: wgpu::Buffer,
    /// The vertices' positions alone, for the shadow pass's position-only stream.
    pub(crate) positions: wgpu::Buffer,
    pub(crate) indices: wgpu::Buffer,
    /// The same triangles, with each clustered mesh's in cluster order: what the
    /// shadow passes draw from.
    shadow_indices: wgpu::Buffer,
    pub(crate) instances: wgpu::Buffer,
    /// Batches sorted by material group, so a bind group changes only between groups.
    pub(crate) batches: Vec<Batch>,
    /// The shadow casters' BVH for ray-traced refinement, built on first use
    /// ([`GpuScene::build_rays`]).
    /// Or why the device cannot take it, kept so that it is not built again.
    rays: std::sync::OnceLock<Result<crate::rays::GpuBvh, crate::rays::RaysUnavailable>>,
    /// The shadow casters as the GPU culler reads them, uploaded on first use
    /// ([`GpuScene::shadow_items`]), or why the device cannot take them.
    shadow_items: std::sync::OnceLock<Result<ShadowItems, GpuCullUnavailable>>,
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
    /// Each mesh's winding where the camera draws only its outer faces: a closed
    /// mesh's, true where they wind counter-clockwise ([`SeenFaces::of`]).
    mesh_windings: Vec<Option<bool>>,
    /// Each mesh's clusters, where a batch of one instance draws a large mesh.
    mesh_clusters: Vec<Option<MeshClusters>>,
    /// Names what the still casters (`Motion::Static`) look like: unique to this upload,
    /// and renewed whenever one of them moves. A cached map drawn under another
    /// generation is drawn again.
    pub(crate) still_generation: u64,
    /// Names where every caster stands: unique to this upload, and renewed whenever
    /// any instance moves. A penumbra history kept under another generation is
    /// thrown away (`frame/penumbra_history.rs`).
    pub(crate) caster_generation: u64,
}

/// The next [`GpuScene::still_generation`], unique in the process.
fn next_generation() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// Every mesh's vertices and indices in one buffer each, and where each mesh lies.
struct PackedMeshes {
    vertices: Vec<VertexGpu>,
    indices: Vec<u32>,
    ranges: Vec<MeshRange>,
}

impl PackedMeshes {
    fn of(scene: &Scene) -> Self {
        let mut packed = PackedMeshes {
            vertices: Vec::new(),
            indices: Vec::new(),
            ranges: Vec::with_capacity(scene.meshes.len()),
        };
        for mesh in &scene.meshes {
            packed.ranges.push(MeshRange {
                first_index: packed.indices.len() as u32,
                index_count: mesh.indices.len() as u32,
                base_vertex: packed.vertices.len() as i32,
            });
            packed.vertices.extend(mesh.positions.iter().zip(&mesh.normals).zip(&mesh.uvs).map(
                |((p, n), uv)| VertexGpu { position: p.to_array(), normal: n.to_array(), uv: uv.to_array() },
            ));
            packed.indices.extend_from_slice(&mesh.indices);
        }
        packed
    }
}

/// The instances' records must fit one storage binding and one buffer of the device.
fn check_instance_bytes(gpu: &Gpu, scene: &Scene, instance_data: &[InstanceGpu]) -> Result<(), RenderError> {
    let instance_bytes = std::mem::size_of_val(instance_data) as u64;
    let limit = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
    if instance_bytes > limit {
        return Err(RenderError::SceneTooLarge {
            scene: scene.name.clone(),
            instances: instance_data.len(),
            bytes: instance_bytes,
            limit,
            max_instances: limit / std::mem::size_of::<InstanceGpu>() as u64,
        });
    }
    Ok(())
}

impl GpuScene {
    pub(crate) fn upload(gpu: &Gpu, scene: &Scene, layouts: &Layouts) -> Result<Self, RenderError> {
        scene.validate()?;
        if scene.instances.is_empty() || scene.triangle_count() == 0 {
            return Err(RenderError::EmptyScene(scene.name.clone()));
        }
        let PackedMeshes { vertices, indices, ranges } = PackedMeshes::of(scene);
        let positions: Vec<[f32; 3]> = vertices.iter().map(|v| v.position).collect();
        let mesh_bounds: Vec<Aabb> = scene.meshes.iter().map(|m| m.bounds()).collect();

        let closed = scene.closed_meshes();
        let mesh_windings = mesh_windings(scene, &closed);
        let (mut batches, order) = batch_instances(scene, &ranges, &mesh_bounds, &closed);
        let mesh_clusters = cluster_meshes(scene, &batches);
        let mut shadow_indices = indices.clone();
        for (range, clusters) in ranges.iter().zip(&mesh_clusters) {
            if let Some(clusters) = clusters {
                let start = range.first_index as usize;
                shadow_indices[start..start + clusters.indices.len()].copy_from_slice(&clusters.indices);
            }
        }
        for batch in batches.iter_mut().filter(|b| b.tree.len() == 1) {
            if let Some(clusters) = &mesh_clusters[batch.mesh] {
                let placed = &scene.instances[order[batch.first_instance as usize]];
                batch.clusters = place_clusters(
                    &scene.meshes[batch.mesh],
                    clusters,
                    batch.first_index,
                    placed.world_from_object,
                );
            }
        }
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
        let instance_data: Vec<InstanceGpu> =
            order.iter().map(|&i| instance_gpu(scene, i, &mesh_windings)).collect();
        check_instance_bytes(gpu, scene, &instance_data)?;
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
            shadow_indices: buffer(
                "scene indices, clustered",
                bytemuck::cast_slice(&shadow_indices),
                wgpu::BufferUsages::INDEX,
            ),
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
            shadow_items: std::sync::OnceLock::new(),
            shadow_order,
            material_groups: materials::material_groups(gpu, scene, layouts),
            bounds,
            slots,
            mesh_bounds,
            mesh_windings,
            mesh_clusters,
            still_generation: next_generation(),
            caster_generation: next_generation(),
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
                    bytemuck::bytes_of(&instance_gpu(scene, index, &self.mesh_windings)),
                );
                // The batches hold consecutive slots, in order.
                let batch = self.batches.partition_point(|b| b.first_instance <= slot) - 1;
                let inst = &scene.instances[index];
                let bounds = self.mesh_bounds[inst.mesh].transformed(inst.world_from_object);
                refits[batch].push((slot - self.batches[batch].first_instance, bounds));
            }
        })?;
        self.caster_generation = next_generation();
        // The upload's grouping decides: a batch of still casters that moved leaves
        // every cached map stale.
        if refits.iter().zip(&self.batches).any(|(moved, b)| !moved.is_empty() && b.motion == Motion::Static)
        {
            self.still_generation = next_generation();
        }
        let moved_batches: Vec<usize> = (0..self.batches.len()).filter(|&b| !refits[b].is_empty()).collect();
        for (batch, moved) in self.batches.iter_mut().zip(refits) {
            if moved.is_empty() {
                continue;
            }
            batch.tree.refit(moved);
            if let Some(clusters) = &self.mesh_clusters[batch.mesh]
                && !batch.clusters.is_empty()
            {
                let slot = batch.first_instance;
                let index =
                    self.slots.iter().position(|&s| s == Some(slot)).expect("every slot is an instance's");
                let world_from_object = scene.instances[index].world_from_object;
                batch.clusters =
                    place_clusters(&scene.meshes[batch.mesh], clusters, batch.first_index, world_from_object);
            }
        }
        self.bounds = self.batches.iter().map(|b| b.tree.bounds()).fold(Aabb::EMPTY, Aabb::union);
        if let Some(Ok(items)) = self.shadow_items.get() {
            gpu.checked("moving the shadow items", || {
                for &batch in &moved_batches {
                    items.rewrite(&gpu.queue, &self.batches, batch);
                }
            })?;
        }
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

    /// The shadow casters as the GPU culler reads them, uploaded once. Ok(Err) says
    /// why this device cannot cull them (the same answer every time); Err is a
    /// failure of the device.
    pub(crate) fn shadow_items(
        &self,
        gpu: &Gpu,
    ) -> Result<Result<&ShadowItems, GpuCullUnavailable>, RenderError> {
        if self.shadow_items.get().is_none() {
            let uploaded = ShadowItems::upload(gpu, &self.batches, &self.shadow_order)?;
            // Another thread may have uploaded them meanwhile: either is the same.
            let _ = self.shadow_items.set(uploaded);
        }
        let uploaded = self.shadow_items.get().expect("set above");
        Ok(uploaded.as_ref().map_err(Clone::clone))
    }

    /// The shadow items, if [`GpuScene::shadow_items`] has uploaded them.
    pub(crate) fn uploaded_shadow_items(&self) -> Option<&ShadowItems> {
        self.shadow_items.get().and_then(|uploaded| uploaded.as_ref().ok())
    }

    /// The casters' BVH, if [`GpuScene::build_rays`] has built it.
    pub(crate) fn rays(&self) -> Option<&crate::rays::GpuBvh> {
        self.rays.get().and_then(|built| built.as_ref().ok())
    }

    /// How many instances were uploaded (those with geometry).
    pub fn instance_count(&self) -> usize {
        self.batches.iter().map(|b| b.tree.len()).sum()
    }

    /// The world bounds of each batch of moving casters (`Motion::Dynamic`): where
    /// their shadows fall in a light's map this frame.
    pub(crate) fn moving_caster_bounds(&self) -> Vec<Aabb> {
        self.batches
            .iter()
            .filter(|b| b.casts_shadow && b.motion == gnomon_scene::Motion::Dynamic && !b.tree.is_empty())
            .map(|b| b.tree.bounds())
            .collect()
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
            batch.push_runs(index, &runs, view, &mut visible);
        }
        visible
    }

    /// Binds the shared index buffer, the instance transforms and `stream`: what
    /// every pipeline declaring [`VertexStream::buffers`] reads.
    pub(crate) fn bind_geometry(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        stream: VertexStream,
        order: IndexOrder,
    ) {
        let indices = match order {
            IndexOrder::Scene => &self.indices,
            IndexOrder::Clusters => &self.shadow_indices,
        };
        pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
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

    /// The arguments of every run of `visible`, in order: what
    /// [`GpuScene::draw_visible`] reads to draw them indirectly.
    pub(crate) fn visible_arguments(&self, visible: &Visible) -> Vec<DrawArgs> {
        visible.runs.iter().map(|run| DrawArgs::of(&self.batches[run.batch as usize], run)).collect()
    }

    /// Binds the geometry and draws `visible`, each material's texture bound as group
    /// `material_group` when it changes: each run of draws under one texture as one
    /// multi-draw from `arguments` ([`GpuScene::visible_arguments`]) where given,
    /// else one by one. Returns (draws, bind group changes).
    pub(crate) fn draw_visible(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        visible: &Visible,
        material_group: u32,
        arguments: Option<&wgpu::Buffer>,
    ) -> (u32, u32) {
        self.bind_geometry(pass, VertexStream::Full, IndexOrder::Scene);
        let mut binds = 0;
        let texture = |run: &Run| self.batches[run.batch as usize].material_group;
        let mut first = 0u32;
        // The camera's view culls batches in their order, sorted by texture: each
        // texture's runs come together.
        for runs in visible.runs.chunk_by(|a, b| texture(a) == texture(b)) {
            pass.set_bind_group(material_group, &self.material_groups[texture(&runs[0])], &[]);
            binds += 1;
            match arguments {
                Some(buffer) => pass.multi_draw_indexed_indirect(
                    buffer,
                    u64::from(first) * DrawArgs::SIZE,
                    runs.len() as u32,
                ),
                None => {
                    for run in runs {
                        Self::draw_run(pass, &self.batches[run.batch as usize], run);
                    }
                }
            }
            first += runs.len() as u32;
        }
        (visible.runs.len() as u32, binds)
    }

    /// Issues one instanced draw of `run`, of `batch`.
    pub(crate) fn draw_run(pass: &mut wgpu::RenderPass<'_>, batch: &Batch, run: &Run) {
        pass.draw_indexed(run.indices.clone(), batch.base_vertex, run.instances.clone());
    }
}

/// One draw's arguments as an indirect draw reads them (Vulkan's
/// `VkDrawIndexedIndirectCommand`, wgpu's `DrawIndexedIndirectArgs`): what
/// [`GpuScene::draw_run`] passes to `draw_indexed`, from a buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct DrawArgs {
    pub index_count: u32,
    pub instance_count: u32,
    pub first_index: u32,
    pub base_vertex: i32,
    pub first_instance: u32,
}

impl DrawArgs {
    /// Bytes from one draw's arguments to the next's.
    pub const SIZE: u64 = std::mem::size_of::<DrawArgs>() as u64;

    /// The arguments of `run`, of `batch`.
    pub fn of(batch: &Batch, run: &Run) -> Self {
        DrawArgs {
            index_count: run.indices.end - run.indices.start,
            instance_count: run.instances.end - run.instances.start,
            first_index: run.indices.start,
            base_vertex: batch.base_vertex,
            first_instance: run.instances.start,
        }
    }
}

const _: () = assert!(DrawArgs::SIZE == 20, "tightly packed, as indirect draws read them");

/// The clusters of each mesh that a batch of one shadow-casting instance draws
/// (meshes drawn by several instances are culled instance by instance), built in
/// parallel.
fn cluster_meshes(scene: &Scene, batches: &[Batch]) -> Vec<Option<MeshClusters>> {
    let mut wanted = vec![false; scene.meshes.len()];
    for batch in batches.iter().filter(|b| b.casts_shadow && b.tree.len() == 1) {
        wanted[batch.mesh] = true;
    }
    scene
        .meshes
        .par_iter()
        .zip(wanted)
        .map(|(mesh, wanted)| if wanted { cluster_mesh(mesh) } else { None })
        .collect()
}

/// Each mesh's winding, given which are `closed`: for a closed mesh that encloses a
/// volume, whether its outer faces wind counter-clockwise seen from outside
/// ([`gnomon_scene::Mesh::signed_volume`]); None for the others, of which the camera
/// draws both faces.
fn mesh_windings(scene: &Scene, closed: &[bool]) -> Vec<Option<bool>> {
    scene
        .meshes
        .iter()
        .zip(closed)
        .map(|(mesh, &closed)| {
            let volume = if closed { mesh.signed_volume() } else { 0.0 };
            (volume != 0.0).then_some(volume > 0.0)
        })
        .collect()
}

/// The GPU record of the scene's instance `i`, whose mesh's winding `windings` holds
/// ([`mesh_windings`]).
fn instance_gpu(scene: &Scene, i: usize, windings: &[Option<bool>]) -> InstanceGpu {
    let inst = &scene.instances[i];
    let material = &scene.materials[inst.material];
    let outward = windings[inst.mesh].filter(|_| !material.double_sided);
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
        seen_faces: SeenFaces::of(outward, inst.world_from_object) as u32,
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
