//! The shadow casters as the GPU culler reads them (`passes/gpu_cull.wgsl`): one item
//! per instance of a batch drawn whole and one per cluster of a large mesh drawn
//! once, each with its world box, its cone of normals and its draw's arguments,
//! grouped into buckets of the items one multi-draw can cover (same cull state,
//! coverage, material texture and motion), in shadow-pass order.
//!
//! The items are the CPU culler's ([`super::Batch::push_runs`] with
//! `Granularity::Clusters`), one by one: the GPU tests each alone where the CPU walks
//! a tree and merges neighbouring clusters, and the same casters reach the map.

use std::ops::Range;

use gnomon_math::{Aabb, facing::NormalCone};
use gnomon_scene::Motion;
use wgpu::util::DeviceExt;

use super::Batch;
use crate::{Gpu, RenderError, passes::shadow::Sides};

/// One item as `ShadowItem` in `gpu_cull.wgsl` reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ItemGpu {
    /// The world box; min > max on some axis for an empty one, which no layer draws.
    pub(crate) min: [f32; 3],
    /// Its bucket, in [`ShadowItems::buckets`].
    pub(crate) bucket: u32,
    pub(crate) max: [f32; 3],
    /// 1 where the item has a cone of normals (`axis`, `sin_half_angle`), else 0.
    pub(crate) has_cone: u32,
    pub(crate) axis: [f32; 3],
    pub(crate) sin_half_angle: f32,
    pub(crate) index_count: u32,
    pub(crate) first_index: u32,
    pub(crate) base_vertex: i32,
    pub(crate) first_instance: u32,
}

const _: () = assert!(std::mem::size_of::<ItemGpu>() == 64, "the layout gpu_cull.wgsl reads");

/// What the draws of a bucket share.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct BucketClass {
    /// The faces that block light: the pipeline's cull mode.
    pub sides: Sides,
    /// Alpha-masked: the pipeline samples `material`.
    pub masked: bool,
    /// The material group an alpha-masked bucket binds; None for opaque ones.
    pub material: Option<usize>,
    /// Whether its casters move: a kept map draws the still ones, the moving ones
    /// are drawn over its copy.
    pub motion: Motion,
}

impl BucketClass {
    /// What the draws of `batch`'s casters share.
    pub fn of(batch: &Batch) -> Self {
        BucketClass {
            sides: batch.sides,
            masked: batch.masked,
            material: batch.masked.then_some(batch.material_group),
            motion: batch.motion,
        }
    }
}

/// A bucket: its class, and where its kept draws go in a layer's arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ItemBucket {
    pub class: BucketClass,
    /// Its first draw's slot in a layer's argument buffer.
    pub first_slot: u32,
    /// How many items it holds: the most draws it can keep.
    pub capacity: u32,
}

/// The items and buckets on the CPU, before upload.
#[derive(Debug, Default)]
pub(crate) struct ItemList {
    pub items: Vec<ItemGpu>,
    pub buckets: Vec<ItemBucket>,
    /// Each batch's items in `items` (empty for one that casts no shadow).
    pub batch_items: Vec<Range<u32>>,
    /// Each batch's bucket (0 for one that casts no shadow).
    pub batch_buckets: Vec<u32>,
}

/// The scene's shadow items on the GPU.
#[derive(Debug)]
pub(crate) struct ShadowItems {
    pub buffer: wgpu::Buffer,
    pub buckets: Vec<ItemBucket>,
    /// How many items the buffer holds.
    pub count: u32,
    batch_items: Vec<Range<u32>>,
    batch_buckets: Vec<u32>,
}

