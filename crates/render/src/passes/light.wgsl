// The light uniform and the depth conventions of its shadow map, shared by the
// geometry passes and the moment-map compute passes. Field meanings are documented
// in `uniforms.rs` (`LightGpu`).

// A technique's own parameters: what each puts where is documented by its module.
struct TechniqueParams {
    reals: vec4<f32>,
    integers: vec4<u32>, // counts, variants, switches (0 or 1)
};

// One layer (cascade) of the map.
struct Cascade {
    texel_world: f32,  // orthographic texel world size (the largest when warped); 0 for perspective
    warp_step: f32,    // world step of a warped layer's finite-difference texel size
    split_start: f32,  // view depth where the cascade starts
    split_end: f32,    // and where it ends
    warped: u32,       // 1 for a warped layer (PSM, LiSPSM, TSM)
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

struct Light {
    clip_from_world: mat4x4<f32>,
    light_from_world: mat4x4<f32>,
    radiance: vec3<f32>,          // colour × intensity
    kind: u32,                    // LIGHT_SUN, LIGHT_SPOT or LIGHT_POINT
    direction: vec3<f32>,         // the sun's travel direction or the spot's axis
    range: f32,                   // spot or point light range
    position: vec3<f32>,          // spot or point light position
    layer_count: u32,             // layers of the map: cascades, cube faces, paraboloids
    ambient: vec3<f32>,           // ambient light (first light only)
    moment_layers: u32,           // moment-map layers per cascade
    cos_inner: f32,
    cos_outer: f32,
    map_near: f32,                // the map's near and far planes along the light's axis
    map_far: f32,
    texel_ortho: f32,             // texel world size of an orthographic map
    texel_per_distance: f32,      // texel world size per unit distance (perspective)
    normal_offset: f32,           // in texels
    resolution: f32,              // texels per side of a layer
    kernel_width: f32,            // PCF kernel width, texels or world units
    kernel_in_world: u32,         // 1 when kernel_width is in world units
    poisson_taps: u32,
    receiver_plane_bias: u32,     // 1 for receiver-plane depth bias
    light_size: f32,              // PCSS: light size (world radius, or tan of the sun's angular radius)
    blocker_taps: u32,            // PCSS: blocker-search taps
    max_penumbra_texels: f32,     // PCSS: largest filter radius
    select_by_projection: u32,    // 1 to pick cascades by projection, 0 by view depth
    cascade_blend: f32,           // blend band, fraction of a cascade's depth range
    depth_bias: f32,              // rasterizer constant bias (units), for passes writing their own depth
    slope_bias: f32,              // and its slope-scaled bias
    contact_steps: u32,           // contact shadows: ray steps (0: off)
    contact_length: f32,          // ray length (world)
    contact_thickness: f32,       // thickness, fraction of view depth
    contact_bias: f32,            // start offset along the normal (world)
    contact_distance: f32,        // view depth where contact shadows end
    penumbra_rays: u32,           // refinement: rays per pixel over the light's area (0: hard, one ray)
    falloff: u32,                 // FALLOFF_CONSTANT or FALLOFF_INVERSE_SQUARE
    falloff_window: f32,          // where the inverse square's window reaches 0 (0: no window)
    _pad0: u32,
    params: TechniqueParams,
    // One layer of the shadow map per cascade (one in all for a single map).
    cascade_clip_from_world: array<mat4x4<f32>, MAX_CASCADES>,
    cascades: array<Cascade, MAX_CASCADES>,
};

// The view depth where cascade `i` starts; `i + 1` where it ends.
fn cascade_split(i: u32) -> f32 {
    if i == 0u {
        return light.cascades[0].split_start;
    }
    return light.cascades[i - 1u].split_end;
}

// World size of one texel of layer `layer` at light distance `distance`.
fn texel_world_size_at(layer: u32, distance: f32) -> f32 {
    return light.cascades[layer].texel_world + light.texel_per_distance * max(distance, 0.0);
}

// Distance along the light's axis (light view −z) of a point whose shadow-map depth
// is `depth`. Orthographic maps store it linearly between the near and far planes;
// perspective ones store the D3D-style f(z − n) / (z (f − n)).
fn light_distance_from_depth(depth: f32) -> f32 {
    let n = light.map_near;
    let f = light.map_far;
    if light.kind == LIGHT_SUN {
        return n + depth * (f - n);
    }
    return n * f / (f - depth * (f - n));
}

// The depth that moment maps store: light distance, linear in [0, 1] from the near
// to the far plane, so that filtering averages distances, not projected depths.
fn moment_depth(depth: f32) -> f32 {
    let n = light.map_near;
    let f = light.map_far;
    return clamp((light_distance_from_depth(depth) - n) / (f - n), 0.0, 1.0);
}
