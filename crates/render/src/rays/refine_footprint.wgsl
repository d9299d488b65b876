// The footprint test that 2D maps (refine_map.wgsl) and a point light's cube faces
// (refine_cube.wgsl) share: the stored depths around a lookup against the receiver's
// plane. Each caller works out the plane's depth and slope in its own map's terms.
import package::passes::light_binding::light;
import package::techniques::bindings::{shadow_gather, shadow_map};
import package::variant::{footprint_receiver, footprint_touched};

import package::constants::UNSURE_RING_TEXELS;
// The depth band, in texel world sizes along the light's ray, inside which a stored
// depth is too close to the receiver's to trust.
const UNSURE_DEPTH_TEXELS: f32 = 2.0;


// A receiver closer than this to edge-on to the light (N·L below it: within 5.7°) is
// `FootprintBounds::grazing`. Its depth in the map changes by tan θ ≥ 10 texels of
// depth per texel, so the default slope bias (1.5) stores it 15 texels or more
// behind its plane along the ray, a surface curving away from the light around it
// is biased as much or more, and the normal offset's push toward the light moves
// the lookup's plane in front of it by the push over N·L (docs/rays-measured.md, "A steep
// caster's bias").
const UNSURE_GRAZING_COS: f32 = 0.1;

// How far from the receiver's plane a stored depth may lie, in the map's depth
// units, and what it then says (`footprint_unsure`).
struct FootprintBounds {
    // Within this in front of the plane, or anywhere behind it: the receiver itself
    // or something behind it (half a texel of the receiver's depth slope, for the
    // plane's fit to a curved surface).
    tolerance: f32,
    // More than this in front: a caster.
    margin: f32,
    // The bias the map was drawn with where the receiver itself is stored
    // (`receiver_bias`): its own surface lies at least this far behind its plane.
    own_bias: f32,
    // How far behind the receiver's plane its surface lies: the plane passes through
    // the lookup's point, which the normal offset moved off the surface toward the
    // light, by the offset over N·L along the light's ray, many texels of depth on a
    // surface nearly edge-on to it.
    surface: f32,
    // Whether the receiver is nearly edge-on to the light (N·L < UNSURE_GRAZING_COS).
    // Such a receiver may lie where a surface curves away from the light, and the
    // crest of the fold beyond it, edge-on from the light, may shadow it: the crest's
    // bias, larger still, stores it farther behind the receiver's plane than the
    // receiver's own bias. So in the bilinear 2×2, a texel is evidence of light only
    // behind the receiver's surface (not the lookup's plane) and its own bias, and a
    // texel farther behind than that makes the pixel unsure. A flat receiver's own
    // texels never are, and a flat ground edge-on to the sun traces only its shadows'
    // edges.
    grazing: bool,
};

// The bias the map's rasterizer added to a surface of depth slope `slope` (its
// largest depth change per texel) at depth `depth`: slope_bias × m + depth_bias × r,
// r the depth's unit in the last place (Vulkan's depth bias; a distance pass writes
// the same itself, shadow_depth.wgsl).
fn receiver_bias(slope: f32, depth: f32) -> f32 {
    let unit = exp2(floor(log2(max(depth, 1e-30))) - 23.0);
    return light.bias.slope * slope + max(light.bias.depth, 0.0) * unit;
}

// A footprint past the map's edge is unsure: a 2D map has nothing to say there, and
// past a cube face's edge the answer would need the next face (the seams' band,
// UNSURE_RING_TEXELS + 1 texels wide on each side; a point-sampled lookup's one tap
// has no disagreement to show there). A ray decides.
const FOOTPRINT_EDGE_UNSURE: bool = true;

// Whether the footprint of a lookup at `uv` (in [0, 1]) in layer `layer` is unsure:
// the bilinear 2×2 and a ring of UNSURE_RING_TEXELS texels, each texel's stored depth
// against the receiver's plane there, which the including file's
// `footprint_receiver(x, y)` gives for a 2×2 block of texels (in gather's order). A
// texel within `bounds.tolerance` behind or in front of the plane, or farther
// behind, is evidence of light; one more than `bounds.margin` in front, of a caster;
// one in between, or both kinds together, make the pixel unsure. A caster that
// touches a texel (`footprint_touched`, a 2D map's touched layer: rays/touched.rs)
// more than `bounds.margin` in front is one too, though the map stored none there:
// one thinner than a texel. A footprint that leaves the layer is
// `FOOTPRINT_EDGE_UNSURE`.
//
// In the bilinear 2×2, the texels the lookup reads, a texel is evidence of light
// only once the receiver's own bias is taken off it as well. The receiver is stored
// that far behind its plane; a texel stored nearer than that is not the receiver
// but a caster that its own, larger bias pushed back. That is what a surface seen
// almost edge-on from the light looks like just before a fold turns it away: its
// slope-scaled bias is many texels of depth, and stores it behind the receiver it
// shadows just past the fold, where the lookup reads light. (Taking off the most
// bias the block's own slopes allow instead, the largest difference between its
// texels, caught more of them, but it also traced the lit sides of coarsely
// tessellated columns whole: there adjacent facets' biases differ, and a facet's
// edge against the ground beyond is a jump.) A receiver nearly edge-on to the light
// is judged against its surface, and is unsure where a texel there lies farther
// behind it than its own bias (`FootprintBounds::grazing`). (Judging every receiver
// against its surface traced a quarter more of `columns`, whose coarse facets'
// biases differ, for fewer errors past folds than this: docs/rays.md.)
fn footprint_unsure(uv: vec2<f32>, bounds: FootprintBounds, layer: u32) -> bool {
    return leaves_unsure(footprint_evidence(uv, bounds, layer));
}

