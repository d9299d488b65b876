// A penumbra by one beam instead of many rays: the share of a light's area that a
// receiver sees, from one walk of the casters' BVH (bvh.rs) by the cone from the
// receiver to the light, with the light's area as a bitmask of BEAM_SAMPLES fixed
// samples (gnomon_math::light_masks). Every caster triangle the cone meets is
// projected from the receiver onto the light's plane, where it is the intersection
// of three half-planes: the samples it hides are the AND of three masks from the
// table, and the samples any caster hides the OR over them (Schwarz & Stamminger,
// "Bitmask Soft Shadows", EG 2007, over a shadow map's texels; Sintorn, Eisemann &
// Assarsson, EGSR 2008, per receiver sample; here over the scene's own triangles).
// The walk ends once every sample is hidden. A triangle costs three table reads for
// all the samples together, where rays would each walk the tree: 128 samples cost
// about what a few rays did.
//
// The samples stand where the CPU reference's rays go, weighted as they are: for a
// sun or a point light, directions uniform in the cone of the disk or sphere (the
// samples lie uniform in area on the plane a unit along the axis, the gnomonic
// projection, so each weighs cos³θ, the density of uniform directions there); for a
// spot, points uniform over its disk, each weighed by its distance's falloff. A
// sample below the receiver's horizon is blocked, as in the reference.
//
// Cut-out casters are alpha-tested per sample, by a ray to each of the samples the
// triangle may hide.
import package::constants::{LIGHT_MASK_ANGLE_BINS, LIGHT_MASK_OFFSET_BINS, LIGHT_MASK_SAMPLES, PI};
import package::passes::light::SamplePlane;
import package::passes::light_binding::light;
import package::passes::light_kinds::{emitter_plane_weight, emitter_sample_plane, emitter_weighs_samples_alike};
import package::rays::light_sample::lowbias32;
import package::rays::trace_bvh::{bvh_nodes, bvh_triangles, shear_ray, triangle_hit};
import package::variant::{NO_ALPHA, TRACE_GROUP, TRACE_STACK_SIZE};

// Row 0: the light's samples (LIGHT_MASK_SAMPLES points of the unit disk, two to a
// texel, as f32 bits); row 1 + i: the half-plane table's angle bin i, a mask to each
// offset bin (`light_mask_words` in rays/mod.rs, `light_masks::half_plane_table`).
@group(TRACE_GROUP) @binding(7) var light_masks: texture_2d<u32>;

const ALL_SAMPLES: vec4<u32> = vec4<u32>(0xffffffffu);

// `beam_entry`'s answer for a box the cone cannot meet: below every entry (t ≥ 0).
const BEAM_MISSES: f32 = -1.0;

// The light's sample k, in the unit disk.
fn light_mask_sample(k: u32) -> vec2<f32> {
    let pair = bitcast<vec4<f32>>(textureLoad(light_masks, vec2<u32>(k / 2u, 0u), 0));
    return select(pair.xy, pair.zw, (k & 1u) == 1u);
}

// The cone from a receiver at `origin` to the light, and the plane its samples lie
// on (`emitter_sample_plane`): a point `w` from the origin (a caster's vertex) is in
// front of the receiver, between it and the light, where its depth
// `w·plane.depth_axis` lies in (0, plane.far).
struct Beam {
    origin: vec3<f32>,
    // The receiver's geometric normal: nothing wholly below its plane blocks.
    normal: vec3<f32>,
    plane: SamplePlane,
};

// The walk's axis ray, and the reciprocals of its direction plus and minus the
// cone's widening, for `beam_entry`.
struct BeamAxis {
    origin: vec3<f32>,
    direction: vec3<f32>,
    // cos and sin of the cone's half-angle.
    cos_half: f32,
    sin_half: f32,
    inv_plus: vec3<f32>,
    inv_minus: vec3<f32>,
    length: f32,
    // The receiver's geometric normal: a box wholly below its plane is not entered.
    normal: vec3<f32>,
};

