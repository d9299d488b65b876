// Variance shadow maps and their exponential warp.
//
// VSM (Donnelly & Lauritzen 2006) stores (d, d²); EVSM (Lauritzen & McCool,
// "Layered variance shadow maps", GI 2008) stores the moments of the warped depths
// p = exp(c⁺·d̃) and n = −exp(−c⁻·d̃), d̃ = 2d − 1 ∈ [−1, 1], whose steep warp
// shrinks the variance that causes light bleeding. Both bounds use the same
// Chebyshev inequality; EVSM keeps the smaller.
//
// Its parameters (`VarianceParams` in variance.rs).
import package::passes::light_binding::light;
import package::techniques::common::ShadowQuery;
import package::techniques::filterable::{chebyshev_upper_bound, receiver_moment_depth, reduce_bleeding, sample_moments};

struct VarianceParams {
    positive_exponent: f32,   // c⁺
    negative_exponent: f32,   // c⁻
    min_variance: f32,        // in depth units
    bleeding_reduction: f32,  // the fraction of the bound cut away as light bleeding
    variant: u32,             // 0 VSM, 2 EVSM2, 4 EVSM4: the moments of the warps kept
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

fn warp_positive(d: f32) -> f32 {
    return exp(light.technique.positive_exponent * (2.0 * d - 1.0));
}

fn warp_negative(d: f32) -> f32 {
    return -exp(-light.technique.negative_exponent * (2.0 * d - 1.0));
}

fn variance_encode_moments(d: f32, layer: u32) -> vec4<f32> {
    if light.technique.variant == 0u {
        return vec4<f32>(d, d * d, 0.0, 0.0);
    }
    let p = warp_positive(d);
    let n = warp_negative(d);
    return vec4<f32>(p, p * p, n, n * n);
}

fn variance_sample_shadow(q: ShadowQuery) -> f32 {
    let m = sample_moments(q, 0u);
    let d = receiver_moment_depth(q);
    let min_variance = light.technique.min_variance;
    let variant = light.technique.variant;
    var p = 1.0;
    if variant == 0u {
        p = chebyshev_upper_bound(m.x, m.y, d, min_variance);
    } else {
        // The minimum variance is given in depth units; a warp w stretches depths
        // near d by w'(d), so variances by w'(d)² (Lauritzen 2008).
        let cp = light.technique.positive_exponent;
        let wp = warp_positive(d);
        let dp = 2.0 * cp * wp;
        p = chebyshev_upper_bound(m.x, m.y, wp, min_variance * dp * dp);
        if variant == 4u {
            let cn = light.technique.negative_exponent;
            let wn = warp_negative(d);
            let dn = 2.0 * cn * wn;
            p = min(p, chebyshev_upper_bound(m.z, m.w, wn, min_variance * dn * dn));
        }
    }
    return reduce_bleeding(p, light.technique.bleeding_reduction);
}