// What texels say of a pixel's light: whether any of them leaves it unsure, and
// whether they hold evidence of light (nothing in front of the receiver) and of a
// caster.
struct Evidence {
    unsure: bool,
    light: bool,
    casters: bool,
};

// The evidence of two sets of texels or taps together.
fn joined(a: Evidence, b: Evidence) -> Evidence {
    return Evidence(a.unsure || b.unsure, a.light || b.light, a.casters || b.casters);
}

// Whether texels' evidence leaves the pixel unsure: a texel did, or they show both
// light and a caster.
fn leaves_unsure(e: Evidence) -> bool {
    return e.unsure || (e.light && e.casters);
}

// A map without a touched layer (`footprint_touched`): nothing touches its texels.
fn untouched_footprint(corner: vec2<f32>, layer: u32) -> vec4<f32> {
    return vec4<f32>(0.0);
}

// The evidence of `footprint_unsure`'s texels, which a light with an area weighs
// against its search over the light's cone (refine_map.wgsl's `area_unsure`).
fn footprint_evidence(uv: vec2<f32>, bounds: FootprintBounds, layer: u32) -> Evidence {
    let size = light.map.resolution;
    // Texel (i, j) holds the depth at its centre, (i + ½, j + ½) texels.
    let base = vec2<i32>(floor(uv * size - vec2<f32>(0.5)));
    let first = base - vec2<i32>(UNSURE_RING_TEXELS);
    let end = base + vec2<i32>(2 + UNSURE_RING_TEXELS);
    if any(first < vec2<i32>(0)) || any(end > vec2<i32>(i32(size))) {
        return Evidence(FOOTPRINT_EDGE_UNSURE, false, false);
    }
    var lit = false;
    var shadowed = false;
    // The footprint, 2 + 2 × UNSURE_RING_TEXELS texels a side, in 2×2 blocks, each
    // gathered at its texels' shared corner (gather's order: (x, y+1), (x+1, y+1),
    // (x+1, y), (x, y)).
    for (var y = first.y; y < end.y; y += 2) {
        for (var x = first.x; x < end.x; x += 2) {
            let corner = vec2<f32>(f32(x + 1), f32(y + 1)) / size;
            let stored = textureGather(shadow_map, shadow_gather, corner, layer);
            let receiver = footprint_receiver(x, y);
            let evidence = block_evidence(stored, receiver, all(vec2<i32>(x, y) == base), bounds);
            if evidence.x {
                return Evidence(true, false, false);
            }
            // A caster the map stored no depth of (thinner than a texel, or between
            // the texels' centres) that touches a texel in front of the receiver.
            let touched = vec4<f32>(1.0) - footprint_touched(corner, layer);
            lit = lit || evidence.y;
            shadowed = shadowed || evidence.z || any(touched <= receiver - vec4<f32>(bounds.margin));
        }
    }
    return Evidence(false, lit, shadowed);
}

// What a 2×2 block of stored depths says against the receiver's depths at the same
// texels (`footprint_unsure`; `bilinear` for the block the lookup reads): whether
// it makes the pixel unsure (x), and whether it holds evidence of light (y) and of
// a caster (z).
fn block_evidence(stored: vec4<f32>, receiver: vec4<f32>, bilinear: bool, bounds: FootprintBounds) -> vec3<bool> {
    var lit_from = receiver - vec4<f32>(bounds.tolerance);
    if bilinear {
        lit_from += vec4<f32>(bounds.own_bias);
        if bounds.grazing {
            // The receiver's own surface, as the map stored it.
            let own = receiver + vec4<f32>(bounds.surface + bounds.own_bias);
            lit_from = own - vec4<f32>(bounds.tolerance);
            let behind_own = stored > own + vec4<f32>(bounds.tolerance);
            if any(behind_own & (stored < vec4<f32>(1.0))) {
                return vec3<bool>(true, false, false);
            }
        }
    }
    let is_lit = stored >= lit_from;
    let is_shadowed = stored <= receiver - vec4<f32>(bounds.margin);
    return vec3<bool>(!all(is_lit | is_shadowed), any(is_lit), any(is_shadowed));
}
