// The draw of the touched layer (touched.wgsl): each layer's thin triangles, as
// the list pass listed them (touched_list.wgsl), drawn conservatively.
import package::passes::light_binding::light;
import package::rays::touched::{EDGE_ON_AREA_TEXELS, doubled_area, grown_edge, oriented_bounds, projected, support};
import package::variant::{LAYER_SHIFT, TRIANGLE_MASK};

// Binding 3: the listed triangles, `layer << LAYER_SHIFT | triangle`; a layer's
// draw starts at its own part (its first vertex, 3 a triangle).
@group(0) @binding(3) var<storage, read> touched_listed: array<u32>;

// What the fragment stage tests: the triangle's bounding box grown by half a texel
// (xy min, xy max, in the map's NDC), its three edges as half-planes grown by the
// half-texel square's support (n · p ≤ w, n unit), and its corners in NDC (x, y)
// with their depths (z); `segment` 1 where it is seen edge-on.
struct TouchedVertex {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) bounds: vec4<f32>,
    @location(1) @interpolate(flat) edge0: vec3<f32>,
    @location(2) @interpolate(flat) edge1: vec3<f32>,
    @location(3) @interpolate(flat) edge2: vec3<f32>,
    @location(4) @interpolate(flat) p0: vec3<f32>,
    @location(5) @interpolate(flat) p1: vec3<f32>,
    @location(6) @interpolate(flat) p2: vec3<f32>,
    @location(7) @interpolate(flat) segment: u32,
};

// A triangle no texel keeps: cut-out (its alpha test would make its whole card a
// caster), behind the light, wholly beyond the far plane, a closed mesh's face
// turned from the light, or one the map holds itself (not thin).
fn dropped() -> TouchedVertex {
    var out: TouchedVertex;
    out.position = vec4<f32>(2.0, 2.0, 2.0, 1.0);
    return out;
}

@vertex
fn vs_touched(@builtin(vertex_index) index: u32) -> TouchedVertex {
    // Half a texel in NDC, which spans 2 over the map's side.
    let half_texel = 1.0 / light.map.resolution;
    let listed = touched_listed[index / 3u];
    let shape = projected(listed & TRIANGLE_MASK, listed >> LAYER_SHIFT, half_texel);
    if !shape.kept {
        return dropped();
    }
    let p = shape.p;
    var out: TouchedVertex;
    out.bounds = vec4<f32>(
        min(p[0].xy, min(p[1].xy, p[2].xy)) - vec2<f32>(half_texel),
        max(p[0].xy, max(p[1].xy, p[2].xy)) + vec2<f32>(half_texel),
    );
    out.p0 = p[0];
    out.p1 = p[1];
    out.p2 = p[2];
    // A texel is 2 half-texels a side; the doubled area is twice the area.
    let texel_area = 4.0 * half_texel * half_texel;
    let edge_on = abs(doubled_area(p[0].xy, p[1].xy, p[2].xy)) < 2.0 * EDGE_ON_AREA_TEXELS * texel_area;
    out.segment = u32(edge_on);
    if edge_on {
        // A segment, its longest edge, kept within half a texel of its line on
        // either side.
        let lengths = vec3<f32>(distance(p[0].xy, p[1].xy), distance(p[1].xy, p[2].xy), distance(p[2].xy, p[0].xy));
        var a = p[2].xy;
        var b = p[0].xy;
        if lengths.x >= max(lengths.y, lengths.z) {
            a = p[0].xy;
            b = p[1].xy;
        } else if lengths.y >= lengths.z {
            a = p[1].xy;
            b = p[2].xy;
        }
        let side = grown_edge(a, b, a + vec2<f32>(b.y - a.y, a.x - b.x), half_texel);
        out.edge0 = side;
        out.edge1 = vec3<f32>(-side.xy, 2.0 * support(side.xy, half_texel) - side.z);
        out.edge2 = vec3<f32>(0.0, 0.0, 1.0);
    } else {
        out.edge0 = grown_edge(p[0].xy, p[1].xy, p[2].xy, half_texel);
        out.edge1 = grown_edge(p[1].xy, p[2].xy, p[0].xy, half_texel);
        out.edge2 = grown_edge(p[2].xy, p[0].xy, p[1].xy, half_texel);
    }
    // A triangle over the grown bounding rectangle: its legs twice the rectangle's
    // sides, so that the rectangle lies inside it.
    let r = oriented_bounds(p, half_texel);
    let corner = array<vec2<f32>, 3>(r.origin, r.origin + 2.0 * r.along, r.origin + 2.0 * r.across)[index % 3u];
    // Any depth inside the clip volume: the fragment stage writes its own.
    out.position = vec4<f32>(corner, 0.5, 1.0);
    return out;
}

