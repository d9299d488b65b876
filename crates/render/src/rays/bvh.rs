//! The shadow casters as a GPU ray tracer reads them: every casting instance's
//! triangles in world space, in a binary BVH (obvhs' PLOC builder) flattened into
//! plain arrays that `trace.wgsl` walks, with what the alpha test of a cut-out
//! material needs (its UVs, cutoff and the alpha channel of its texture).
//!
//! Non-casters are left out: a shadow ray only asks whether something blocks it.
//!
//! When instances move, [`CasterBvh::refit`] moves their triangles and refits the
//! boxes bottom-up over the same tree (Wald, Boulos & Shirley, "Ray tracing deformable
//! scenes using dynamic bounding volume hierarchies", ACM TOG 26(1), 2007): linear in
//! the tree's size, with no build, and every box still bounds its subtree, so rays
//! get the same answers as from a fresh build; only traversal slows if instances move
//! far from where the build grouped them.

use std::ops::Range;

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3, Vec3A};
use gnomon_scene::{AlphaMode, Scene, Texture, Wrap};
use obvhs::{
    Boundable, BvhBuildParams,
    aabb::Aabb,
    bvh2::{Bvh2, leaf_collapser::collapse, reinsertion::ReinsertionOptimizer},
    ploc::PlocBuilder,
};
use rayon::prelude::*;

/// The deepest BVH `trace.wgsl` walks: the size of its traversal stack
/// (`TRACE_STACK_SIZE` there, which `rays::wgsl` writes from this constant). A deeper
/// tree is refused at build time rather than traversed wrongly.
pub(crate) const MAX_DEPTH: u32 = 64;

/// Marks a triangle whose material is opaque: no alpha test.
pub(crate) const NO_ALPHA: u32 = u32::MAX;

/// Marks an alpha test with no texture: the material's alpha alone decides.
pub(crate) const NO_TEXTURE: u32 = u32::MAX;

/// A node of the flattened BVH (obvhs' `Bvh2Node`): an inner node when `count` is 0,
/// its children at `first` and `first + 1`; a leaf of `count` triangles from `first`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct NodeGpu {
    pub min: [f32; 3],
    pub count: u32,
    pub max: [f32; 3],
    pub first: u32,
}

/// A world-space triangle, in BVH leaf order.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct TriangleGpu {
    pub v0: [f32; 3],
    /// Index of its [`AlphaGpu`], or [`NO_ALPHA`].
    pub alpha: u32,
    pub v1: [f32; 3],
    /// 1 for a triangle of a closed, opaque mesh (`gnomon_math::topology`), whose
    /// faces on one side of a point a penumbra beam may skip: every segment that
    /// meets the mesh from outside crosses a face of either side
    /// (`penumbra_beam.wgsl`); 0 otherwise.
    pub closed: u32,
    pub v2: [f32; 3],
    pub _pad2: u32,
}

/// The alpha test of one triangle of a cut-out (glTF MASK) material.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct AlphaGpu {
    pub uv0: [f32; 2],
    pub uv1: [f32; 2],
    pub uv2: [f32; 2],
    /// Index of its [`AlphaTextureGpu`], or [`NO_TEXTURE`].
    pub texture: u32,
    /// The material's own alpha, multiplied with the texture's.
    pub base_alpha: f32,
    pub cutoff: f32,
    pub _pad: u32,
}

/// The alpha channel of one texture, one byte a texel packed four to a word from
/// `first_word` of the texel buffer, row by row from the top (v = 0).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct AlphaTextureGpu {
    pub first_word: u32,
    pub width: u32,
    pub height: u32,
    /// [`wrap_code`] of the horizontal wrap.
    pub wrap_u: u32,
    pub wrap_v: u32,
    /// 1 for nearest-texel lookups, 0 for bilinear.
    pub nearest: u32,
    pub _pad0: u32,
    pub _pad1: u32,
}

