// The mask pass's list of the pixels it leaves to rays (refine_classify.wgsl decides
// which), for the trace pass (refine_trace.wgsl).
import package::rays::refine_list::{UnsurePixel, unsure_pixels};
import package::variant::{REFINE_GROUP_SIZE, REFINE_MAX_GROUPS};

// The first three words are the trace pass's `dispatch_workgroups_indirect`
// arguments: one workgroup per REFINE_GROUP_SIZE pixels listed (at most
// REFINE_MAX_GROUPS, which then loop), by 1, by 1. The next four are the same for
// the pixels listed from the list's far end to be filled (penumbra_mask.wgsl). All
// start at zero, which dispatches nothing.
struct RefineCounters {
    groups_x: atomic<u32>,
    groups_y: u32,
    groups_z: u32,
    count: atomic<u32>,
    fill_groups_x: atomic<u32>,
    fill_groups_y: u32,
    fill_groups_z: u32,
    fill_count: atomic<u32>,
    // Unsure pixels answered by the beams their history holds, neither beamed nor
    // filled this frame (penumbra_mask.wgsl).
    kept_count: atomic<u32>,
    // To `ListedPixels`' 48 bytes, the size of Rust's `RefineCountersGpu`.
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(1) @binding(4) var<storage, read_write> refine_counters: RefineCounters;

// Appends `pixel` to the list, and counts one more workgroup for the trace pass at
// the start of every REFINE_GROUP_SIZE pixels.
fn listed_defer_to_ray(pixel: vec2<u32>, layer: u32) {
    listed_defer_beam(pixel, layer, vec2<f32>(0.0));
}

// `listed_defer_to_ray` of a pixel whose history holds `past`: the mean of its beams
// and how many (penumbra_mask.wgsl).
fn listed_defer_beam(pixel: vec2<u32>, layer: u32, past: vec2<f32>) {
    let index = atomicAdd(&refine_counters.count, 1u);
    if index == 0u {
        refine_counters.groups_y = 1u;
        refine_counters.groups_z = 1u;
    }
    if index % REFINE_GROUP_SIZE == 0u && index / REFINE_GROUP_SIZE < REFINE_MAX_GROUPS {
        atomicAdd(&refine_counters.groups_x, 1u);
    }
    // The list holds a pixel per pixel of the screen, and each pixel lists itself at
    // most once per light: the index is in bounds.
    unsure_pixels[index] = UnsurePixel(pixel.x | (pixel.y << 16u), layer, past.x, past.y);
}

// Counts an unsure pixel its history answered.
fn count_kept() {
    atomicAdd(&refine_counters.kept_count, 1u);
}

// Appends `pixel` to the fill list, which runs from the list's far end down, and
// counts its workgroups as the trace pass's are counted. The two never meet: a pixel
// is listed once, in one of them.
fn listed_defer_to_fill(pixel: vec2<u32>, layer: u32) {
    let index = atomicAdd(&refine_counters.fill_count, 1u);
    if index == 0u {
        refine_counters.fill_groups_y = 1u;
        refine_counters.fill_groups_z = 1u;
    }
    if index % REFINE_GROUP_SIZE == 0u && index / REFINE_GROUP_SIZE < REFINE_MAX_GROUPS {
        atomicAdd(&refine_counters.fill_groups_x, 1u);
    }
    unsure_pixels[arrayLength(&unsure_pixels) - 1u - index] = UnsurePixel(pixel.x | (pixel.y << 16u), layer, 0.0, 0.0);
}
