//! Clusters of a mesh's triangles, so that a shadow layer draws only the part of a
//! large mesh it sees: Sponza is one mesh of 279k triangles, and a cascade that
//! covers a few metres around the camera would otherwise draw all of it.
//!
//! At upload, meshoptimizer (`meshopt::build_meshlets`) splits a mesh into clusters
//! of at most [`MAX_CLUSTER_TRIANGLES`] triangles that share few vertices and face
//! alike, and the shadow pass's index buffer holds the mesh's triangles in cluster
//! order: a cluster, or a run of neighbouring ones, is one index range. Each cluster
//! placed by its instance keeps a world-space box and a cone of normals
//! (`gnomon_math::facing`). A layer then skips the clusters outside its frustum,
//! and those whose every triangle winds the way its pass culls.
//!
//! Nothing a layer draws changes: a skipped cluster has no triangle the rasterizer
//! would have kept, and a depth test with `Less` keeps the nearest depth whatever
//! order the triangles come in. `reference/tests/truth/clusters.rs` holds the maps to that.

use std::ops::Range;

use glam::{Mat4, Vec3};
use gnomon_math::{
    Aabb,
    culling::Frustum,
    facing::{NormalCone, ProjectionCentre, Winding},
};
use gnomon_scene::Mesh;

/// The most triangles in a cluster: meshoptimizer's advice for culling (it must be
/// divisible by 4).
pub(crate) const MAX_CLUSTER_TRIANGLES: usize = 124;
/// The most distinct vertices in a cluster.
#[cfg(feature = "clusters")]
const MAX_CLUSTER_VERTICES: usize = 64;
/// How much meshoptimizer weighs a tight normal cone against a compact cluster,
/// in [0, 1]: cones decide the back-facing clusters a pass skips.
#[cfg(feature = "clusters")]
const CONE_WEIGHT: f32 = 0.5;
/// The fewest triangles a mesh is clustered at: a smaller one is drawn whole, where
/// clusters would add draws and save little.
pub(crate) const MIN_CLUSTERED_TRIANGLES: usize = 4 * MAX_CLUSTER_TRIANGLES;

/// A mesh's triangles in cluster order.
#[derive(Clone, Debug)]
pub(crate) struct MeshClusters {
    /// The mesh's indices, cluster after cluster: the same triangles with the same
    /// corners in the same turn, in another order.
    pub indices: Vec<u32>,
    /// Each cluster's range in `indices`.
    pub ranges: Vec<Range<u32>>,
}

/// Splits `mesh` into clusters, or None where it is too small to gain from them.
pub(crate) fn cluster_mesh(mesh: &Mesh) -> Option<MeshClusters> {
    if mesh.triangle_count() < MIN_CLUSTERED_TRIANGLES {
        return None;
    }
    let (indices, ranges) = build_clusters(mesh)?;
    // Every triangle once: anything else would change the map, so the mesh is then
    // drawn whole.
    (same_triangles(&mesh.indices, &indices)).then_some(MeshClusters { indices, ranges })
}

/// Whether this build clusters large meshes (the `clusters` feature, on by default):
/// without meshoptimizer, which is C++, a build for a target with no C++ compiler
/// (wasm32) culls each mesh whole, per instance, and draws the same maps.
pub const CLUSTERS_BUILT: bool = cfg!(feature = "clusters");

/// meshoptimizer's clusters of `mesh`: the indices in cluster order and each
/// cluster's range.
#[cfg(feature = "clusters")]
fn build_clusters(mesh: &Mesh) -> Option<(Vec<u32>, Vec<Range<u32>>)> {
    let positions: &[u8] = bytemuck::cast_slice(&mesh.positions);
    let adapter = meshopt::VertexDataAdapter::new(positions, std::mem::size_of::<Vec3>(), 0).ok()?;
    let meshlets = meshopt::build_meshlets(
        &mesh.indices,
        &adapter,
        MAX_CLUSTER_VERTICES,
        MAX_CLUSTER_TRIANGLES,
        CONE_WEIGHT,
    );
    let mut indices = Vec::with_capacity(mesh.indices.len());
    let mut ranges = Vec::with_capacity(meshlets.len());
    for meshlet in meshlets.iter() {
        let start = indices.len() as u32;
        indices.extend(meshlet.triangles.iter().map(|&local| meshlet.vertices[usize::from(local)]));
        ranges.push(start..indices.len() as u32);
    }
    Some((indices, ranges))
}