/// Why a light's layers that were to be culled on the GPU
/// (`DrawSubmission::GpuCulled`) were culled on the CPU instead and drawn from
/// uploaded arguments: the same maps, at the CPU's cost (`LightStats::cull_fallback`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GpuCullUnavailable {
    /// Nothing casts a shadow: nothing to cull. Not reported as a fallback.
    #[error("no shadow casters")]
    NoCasters,
    /// The device cannot draw a count it reads from a buffer (wgpu's
    /// `MULTI_DRAW_INDIRECT_COUNT`), which is how the culler's kept draws are drawn.
    #[error("the device cannot draw a count read from a buffer (wgpu's MULTI_DRAW_INDIRECT_COUNT)")]
    NoIndirectCount,
    /// The items exceed the device's storage binding limit.
    #[error("{items} shadow items need {bytes} bytes, over the device's storage binding limit of {limit}")]
    TooLarge {
        /// Shadow items: instances drawn whole, and clusters of large meshes.
        items: u32,
        /// The bytes they need.
        bytes: u64,
        /// The device's storage binding limit, or its buffer size limit if smaller.
        limit: u64,
    },
    /// One workgroup per 64 items exceeds the device's dispatch limit.
    #[error("{items} shadow items need {workgroups} workgroups, over the device's limit of {limit}")]
    TooManyWorkgroups {
        /// Shadow items: instances drawn whole, and clusters of large meshes.
        items: u32,
        /// The workgroups a layer's dispatch needs.
        workgroups: u32,
        /// The device's `max_compute_workgroups_per_dimension`.
        limit: u32,
    },
}

impl ItemList {
    /// The items of every shadow-casting batch, batch by batch in `shadow_order`.
    pub fn of(batches: &[Batch], shadow_order: &[u32]) -> ItemList {
        let mut list = ItemList {
            batch_items: vec![0..0; batches.len()],
            batch_buckets: vec![0; batches.len()],
            ..Default::default()
        };
        for &index in shadow_order {
            let batch = &batches[index as usize];
            if !batch.casts_shadow {
                continue;
            }
            let class = BucketClass::of(batch);
            let bucket = match list.buckets.iter().position(|b| b.class == class) {
                Some(found) => found,
                None => {
                    list.buckets.push(ItemBucket { class, first_slot: 0, capacity: 0 });
                    list.buckets.len() - 1
                }
            };
            let start = list.items.len() as u32;
            list.items.extend(batch_items(batch, bucket as u32));
            let end = list.items.len() as u32;
            list.buckets[bucket].capacity += end - start;
            list.batch_items[index as usize] = start..end;
            list.batch_buckets[index as usize] = bucket as u32;
        }
        let mut next = 0;
        for bucket in &mut list.buckets {
            bucket.first_slot = next;
            next += bucket.capacity;
        }
        list
    }
}

/// The items of `batch`, of bucket `bucket`: its clusters where it has them, else
/// its instances.
fn batch_items(batch: &Batch, bucket: u32) -> Vec<ItemGpu> {
    let item = |bounds: &Aabb, cone: Option<NormalCone>, indices: Range<u32>, instance: u32| {
        let (axis, sin_half_angle) =
            cone.map_or(([0.0; 3], 1.0), |c| (c.axis().as_vec3().to_array(), c.sin_half_angle() as f32));
        ItemGpu {
            min: bounds.min.to_array(),
            bucket,
            max: bounds.max.to_array(),
            has_cone: cone.is_some().into(),
            axis,
            sin_half_angle,
            index_count: indices.end - indices.start,
            first_index: indices.start,
            base_vertex: batch.base_vertex,
            first_instance: instance,
        }
    };
    if batch.clusters.is_empty() {
        let whole = batch.first_index..batch.first_index + batch.index_count;
        let first = batch.first_instance;
        batch
            .tree
            .instance_bounds()
            .iter()
            .zip(first..)
            .map(|(b, i)| item(b, None, whole.clone(), i))
            .collect()
    } else {
        // A clustered batch holds one instance.
        batch
            .clusters
            .iter()
            .map(|c| item(&c.bounds, c.cone, c.indices.clone(), batch.first_instance))
            .collect()
    }
}

