// Shadow rays against Gnomon's own BVH of the casters (bvh.rs), walked by the shader
// on any adapter: is the segment from a surface point toward the light blocked? The
// same answers as the CPU reference (reference/tracer.rs): the watertight
// ray/triangle test of Woop, Benthin & Wald (JCGT 2(1), 2013) with PBRT's bound on
// the error of t, and cut-out casters alpha-tested (trace_common.wgsl).
//
// Bindings 2 and 3 of group TRACE_GROUP: the nodes and the triangles.
import package::rays::bvh_triangle::BvhTriangle;
import package::rays::trace_common::alpha_blocks;
import package::variant::{NO_ALPHA, TRACE_GROUP, TRACE_STACK_SIZE};

struct BvhNode {
    min: vec3<f32>,
    // Triangles in the leaf; 0 for an inner node.
    count: u32,
    max: vec3<f32>,
    // The first child (the second follows it), or the leaf's first triangle.
    first: u32,
};

@group(TRACE_GROUP) @binding(2) var<storage, read> bvh_nodes: array<BvhNode>;
@group(TRACE_GROUP) @binding(3) var<storage, read> bvh_triangles: array<BvhTriangle>;

// A ray made the +z axis by a permutation and a shear (Woop et al. §2).
struct ShearedRay {
    origin: vec3<f32>,
    kx: u32,
    ky: u32,
    kz: u32,
    shear: vec3<f32>,
};

fn shear_ray(origin: vec3<f32>, direction: vec3<f32>) -> ShearedRay {
    let a = abs(direction);
    var kz = 2u;
    if a.x >= a.y && a.x >= a.z {
        kz = 0u;
    } else if a.y >= a.z {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kz + 2u) % 3u;
    // Keep the winding: swap when the dominant axis points backward.
    if direction[kz] < 0.0 {
        let swap = kx;
        kx = ky;
        ky = swap;
    }
    let dz = direction[kz];
    return ShearedRay(origin, kx, ky, kz, vec3<f32>(direction[kx] / dz, direction[ky] / dz, 1.0 / dz));
}

// PBRT's γ(n) = nε / (1 − nε), ε half an ulp of 1.
fn gamma(n: f32) -> f32 {
    let e = n * 0.5 * 1.1920929e-7;
    return e / (1.0 - e);
}

// Where triangle `index` blocks the ray in (0, t_max], its alpha test included: the
// distance along the ray, or -1 where it does not.
fn triangle_hit(ray: ShearedRay, index: u32, t_max: f32) -> f32 {
    let tri = bvh_triangles[index];
    let a = tri.v0 - ray.origin;
    let b = tri.v1 - ray.origin;
    let c = tri.v2 - ray.origin;
    let s = ray.shear;
    let ax = a[ray.kx] - s.x * a[ray.kz];
    let ay = a[ray.ky] - s.y * a[ray.kz];
    let bx = b[ray.kx] - s.x * b[ray.kz];
    let by = b[ray.ky] - s.y * b[ray.kz];
    let cx = c[ray.kx] - s.x * c[ray.kz];
    let cy = c[ray.ky] - s.y * c[ray.kz];
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return -1.0;
    }
    let det = u + v + w;
    if det == 0.0 {
        return -1.0;
    }
    let az = s.z * a[ray.kz];
    let bz = s.z * b[ray.kz];
    let cz = s.z * c[ray.kz];
    let t = (u * az + v * bz + w * cz) / det;
    // A hit closer than the rounding error of t may be the surface the ray leaves
    // (Pharr, Jakob & Humphreys, PBRT 3rd ed., §3.9.6).
    let max_z = max(abs(az), max(abs(bz), abs(cz)));
    let max_x = max(abs(ax), max(abs(bx), abs(cx)));
    let max_y = max(abs(ay), max(abs(by), abs(cy)));
    let delta_x = gamma(5.0) * (max_x + max_z);
    let delta_y = gamma(5.0) * (max_y + max_z);
    let delta_z = gamma(3.0) * max_z;
    let delta_e = 2.0 * (gamma(2.0) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    let max_e = max(abs(u), max(abs(v), abs(w)));
    let delta_t = 3.0 * (gamma(3.0) * max_e * max_z + delta_e * max_z + delta_z * max_e) / abs(det);
    if !(t > delta_t && t <= t_max) {
        return -1.0;
    }
    if tri.alpha == NO_ALPHA {
        return t;
    }
    // U weighs the vertex opposite edge BC (A), V the one opposite CA (B), W C.
    return select(-1.0, t, alpha_blocks(tri.alpha, vec3<f32>(u, v, w), det));
}

