// The touched layer of a 2D shadow map (touched.rs): for every texel, the nearest
// depth of any thin opaque caster triangle that touches the texel's square at all.
// The map itself stores a caster only where it covers a texel's centre, so a wire a
// quarter of a texel thick, or one running between the centres, leaves no depth
// there, and the footprint test (refine_footprint.wgsl) saw only light and traced
// no ray. Read beside the map, a touched depth in front of the receiver says that a
// caster the map missed lies there.
//
// Thin means narrower than the map can hold for sure: an inscribed circle too small
// to hold a texel's centre wherever it lies (`THIN_INRADIUS_TEXELS`), or a triangle
// seen edge-on from the light.
// A wider one covers texel centres all along it, and the footprint test's ring
// (UNSURE_RING_TEXELS) sees those past its edges; drawing it here too made pixels
// near a steep facet's edge unsure (a sphere's terminator: 2.04 % of `spheres`'
// screen traced under a moving sun, against 1.42 % without the layer and 1.53 % with
// thin triangles alone), and cost a map's fill.
//
// Conservative rasterization without the GPU feature (WebGPU and lavapipe lack
// it), after Hasselgren, Akenine-Möller & Ohlsson, "Conservative Rasterization",
// GPU Gems 2, ch. 42 (2005): every triangle is pulled from the BVH's world-space
// buffer (three vertices a triangle, no vertex buffer) and drawn over its bounding
// rectangle along its longest edge, grown by the half-texel square's support. The
// fragment stage keeps a texel only where the square and the triangle overlap (the
// separating-axis test: the square's axes by the triangle's bounding box, then the
// three edges' normals; a segment's line both ways), at the nearest depth of the
// triangle clipped to the square (`nearest_over_square`). So a sliver of a finely
// cut floor holds the floor's depth where it crosses the texel, not a far end's.
//
// The layer stores nearness, 1 − depth, kept by the greatest: a texel nothing
// touches holds 0, what a new texture holds, and a placeholder bound where a map
// has no touched layer says nothing touches it.
//
// Two passes: a compute pass lists each layer's thin triangles and counts them
// into its indirect draw (touched_list.wgsl), then the draw of each layer draws
// those alone (touched_draw.wgsl): most of a scene's triangles are not thin, and
// three vertex invocations apiece, each projecting all three corners, cost
// Sponza's frame more than the map's own pass.
//
// Bindings of group 0, both passes: the triangles (0) and the light (1,
// `light_binding.wgsl`); each pass's own from 2.
import package::passes::light_binding::light;
import package::rays::bvh_triangle::BvhTriangle;
import package::variant::NO_ALPHA;

@group(0) @binding(0) var<storage, read> touched_triangles: array<BvhTriangle>;

// A triangle whose inscribed circle's radius is under this, in texels, is thin:
// the map may hold none of it. A circle of radius √2/2 holds a texel's centre
// wherever it lies; a smaller one fits between four.
const THIN_INRADIUS_TEXELS: f32 = 0.75;

// A triangle of less than a ten-thousandth of a texel's area is seen edge-on from
// the light: a segment.
const EDGE_ON_AREA_TEXELS: f32 = 1e-4;

// How far the half-texel square reaches along the unit direction `n`.
fn support(n: vec2<f32>, half_texel: f32) -> f32 {
    return half_texel * (abs(n.x) + abs(n.y));
}

// The half-plane beside the edge from `a` to `b`, away from `opposite`, grown by
// `half_texel` along both of the map's axes: n · p ≤ w for every point of the
// triangle grown by the half-texel square. A zero-length edge says nothing.
fn grown_edge(a: vec2<f32>, b: vec2<f32>, opposite: vec2<f32>, half_texel: f32) -> vec3<f32> {
    let e = b - a;
    let length_e = length(e);
    if length_e < 1e-12 {
        return vec3<f32>(0.0, 0.0, 1.0);
    }
    var n = vec2<f32>(e.y, -e.x) / length_e;
    if dot(n, opposite - a) > 0.0 {
        n = -n;
    }
    return vec3<f32>(n, dot(n, a) + support(n, half_texel));
}

