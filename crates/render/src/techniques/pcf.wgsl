// The PCF family (Reeves, Salesin & Cook 1987) on the comparison sampler, whose
// linear filter is the hardware's 2×2 bilinear PCF.
//
// Box and tent kernels are built from bilinear taps (Castaño, "Shadow mapping
// summary, part 1", 2013): along each axis the kernel gives every texel cell an
// exact weight (the kernel's integral over the cell); two neighbouring cells i and
// i + 1 with weights a and b are read by one bilinear tap placed b / (a + b) of the
// way from texel centre i to centre i + 1, weighted a + b. A width-W kernel touches
// ⌈W⌉ + 1 cells per axis, so it costs ⌈(⌈W⌉ + 1) / 2⌉² taps instead of (⌈W⌉ + 1)².
import package::passes::light_binding::light;
import package::techniques::common::{ShadowQuery, compare_tap, receiver_depth_gradient};

// Integral from −∞ to t of the unit-area box of half-width h.
fn box_cdf(t: f32, h: f32) -> f32 {
    return clamp((t + h) / (2.0 * h), 0.0, 1.0);
}

// Integral from −∞ to t of the unit-area tent of half-width h.
fn tent_cdf(t: f32, h: f32) -> f32 {
    let s = clamp(t, -h, h);
    if s < 0.0 {
        return 0.5 * (s + h) * (s + h) / (h * h);
    }
    return 1.0 - 0.5 * (h - s) * (h - s) / (h * h);
}

// Weight of texel cell [i, i + 1] for a kernel centred at p (texel units).
fn cell_weight(p: f32, i: f32, h: f32, tent: bool) -> f32 {
    if tent {
        return tent_cdf(i + 1.0 - p, h) - tent_cdf(i - p, h);
    }
    return box_cdf(i + 1.0 - p, h) - box_cdf(i - p, h);
}

// Position (texel units, relative to p) and weight of the bilinear tap covering
// cells i and i + 1.
fn pair_tap(p: f32, i: f32, h: f32, tent: bool) -> vec2<f32> {
    let a = cell_weight(p, i, h, tent);
    let b = cell_weight(p, i + 1.0, h, tent);
    let w = a + b;
    let x = i + 0.5 + select(0.5, b / w, w > 0.0);
    return vec2<f32>(x - p, w);
}

// The bilinear taps of a box or tent kernel round the texel point `p`: `taps` per
// axis, tap k reading cells `first + 2k` and `first + 2k + 1`. Every map kind's
// kernel walks the same grid and differs only in how it reads a tap (`pcf_kernel`
// here, `virtual_pcf_kernel` through a page table).
struct KernelGrid {
    p: vec2<f32>,
    // The first texel cell the kernel touches, per axis.
    first: vec2<f32>,
    half_width: f32,
    taps: vec2<i32>,
    tent: bool,
};

fn kernel_grid(p: vec2<f32>, width: f32, tent: bool) -> KernelGrid {
    let h = 0.5 * width;
    let first = floor(p - vec2<f32>(h));
    let cells = vec2<i32>(floor(p + vec2<f32>(h)) - first) + vec2<i32>(1);
    return KernelGrid(p, first, h, (cells + vec2<i32>(1)) / 2, tent);
}

// Tap k along x: its offset from p in texels, and its weight along x.
fn kernel_grid_x(g: KernelGrid, k: i32) -> vec2<f32> {
    return pair_tap(g.p.x, g.first.x + f32(2 * k), g.half_width, g.tent);
}

// Tap k along y: its offset from p in texels, and its weight along y.
fn kernel_grid_y(g: KernelGrid, k: i32) -> vec2<f32> {
    return pair_tap(g.p.y, g.first.y + f32(2 * k), g.half_width, g.tent);
}

fn pcf_kernel(q: ShadowQuery, width: f32, tent: bool) -> f32 {
    let gradient = receiver_depth_gradient(q);
    let g = kernel_grid(q.coords.xy * light.map.resolution, width, tent);
    var sum = 0.0;
    var total = 0.0;
    for (var j = 0; j < g.taps.y; j++) {
        let ty = kernel_grid_y(g, j);
        for (var i = 0; i < g.taps.x; i++) {
            let tx = kernel_grid_x(g, i);
            let w = tx.y * ty.y;
            if w > 0.0 {
                sum += w * compare_tap(q, gradient, vec2<f32>(tx.x, ty.x));
                total += w;
            }
        }
    }
    return sum / max(total, 1e-12);
}
