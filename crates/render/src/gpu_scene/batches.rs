//! How the uploaded instances are grouped and culled: batches of instances that one
//! draw covers, what a view draws of them ([`Visible`], in [`Run`]s), and the culling
//! of a batch for a view, instance by instance or, for a large mesh drawn once,
//! cluster by cluster (`crate::clusters`).

use std::ops::Range;

use gnomon_math::{
    Aabb,
    culling::{CullTree, Frustum},
    facing::{ProjectionCentre, Winding},
};
use gnomon_scene::{AlphaMode, Motion, Scene, settings::CullMode};

use crate::{
    clusters::{Cluster, WindingCull, visible_clusters},
    passes::shadow::{DepthTarget, Sides},
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
    /// Alpha-masked (glTF MASK): the shadow pass must sample the texture.
    pub masked: bool,
    /// Which faces can block light: a double-sided material, or a closed or an
    /// open mesh (what `cull auto` culls by).
    pub sides: Sides,
    /// Index into [`super::GpuScene::material_groups`]: the texture this batch samples.
    pub material_group: usize,
    /// The scene's mesh its instances draw.
    pub mesh: usize,
    /// Whether its instances are expected to move: a cached map leaves them out.
    pub motion: Motion,
    /// The batch's instances, in the order the instance buffer holds them.
    pub(super) tree: CullTree,
    /// Its mesh's clusters placed by its one instance, for shadow layers to cull one
    /// by one; empty for a batch of several instances or a small mesh, drawn whole.
    pub(super) clusters: Vec<Cluster>,
}

/// One draw: a range of a batch's indices (its whole mesh, or some of its clusters)
/// for a range of its instances.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Run {
    /// Index into [`super::GpuScene::batches`].
    pub batch: u32,
    /// The instances drawn, in the instance buffer.
    pub instances: Range<u32>,
    /// The indices drawn, in the index buffer the pass binds.
    pub indices: Range<u32>,
}

/// What a view draws: the runs of each batch that survive culling, in drawing order.
#[derive(Clone, Debug, Default)]
pub(crate) struct Visible {
    pub runs: Vec<Run>,
}

impl Visible {
    /// How many instances the runs hold (an instance drawn in several runs of its
    /// clusters counts once).
    pub fn instances(&self) -> u32 {
        let mut count = 0;
        let mut last: Option<&Range<u32>> = None;
        for run in &self.runs {
            if last != Some(&run.instances) {
                count += run.instances.end - run.instances.start;
            }
            last = Some(&run.instances);
        }
        count
    }

    /// How many triangles the runs draw.
    pub fn triangles(&self) -> u64 {
        let per_run = |run: &Run| {
            u64::from(run.indices.end - run.indices.start) / 3
                * u64::from(run.instances.end - run.instances.start)
        };
        self.runs.iter().map(per_run).sum()
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
    pub granularity: Granularity,
}

/// How finely a view culls.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Granularity {
    /// Instance by instance.
    Instances,
    /// Cluster by cluster where a batch has clusters (a shadow layer's view, whose
    /// index buffer holds meshes in cluster order), skipping those wholly of the
    /// winding its pass culls where `faces` says which.
    Clusters { faces: Option<LayerFaces> },
}

/// What decides the faces a shadow layer's pass culls.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LayerFaces {
    centre: ProjectionCentre,
    target: DepthTarget,
    mode: CullMode,
}

impl LayerFaces {
    /// For a layer drawn through `clip_from_world` into `target` under cull `mode`:
    /// None for a dual-paraboloid layer, which bends its triangles in the vertex
    /// stage, so no matrix tells their winding.
    pub fn of(clip_from_world: glam::Mat4, target: DepthTarget, mode: CullMode) -> Option<LayerFaces> {
        match target {
            DepthTarget::Projected | DepthTarget::CubeFace => {
                Some(LayerFaces { centre: ProjectionCentre::of(clip_from_world), target, mode })
            }
            DepthTarget::Paraboloid => None,
        }
    }

    /// The layer's centre of projection.
    pub fn centre(&self) -> ProjectionCentre {
        self.centre
    }

    /// The winding the pass culls on casters of `sides`, if any.
    pub fn culls(&self, sides: Sides) -> Option<WindingCull> {
        let face = sides.culled_face(self.mode)?;
        let (front, back) = match self.target.front_face() {
            wgpu::FrontFace::Ccw => (Winding::CounterClockwise, Winding::Clockwise),
            wgpu::FrontFace::Cw => (Winding::Clockwise, Winding::CounterClockwise),
        };
        let culled = match face {
            wgpu::Face::Front => front,
            wgpu::Face::Back => back,
        };
        Some(WindingCull { centre: self.centre, culled })
    }
}

impl Batch {
    /// Appends to `visible` the runs of this batch (number `index`) that `view` draws,
    /// given the runs of its instances that reach into the view (`instances`, from the
    /// start of the batch).
    pub(super) fn push_runs(
        &self,
        index: u32,
        instances: &[Range<u32>],
        view: &CullView,
        visible: &mut Visible,
    ) {
        let first = self.first_instance;
        match view.granularity {
            Granularity::Clusters { faces } if !self.clusters.is_empty() && !instances.is_empty() => {
                let winding = faces.and_then(|f| f.culls(self.sides));
                let mut ranges = Vec::new();
                visible_clusters(&self.clusters, &view.frustum, view.near, winding, &mut ranges);
                // A clustered batch holds one instance.
                visible.runs.extend(ranges.into_iter().map(|indices| Run {
                    batch: index,
                    instances: first..first + 1,
                    indices,
                }));
            }
            Granularity::Clusters { .. } | Granularity::Instances => {
                let whole = self.first_index..self.first_index + self.index_count;
                visible.runs.extend(instances.iter().map(|r| Run {
                    batch: index,
                    instances: first + r.start..first + r.end,
                    indices: whole.clone(),
                }));
            }
        }
    }
}

/// Where a mesh lies in the shared vertex and index buffers.
#[derive(Clone, Copy, Debug)]
pub(super) struct MeshRange {
    pub first_index: u32,
    pub index_count: u32,
    pub base_vertex: i32,
}

/// What the instances of one batch share: one draw covers them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct BatchKey {
    /// The base-colour texture's bind group (0 for none).
    material_group: usize,
    masked: bool,
    sides: Sides,
    casts_shadow: bool,
    motion: Motion,
    mesh: usize,
}

/// Groups the instances into batches by everything a draw of them shares, each with
/// its culling tree; returns the batches and the instances in buffer order.
/// `closed` says, per mesh, whether it is closed ([`Scene::closed_meshes`]).
pub(super) fn batch_instances(
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
            motion: inst.motion,
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
        let BatchKey { material_group, masked, sides, casts_shadow, motion, mesh } = key_of(group[0]);
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
            mesh,
            motion,
            tree,
            clusters: Vec::new(),
        });
        order.extend(tree_order.iter().map(|&k| group[k as usize]));
    }
    (batches, order)
}
