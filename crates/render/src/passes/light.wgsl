// The light uniform's structs, shared by every pass that reads a light (the uniform
// itself and the functions that read it are light_binding.wgsl's). Field meanings
// are documented in `uniforms/light.rs` (`LightGpu`).
import package::constants::MAX_CASCADES;
import package::variant::TechniqueParams;

// The parameters of a technique that has none, and of a shader linked without one
// (`NoParams` in techniques/params.rs). `TechniqueParams` is a generated alias of the
// linked technique's own struct (`VarianceParams`, …), 32 bytes each.
struct NoParams {
    _pad0: vec4<u32>,
    _pad1: vec4<u32>,
};

// A light as it emits: the light uniform's first block, and an element of the
// light-list pass's array (`EmitterGpu` in uniforms/light.rs).
struct Emitter {
    radiance: vec3<f32>,   // colour × intensity
    kind: u32,             // read only by light_kinds.wgsl
    direction: vec3<f32>,  // the sun's travel direction or the spot's axis
    range: f32,            // spot or point light range
    position: vec3<f32>,   // spot or point light position
    cos_inner: f32,        // cos of the spot's inner and outer half-angles
    cos_outer: f32,
    falloff: u32,          // FALLOFF_CONSTANT or FALLOFF_INVERSE_SQUARE
    falloff_window: f32,   // where the inverse square's window reaches 0 (0: no window)
    size: f32,             // radius in world units, or tan of the sun's angular radius
};

// The plane of a light's samples as a receiver sees it (`emitter_sample_plane` in
// light_kinds.wgsl), for a penumbra beam (rays/penumbra_beam.wgsl).
struct SamplePlane {
    toward: vec3<f32>,      // the direction to the disk's centre, in units of its radius
    b0: vec3<f32>,          // the disk's axes, unit
    b1: vec3<f32>,
    depth_axis: vec3<f32>,  // a caster's depth along the beam is w·depth_axis
    far: f32,               // depths in (0, far) can block
    axis: vec3<f32>,        // the walk's axis ray, unit
    axis_length: f32,
    widening: f32,          // the cone's radius over its distance along the axis, at most
};

// The light's map: its layers, texel sizes and depth range.
struct ShadowMap {
    layer_count: u32,         // layers: cascades, cube faces, paraboloids
    moment_layers: u32,       // moment-map layers per cascade
    resolution: f32,          // texels per side of a layer
    near: f32,                // the map's near and far planes along the light's axis
    far: f32,
    texel_ortho: f32,         // texel world size of an orthographic map
    texel_per_distance: f32,  // texel world size per unit distance (perspective)
    _pad0: u32,
};

// How a pixel picks its cascade (shadow.cascades).
struct CascadeChoice {
    by_projection: u32,  // 1 to pick cascades by projection, 0 by view depth
    blend: f32,          // blend band, fraction of a cascade's depth range
    _pad0: u32,
    _pad1: u32,
};

// The biases against acne (shadow.bias).
struct Bias {
    normal_offset: f32,    // in texels
    depth: f32,            // rasterizer constant bias (units), for passes writing their own depth
    slope: f32,            // and its slope-scaled bias
    receiver_plane: u32,   // 1 for receiver-plane depth bias
};

// The PCF kernel (shadow.filter), which PCSS's filtering step uses too.
struct Pcf {
    kernel_width: f32,     // texels or world units
    kernel_in_world: u32,  // 1 when kernel_width is in world units
    poisson_taps: u32,
    _pad0: u32,
};

// PCSS's blocker search (shadow.filter.pcss); the light's size is the emitter's.
struct Pcss {
    blocker_taps: u32,
    max_penumbra_texels: f32,  // largest filter radius
    max_search_texels: f32,    // largest blocker-search radius
    _pad1: u32,
};

// Contact shadows (shadow.contact): all zero when off.
struct Contact {
    steps: u32,        // ray steps (0: off)
    length: f32,       // ray length (world)
    thickness: f32,    // fraction of view depth
    bias: f32,         // start offset along the normal (world)
    distance: f32,     // view depth where contact shadows end
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

// Refinement by rays (screen).
struct Rays {
    penumbra_rays: u32,  // rays per pixel over the light's area (0: hard, one ray)
    history: u32,        // 1 where the penumbra history holds last frame's answers
    frame: u32,          // frames the history holds, this one counted
    penumbra_frames: u32, // frames a still view's penumbrae gather, then beam no more
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
    emitter: Emitter,
    ambient: vec3<f32>,           // ambient light (first light only)
    _pad0: u32,
    map: ShadowMap,
    cascade_choice: CascadeChoice,
    bias: Bias,
    pcf: Pcf,
    pcss: Pcss,
    contact: Contact,
    rays: Rays,
    technique: TechniqueParams,   // the composed technique's own struct
    // One layer of the shadow map per cascade (one in all for a single map).
    cascade_clip_from_world: array<mat4x4<f32>, MAX_CASCADES>,
    cascades: array<Cascade, MAX_CASCADES>,
};
