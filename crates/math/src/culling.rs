//! Frustum culling: the planes of a projection's clip volume, a conservative test of a
//! bounding box against them, and [`CullTree`], a bounding-volume hierarchy over many
//! instances whose culling cost follows the frustum's boundary, not the instance count.

use std::ops::Range;

use glam::{Mat4, Vec3, Vec4};

use crate::Aabb;

/// The six planes bounding a clip volume, each `(n, d)` with `n · p + d ≥ 0` inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frustum {
    /// Left, right, bottom, top, near, far.
    pub planes: [Vec4; 6],
}

impl Frustum {
    /// The planes of `clip_from_world`'s volume: −w ≤ x, y ≤ w and 0 ≤ z ≤ w (WebGPU
    /// depth), read off the matrix's rows (Gribb & Hartmann, "Fast extraction of
    /// viewing frustum planes from the world-view-projection matrix", 2001).
    pub fn from_clip_from_world(clip_from_world: Mat4) -> Frustum {
        let m = clip_from_world.transpose();
        let (x, y, z, w) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
        Frustum { planes: [w + x, w - x, w + y, w - y, z, w - z] }
    }

    /// Whether `bounds` may reach inside the volume: false only when the whole box
    /// lies outside one plane (it can say true for a box outside near a corner,
    /// never false for a box inside). `near` includes the near plane; a pass that
    /// clamps depth (pancaking) draws casters in front of it and leaves it out.
    pub fn intersects(&self, bounds: &Aabb, near: bool) -> bool {
        self.classify(bounds, near) != Containment::Outside
    }

    /// Where `bounds` lies: outside one plane, inside all of them, or straddling.
    /// The same test as [`Frustum::intersects`] for `Outside`; `Inside` is exact (every
    /// corner is inside every plane), so a whole subtree can be taken without testing
    /// its boxes one by one.
    pub fn classify(&self, bounds: &Aabb, near: bool) -> Containment {
        if bounds.is_empty() {
            return Containment::Outside;
        }
        let mut inside = true;
        for (i, plane) in self.planes.iter().enumerate() {
            if i == 4 && !near {
                continue;
            }
            // The box corners farthest along the plane's normal and against it (the
            // "p-vertex" and "n-vertex"; Greene, "Detecting intersection of a
            // rectangular solid and a convex polyhedron", Graphics Gems IV, 1994).
            let n = plane.truncate();
            let positive = n.cmpge(Vec3::ZERO);
            if n.dot(Vec3::select(positive, bounds.max, bounds.min)) + plane.w < 0.0 {
                return Containment::Outside;
            }
            inside &= n.dot(Vec3::select(positive, bounds.min, bounds.max)) + plane.w >= 0.0;
        }
        if inside { Containment::Inside } else { Containment::Partial }
    }
}

/// Where a box lies against a [`Frustum`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Containment {
    /// Wholly outside at least one plane: nothing in the box can be visible, so it is skipped.
    Outside,
    /// Neither provably outside nor wholly inside: the box straddles the boundary (or lies just
    /// outside near a corner, which the plane test cannot tell apart), so its contents need testing.
    Partial,
    /// Every corner inside every plane: everything in the box is in the volume, without further tests.
    Inside,
}

/// A bounding-volume hierarchy over instance bounds, for culling many instances
/// against many frusta. [`CullTree::build`] reorders the instances so that every
/// subtree holds a contiguous run of them; [`CullTree::cull`] then answers with runs
/// (a subtree wholly inside the frustum is one run, found without visiting its
/// leaves), which a renderer draws as instanced draws. Culling visits only the nodes
/// that straddle the frustum's boundary and their children, so its cost grows with
/// that boundary, not with the number of instances.
#[derive(Clone, Debug, Default)]
pub struct CullTree {
    nodes: Vec<CullNode>,
    /// Each instance's bounds, in the tree's order.
    bounds: Vec<Aabb>,
}

#[derive(Clone, Copy, Debug)]
struct CullNode {
    bounds: Aabb,
    /// The instances below this node: `first .. first + count` in the tree's order.
    first: u32,
    count: u32,
    /// The index of the right child; the left child follows its parent. 0 for a leaf.
    right: u32,
}

impl CullTree {
    /// At most this many instances share a leaf, which is tested box by box.
    pub const LEAF_SIZE: usize = 8;

