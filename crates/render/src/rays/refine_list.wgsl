// The list of pixels that the mask pass leaves to a ray (refine_classify.wgsl, which
// writes it) and the trace pass answers (refine_trace.wgsl, which reads it), at group 1
// binding 3, beside the camera and the prepass; each light's counters at binding 4,
// at the light's own offset.

struct UnsurePixel {
    // x | y << 16.
    pixel: u32,
    // Low 16 bits: the shadow-map layer that shaded it, kept in the mask for the
    // cascade view. High 16 bits: under a light with an area traced by rays, the
    // penumbra's width on screen in 1/16 px, which the trace pass writes for the
    // filter pass (0 before).
    layer: u32,
    // Under a light with an area beamed (penumbra_mask.wgsl): the mean of the beams
    // the pixel's history holds, and how many (0: none).
    mean: f32,
    beams: f32,
};

// A light's counters (`RefineCounters` in refine_append.wgsl) as the passes
// dispatched by them read them, each at binding 4 of its own group 1: the trace and
// fill passes' workgroups and pixels, then the unsure pixels the history answered.
struct ListedPixels {
    groups: vec3<u32>,
    count: u32,
    fill_groups: vec3<u32>,
    fill_count: u32,
    kept_count: u32,
};

// Written by the mask pass (refine_append.wgsl), completed by the trace pass.
@group(1) @binding(3) var<storage, read_write> unsure_pixels: array<UnsurePixel>;
