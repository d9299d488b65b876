// The light uniform and the depth conventions of its shadow map, shared by the
// geometry passes and the moment-map compute passes. Field meanings are documented
// in `gpu_types.rs` (`LightGpu`).

struct Light {
    clip_from_world: mat4x4<f32>,
    light_from_world: mat4x4<f32>,
    radiance: vec4<f32>,     // rgb: colour × intensity
    direction: vec4<f32>,    // xyz: travel direction (sun) or cone axis (spot); w: 0 sun, 1 spot, 2 point
    position: vec4<f32>,     // xyz: spot or point light position; w: range
    cone: vec4<f32>,         // x: cos inner, y: cos outer, z: map near, w: map far
    texel: vec4<f32>,        // x: ortho texel size, y: texel size per unit distance, z: normal offset (texels), w: map size
    kernel: vec4<f32>,       // x: kernel width, y: 1 when in world units, z: Poisson taps, w: 1 for receiver-plane bias
    pcss: vec4<f32>,         // x: light size, y: blocker-search taps, z: largest radius (texels)
    params: array<vec4<f32>, 2>, // technique parameters, see each technique
    ambient: vec4<f32>,      // rgb: ambient light
    // One layer of the shadow map per cascade (one in all for a single map).
    cascade_clip_from_world: array<mat4x4<f32>, 8>,
    cascade_texel: array<vec4<f32>, 8>,  // x: orthographic texel world size; y: 1 when warped; z: warped difference step
    cascade_splits: array<vec4<f32>, 3>, // view depth where cascade i starts (i) and ends (i + 1)
    cascades: vec4<f32>,     // x: count, y: 1 to select by projection, z: blend band, w: moment layers per cascade
    raster_bias: vec4<f32>,  // x: constant depth bias (units), y: slope-scaled bias, for passes that write their own depth
    contact: vec4<f32>,      // contact shadows: x: ray length (world), y: steps (0: off), z: thickness (fraction of view depth), w: start offset (world)
    contact_range: vec4<f32>, // x: view depth where contact shadows end
};

// The view depth where cascade `i` starts; `i + 1` where it ends.
fn cascade_split(i: u32) -> f32 {
    return light.cascade_splits[i / 4u][i % 4u];
}

// World size of one texel of layer `layer` at light distance `distance`.
fn texel_world_size_at(layer: u32, distance: f32) -> f32 {
    return light.cascade_texel[layer].x + light.texel.y * max(distance, 0.0);
}

// Distance along the light's axis (light view −z) of a point whose shadow-map depth
// is `depth`. Orthographic maps store it linearly between the near and far planes;
// perspective ones store the D3D-style f(z − n) / (z (f − n)).
fn light_distance_from_depth(depth: f32) -> f32 {
    let n = light.cone.z;
    let f = light.cone.w;
    if light.direction.w < 0.5 {
        return n + depth * (f - n);
    }
    return n * f / (f - depth * (f - n));
}

// The depth that moment maps store: light distance, linear in [0, 1] from the near
// to the far plane, so that filtering averages distances, not projected depths.
fn moment_depth(depth: f32) -> f32 {
    let n = light.cone.z;
    let f = light.cone.w;
    return clamp((light_distance_from_depth(depth) - n) / (f - n), 0.0, 1.0);
}