fn beam_axis(beam: Beam) -> BeamAxis {
    let a = beam.plane.axis;
    let k = beam.plane.widening;
    // A zero slope would make a reciprocal infinite, and 0 · ∞ a NaN: a tiny one of
    // either sign bounds nothing, as it should.
    let plus = a + vec3<f32>(k);
    let minus = a - vec3<f32>(k);
    let tiny = vec3<f32>(1e-30);
    let cos_half = inverseSqrt(1.0 + k * k);
    return BeamAxis(
        beam.origin,
        a,
        cos_half,
        k * cos_half,
        1.0 / select(plus, tiny, abs(plus) < tiny),
        1.0 / select(minus, -tiny, abs(minus) < tiny),
        beam.plane.axis_length,
        beam.normal,
    );
}

// Whether the cone may meet the box `lo`–`hi`. A point of the cone a distance t
// along its axis lies within `widening` · t of the axis there, so inside a cube of
// that half-size about the axis's point: the cone may meet the box only at a t where
// that cube does, which along each of the box's axes is a pair of linear bounds on t,
// o + t a ≥ lo − k t and o + t a ≤ hi + k t: a slab test whose two sides have their
// own slopes, a ± k, exact for the growing cube. Returns the least such t, by which
// the walk visits the nearer child first, or `BEAM_MISSES` where the cone cannot
// meet the box.
fn beam_entry(axis: BeamAxis, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    // The box's corner farthest along the normal, over the receiver's plane.
    let above = select(lo, hi, axis.normal > vec3<f32>(0.0)) - axis.origin;
    if dot(above, axis.normal) <= 0.0 {
        return BEAM_MISSES;
    }
    // t (a + k) ≥ lo − o: a lower bound on t where a + k > 0, an upper one where not.
    let low = (lo - axis.origin) * axis.inv_plus;
    let high = (hi - axis.origin) * axis.inv_minus;
    let rising = axis.inv_plus > vec3<f32>(0.0);
    let falling = axis.inv_minus < vec3<f32>(0.0);
    // From lo: t ≥ low where rising, t ≤ low where not; from hi: t ≤ high where
    // a − k > 0, t ≥ high where falling.
    let from_lo_min = select(vec3<f32>(-3.0e38), low, rising);
    let from_lo_max = select(low, vec3<f32>(3.0e38), rising);
    let from_hi_min = select(vec3<f32>(-3.0e38), high, falling);
    let from_hi_max = select(high, vec3<f32>(3.0e38), falling);
    let t_min = max(max(from_lo_min, from_hi_min), vec3<f32>(0.0));
    let t_max = min(min(from_lo_max, from_hi_max), vec3<f32>(axis.length));
    let near = max(t_min.x, max(t_min.y, t_min.z));
    let far = min(t_max.x, min(t_max.y, t_max.z));
    if near > far * 1.000001 + 1e-30 {
        return BEAM_MISSES;
    }
    // And the box's bounding sphere against the cone itself: its centre no farther
    // outside the cone's surface than its radius (the cube bound above is √3 loose
    // across an oblique axis).
    let centre = 0.5 * (lo + hi) - axis.origin;
    let radius = 0.5 * length(hi - lo);
    let along = dot(centre, axis.direction);
    let across = length(centre - along * axis.direction);
    return select(BEAM_MISSES, near, across * axis.cos_half - along * axis.sin_half <= radius * 1.000001);
}

