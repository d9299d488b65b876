// The list pass of the touched layer (touched.wgsl): one invocation a triangle and
// a layer, appending the thin ones the layer draws (`projected`, less those the map
// holds itself, `map_holds`) to its part of the list and counting them into its
// indirect draw.
import package::passes::light_binding::light;
import package::rays::touched::{EDGE_ON_AREA_TEXELS, projected, touched_triangles};
import package::variant::{LAYER_SHIFT, TOUCHED_GROUP_SIZE};

// One layer's draw, as `draw_indirect` reads it (wgpu's `DrawIndirectArgs`): its
// vertex count grows by 3 a listed triangle; its first vertex is 3 × its part's
// start.
struct TouchedDraw {
    vertex_count: atomic<u32>,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
};

// Binding 2: each layer's draw; binding 3: the list, each layer's part as long as
// the triangles; binding 4: the map itself.
@group(0) @binding(2) var<storage, read_write> touched_draws: array<TouchedDraw>;
@group(0) @binding(3) var<storage, read_write> touched_list: array<u32>;
@group(0) @binding(4) var touched_map_depths: texture_depth_2d_array;

// The most texels along its longest edge `map_holds` reads of a triangle; a longer
// one is drawn.
const HOLDS_MAX_STEPS: u32 = 4096u;

// Whether the map holds the thin triangle `p` of layer `layer` itself, or
// something nearer the light in front of it, so that the layer need not draw it:
// at every texel along its longest edge, a texel apart, the map stores a depth no
// farther than the triangle's own there (give or take the bias a surface of its
// slope is drawn with, and a texel's change of depth). Every texel it touches is
// then within two texels of one of those, which the footprint test's ring reads:
// a pixel there is unsure by the map alone, or in the shadow of what the map holds
// in front of it.
// Sponza's ornaments and fluted columns are a hundred thousand slivers, pieces of
// surfaces the map holds; a wire's, or a speck's, the map holds in dashes or not
// at all, and the layer draws it (`wires`: 0.170 % wrong without it). A triangle
// seen edge-on has no slope to judge by: drawn.
fn map_holds(p: array<vec3<f32>, 3>, layer: u32, half_texel: f32) -> bool {
    let u = p[1] - p[0];
    let w = p[2] - p[0];
    let det = u.x * w.y - u.y * w.x;
    let texel = 2.0 * half_texel;
    if abs(det) < 2.0 * EDGE_ON_AREA_TEXELS * texel * texel {
        return false;
    }
    // Depth per texel along x and y, from the plane's gradient over NDC.
    let gradient = vec2<f32>(u.z * w.y - w.z * u.y, u.x * w.z - w.x * u.z) / det * texel;
    let slope = abs(gradient.x) + abs(gradient.y);
    let farthest = max(p[0].z, max(p[1].z, p[2].z));
    // The rasterizer's bias (slope-scaled, and its constant in units of the last
    // place), then a texel's change of depth on either side.
    let unit = exp2(floor(log2(max(farthest, 1e-30))) - 23.0);
    let slack = (max(light.bias.slope, 0.0) + 2.0) * slope + (max(light.bias.depth, 0.0) + 4.0) * unit;
    var a = p[0];
    var b = p[1];
    if distance(p[1].xy, p[2].xy) > distance(a.xy, b.xy) {
        a = p[1];
        b = p[2];
    }
    if distance(p[2].xy, p[0].xy) > distance(a.xy, b.xy) {
        a = p[2];
        b = p[0];
    }
    let steps = u32(ceil(distance(a.xy, b.xy) / texel));
    if steps > HOLDS_MAX_STEPS {
        return false;
    }
    let size = light.map.resolution;
    for (var i = 0u; i <= steps; i++) {
        let q = mix(a, b, f32(i) / f32(max(steps, 1u)));
        let uv = q.xy * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5);
        let at = clamp(vec2<i32>(floor(uv * size)), vec2<i32>(0), vec2<i32>(i32(size) - 1));
        let stored = textureLoad(touched_map_depths, at, layer, 0);
        if stored > q.z + slack {
            return false;
        }
    }
    return true;
}

@compute @workgroup_size(TOUCHED_GROUP_SIZE, 1, 1)
fn cs_touched_list(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    // Groups past MAX_GROUPS along x wrap onto y.
    let index = id.y * groups.x * TOUCHED_GROUP_SIZE + id.x;
    let layer = id.z;
    if index >= arrayLength(&touched_triangles) {
        return;
    }
    let half_texel = 1.0 / light.map.resolution;
    let shape = projected(index, layer, half_texel);
    if !shape.kept || map_holds(shape.p, layer, half_texel) {
        return;
    }
    let slot = atomicAdd(&touched_draws[layer].vertex_count, 3u) / 3u;
    touched_list[touched_draws[layer].first_vertex / 3u + slot] = (layer << LAYER_SHIFT) | index;
}