/// How `trace.wgsl` names a wrap mode.
pub(crate) fn wrap_code(wrap: Wrap) -> u32 {
    match wrap {
        Wrap::Repeat => 0,
        Wrap::MirroredRepeat => 1,
        Wrap::ClampToEdge => 2,
    }
}

/// Where each caster's triangles lie in a built tree: what a refit needs.
#[derive(Debug, Default)]
pub(crate) struct TreeShape {
    /// For each scene instance, its triangles' range in gathering order (empty for
    /// one that casts no shadow).
    instance_triangles: Vec<Range<u32>>,
    /// For each gathered triangle, its position in the leaves (`triangles`).
    leaf_of: Vec<u32>,
    /// For each position in `triangles`, the leaf node holding it.
    leaf_node: Vec<u32>,
    /// Each node's parent ([`NO_PARENT`] for the root) and depth (the root's is 1).
    parent: Vec<u32>,
    depth: Vec<u32>,
    /// The inner nodes, deepest first: the order a refit of the whole tree takes.
    inner_deepest_first: Vec<u32>,
    /// The absolute part of every box's padding (see [`triangle_box`]).
    pad: f32,
}

/// The root's parent in [`TreeShape::parent`].
const NO_PARENT: u32 = u32::MAX;

/// What a refit changed, as runs of elements to upload.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct Refitted {
    pub nodes: Vec<Range<u32>>,
    pub triangles: Vec<Range<u32>>,
}

/// The casters' BVH on the CPU, ready to upload.
#[derive(Debug, Default)]
pub(crate) struct CasterBvh {
    pub nodes: Vec<NodeGpu>,
    pub triangles: Vec<TriangleGpu>,
    pub alpha: Vec<AlphaGpu>,
    pub textures: Vec<AlphaTextureGpu>,
    pub texels: Vec<u32>,
    /// The deepest leaf, counting the root as depth 1.
    pub depth: u32,
    /// The casters' triangles (`triangles` holds one of zero area when there are none).
    pub casters: usize,
    pub shape: TreeShape,
}

/// The caster triangles before the build, with their alpha tests.
struct Gathered {
    triangles: Vec<[Vec3A; 3]>,
    alpha: Vec<Option<AlphaGpu>>,
    /// Whether each triangle's mesh is closed and opaque ([`TriangleGpu::closed`]).
    closed: Vec<bool>,
    /// Per scene instance, its triangles' range (empty for a non-caster).
    instance_triangles: Vec<Range<u32>>,
}