/// Without the `clusters` feature no mesh is clustered ([`CLUSTERS_BUILT`]).
#[cfg(not(feature = "clusters"))]
fn build_clusters(_mesh: &Mesh) -> Option<(Vec<u32>, Vec<Range<u32>>)> {
    None
}

/// Whether `a` and `b` hold the same triangles, each with the same turn of corners.
fn same_triangles(a: &[u32], b: &[u32]) -> bool {
    let canonical = |indices: &[u32]| {
        let mut triangles: Vec<[u32; 3]> = indices
            .chunks_exact(3)
            .map(|t| {
                // Rotate the smallest index first: the same triangle, the same turn.
                let first = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
                [t[first], t[(first + 1) % 3], t[(first + 2) % 3]]
            })
            .collect();
        triangles.sort_unstable();
        triangles
    };
    a.len() == b.len() && canonical(a) == canonical(b)
}

/// A cluster placed in the world by its instance.
#[derive(Clone, Debug)]
pub(crate) struct Cluster {
    /// Its range in the shadow pass's index buffer.
    pub indices: Range<u32>,
    /// The world-space box of its corners.
    pub bounds: Aabb,
    /// The cone of its world-space normals; None where they open too wide.
    pub cone: Option<NormalCone>,
}

/// `clusters` of `mesh` (whose indices start at `first_index` in the index buffer)
/// placed by `world_from_object`. The normals are taken from the placed corners, so a
/// mirroring or shearing transform turns them as the rasterizer sees it.
pub(crate) fn place_clusters(
    mesh: &Mesh,
    clusters: &MeshClusters,
    first_index: u32,
    world_from_object: Mat4,
) -> Vec<Cluster> {
    let world: Vec<Vec3> = mesh.positions.iter().map(|&p| world_from_object.transform_point3(p)).collect();
    clusters
        .ranges
        .iter()
        .map(|range| {
            let indices = &clusters.indices[range.start as usize..range.end as usize];
            let triangles: Vec<[Vec3; 3]> =
                indices.chunks_exact(3).map(|t| [0, 1, 2].map(|k| world[t[k] as usize])).collect();
            Cluster {
                indices: first_index + range.start..first_index + range.end,
                bounds: Aabb::from_points(triangles.iter().flatten().copied()),
                cone: NormalCone::of_triangles(&triangles),
            }
        })
        .collect()
}

/// What a layer's pass discards by winding, for the clusters of one batch.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WindingCull {
    /// The layer's centre of projection.
    pub centre: ProjectionCentre,
    /// The winding its pipeline culls for this batch (in NDC, y up).
    pub culled: Winding,
}

