// Convolution shadow maps (T. Annen, T. Mertens, P. Bekaert, H.-P. Seidel & J. Kautz,
// "Convolution shadow maps", EGSR 2007). The depth test is expanded in the Fourier
// series of a square wave (see `gnomon_math::kernels::convolution_frequencies`):
//   H(d − z) ≈ ½ + 2 Σₖ aₖ/cₖ · (sin(cₖd)·cos(cₖz) − cos(cₖd)·sin(cₖz)),
// cₖ = π(2k − 1) (period 2, as in the paper), which is linear in the stored sin(cₖd) and cos(cₖd), so filtering
// the map filters the test. Truncation rings (Gibbs); aₖ = exp(−α (k/M)²) damps the
// high terms. The reconstruction f is then sharpened: visibility = s·(f − ½ + o) + ½.
//
// Layer j holds (sin, cos) of terms 2j and 2j + 1 (0-based).
// Its parameters (`ConvolutionParams` in convolution.rs).
import package::constants::PI;
import package::passes::light_binding::light;
import package::techniques::common::ShadowQuery;
import package::techniques::filterable::{receiver_moment_depth, sample_moments};

struct ConvolutionParams {
    terms: u32,        // M, the Fourier terms kept
    attenuation: f32,  // α, the ringing suppression
    scale: f32,        // s, the reconstruction's sharpening scale
    offset: f32,       // o, its offset
    _pad0: vec4<u32>,
};

fn frequency(k: u32) -> f32 {
    return PI * f32(2u * k + 1u);
}

fn convolution_encode_moments(d: f32, layer: u32) -> vec4<f32> {
    let c0 = frequency(2u * layer);
    let c1 = frequency(2u * layer + 1u);
    return vec4<f32>(sin(c0 * d), cos(c0 * d), sin(c1 * d), cos(c1 * d));
}

fn convolution_sample_shadow(q: ShadowQuery) -> f32 {
    let terms = light.technique.terms;
    let m = f32(terms);
    let alpha = light.technique.attenuation;
    let z = receiver_moment_depth(q);
    var f = 0.5;
    for (var layer = 0u; 2u * layer < terms; layer++) {
        let s = sample_moments(q, layer);
        for (var t = 0u; t < 2u; t++) {
            let k = 2u * layer + t;
            if k >= terms {
                break;
            }
            let c = frequency(k);
            let a = exp(-alpha * pow(f32(k + 1u) / m, 2.0));
            let sin_d = select(s.x, s.z, t == 1u);
            let cos_d = select(s.y, s.w, t == 1u);
            f += 2.0 * a / c * (sin_d * cos(c * z) - cos_d * sin(c * z));
        }
    }
    return clamp(light.technique.scale * (f - 0.5 + light.technique.offset) + 0.5, 0.0, 1.0);
}