impl CasterBvh {
    /// Gathers the triangles of every instance that casts a shadow and builds the BVH
    /// over them. The scene must be valid ([`Scene::validate`]): its indices are
    /// trusted. With no caster, the tree is one leaf holding a triangle of zero area
    /// at the origin, which every ray misses. (An inverted box is no empty tree: the
    /// slab test's min and max swap it into a box that holds everything.)
    pub fn build(scene: &Scene) -> Self {
        let (textures, texels, texture_slots) = alpha_textures(scene);
        let gathered = gather(scene, &texture_slots);
        let scene_size = scene.bounds().extent().max_element().max(1e-3);
        let pad = 1e-6 * scene_size;
        if gathered.triangles.is_empty() {
            let leaf = NodeGpu { min: [0.0; 3], count: 1, max: [0.0; 3], first: 0 };
            let point = TriangleGpu {
                v0: [0.0; 3],
                alpha: NO_ALPHA,
                v1: [0.0; 3],
                closed: 0,
                v2: [0.0; 3],
                _pad2: 0,
            };
            return Self {
                nodes: vec![leaf],
                triangles: vec![point],
                depth: 1,
                textures,
                texels,
                alpha: vec![],
                casters: 0,
                shape: TreeShape {
                    instance_triangles: gathered.instance_triangles,
                    pad,
                    ..Default::default()
                },
            };
        }
        let boxes: Vec<Aabb> = gathered.triangles.iter().map(|t| triangle_box(t, pad)).collect();
        let bvh = build_tree(
            &boxes,
            // obvhs' slow build (a wider PLOC search, 20 % of nodes reinserted): traces
            // 6–21 % faster than its medium build for a build twice as long, paid once.
            // Without pre-splitting, which would list a large triangle in several
            // leaves where `leaf_of` and the refit expect one (docs/rays.md).
            BvhBuildParams {
                pre_split: false,
                max_prims_per_leaf: 4,
                collapse_traversal_cost: 1.0,
                ..BvhBuildParams::slow_build()
            },
        );
        let mut alpha = Vec::new();
        let triangles = bvh
            .primitive_indices
            .iter()
            .map(|&k| {
                let [v0, v1, v2] = gathered.triangles[k as usize].map(|v| Vec3::from(v).to_array());
                let test = gathered.alpha[k as usize].map_or(NO_ALPHA, |a| {
                    alpha.push(a);
                    alpha.len() as u32 - 1
                });
                TriangleGpu {
                    v0,
                    alpha: test,
                    v1,
                    closed: u32::from(gathered.closed[k as usize]),
                    v2,
                    _pad2: 0,
                }
            })
            .collect();
        let nodes: Vec<NodeGpu> = bvh
            .nodes
            .iter()
            .map(|n| NodeGpu {
                min: Vec3::from(n.aabb.min).to_array(),
                count: n.prim_count,
                max: Vec3::from(n.aabb.max).to_array(),
                first: n.first_index,
            })
            .collect();
        let casters = gathered.triangles.len();
        let mut leaf_of = vec![0u32; casters];
        for (leaf, &k) in bvh.primitive_indices.iter().enumerate() {
            leaf_of[k as usize] = leaf as u32;
        }
        let (parent, node_depth, leaf_node) = tree_links(&nodes, casters);
        let depth = node_depth.iter().copied().max().unwrap_or(1);
        let mut inner_deepest_first: Vec<u32> =
            (0..nodes.len() as u32).filter(|&n| nodes[n as usize].count == 0).collect();
        inner_deepest_first.sort_unstable_by_key(|&n| std::cmp::Reverse(node_depth[n as usize]));
        let shape = TreeShape {
            instance_triangles: gathered.instance_triangles,
            leaf_of,
            leaf_node,
            parent,
            depth: node_depth,
            inner_deepest_first,
            pad,
        };
        Self { nodes, triangles, alpha, textures, texels, depth, casters, shape }
    }

    /// How many instances the scene the tree was built from had.
    pub fn instance_count(&self) -> usize {
        self.shape.instance_triangles.len()
    }

    /// Moves the triangles of the `moved` instances to where `scene` now places them
    /// and refits the boxes above them, keeping the tree's shape: the leaves that hold
    /// a moved triangle and their ancestors, no other, so the cost follows what moved.
    /// `scene` must be the one the tree was built from, with new transforms only.
    /// Returns the runs of nodes and triangles that changed, for the upload.
    pub fn refit(&mut self, scene: &Scene, moved: &[usize]) -> Refitted {
        let mut changed = Vec::new();
        for &index in moved {
            let range = self.shape.instance_triangles.get(index).cloned().unwrap_or_default();
            if range.is_empty() {
                continue;
            }
            let inst = &scene.instances[index];
            let mesh = &scene.meshes[inst.mesh];
            let world =
                |i: u32| inst.world_from_object.transform_point3(mesh.positions[i as usize]).to_array();
            for (k, tri) in range.zip(mesh.indices.chunks_exact(3)) {
                let leaf = self.shape.leaf_of[k as usize];
                let t = &mut self.triangles[leaf as usize];
                (t.v0, t.v1, t.v2) = (world(tri[0]), world(tri[1]), world(tri[2]));
                changed.push(leaf);
            }
        }
        if changed.is_empty() {
            return Refitted::default();
        }
        // Past a quarter of the triangles, walking the paths up from each leaf costs
        // more than one sweep over the whole tree.
        if 4 * changed.len() >= self.triangles.len() {
            let mut marked = vec![false; self.triangles.len()];
            for &p in &changed {
                marked[p as usize] = true;
            }
            let sorted: Vec<u32> = (0..marked.len() as u32).filter(|&p| marked[p as usize]).collect();
            self.refit_all();
            let whole_tree = 0..self.nodes.len() as u32;
            return Refitted { nodes: std::iter::once(whole_tree).collect(), triangles: runs(&sorted) };
        }
        changed.sort_unstable();
        let nodes = self.refit_paths(&changed);
        Refitted { nodes: runs(&nodes), triangles: runs(&changed) }
    }