// The samples on the inner side of the plane through the origin with normal `m`:
// `m·(toward + x.x b0 + x.y b1) > 0`, from the table.
fn plane_mask(beam: Beam, m: vec3<f32>) -> vec4<u32> {
    let n = vec2<f32>(dot(m, beam.plane.b0), dot(m, beam.plane.b1));
    let c = dot(m, beam.plane.toward);
    let length = sqrt(dot(n, n));
    // n·x > −c: over |n|, the line n̂·x = d.
    let d = -c / length;
    if !(length > 0.0) || d <= -1.0 || d >= 1.0 {
        // The line passes outside the disk, or lies at infinity: every sample
        // inside, or none.
        return select(vec4<u32>(0u), ALL_SAMPLES, c > 0.0);
    }
    let turns = (atan2(n.y, n.x) + PI) / (2.0 * PI);
    let i = min(u32((turns - floor(turns)) * f32(LIGHT_MASK_ANGLE_BINS)), LIGHT_MASK_ANGLE_BINS - 1u);
    let j = min(u32((d + 1.0) * 0.5 * f32(LIGHT_MASK_OFFSET_BINS)), LIGHT_MASK_OFFSET_BINS - 1u);
    return textureLoad(light_masks, vec2<u32>(j, 1u + i), 0);
}

// Where the segment from a to b (depths da, db along the beam) crosses depth `at`.
fn cross_depth(a: vec3<f32>, b: vec3<f32>, da: f32, db: f32, at: f32) -> vec3<f32> {
    return mix(a, b, (at - da) / (db - da));
}

// The samples a convex polygon `w[0..count)` (points from the origin, all in front
// of it along the beam) hides: the AND of its edges' planes through the origin, on
// the side its winding faces.
fn polygon_mask(beam: Beam, w: ptr<function, array<vec3<f32>, 5>>, count: u32) -> vec4<u32> {
    let winding = dot(cross((*w)[0], (*w)[1]), (*w)[2]);
    if winding == 0.0 {
        return vec4<u32>(0u);
    }
    let side = sign(winding);
    var mask = ALL_SAMPLES;
    for (var k = 0u; k < count; k++) {
        let m = side * cross((*w)[k], (*w)[(k + 1u) % count]);
        mask &= plane_mask(beam, m);
    }
    return mask;
}

// Clips the polygon `w[0..count)` to the beam's depths above `at` (`keep_above`) or
// below it, in place; returns the new count (at most one more).
fn clip_polygon(beam: Beam, w: ptr<function, array<vec3<f32>, 5>>, count: u32, at: f32, keep_above: bool) -> u32 {
    var out: array<vec3<f32>, 5>;
    var n = 0u;
    for (var k = 0u; k < count; k++) {
        let a = (*w)[k];
        let b = (*w)[(k + 1u) % count];
        let da = dot(a, beam.plane.depth_axis);
        let db = dot(b, beam.plane.depth_axis);
        let a_in = (da > at) == keep_above;
        let b_in = (db > at) == keep_above;
        if a_in && n < 5u {
            out[n] = a;
            n++;
        }
        if a_in != b_in && n < 5u {
            out[n] = cross_depth(a, b, da, db, at);
            n++;
        }
    }
    *w = out;
    return n;
}

// The samples the triangle `v0`, `v1`, `v2` may hide from the beam's origin
// (before any alpha test), of those not yet hidden (`open`): the AND of its three
// edges' planes through the origin, read one at a time so that a triangle whose first
// edge leaves nothing open costs one read. A triangle that crosses the receiver's
// plane across the beam, or the light's, is clipped first (`clipped_mask`).
fn triangle_mask(beam: Beam, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, open: vec4<u32>) -> vec4<u32> {
    let w0 = v0 - beam.origin;
    let w1 = v1 - beam.origin;
    let w2 = v2 - beam.origin;
    // Wholly below the receiver's plane: it meets no ray that leaves above it.
    let above = vec3<f32>(dot(w0, beam.normal), dot(w1, beam.normal), dot(w2, beam.normal));
    if all(above <= vec3<f32>(0.0)) {
        return vec4<u32>(0u);
    }
    let axis = beam.plane.depth_axis;
    let depth = vec3<f32>(dot(w0, axis), dot(w1, axis), dot(w2, axis));
    let far = vec3<f32>(beam.plane.far);
    if all(depth <= vec3<f32>(0.0)) || all(depth >= far) {
        return vec4<u32>(0u);
    }
    if any(depth <= vec3<f32>(0.0)) || any(depth >= far) {
        return clipped_mask(beam, w0, w1, w2) & open;
    }
    let e01 = cross(w0, w1);
    let winding = dot(e01, w2);
    if winding == 0.0 {
        return vec4<u32>(0u);
    }
    let side = sign(winding);
    var mask = plane_mask(beam, side * e01) & open;
    if all(mask == vec4<u32>(0u)) {
        return mask;
    }
    mask &= plane_mask(beam, side * cross(w1, w2));
    if all(mask == vec4<u32>(0u)) {
        return mask;
    }
    return mask & plane_mask(beam, side * cross(w2, w0));
}

