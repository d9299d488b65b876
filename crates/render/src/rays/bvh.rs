//! The shadow casters as a GPU ray tracer reads them: every casting instance's
//! triangles in world space, in a binary BVH (obvhs' PLOC builder) flattened into
//! plain arrays that `trace.wgsl` walks, with what the alpha test of a cut-out
//! material needs (its UVs, cutoff and the alpha channel of its texture).
//!
//! Non-casters are left out: a shadow ray only asks whether something blocks it.

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3, Vec3A};
use gnomon_scene::{AlphaMode, Scene, Texture, Wrap};
use obvhs::{BvhBuildParams, aabb::Aabb, bvh2::builder::build_bvh2};

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
    pub _pad1: u32,
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
    pub _pad: [u32; 2],
}

/// How `trace.wgsl` names a wrap mode.
pub(crate) fn wrap_code(wrap: Wrap) -> u32 {
    match wrap {
        Wrap::Repeat => 0,
        Wrap::MirroredRepeat => 1,
        Wrap::ClampToEdge => 2,
    }
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
}

/// One caster triangle before the build, with its alpha test.
struct Gathered {
    triangles: Vec<[Vec3A; 3]>,
    alpha: Vec<Option<AlphaGpu>>,
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
        if gathered.triangles.is_empty() {
            let leaf = NodeGpu { min: [0.0; 3], count: 1, max: [0.0; 3], first: 0 };
            let point =
                TriangleGpu { v0: [0.0; 3], alpha: NO_ALPHA, v1: [0.0; 3], _pad1: 0, v2: [0.0; 3], _pad2: 0 };
            return Self {
                nodes: vec![leaf],
                triangles: vec![point],
                depth: 1,
                textures,
                texels,
                alpha: vec![],
                casters: 0,
            };
        }
        // Bounds inflated by a hair, as the CPU reference's are, so that the slab test
        // stays conservative for rays grazing a box face (T. Ize, "Robust BVH Ray
        // Traversal", JCGT 2(2), 2013, §3); the triangles themselves are exact.
        let scene_size = scene.bounds().extent().max_element().max(1e-3);
        let boxes: Vec<Aabb> = gathered
            .triangles
            .iter()
            .map(|t| {
                let (min, max) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
                let pad = Vec3A::splat(1e-6 * scene_size) + min.abs().max(max.abs()) * 4.0 * f32::EPSILON;
                Aabb::new(min - pad, max + pad)
            })
            .collect();
        let bvh = build_bvh2(
            &boxes,
            BvhBuildParams {
                max_prims_per_leaf: 4,
                collapse_traversal_cost: 1.0,
                ..BvhBuildParams::medium_build()
            },
            &mut Default::default(),
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
                TriangleGpu { v0, alpha: test, v1, _pad1: 0, v2, _pad2: 0 }
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
        let depth = tree_depth(&nodes);
        let casters = gathered.triangles.len();
        Self { nodes, triangles, alpha, textures, texels, depth, casters }
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

/// Every casting instance's triangles in world space, with their alpha tests.
fn gather(scene: &Scene, texture_slots: &[Option<u32>]) -> Gathered {
    let mut out = Gathered { triangles: Vec::new(), alpha: Vec::new() };
    for inst in scene.instances.iter().filter(|i| i.casts_shadow) {
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
        }
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
            _pad: [0; 2],
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

/// The depth of the deepest leaf, the root counting 1.
fn tree_depth(nodes: &[NodeGpu]) -> u32 {
    let mut deepest = 0;
    let mut stack = vec![(0usize, 1u32)];
    while let Some((index, depth)) = stack.pop() {
        deepest = deepest.max(depth);
        let node = &nodes[index];
        if node.count == 0 {
            stack.push((node.first as usize, depth + 1));
            stack.push((node.first as usize + 1, depth + 1));
        }
    }
    deepest
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;
    use gnomon_scene::{Instance, builtin, geometry};

    fn one_instance(mesh: gnomon_scene::Mesh, casts_shadow: bool) -> Scene {
        let mut scene = builtin::spheres();
        scene.meshes = vec![mesh];
        scene.instances = vec![Instance {
            name: "only".into(),
            mesh: 0,
            material: 0,
            world_from_object: Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)),
            casts_shadow,
        }];
        scene
    }

    #[test]
    fn every_caster_triangle_is_in_exactly_one_leaf_inside_its_boxes() {
        let scene = builtin::spheres();
        let bvh = CasterBvh::build(&scene);
        let casters: usize = scene
            .instances
            .iter()
            .filter(|i| i.casts_shadow)
            .map(|i| scene.meshes[i.mesh].indices.len() / 3)
            .sum();
        assert_eq!(bvh.triangles.len(), casters);
        let mut seen = vec![0u32; casters];
        let mut stack = vec![(0usize, Vec::<usize>::new())];
        while let Some((index, ancestors)) = stack.pop() {
            let node = bvh.nodes[index];
            let mut chain = ancestors.clone();
            chain.push(index);
            if node.count == 0 {
                stack.push((node.first as usize, chain.clone()));
                stack.push((node.first as usize + 1, chain));
                continue;
            }
            for t in node.first..node.first + node.count {
                seen[t as usize] += 1;
                let tri = bvh.triangles[t as usize];
                for v in [tri.v0, tri.v1, tri.v2] {
                    for &a in &chain {
                        let (min, max) = (Vec3::from(bvh.nodes[a].min), Vec3::from(bvh.nodes[a].max));
                        let v = Vec3::from(v);
                        assert!(v.cmpge(min).all() && v.cmple(max).all(), "vertex {v} outside node {a}");
                    }
                }
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "each triangle in one leaf");
        assert!(bvh.depth <= MAX_DEPTH && bvh.depth > 1);
    }

    #[test]
    fn non_casters_are_left_out_and_an_empty_tree_is_one_leaf_of_zero_area() {
        let bvh = CasterBvh::build(&one_instance(geometry::cuboid(Vec3::ONE), false));
        assert_eq!((bvh.nodes.len(), bvh.triangles.len()), (1, 1));
        assert_eq!(bvh.nodes[0].count, 1, "a leaf: an inner node would send the walk to its children");
        let t = bvh.triangles[0];
        assert!(t.v0 == t.v1 && t.v1 == t.v2, "a triangle no ray hits");
        let bvh = CasterBvh::build(&one_instance(geometry::cuboid(Vec3::ONE), true));
        assert_eq!(bvh.triangles.len(), 12);
        // Placed in world space.
        let min =
            bvh.triangles.iter().flat_map(|t| [t.v0, t.v1, t.v2]).fold(Vec3::MAX, |m, v| m.min(v.into()));
        assert!(min.abs_diff_eq(Vec3::new(0.0, 1.0, 2.0), 1e-5), "{min}");
    }

    #[test]
    fn alpha_bytes_pack_four_to_a_word_in_texel_order() {
        let texture = Texture {
            name: "a".into(),
            width: 5,
            height: 1,
            rgba8: [10u8, 20, 30, 40, 50].iter().flat_map(|&a| [0, 0, 0, a]).collect(),
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
            nearest: true,
        };
        assert_eq!(pack_alpha(&texture), vec![10 | 20 << 8 | 30 << 16 | 40 << 24, 50]);
    }
}
