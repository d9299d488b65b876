// Helpers of the filterable techniques, which sample a blurred map of functions of
// depth (`moment_map`, an array of RGBA layers) instead of comparing depths.
import package::passes::light_binding::{light, moment_depth};
import package::techniques::bindings::{moment_map, moment_sampler};
import package::techniques::common::ShadowQuery;

// The filtered value of `layer` at the lookup, trilinear when the map has mipmaps
// (the screen derivatives choose the level; they were taken in uniform control flow).
fn sample_moments(q: ShadowQuery, layer: u32) -> vec4<f32> {
    let index = q.layer * light.map.moment_layers + layer;
    return textureSampleGrad(moment_map, moment_sampler, q.coords.xy, index, q.coords_dx.xy, q.coords_dy.xy);
}

// The receiver's depth in the moment map's convention (linear in [0, 1]).
fn receiver_moment_depth(q: ShadowQuery) -> f32 {
    return moment_depth(q.coords.z);
}

// One-tailed Chebyshev (Cantelli) inequality: an upper bound on the fraction of the
// filter region whose depth is ≥ t, from the mean and mean square of the depths
// (Donnelly & Lauritzen, "Variance shadow maps", I3D 2006).
fn chebyshev_upper_bound(mean: f32, mean_square: f32, t: f32, min_variance: f32) -> f32 {
    if t <= mean {
        return 1.0;
    }
    let variance = max(mean_square - mean * mean, min_variance);
    let d = t - mean;
    return variance / (variance + d * d);
}

// Light-bleeding reduction (Lauritzen, "Summed-area variance shadow maps", GPU Gems 3,
// 2007): bounds below `amount` become 0 and the rest is stretched over [0, 1].
fn reduce_bleeding(p: f32, amount: f32) -> f32 {
    return clamp((p - amount) / (1.0 - amount), 0.0, 1.0);
}
