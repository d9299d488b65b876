//! The casters' BVH on the CPU: every caster triangle in one leaf inside all its
//! boxes, non-casters left out, alpha bytes packed, and a refit that holds exactly
//! what a fresh build of the moved scene holds, with every box tight.

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
        motion: gnomon_scene::Motion::Static,
    }];
    scene
}

/// Checks that every triangle lies in one leaf, inside the boxes of all the nodes
/// above it.
fn assert_boxes_hold_their_triangles(bvh: &CasterBvh) {
    let mut seen = vec![0u32; bvh.triangles.len()];
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
}

fn caster_triangles(scene: &Scene) -> usize {
    scene.instances.iter().filter(|i| i.casts_shadow).map(|i| scene.meshes[i.mesh].indices.len() / 3).sum()
}

#[test]
fn every_caster_triangle_is_in_exactly_one_leaf_inside_its_boxes() {
    let scene = builtin::spheres();
    let bvh = CasterBvh::build(&scene);
    assert_eq!(bvh.triangles.len(), caster_triangles(&scene));
    assert_boxes_hold_their_triangles(&bvh);
    assert!(bvh.depth <= MAX_DEPTH && bvh.depth > 1);
}

/// 500 copies of one mesh in one place (issue 75: 1 000 made PLOC's tree 1 009
/// levels deep): the median-split fallback keeps every triangle in one leaf inside
/// its boxes, and the tree shallow enough for the GPU's stack, and refits.
#[test]
fn coincident_instances_build_a_shallow_tree_that_refits() {
    let mut scene = builtin::spheres();
    let copy = scene.instances[1].clone();
    scene.instances.extend((0..500).map(|_| copy.clone()));
    let mut bvh = CasterBvh::build(&scene);
    assert_eq!(bvh.triangles.len(), caster_triangles(&scene));
    assert_boxes_hold_their_triangles(&bvh);
    assert!(bvh.depth <= MAX_DEPTH, "depth {}", bvh.depth);
    let last = scene.instances.len() - 1;
    scene.instances[last].world_from_object *= Mat4::from_translation(Vec3::new(0.0, 5.0, 0.0));
    bvh.refit(&scene, &[last]);
    assert_refitted(&bvh, &scene);
}

/// Checks that `bvh`, refitted after moves, holds exactly the triangles a new
/// build of `scene` holds, each inside all of its boxes, and that every box is
/// tight: the refitted ones and those the refit left alone.
fn assert_refitted(bvh: &CasterBvh, scene: &Scene) {
    assert_boxes_hold_their_triangles(bvh);
    let pad = bvh.shape.pad;
    for node in &bvh.nodes {
        let (min, max) = if node.count > 0 {
            let b = leaf_box(&bvh.triangles[node.first as usize..(node.first + node.count) as usize], pad);
            (Vec3::from(b.min).to_array(), Vec3::from(b.max).to_array())
        } else {
            let (a, b) = (bvh.nodes[node.first as usize], bvh.nodes[node.first as usize + 1]);
            (Vec3::from(a.min).min(b.min.into()).to_array(), Vec3::from(a.max).max(b.max.into()).to_array())
        };
        assert_eq!((node.min, node.max), (min, max), "{node:?}");
    }
    let sorted = |b: &CasterBvh| {
        let mut t: Vec<[u32; 9]> = b
            .triangles
            .iter()
            .map(|t| {
                let v = [t.v0, t.v1, t.v2].concat();
                std::array::from_fn(|k| v[k].to_bits())
            })
            .collect();
        t.sort_unstable();
        t
    };
    assert_eq!(sorted(bvh), sorted(&CasterBvh::build(scene)));
}

#[test]
fn a_refit_holds_the_same_triangles_as_a_fresh_build_of_the_moved_scene() {
    // Two casters move far (one out past the scene's old bounds): only their
    // leaves' paths to the root are refitted.
    let mut scene = builtin::columns();
    let mut bvh = CasterBvh::build(&scene);
    let moved = [1, scene.instances.len() / 2];
    scene.instances[moved[0]].world_from_object =
        Mat4::from_translation(Vec3::new(40.0, 3.0, -7.0)) * scene.instances[moved[0]].world_from_object;
    scene.instances[moved[1]].world_from_object *= Mat4::from_rotation_y(0.7);
    let changed = bvh.refit(&scene, &moved);
    let moved_triangles: usize =
        moved.iter().map(|&i| scene.meshes[scene.instances[i].mesh].indices.len() / 3).sum();
    let covered = |runs: &[Range<u32>]| runs.iter().map(|r| r.end - r.start).sum::<u32>() as usize;
    let disjoint = |runs: &[Range<u32>]| runs.windows(2).all(|w| w[0].end < w[1].start);
    assert!(covered(&changed.triangles) >= moved_triangles && disjoint(&changed.triangles));
    assert!(disjoint(&changed.nodes) && changed.nodes[0].start == 0, "the root is refitted");
    assert!(covered(&changed.nodes) < bvh.nodes.len() / 2, "only the moved leaves' paths: {changed:?}");
    assert_refitted(&bvh, &scene);
    // The root grew to hold the caster moved out of the old bounds.
    assert!(bvh.nodes[0].max[0] > 35.0, "{:?}", bvh.nodes[0]);
    assert_eq!(bvh.refit(&scene, &[]), Refitted::default());
    // Every instance moves: the whole tree is swept.
    let all: Vec<usize> = (0..scene.instances.len()).collect();
    for inst in &mut scene.instances {
        inst.world_from_object = Mat4::from_rotation_y(0.3) * inst.world_from_object;
    }
    let changed = bvh.refit(&scene, &all);
    let whole = |n: usize| std::iter::once(0..n as u32).collect::<Vec<_>>();
    assert_eq!(changed.nodes, whole(bvh.nodes.len()));
    assert_eq!(changed.triangles, whole(bvh.triangles.len()));
    assert_refitted(&bvh, &scene);
}

#[test]
fn runs_join_near_neighbours() {
    assert_eq!(runs(&[1, 2, 3, 10, 40, 41]), vec![1..11, 40..42]);
    assert_eq!(runs(&[]), Vec::<Range<u32>>::new());
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
    let min = bvh.triangles.iter().flat_map(|t| [t.v0, t.v1, t.v2]).fold(Vec3::MAX, |m, v| m.min(v.into()));
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