    /// Builds the tree over `bounds` by median splits along the widest axis of the
    /// boxes' centres. Returns the tree and the order it keeps the instances in:
    /// `order[i]` is the index into `bounds` of the tree's `i`-th instance.
    pub fn build(bounds: &[Aabb]) -> (CullTree, Vec<u32>) {
        let mut order: Vec<u32> = (0..bounds.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * bounds.len() / Self::LEAF_SIZE + 1);
        if !bounds.is_empty() {
            Self::build_node(bounds, &mut order, 0, &mut nodes);
        }
        let sorted = order.iter().map(|&i| bounds[i as usize]).collect();
        (CullTree { nodes, bounds: sorted }, order)
    }

    fn build_node(bounds: &[Aabb], order: &mut [u32], first: usize, nodes: &mut Vec<CullNode>) {
        let node_bounds = order.iter().map(|&i| bounds[i as usize]).fold(Aabb::EMPTY, Aabb::union);
        let index = nodes.len();
        nodes.push(CullNode {
            bounds: node_bounds,
            first: first as u32,
            count: order.len() as u32,
            right: 0,
        });
        if order.len() <= Self::LEAF_SIZE {
            return;
        }
        let centres = Aabb::from_points(order.iter().map(|&i| bounds[i as usize].center()));
        let extent = centres.extent();
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let half = order.len() / 2;
        order.select_nth_unstable_by(half, |&a, &b| {
            let (a, b) = (bounds[a as usize].center()[axis], bounds[b as usize].center()[axis]);
            a.total_cmp(&b)
        });
        let (left, right) = order.split_at_mut(half);
        Self::build_node(bounds, left, first, nodes);
        nodes[index].right = nodes.len() as u32;
        Self::build_node(bounds, right, first + half, nodes);
    }