    /// Refits every leaf around its triangles, then every inner node around its
    /// children, deepest first.
    fn refit_all(&mut self) {
        let (pad, triangles) = (self.shape.pad, &self.triangles);
        self.nodes.par_iter_mut().filter(|n| n.count > 0).for_each(|node| {
            let held = &triangles[node.first as usize..(node.first + node.count) as usize];
            let bounds = leaf_box(held, pad);
            (node.min, node.max) = (Vec3::from(bounds.min).to_array(), Vec3::from(bounds.max).to_array());
        });
        for &index in &self.shape.inner_deepest_first {
            refit_inner(&mut self.nodes, index);
        }
    }

    /// Refits the leaves holding the `changed` triangle positions around their
    /// triangles, then their ancestors around their children, deepest first. Returns
    /// the nodes refitted, sorted.
    fn refit_paths(&mut self, changed: &[u32]) -> Vec<u32> {
        let shape = &self.shape;
        let mut dirty = vec![false; self.nodes.len()];
        let mut leaves: Vec<u32> = Vec::new();
        for &p in changed {
            let leaf = shape.leaf_node[p as usize];
            if !std::mem::replace(&mut dirty[leaf as usize], true) {
                leaves.push(leaf);
            }
        }
        let mut inner: Vec<u32> = Vec::new();
        for &leaf in &leaves {
            let mut node = shape.parent[leaf as usize];
            while node != NO_PARENT && !std::mem::replace(&mut dirty[node as usize], true) {
                inner.push(node);
                node = shape.parent[node as usize];
            }
        }
        let (pad, triangles) = (shape.pad, &self.triangles);
        let boxes: Vec<(u32, Aabb)> = leaves
            .par_iter()
            .map(|&leaf| {
                let node = &self.nodes[leaf as usize];
                (leaf, leaf_box(&triangles[node.first as usize..(node.first + node.count) as usize], pad))
            })
            .collect();
        for (leaf, bounds) in boxes {
            let node = &mut self.nodes[leaf as usize];
            (node.min, node.max) = (Vec3::from(bounds.min).to_array(), Vec3::from(bounds.max).to_array());
        }
        // A child is deeper than its parent: deepest first meets every child first.
        inner.sort_unstable_by_key(|&n| std::cmp::Reverse(shape.depth[n as usize]));
        for &index in &inner {
            refit_inner(&mut self.nodes, index);
        }
        leaves.extend(inner);
        leaves.sort_unstable();
        leaves
    }