// Entry distance of the ray into a node's box, or a negative value on a miss. The far
// distance is widened by 2γ(3) so that a ray grazing a face is not lost to rounding
// (Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013).
fn enter_box(node: BvhNode, origin: vec3<f32>, inv_direction: vec3<f32>, t_max: f32) -> f32 {
    let t0 = (node.min - origin) * inv_direction;
    let t1 = (node.max - origin) * inv_direction;
    let near = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    let far = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), min(max(t0.z, t1.z), t_max)) * (1.0 + 2.0 * gamma(3.0));
    return select(-1.0, near, near <= far);
}

// The distance along the segment from `origin` along the unit `direction` to the
// first caster the walk meets before `t_max`, or -1 where none blocks it. Any hit
// ends the walk: a shadow ray needs no closest one, so this is some caster's
// distance, not the nearest's.
fn bvh_ray_first_hit(origin: vec3<f32>, direction: vec3<f32>, t_max: f32) -> f32 {
    let ray = shear_ray(origin, direction);
    // A zero component would give an infinite reciprocal, and 0 · ∞ a NaN slab
    // distance that loses the box; a tiny component of the same sign gives a huge,
    // finite one, so the slabs of that axis span everything or nothing, as they should.
    let tiny = select(vec3<f32>(1e-30), vec3<f32>(-1e-30), direction < vec3<f32>(0.0));
    let inv_direction = 1.0 / select(direction, tiny, abs(direction) < vec3<f32>(1e-30));
    var stack: array<u32, TRACE_STACK_SIZE>;
    var top = 0u;
    // The node being visited, as read when its box was tested: a child's record is
    // loaded once, for its box, and kept for its visit (only a node taken from the
    // stack is read again).
    var node = bvh_nodes[0];
    if enter_box(node, origin, inv_direction, t_max) < 0.0 {
        return -1.0;
    }
    // A walk visits each node at most once; more steps than nodes means a broken tree,
    // and a shader that never ends would hang the device.
    let max_steps = arrayLength(&bvh_nodes);
    var steps = 0u;
    loop {
        // Down the inner nodes to a leaf (Aila & Laine's while-while: lanes in
        // lockstep test boxes together, then triangles together).
        while node.count == 0u && steps <= max_steps {
            steps++;
            let left = bvh_nodes[node.first];
            let right = bvh_nodes[node.first + 1u];
            let t_left = enter_box(left, origin, inv_direction, t_max);
            let t_right = enter_box(right, origin, inv_direction, t_max);
            if t_left >= 0.0 && t_right >= 0.0 {
                let near_first = t_left <= t_right;
                stack[top] = select(node.first, node.first + 1u, near_first);
                top++;
                if near_first {
                    node = left;
                } else {
                    node = right;
                }
            } else if t_left >= 0.0 {
                node = left;
            } else if t_right >= 0.0 {
                node = right;
            } else {
                if top == 0u {
                    return -1.0;
                }
                top--;
                node = bvh_nodes[stack[top]];
            }
        }
        if steps > max_steps {
            return -1.0;
        }
        steps++;
        for (var i = node.first; i < node.first + node.count; i++) {
            let t = triangle_hit(ray, i, t_max);
            if t >= 0.0 {
                return t;
            }
        }
        if top == 0u {
            return -1.0;
        }
        top--;
        node = bvh_nodes[stack[top]];
    }
    return -1.0;
}