// Twice the area of the triangle (a, b, c), signed.
fn doubled_area(a: vec2<f32>, b: vec2<f32>, c: vec2<f32>) -> f32 {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Triangle `index` in layer `layer`'s NDC (x, y) with its depth (z), and whether the
// layer draws it.
struct Projected {
    p: array<vec3<f32>, 3>,
    kept: bool,
};

fn projected(index: u32, layer: u32, half_texel: f32) -> Projected {
    let triangle = touched_triangles[index];
    let clip_from_world = light.cascade_clip_from_world[layer];
    let clip = array<vec4<f32>, 3>(
        clip_from_world * vec4<f32>(triangle.v0, 1.0),
        clip_from_world * vec4<f32>(triangle.v1, 1.0),
        clip_from_world * vec4<f32>(triangle.v2, 1.0),
    );
    let p = array<vec3<f32>, 3>(clip[0].xyz / clip[0].w, clip[1].xyz / clip[1].w, clip[2].xyz / clip[2].w);
    let in_front = min(clip[0].w, min(clip[1].w, clip[2].w)) > 1e-6;
    let before_far = min(p[0].z, min(p[1].z, p[2].z)) <= 1.0;
    // Inside the layer, grown by half a texel: the rasterizer's clipping would drop
    // the others, but not before their setup, which costs lavapipe most of the pass.
    let low = min(p[0].xy, min(p[1].xy, p[2].xy));
    let high = max(p[0].xy, max(p[1].xy, p[2].xy));
    let on_map = all(low <= vec2<f32>(1.0 + half_texel)) && all(high >= vec2<f32>(-1.0 - half_texel));
    let area = doubled_area(p[0].xy, p[1].xy, p[2].xy);
    // A closed mesh's faces turned from the light, which the map culls too (`cull
    // auto`): its faces toward the light cover all it covers, nearer.
    let turned_away = triangle.closed != 0u && area < 0.0;
    // Its inscribed circle's radius, 2 × area / perimeter, in texels (2 half-texels).
    let perimeter = distance(p[0].xy, p[1].xy) + distance(p[1].xy, p[2].xy) + distance(p[2].xy, p[0].xy);
    let thin = abs(area) < THIN_INRADIUS_TEXELS * 2.0 * half_texel * perimeter;
    return Projected(p, triangle.alpha == NO_ALPHA && in_front && before_far && on_map && !turned_away && thin);
}

// The bounding rectangle of the triangle `p` grown by the half-texel square, along
// its longest edge: corners `origin`, `origin + along` and `origin + across`, and a
// fourth.
struct Rectangle {
    origin: vec2<f32>,
    along: vec2<f32>,
    across: vec2<f32>,
};

fn oriented_bounds(p: array<vec3<f32>, 3>, half_texel: f32) -> Rectangle {
    let edges = array<vec2<f32>, 3>(p[1].xy - p[0].xy, p[2].xy - p[1].xy, p[0].xy - p[2].xy);
    var axis = edges[0];
    for (var i = 1; i < 3; i++) {
        if dot(edges[i], edges[i]) > dot(axis, axis) {
            axis = edges[i];
        }
    }
    let x = select(vec2<f32>(1.0, 0.0), normalize(axis), dot(axis, axis) > 1e-24);
    let y = vec2<f32>(-x.y, x.x);
    var low = vec2<f32>(1e30);
    var high = vec2<f32>(-1e30);
    for (var i = 0; i < 3; i++) {
        let q = vec2<f32>(dot(p[i].xy, x), dot(p[i].xy, y));
        low = min(low, q);
        high = max(high, q);
    }
    let grow = vec2<f32>(support(x, half_texel), support(y, half_texel));
    low -= grow;
    high += grow;
    return Rectangle(low.x * x + low.y * y, (high.x - low.x) * x, (high.y - low.y) * y);
}