    /// Bytes of each buffer, named as the errors name them.
    pub fn buffer_sizes(&self) -> [(&'static str, u64); 5] {
        let bytes = |b: &[u8]| b.len() as u64;
        [
            ("nodes", bytes(bytemuck::cast_slice(&self.nodes))),
            ("triangles", bytes(bytemuck::cast_slice(&self.triangles))),
            ("alpha tests", bytes(bytemuck::cast_slice(&self.alpha))),
            ("alpha textures", bytes(bytemuck::cast_slice(&self.textures))),
            ("alpha texels", bytes(bytemuck::cast_slice(&self.texels))),
        ]
    }
}

/// A triangle's box, inflated by a hair as the CPU reference's are, so that the slab
/// test stays conservative for rays grazing a box face (T. Ize, "Robust BVH Ray
/// Traversal", JCGT 2(2), 2013, §3): `pad` plus four ulps of the largest coordinate.
/// The triangles themselves are exact.
fn triangle_box(t: &[Vec3A; 3], pad: f32) -> Aabb {
    let (min, max) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
    let pad = Vec3A::splat(pad) + min.abs().max(max.abs()) * 4.0 * f32::EPSILON;
    Aabb::new(min - pad, max + pad)
}

/// Sets an inner node's box around its children's.
fn refit_inner(nodes: &mut [NodeGpu], index: u32) {
    let first = nodes[index as usize].first as usize;
    let (a, b) = (nodes[first], nodes[first + 1]);
    let node = &mut nodes[index as usize];
    node.min = Vec3::from(a.min).min(Vec3::from(b.min)).to_array();
    node.max = Vec3::from(a.max).max(Vec3::from(b.max)).to_array();
}

/// A leaf's box: around its triangles' padded boxes.
fn leaf_box(held: &[TriangleGpu], pad: f32) -> Aabb {
    held.iter().fold(Aabb::empty(), |b, t| b.union(&triangle_box(&[t.v0, t.v1, t.v2].map(Vec3A::from), pad)))
}

/// Sorted positions merged into runs, neighbours a few elements apart joined: fewer,
/// slightly larger uploads.
fn runs(sorted: &[u32]) -> Vec<Range<u32>> {
    const JOIN_GAP: u32 = 16;
    let mut out: Vec<Range<u32>> = Vec::new();
    for &p in sorted {
        match out.last_mut() {
            Some(last) if p < last.end + JOIN_GAP => last.end = last.end.max(p + 1),
            _ => out.push(p..p + 1),
        }
    }
    out
}

/// Every casting instance's triangles in world space, with their alpha tests.
fn gather(scene: &Scene, texture_slots: &[Option<u32>]) -> Gathered {
    let mut out = Gathered {
        triangles: Vec::new(),
        alpha: Vec::new(),
        closed: Vec::new(),
        instance_triangles: Vec::new(),
    };
    let closed_meshes = scene.closed_meshes();
    for inst in &scene.instances {
        let first = out.triangles.len() as u32;
        if !inst.casts_shadow {
            out.instance_triangles.push(first..first);
            continue;
        }
        let mesh = &scene.meshes[inst.mesh];
        let material = &scene.materials[inst.material];
        let world: Vec<Vec3A> =
            mesh.positions.iter().map(|p| inst.world_from_object.transform_point3(*p).into()).collect();
        for tri in mesh.indices.chunks_exact(3) {
            out.triangles.push([0, 1, 2].map(|k| world[tri[k] as usize]));
            out.alpha.push(match material.alpha_mode {
                AlphaMode::Mask { cutoff } => {
                    let uv =
                        |k: usize| mesh.uvs.get(tri[k] as usize).copied().unwrap_or(Vec2::ZERO).to_array();
                    Some(AlphaGpu {
                        uv0: uv(0),
                        uv1: uv(1),
                        uv2: uv(2),
                        texture: material
                            .base_color_texture
                            .and_then(|t| texture_slots[t])
                            .unwrap_or(NO_TEXTURE),
                        base_alpha: material.alpha,
                        cutoff,
                        _pad: 0,
                    })
                }
                AlphaMode::Opaque | AlphaMode::Blend => None,
            });
            let opaque = matches!(material.alpha_mode, AlphaMode::Opaque | AlphaMode::Blend);
            out.closed.push(opaque && closed_meshes[inst.mesh]);
        }
        out.instance_triangles.push(first..out.triangles.len() as u32);
    }
    out
}

/// The alpha channels of the textures that cut-out casting materials use, packed;
/// and for each scene texture, its slot among them.
fn alpha_textures(scene: &Scene) -> (Vec<AlphaTextureGpu>, Vec<u32>, Vec<Option<u32>>) {
    let mut used = vec![false; scene.textures.len()];
    for inst in scene.instances.iter().filter(|i| i.casts_shadow) {
        let material = &scene.materials[inst.material];
        if let (AlphaMode::Mask { .. }, Some(t)) = (material.alpha_mode, material.base_color_texture) {
            used[t] = true;
        }
    }
    let (mut headers, mut texels, mut slots) = (Vec::new(), Vec::new(), vec![None; scene.textures.len()]);
    for (index, texture) in scene.textures.iter().enumerate().filter(|(i, _)| used[*i]) {
        slots[index] = Some(headers.len() as u32);
        headers.push(AlphaTextureGpu {
            first_word: texels.len() as u32,
            width: texture.width,
            height: texture.height,
            wrap_u: wrap_code(texture.wrap_u),
            wrap_v: wrap_code(texture.wrap_v),
            nearest: texture.nearest as u32,
            _pad0: 0,
            _pad1: 0,
        });
        texels.extend(pack_alpha(texture));
    }
    (headers, texels, slots)
}

/// A texture's alpha bytes, four to a little-endian word.
fn pack_alpha(texture: &Texture) -> Vec<u32> {
    let alpha: Vec<u8> = texture.rgba8.chunks_exact(4).map(|p| p[3]).collect();
    alpha.chunks(4).map(|c| c.iter().rev().fold(0u32, |word, &a| (word << 8) | a as u32)).collect()
}

/// Each node's parent and depth (the root's is 1), and for each triangle position,
/// the leaf holding it.
fn tree_links(nodes: &[NodeGpu], triangles: usize) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let mut parent = vec![NO_PARENT; nodes.len()];
    let mut depth = vec![1u32; nodes.len()];
    let mut leaf_node = vec![0u32; triangles];
    let mut stack = vec![0u32];
    while let Some(index) = stack.pop() {
        let node = nodes[index as usize];
        if node.count > 0 {
            leaf_node[node.first as usize..(node.first + node.count) as usize].fill(index);
            continue;
        }
        for child in [node.first, node.first + 1] {
            parent[child as usize] = index;
            depth[child as usize] = depth[index as usize] + 1;
            stack.push(child);
        }
    }
    (parent, depth, leaf_node)
}