// `triangle_mask` of a triangle (`w0`, `w1`, `w2` from the origin) clipped to the
// depths in front of the receiver and short of the light.
fn clipped_mask(beam: Beam, w0: vec3<f32>, w1: vec3<f32>, w2: vec3<f32>) -> vec4<u32> {
    var w = array<vec3<f32>, 5>(w0, w1, w2, vec3<f32>(0.0), vec3<f32>(0.0));
    var count = clip_polygon(beam, &w, 3u, 0.0, true);
    count = clip_polygon(beam, &w, count, beam.plane.far, false);
    if count < 3u {
        return vec4<u32>(0u);
    }
    return polygon_mask(beam, &w, count);
}

// The unnormalized direction from the origin to sample `x`.
fn sample_direction(beam: Beam, x: vec2<f32>) -> vec3<f32> {
    return beam.plane.toward + beam.plane.b0 * x.x + beam.plane.b1 * x.y;
}

// Of the samples in `candidates`, those the cut-out triangle `index` blocks: a ray
// to each, alpha test included (trace_bvh.wgsl's `triangle_hit`).
fn alpha_tested_mask(beam: Beam, index: u32, candidates: vec4<u32>) -> vec4<u32> {
    var hidden = vec4<u32>(0u);
    for (var word = 0u; word < 4u; word++) {
        var bits = candidates[word];
        while bits != 0u {
            let bit = firstTrailingBit(bits);
            bits &= bits - 1u;
            let k = word * 32u + bit;
            let direction = normalize(sample_direction(beam, light_mask_sample(k)));
            if triangle_hit(shear_ray(beam.origin, direction), index, 3.0e38) >= 0.0 {
                hidden[word] |= 1u << bit;
            }
        }
    }
    return hidden;
}

fn mask_count(m: vec4<u32>) -> u32 {
    return countOneBits(m.x) + countOneBits(m.y) + countOneBits(m.z) + countOneBits(m.w);
}

// What one walk of the beam found: the samples the casters hide, and the sum of
// their casters' distances (for the mean).
struct BeamHits {
    hidden: vec4<u32>,
    distance_sum: f32,
};