/// Appends to `ranges` the index ranges of the `clusters` that a layer with
/// `frustum` (its near plane counted where `near`) may draw, neighbours merged into
/// one range: those that reach into the frustum and are not wholly of the winding
/// `winding` culls.
pub(crate) fn visible_clusters(
    clusters: &[Cluster],
    frustum: &Frustum,
    near: bool,
    winding: Option<WindingCull>,
    ranges: &mut Vec<Range<u32>>,
) {
    for cluster in clusters {
        if !frustum.intersects(&cluster.bounds, near) {
            continue;
        }
        if let (Some(cull), Some(cone)) = (winding, cluster.cone)
            && cone.winding(&cull.centre, &cluster.bounds) == Some(cull.culled)
        {
            continue;
        }
        match ranges.last_mut() {
            Some(last) if last.end == cluster.indices.start => last.end = cluster.indices.end,
            _ => ranges.push(cluster.indices.clone()),
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use super::*;

    /// A w × h grid of quads in the xz plane, facing +y.
    fn grid(w: u32, h: u32) -> Mesh {
        let mut positions = Vec::new();
        for z in 0..=h {
            for x in 0..=w {
                positions.push(Vec3::new(x as f32, 0.0, z as f32));
            }
        }
        let mut indices = Vec::new();
        for z in 0..h {
            for x in 0..w {
                let i = z * (w + 1) + x;
                indices.extend([i, i + w + 1, i + 1, i + 1, i + w + 1, i + w + 2]);
            }
        }
        let n = positions.len();
        Mesh { name: "grid".into(), positions, normals: vec![Vec3::Y; n], uvs: vec![Vec2::ZERO; n], indices }
    }

    #[test]
    fn clusters_hold_every_triangle_once_in_its_own_turn() {
        let mesh = grid(40, 30);
        let clusters = cluster_mesh(&mesh).expect("2,400 triangles are clustered");
        assert!(same_triangles(&mesh.indices, &clusters.indices));
        assert!(clusters.ranges.len() >= mesh.triangle_count() / MAX_CLUSTER_TRIANGLES);
        let mut next = 0;
        for range in &clusters.ranges {
            assert_eq!(range.start, next, "the ranges tile the indices");
            assert!((range.end - range.start) as usize <= 3 * MAX_CLUSTER_TRIANGLES);
            next = range.end;
        }
        assert_eq!(next as usize, mesh.indices.len());
        assert!(cluster_mesh(&grid(10, 10)).is_none(), "200 triangles are drawn whole");
    }

    #[test]
    fn a_turned_triangle_is_not_the_same_triangle() {
        assert!(same_triangles(&[0, 1, 2, 3, 4, 5], &[4, 5, 3, 1, 2, 0]));
        assert!(!same_triangles(&[0, 1, 2], &[0, 2, 1]));
        assert!(!same_triangles(&[0, 1, 2], &[0, 1, 2, 0, 1, 2]));
    }

    #[test]
    fn a_layer_draws_the_clusters_in_its_frustum_facing_it() {
        let mesh = grid(40, 40);
        let clusters = cluster_mesh(&mesh).unwrap();
        let placed = place_clusters(&mesh, &clusters, 0, Mat4::IDENTITY);
        let every = 0..mesh.indices.len() as u32;
        // A sun overhead looking down at the whole grid, a spot above one corner.
        let view = gnomon_math::view_from_world_look_at(
            Vec3::new(20.0, 10.0, 20.0),
            Vec3::new(20.0, 0.0, 20.0),
            Vec3::Z,
        );
        let whole = glam::camera::rh::proj::directx::orthographic(-25.0, 25.0, -25.0, 25.0, 0.1, 20.0) * view;
        let corner_view =
            gnomon_math::view_from_world_look_at(Vec3::new(2.0, 3.0, 2.0), Vec3::new(2.0, 0.0, 2.0), Vec3::Z);
        let corner = glam::camera::rh::proj::directx::perspective(0.8, 1.0, 0.1, 10.0) * corner_view;
        let count = |ranges: &[Range<u32>]| ranges.iter().map(|r| r.end - r.start).sum::<u32>();

        let mut ranges = Vec::new();
        visible_clusters(&placed, &Frustum::from_clip_from_world(whole), true, None, &mut ranges);
        assert_eq!(ranges, vec![every.clone()], "one merged range");

        ranges.clear();
        visible_clusters(&placed, &Frustum::from_clip_from_world(corner), true, None, &mut ranges);
        let seen = count(&ranges);
        assert!(seen > 0 && seen < every.end / 8, "the corner draws {seen} of {} indices", every.end);

        // The grid faces the sun (+y, toward it): culling clockwise keeps it all,
        // culling counter-clockwise (its turn as the sun sees it) skips it all.
        for (culled, expected) in [(Winding::Clockwise, every.end), (Winding::CounterClockwise, 0)] {
            ranges.clear();
            let cull = WindingCull { centre: ProjectionCentre::of(whole), culled };
            visible_clusters(&placed, &Frustum::from_clip_from_world(whole), true, Some(cull), &mut ranges);
            assert_eq!(count(&ranges), expected, "{culled:?} culled");
        }
    }
}
