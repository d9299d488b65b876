//! A bounding volume hierarchy built by median splits, for the inputs a
//! locally-ordered clustering builder (PLOC: Meister & Bittner, "Parallel Locally-
//! Ordered Clustering for Bounding Volume Hierarchy Construction", IEEE TVCG 24(3),
//! 2018) cannot take: many primitives with the same box. PLOC merges each cluster
//! with its nearest neighbour; among identical boxes every neighbour is nearest, so
//! few pairs are mutual, merging takes one pass per level of a chain, and the tree
//! is as deep as the group is large (1 000 coincident copies of a mesh built a tree
//! 1 009 levels deep, in 24 s).
//!
//! Here each node splits its primitives at the median of their centres along the
//! widest axis of those centres, ties broken by position in the list, so the tree
//! is balanced whatever the input: ⌈log₂(n / leaf)⌉ + 1 levels, O(n log n) work.
//! The boxes it makes are looser than PLOC's on ordinary scenes, so it is the
//! fallback, chosen by [`largest_coincident_group`].

use crate::Aabb;

/// One node: an inner node when `count` is 0 (its children at `first` and
/// `first + 1`), else a leaf of `count` primitives from `first` in [`MedianTree::order`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MedianNode {
    /// The node's bounds.
    pub bounds: Aabb,
    /// Primitives in a leaf; 0 for an inner node.
    pub count: u32,
    /// The first child (inner node) or the first primitive's slot in `order` (leaf).
    pub first: u32,
}

/// A tree over primitives given by their boxes: its nodes, the root first, and the
/// primitives' indices in leaf order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MedianTree {
    /// The nodes, the root at 0.
    pub nodes: Vec<MedianNode>,
    /// The input indices of the primitives, leaf by leaf.
    pub order: Vec<u32>,
}

/// The most primitives of one box that PLOC is given: past it, the median builder.
/// Duplicated faces (a double-sided mesh stored twice) make groups of two; 1 000
/// coincident instances, groups of 1 000.
pub const MAX_COINCIDENT: usize = 8;

/// The size of the largest group of boxes that are bit-for-bit the same.
pub fn largest_coincident_group(boxes: &[Aabb]) -> usize {
    let mut counts: std::collections::HashMap<[u32; 6], usize> = std::collections::HashMap::new();
    let mut largest = 0;
    for b in boxes {
        let key = [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z].map(f32::to_bits);
        let n = counts.entry(key).or_default();
        *n += 1;
        largest = largest.max(*n);
    }
    largest
}

/// The median-split tree over `boxes`, with at most `leaf` primitives a leaf.
pub fn build(boxes: &[Aabb], leaf: usize) -> MedianTree {
    let leaf = leaf.max(1);
    let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
    let centre = |i: u32| {
        let b = &boxes[i as usize];
        (b.min + b.max) * 0.5
    };
    let empty =
        MedianNode { bounds: Aabb { min: glam::Vec3::ZERO, max: glam::Vec3::ZERO }, count: 0, first: 0 };
    let mut nodes = vec![empty];
    let mut todo = vec![(0usize, 0usize, boxes.len())];
    while let Some((node, start, end)) = todo.pop() {
        let slice = &mut order[start..end];
        let bounds = slice.iter().fold(
            Aabb { min: glam::Vec3::splat(f32::INFINITY), max: glam::Vec3::splat(f32::NEG_INFINITY) },
            |a, &i| Aabb { min: a.min.min(boxes[i as usize].min), max: a.max.max(boxes[i as usize].max) },
        );
        if end - start <= leaf {
            nodes[node] = MedianNode { bounds, count: (end - start) as u32, first: start as u32 };
            continue;
        }
        let (lo, hi) = slice.iter().fold(
            (glam::Vec3::splat(f32::INFINITY), glam::Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &i| (lo.min(centre(i)), hi.max(centre(i))),
        );
        let spread = hi - lo;
        let axis = if spread.x >= spread.y && spread.x >= spread.z {
            0
        } else if spread.y >= spread.z {
            1
        } else {
            2
        };
        let mid = (end - start) / 2;
        // Ties (identical centres) fall by index: the split is at the median slot
        // whatever the centres are, which is what bounds the depth.
        slice.select_nth_unstable_by(mid, |&a, &b| {
            centre(a)[axis].total_cmp(&centre(b)[axis]).then(a.cmp(&b))
        });
        let first = nodes.len();
        nodes.extend([empty, empty]);
        nodes[node] = MedianNode { bounds, count: 0, first: first as u32 };
        todo.push((first, start, start + mid));
        todo.push((first + 1, start + mid, end));
    }
    MedianTree { nodes, order }
}

/// The median tree over `boxes` as obvhs' binary BVH (leaves of at most `leaf`
/// primitives) where PLOC cannot take them (more than [`MAX_COINCIDENT`] share a
/// box); `None` where it can. The GPU tracer's and the reference's builders both ask.
#[cfg(feature = "obvhs")]
pub fn obvhs_fallback(boxes: &[obvhs::aabb::Aabb], leaf: usize) -> Option<obvhs::bvh2::Bvh2> {
    use obvhs::{aabb::Aabb as ObvhsAabb, bvh2::node::Bvh2Node};
    let plain: Vec<Aabb> = boxes.iter().map(|b| Aabb { min: b.min.into(), max: b.max.into() }).collect();
    if largest_coincident_group(&plain) <= MAX_COINCIDENT {
        return None;
    }
    let tree = build(&plain, leaf);
    let nodes = tree
        .nodes
        .iter()
        .map(|n| Bvh2Node::new(ObvhsAabb::new(n.bounds.min.into(), n.bounds.max.into()), n.count, n.first))
        .collect();
    Some(obvhs::bvh2::Bvh2 { nodes, primitive_indices: tree.order, ..Default::default() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn depth(tree: &MedianTree, node: usize) -> usize {
        let n = tree.nodes[node];
        if n.count > 0 { 1 } else { 1 + depth(tree, n.first as usize).max(depth(tree, n.first as usize + 1)) }
    }

    #[test]
    fn coincident_boxes_make_a_balanced_tree_that_holds_every_primitive_once() {
        let one = Aabb { min: Vec3::ZERO, max: Vec3::ONE };
        let boxes = vec![one; 10_000];
        assert_eq!(largest_coincident_group(&boxes), 10_000);
        let tree = build(&boxes, 4);
        assert!(depth(&tree, 0) <= 13, "depth {}", depth(&tree, 0)); // ⌈log₂ 2500⌉ + 1
        let mut seen = tree.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..10_000).collect::<Vec<u32>>());
    }

    #[test]
    fn every_node_bounds_its_primitives_and_leaves_hold_at_most_the_leaf_size() {
        let boxes: Vec<Aabb> = (0..1000)
            .map(|i| {
                let p = Vec3::new((i * 37 % 101) as f32, (i * 11 % 53) as f32, (i % 7) as f32);
                Aabb { min: p, max: p + Vec3::splat(0.5) }
            })
            .collect();
        assert_eq!(largest_coincident_group(&boxes), 1);
        let tree = build(&boxes, 4);
        for n in &tree.nodes {
            if n.count > 0 {
                assert!(n.count <= 4);
                for &i in &tree.order[n.first as usize..(n.first + n.count) as usize] {
                    let b = boxes[i as usize];
                    assert!(b.min.cmpge(n.bounds.min).all() && b.max.cmple(n.bounds.max).all());
                }
            }
        }
        assert!(depth(&tree, 0) <= 9, "depth {}", depth(&tree, 0));
        assert_eq!(build(&[], 4).nodes.len(), 1, "an empty input is one empty leaf");
    }
}