// Walks the BVH with the beam: every leaf whose box the cone may meet, each of its
// triangles adding the samples it hides, until all are hidden.
fn walk_beam(beam: Beam) -> BeamHits {
    let axis = beam_axis(beam);
    var hits = BeamHits(vec4<u32>(0u), 0.0);
    var stack: array<u32, TRACE_STACK_SIZE>;
    var top = 0u;
    var node = bvh_nodes[0];
    if beam_entry(axis, node.min, node.max) == BEAM_MISSES {
        return hits;
    }
    let max_steps = arrayLength(&bvh_nodes);
    var steps = 0u;
    loop {
        while node.count == 0u && steps <= max_steps {
            steps++;
            let left = bvh_nodes[node.first];
            let right = bvh_nodes[node.first + 1u];
            let left_at = beam_entry(axis, left.min, left.max);
            let right_at = beam_entry(axis, right.min, right.max);
            let in_left = left_at != BEAM_MISSES;
            let in_right = right_at != BEAM_MISSES;
            if in_left && in_right {
                // Nearer the receiver first: a near caster hides the most of the
                // light, and a walk ends once every sample is hidden.
                if left_at <= right_at {
                    stack[top] = node.first + 1u;
                    node = left;
                } else {
                    stack[top] = node.first;
                    node = right;
                }
                top++;
            } else if in_left {
                node = left;
            } else if in_right {
                node = right;
            } else {
                if top == 0u {
                    return hits;
                }
                top--;
                node = bvh_nodes[stack[top]];
            }
        }
        if steps > max_steps {
            return hits;
        }
        steps++;
        for (var i = node.first; i < node.first + node.count; i++) {
            let tri = bvh_triangles[i];
            // Of a closed mesh, the faces turned one way from the origin alone: a
            // segment that meets the mesh from outside enters and leaves it, crossing a
            // face turned each way.
            if tri.closed == 1u && dot(cross(tri.v1 - tri.v0, tri.v2 - tri.v0), tri.v0 - beam.origin) < 0.0 {
                continue;
            }
            var hidden = triangle_mask(beam, tri.v0, tri.v1, tri.v2, ~hits.hidden);
            if any(hidden != vec4<u32>(0u)) && tri.alpha != NO_ALPHA {
                hidden = alpha_tested_mask(beam, i, hidden);
            }
            let newly = mask_count(hidden);
            if newly > 0u {
                hits.hidden |= hidden;
                let centre = (tri.v0 + tri.v1 + tri.v2) / 3.0 - beam.origin;
                hits.distance_sum += f32(newly) * length(centre);
                if all(hits.hidden == ALL_SAMPLES) {
                    return hits;
                }
            }
        }
        if top == 0u {
            return hits;
        }
        top--;
        node = bvh_nodes[stack[top]];
    }
    return hits;
}

// The share of the light's area that reaches the receiver at `origin` (geometric
// normal `geometric_n`), weighted as the reference's rays, and the mean distance to
// the casters that hid the rest (-1 when none did). `pixel` seeds the turn of the
// samples, so that neighbours' errors are independent.
fn beam_area_visibility(origin: vec3<f32>, world: vec3<f32>, geometric_n: vec3<f32>, pixel: u32) -> vec2<f32> {
    let turn = f32(lowbias32(pixel ^ 0x9e3779b9u) >> 8u) * (2.0 * PI / 16777216.0);
    let beam = Beam(origin, geometric_n, emitter_sample_plane(light.emitter, origin, turn));
    let hits = walk_beam(beam);
    let hidden_count = mask_count(hits.hidden);
    let mean_distance = select(-1.0, hits.distance_sum / f32(max(hidden_count, 1u)), hidden_count > 0u);
    // With the whole disk above the receiver's horizon, what arrives is what no
    // caster hid: all of it where none did, and where the samples weigh alike, their
    // count. The weighed sum below gives the same, 128 samples later.
    let all_above = horizon_clears_disk(beam);
    if all_above && (hidden_count == 0u || emitter_weighs_samples_alike(light.emitter)) {
        return vec2<f32>(1.0 - f32(hidden_count) / f32(LIGHT_MASK_SAMPLES), mean_distance);
    }
    var arrived = 0.0;
    var total = 0.0;
    for (var k = 0u; k < LIGHT_MASK_SAMPLES; k++) {
        let x = light_mask_sample(k);
        let d = sample_direction(beam, x);
        let weight = emitter_plane_weight(light.emitter, beam.plane, d);
        total += weight;
        let hidden = (hits.hidden[k / 32u] >> (k % 32u)) & 1u;
        if hidden == 0u && dot(d, geometric_n) > 0.0 {
            arrived += weight;
        }
    }
    return vec2<f32>(arrived / max(total, 1e-30), mean_distance);
}

// Whether every direction from the receiver to the light's disk (`toward + x.x b0 +
// x.y b1`, |x| ≤ 1) leaves above its plane: the least of `d·n` over the disk,
// `toward·n` less the length of n's part along the disk, is positive.
fn horizon_clears_disk(beam: Beam) -> bool {
    let n = beam.normal;
    let across = vec2<f32>(dot(beam.plane.b0, n), dot(beam.plane.b1, n));
    return dot(beam.plane.toward, n) - length(across) > 0.0;
}