    /// Gives the instance at `index` in the tree's order new bounds (it moved) and
    /// refits every node's box to its children, bottom-up, keeping the tree's shape.
    /// Culling stays exact, since every box still holds its subtree; only its speed
    /// suffers when instances move far from where the tree grouped them, and then a
    /// new [`CullTree::build`] pays off. Out-of-range indices are ignored.
    pub fn refit(&mut self, moved: impl IntoIterator<Item = (u32, Aabb)>) {
        for (index, bounds) in moved {
            if let Some(slot) = self.bounds.get_mut(index as usize) {
                *slot = bounds;
            }
        }
        // Children follow their parent in the node array (the left one directly, the
        // right one later), so a reverse sweep meets every child before its parent.
        for index in (0..self.nodes.len()).rev() {
            let node = self.nodes[index];
            self.nodes[index].bounds = if node.right == 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                self.bounds[range].iter().copied().fold(Aabb::EMPTY, Aabb::union)
            } else {
                self.nodes[index + 1].bounds.union(self.nodes[node.right as usize].bounds)
            };
        }
    }

    /// Each instance's bounds, in the tree's order (the order it keeps them in).
    pub fn instance_bounds(&self) -> &[Aabb] {
        &self.bounds
    }

    /// How many instances the tree holds.
    pub fn len(&self) -> usize {
        self.bounds.len()
    }

    /// Whether the tree holds no instances.
    pub fn is_empty(&self) -> bool {
        self.bounds.is_empty()
    }

    /// The world bounds of every instance.
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    /// Appends to `runs` the runs of instances (in the tree's order) whose boxes
    /// [`Frustum::intersects`] accepts, in increasing order, adjacent runs merged.
    /// `near` as for [`Frustum::intersects`].
    pub fn cull(&self, frustum: &Frustum, near: bool, runs: &mut Vec<Range<u32>>) {
        if self.nodes.is_empty() {
            return;
        }
        let mut push = |run: Range<u32>| match runs.last_mut() {
            Some(last) if last.end == run.start => last.end = run.end,
            _ => runs.push(run),
        };
        let mut stack = vec![0u32];
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index as usize];
            match frustum.classify(&node.bounds, near) {
                Containment::Outside => {}
                Containment::Inside => push(node.first..node.first + node.count),
                Containment::Partial if node.right == 0 => {
                    for i in node.first..node.first + node.count {
                        if frustum.intersects(&self.bounds[i as usize], near) {
                            push(i..i + 1);
                        }
                    }
                }
                Containment::Partial => {
                    // Right first, so the left subtree (lower instances) pops first and
                    // the runs come out in order.
                    stack.push(node.right);
                    stack.push(index + 1);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{omni::cube_face_projections, test_rng::Lcg};

    #[test]
    fn boxes_inside_touching_and_outside_a_face() {
        let faces = cube_face_projections(Vec3::ZERO, 0.1, 10.0);
        // Layer 0 looks down +x.
        let frustum = Frustum::from_clip_from_world(faces[0].clip_from_world());
        let cube = |c: Vec3, h: f32| Aabb::new(c - Vec3::splat(h), c + Vec3::splat(h));
        assert!(frustum.intersects(&cube(Vec3::new(5.0, 0.0, 0.0), 0.5), true));
        assert!(!frustum.intersects(&cube(Vec3::new(-5.0, 0.0, 0.0), 0.5), true), "behind the face");
        assert!(!frustum.intersects(&cube(Vec3::new(12.0, 0.0, 0.0), 0.5), true), "beyond the range");
        assert!(!frustum.intersects(&cube(Vec3::new(2.0, 5.0, 0.0), 0.5), true), "beside the 90° cone");
        // Straddling the 45° boundary to the +y face: both faces draw it.
        let up = Frustum::from_clip_from_world(faces[2].clip_from_world());
        let seam = cube(Vec3::new(3.0, 3.0, 0.0), 0.3);
        assert!(frustum.intersects(&seam, true) && up.intersects(&seam, true));
        assert!(!frustum.intersects(&Aabb::EMPTY, true));
    }

    #[test]
    fn no_box_with_a_point_inside_is_culled() {
        // Property: a box holding a point that projects inside the volume is never
        // culled, with or without the near plane.
        let mut rng = Lcg(11);
        let faces = cube_face_projections(Vec3::new(1.0, -2.0, 0.5), 0.05, 20.0);
        for projection in faces {
            let clip_from_world = projection.clip_from_world();
            let frustum = Frustum::from_clip_from_world(clip_from_world);
            let world_from_clip = clip_from_world.inverse();
            for _ in 0..500 {
                let ndc = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(0.0, 1.0));
                let p = world_from_clip.project_point3(ndc);
                let b = Aabb::new(p - rng.vec(0.0, 2.0), p + rng.vec(0.0, 2.0));
                assert!(frustum.intersects(&b, true) && frustum.intersects(&b, false));
            }
        }
    }

    /// Random boxes scattered over a wide area, most of them far outside `frustum`.
    fn scattered_boxes(rng: &mut Lcg, count: usize) -> Vec<Aabb> {
        (0..count)
            .map(|_| {
                let c = Vec3::new(rng.range(-200.0, 200.0), rng.range(-5.0, 5.0), rng.range(-200.0, 200.0));
                let h = rng.vec(0.05, 1.5);
                Aabb::new(c - h, c + h)
            })
            .collect()
    }

    #[test]
    fn the_tree_culls_exactly_what_the_box_test_culls() {
        // Property: for random frusta, the runs hold every instance the per-box test
        // accepts and no other, each once, in increasing order.
        let mut rng = Lcg(7);
        for count in [0, 1, 5, 8, 9, 100, 3000] {
            let boxes = scattered_boxes(&mut rng, count);
            let (tree, order) = CullTree::build(&boxes);
            assert_eq!(tree.len(), count);
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert!(sorted.iter().enumerate().all(|(i, &o)| i as u32 == o), "order is a permutation");
            for _ in 0..20 {
                let eye = rng.vec(-150.0, 150.0);
                let target = eye + rng.vec(-1.0, 1.0);
                let view = crate::view_from_world_look_at(eye, target, Vec3::Y);
                let projection =
                    crate::camera_clip_from_view(rng.range(0.3, 1.5), 1.5, 0.5, rng.range(20.0, 300.0));
                let frustum = Frustum::from_clip_from_world(projection * view);
                let near = rng.next() < 0.5;
                let mut runs = Vec::new();
                tree.cull(&frustum, near, &mut runs);
                let culled: Vec<u32> = runs.iter().flat_map(|r| r.clone()).collect();
                assert!(culled.windows(2).all(|w| w[0] < w[1]), "runs are increasing and disjoint");
                assert!(runs.windows(2).all(|w| w[0].end < w[1].start), "adjacent runs are merged");
                let expected: Vec<u32> = (0..count as u32)
                    .filter(|&i| frustum.intersects(&boxes[order[i as usize] as usize], near))
                    .collect();
                assert_eq!(culled, expected);
            }
        }
    }

    #[test]
    fn a_refitted_tree_culls_exactly_what_the_box_test_culls() {
        // Property: after random instances move anywhere (far from where the tree
        // grouped them), culling still returns exactly the boxes the per-box test
        // accepts.
        let mut rng = Lcg(19);
        for count in [1, 9, 100, 2000] {
            let mut boxes = scattered_boxes(&mut rng, count);
            let (mut tree, order) = CullTree::build(&boxes);
            let moved: Vec<u32> = (0..count as u32).filter(|_| rng.next() < 0.3).collect();
            for &i in &moved {
                let replacement = scattered_boxes(&mut rng, 1)[0];
                boxes[order[i as usize] as usize] = replacement;
            }
            tree.refit(moved.iter().map(|&i| (i, boxes[order[i as usize] as usize])));
            assert_eq!(tree.bounds(), boxes.iter().copied().fold(Aabb::EMPTY, Aabb::union));
            for _ in 0..20 {
                let eye = rng.vec(-150.0, 150.0);
                let view = crate::view_from_world_look_at(eye, eye + rng.vec(-1.0, 1.0), Vec3::Y);
                let projection = crate::camera_clip_from_view(1.0, 1.5, 0.5, rng.range(20.0, 300.0));
                let frustum = Frustum::from_clip_from_world(projection * view);
                let mut runs = Vec::new();
                tree.cull(&frustum, true, &mut runs);
                let culled: Vec<u32> = runs.iter().flat_map(|r| r.clone()).collect();
                let expected: Vec<u32> = (0..count as u32)
                    .filter(|&i| frustum.intersects(&boxes[order[i as usize] as usize], true))
                    .collect();
                assert_eq!(culled, expected);
            }
        }
    }

    #[test]
    fn a_wholly_visible_subtree_is_one_run() {
        // 10 000 boxes in a 100 × 100 grid, a frustum seeing a corner of it: the
        // visible boxes come out as far fewer runs than boxes, and culling visits far
        // fewer nodes than there are boxes (the point of the tree).
        let boxes: Vec<Aabb> = (0..10_000)
            .map(|i| {
                let c = Vec3::new((i % 100) as f32, 0.0, (i / 100) as f32);
                Aabb::new(c - Vec3::splat(0.3), c + Vec3::splat(0.3))
            })
            .collect();
        let (tree, _) = CullTree::build(&boxes);
        let ortho = crate::LightProjection::orthographic(
            crate::view_from_world_look_at(Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, Vec3::NEG_Z),
            (-0.5, 30.5, -30.5, 0.5),
            1.0,
            20.0,
        );
        let frustum = Frustum::from_clip_from_world(ortho.clip_from_world());
        let mut runs = Vec::new();
        tree.cull(&frustum, true, &mut runs);
        let visible: u32 = runs.iter().map(|r| r.end - r.start).sum();
        assert_eq!(visible, 31 * 31);
        assert!(runs.len() < 200, "{} runs for {visible} boxes", runs.len());
    }

    #[test]
    fn classify_tells_inside_from_straddling() {
        let ortho = crate::LightProjection::orthographic(Mat4::IDENTITY, (-1.0, 1.0, -1.0, 1.0), 1.0, 5.0);
        let frustum = Frustum::from_clip_from_world(ortho.clip_from_world());
        let at = |z: f32, h: f32| Aabb::new(Vec3::new(-h, -h, z - h), Vec3::new(h, h, z + h));
        assert_eq!(frustum.classify(&at(-3.0, 0.5), true), Containment::Inside);
        assert_eq!(frustum.classify(&at(-3.0, 1.5), true), Containment::Partial);
        assert_eq!(frustum.classify(&at(-9.0, 0.5), true), Containment::Outside);
        // Before the near plane: outside with it, inside without it.
        assert_eq!(frustum.classify(&at(-0.3, 0.1), true), Containment::Outside);
        assert_eq!(frustum.classify(&at(-0.3, 0.1), false), Containment::Inside);
    }

    #[test]
    fn leaving_out_the_near_plane_keeps_casters_before_it() {
        let ortho = crate::LightProjection::orthographic(Mat4::IDENTITY, (-1.0, 1.0, -1.0, 1.0), 1.0, 5.0);
        let frustum = Frustum::from_clip_from_world(ortho.clip_from_world());
        // The view looks down −z: z = −0.5 is in front of the near plane at distance 1.
        let before = Aabb::new(Vec3::new(-0.1, -0.1, -0.6), Vec3::new(0.1, 0.1, -0.4));
        assert!(!frustum.intersects(&before, true));
        assert!(frustum.intersects(&before, false));
    }
}