// The nearest depth along the edge from `a` to `b` (NDC x, y and depth) inside the
// square from `low` to `high`: at one end of the part the square clips (Liang &
// Barsky); 2 where the edge misses the square.
fn edge_nearest(a: vec3<f32>, b: vec3<f32>, low: vec2<f32>, high: vec2<f32>) -> f32 {
    let d = b - a;
    var t = vec2<f32>(0.0, 1.0);
    for (var axis = 0; axis < 2; axis++) {
        if abs(d[axis]) < 1e-20 {
            if a[axis] < low[axis] || a[axis] > high[axis] {
                return 2.0;
            }
            continue;
        }
        let enter = (low[axis] - a[axis]) / d[axis];
        let leave = (high[axis] - a[axis]) / d[axis];
        t = vec2<f32>(max(t.x, min(enter, leave)), min(t.y, max(enter, leave)));
    }
    if t.x > t.y {
        return 2.0;
    }
    return min(a.z + t.x * d.z, a.z + t.y * d.z);
}

// The nearest depth of the triangle `v` over the square from `low` to `high`: its
// depth is affine over the triangle clipped to the square, least at a corner of that
// polygon, which is on one of its edges or the square's corner where its plane is
// least. A segment's depths along its line are least on its edges too. 2 where
// rounding put it outside.
fn nearest_over_square(v: TouchedVertex, low: vec2<f32>, high: vec2<f32>) -> f32 {
    var nearest = min(edge_nearest(v.p0, v.p1, low, high), min(edge_nearest(v.p1, v.p2, low, high), edge_nearest(v.p2, v.p0, low, high)));
    let u = v.p1 - v.p0;
    let w = v.p2 - v.p0;
    let det = u.x * w.y - u.y * w.x;
    if v.segment != 0u || det == 0.0 {
        return nearest;
    }
    // The plane z = z0 + a (x − x0) + b (y − y0), least at the square's corner
    // against its gradient.
    let gradient = vec2<f32>(u.z * w.y - w.z * u.y, u.x * w.z - w.x * u.z) / det;
    let corner = select(high, low, gradient > vec2<f32>(0.0));
    // Inside the triangle: on the same side of every edge as the triangle's area.
    let inside = doubled_area(v.p0.xy, v.p1.xy, corner) * det >= 0.0 && doubled_area(v.p1.xy, v.p2.xy, corner) * det >= 0.0
        && doubled_area(v.p2.xy, v.p0.xy, corner) * det >= 0.0;
    if inside {
        nearest = min(nearest, v.p0.z + dot(gradient, corner - v.p0.xy));
    }
    return nearest;
}

// The texel's nearness (1 − depth) to the light of the triangle's nearest point
// over the texel's square.
@fragment
fn fs_touched(v: TouchedVertex) -> @builtin(frag_depth) f32 {
    // The texel's centre in the map's NDC.
    let side = light.map.resolution;
    let half_texel = 1.0 / side;
    let p = vec2<f32>(v.position.x / side * 2.0 - 1.0, 1.0 - v.position.y / side * 2.0);
    if any(p < v.bounds.xy) || any(p > v.bounds.zw) {
        discard;
    }
    for (var i = 0; i < 3; i++) {
        let edge = array<vec3<f32>, 3>(v.edge0, v.edge1, v.edge2)[i];
        if dot(edge.xy, p) > edge.z {
            discard;
        }
    }
    // Where rounding put the triangle outside a square the test says it touches:
    // its nearest vertex.
    let clipped = nearest_over_square(v, p - vec2<f32>(half_texel), p + vec2<f32>(half_texel));
    let nearest = select(min(v.p0.z, min(v.p1.z, v.p2.z)), clipped, clipped <= 1.5);
    return 1.0 - clamp(nearest, 0.0, 1.0);
}