/// obvhs' `build_bvh2`, step for step (PLOC, reinsertion, leaves collapsed,
/// reinsertion again), without its timer: `std::time::Instant`, which it reads,
/// panics in a browser (`wasm32-unknown-unknown` has no clock there).
/// Inputs with many coincident boxes (a mesh instanced a thousand times in one
/// place) take the median-split builder instead (`gnomon_math::median_bvh`), whose
/// depth stays logarithmic where PLOC's would grow with the group.
fn build_tree<T: Boundable>(primitives: &[T], config: BvhBuildParams) -> Bvh2 {
    let boxes: Vec<Aabb> = primitives.iter().map(Boundable::aabb).collect();
    let leaf = config.max_prims_per_leaf.clamp(1, 255) as usize;
    if let Some(bvh) = gnomon_math::median_bvh::obvhs_fallback(&boxes, leaf) {
        return bvh;
    }
    drop(boxes); // PLOC reads the primitives' own boxes
    let mut bvh = PlocBuilder::with_capacity(primitives.len()).build(
        config.ploc_search_distance,
        primitives,
        (0..primitives.len() as u32).collect(),
        config.sort_precision,
        config.search_depth_threshold,
    );
    let mut reinsertion = ReinsertionOptimizer::default();
    reinsertion.run(&mut bvh, config.reinsertion_batch_ratio, None);
    collapse(&mut bvh, leaf as u32, config.collapse_traversal_cost);
    reinsertion.run(
        &mut bvh,
        config.reinsertion_batch_ratio * config.post_collapse_reinsertion_batch_ratio_multiplier,
        None,
    );
    bvh
}

#[cfg(test)]
#[path = "bvh_tests.rs"]
mod tests;