impl ShadowItems {
    /// Uploads the items of `batches` (in `shadow_order`), or says why the GPU cannot
    /// cull them.
    pub fn upload(
        gpu: &Gpu,
        batches: &[Batch],
        shadow_order: &[u32],
    ) -> Result<Result<ShadowItems, GpuCullUnavailable>, RenderError> {
        let list = ItemList::of(batches, shadow_order);
        let count = list.items.len() as u32;
        if count == 0 {
            return Ok(Err(GpuCullUnavailable::NoCasters));
        }
        let bytes = std::mem::size_of_val(list.items.as_slice()) as u64;
        let limit = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
        if bytes > limit {
            return Ok(Err(GpuCullUnavailable::TooLarge { items: count, bytes, limit }));
        }
        let workgroups = crate::passes::gpu_cull::workgroups(count);
        let limit = gpu.limits.max_compute_workgroups_per_dimension;
        if workgroups > limit {
            return Ok(Err(GpuCullUnavailable::TooManyWorkgroups { items: count, workgroups, limit }));
        }
        let buffer = gpu.checked("uploading the shadow items", || {
            gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("shadow items"),
                contents: bytemuck::cast_slice(&list.items),
                // Moving an instance rewrites its batch's items in place.
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            })
        })?;
        Ok(Ok(ShadowItems {
            buffer,
            buckets: list.buckets,
            count,
            batch_items: list.batch_items,
            batch_buckets: list.batch_buckets,
        }))
    }

    /// Rewrites the items of batch `index`, whose instances or clusters moved.
    pub fn rewrite(&self, queue: &wgpu::Queue, batches: &[Batch], index: usize) {
        let range = &self.batch_items[index];
        if range.is_empty() {
            return;
        }
        let items = batch_items(&batches[index], self.batch_buckets[index]);
        debug_assert_eq!(items.len() as u32, range.end - range.start, "a move keeps the item count");
        let offset = u64::from(range.start) * std::mem::size_of::<ItemGpu>() as u64;
        queue.write_buffer(&self.buffer, offset, bytemuck::cast_slice(&items));
    }
}

#[cfg(test)]
mod tests {
    use gnomon_scene::builtin;

    use super::*;
    use crate::gpu_scene::batches::{MeshRange, batch_instances};

    /// The batches of `scene`, as an upload groups them (without clusters).
    fn batches_of(scene: &gnomon_scene::Scene) -> Vec<Batch> {
        let mut first_index = 0;
        let ranges: Vec<MeshRange> = scene
            .meshes
            .iter()
            .map(|m| {
                let range = MeshRange { first_index, index_count: m.indices.len() as u32, base_vertex: 0 };
                first_index += m.indices.len() as u32;
                range
            })
            .collect();
        let bounds: Vec<Aabb> = scene.meshes.iter().map(|m| m.bounds()).collect();
        batch_instances(scene, &ranges, &bounds, &scene.closed_meshes()).0
    }

    #[test]
    fn every_caster_is_one_item_and_the_buckets_tile_the_slots() {
        let mut scene = builtin::columns();
        // A moving caster and one that casts no shadow: their own bucket, and no item.
        scene.instances[1].motion = Motion::Dynamic;
        scene.instances[2].casts_shadow = false;
        let batches = batches_of(&scene);
        let order: Vec<u32> = (0..batches.len() as u32).collect();
        let list = ItemList::of(&batches, &order);
        let casters = scene.instances.iter().filter(|i| i.casts_shadow).count();
        assert_eq!(list.items.len(), casters, "one item per casting instance (no clusters here)");
        let mut next = 0;
        for bucket in &list.buckets {
            assert_eq!(bucket.first_slot, next, "the buckets' slots follow one another");
            next += bucket.capacity;
        }
        assert_eq!(next as usize, list.items.len(), "and hold every item");
        for (index, bucket) in list.buckets.iter().enumerate() {
            let held = list.items.iter().filter(|i| i.bucket as usize == index).count();
            assert_eq!(held as u32, bucket.capacity, "bucket {index}");
        }
        assert!(list.buckets.iter().any(|b| b.class.motion == Motion::Dynamic));
        // Each batch's items carry its draw: its instances, its whole mesh.
        for (batch, range) in batches.iter().zip(&list.batch_items) {
            let items = &list.items[range.start as usize..range.end as usize];
            assert_eq!(items.len(), if batch.casts_shadow { batch.tree.len() } else { 0 });
            for (k, item) in items.iter().enumerate() {
                assert_eq!(item.first_instance, batch.first_instance + k as u32);
                assert_eq!((item.first_index, item.index_count), (batch.first_index, batch.index_count));
            }
        }
    }
}
