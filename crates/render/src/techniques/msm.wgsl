// Moment shadow maps (C. Peters & R. Klein, "Moment shadow mapping", I3D 2015) with
// four moments b = (E[d], E[d²], E[d³], E[d⁴]) of the filtered depths.
//
// The shadow intensity is the sharpest lower bound on the fraction of depths in
// front of the receiver depth z over all distributions with these moments. It is
// attained by a distribution with an atom at z and two more at the roots z₂ < z₃ of
// the quadratic whose coefficients c solve the Hankel system
//   [1 b₁ b₂; b₁ b₂ b₃; b₂ b₃ b₄] · c = (1, z, z²)
// (solved here by an LDLᵀ factorisation). The atoms' weights then follow from the
// first three moments (Lagrange interpolation on the atoms).
//
// Hamburger: depths on the whole real line. Hausdorff: depths in [0, 1]; when a root
// leaves [0, 1] the extremal distribution instead puts atoms at 0, z, 1 and a fourth
// free point, fixed by all four moments.
//
// 16-bit maps store the moments in the optimised basis of Peters & Klein (2015,
// section 4.3): an affine map chosen so that rounding to half floats perturbs the
// reconstructed moments as little as possible. Filtering commutes with it.
//
// Its parameters (`MsmParams` in msm.rs).
import package::passes::light_binding::light;
import package::techniques::common::ShadowQuery;
import package::techniques::filterable::{receiver_moment_depth, sample_moments};

struct MsmParams {
    moment_bias: f32,  // α
    hausdorff: u32,    // 1 for the Hausdorff bound, 0 for Hamburger
    quantised: u32,    // 1 for the optimised 16-bit basis
    _pad0: u32,
    _pad1: vec4<u32>,
};

// Columns are the rows of the paper's matrix: b_opt = QUANTISE · b + (0.0359558848, 0, 0, 0).
const QUANTISE: mat4x4<f32> = mat4x4<f32>(
    vec4<f32>(-2.07224649, 13.7948857237, 0.105877704, 9.7924062118),
    vec4<f32>(32.23703778, -59.4683975703, -1.9077466311, -33.7652110555),
    vec4<f32>(-68.571074599, 82.0359750338, 9.3496555107, 47.9456096605),
    vec4<f32>(39.3703274134, -35.364903257, -6.6543490743, -23.9728048165),
);
// Its inverse: b = DEQUANTISE · (b_opt − (0.0359558848, 0, 0, 0)).
const DEQUANTISE: mat4x4<f32> = mat4x4<f32>(
    vec4<f32>(0.2227744146, 0.1549679261, 0.1451988946, 0.163127443),
    vec4<f32>(0.0771972861, 0.1394629426, 0.2120202157, 0.2591432266),
    vec4<f32>(0.7926986636, 0.7963415838, 0.7258694464, 0.6539092497),
    vec4<f32>(0.0319417555, -0.1722823173, -0.2758014811, -0.3376131734),
);
const QUANTISE_OFFSET: vec4<f32> = vec4<f32>(0.035955884801, 0.0, 0.0, 0.0);

fn msm_encode_moments(d: f32, layer: u32) -> vec4<f32> {
    let d2 = d * d;
    let b = vec4<f32>(d, d2, d2 * d, d2 * d2);
    if light.technique.quantised == 1u {
        return QUANTISE * b + QUANTISE_OFFSET;
    }
    return b;
}

// Weight of the atom at `a` of a three-atom distribution on {a, u, v} with
// moments 1, m1, m2.
fn atom_weight(a: f32, u: f32, v: f32, m1: f32, m2: f32) -> f32 {
    return (m2 - (u + v) * m1 + u * v) / ((a - u) * (a - v));
}

fn msm_sample_shadow(q: ShadowQuery) -> f32 {
    // The moment bias pulls the moments toward those of ½δ₀ + ½δ₁, strictly inside
    // the moment space, so the system stays well-conditioned after quantisation.
    var stored = sample_moments(q, 0u);
    if light.technique.quantised == 1u {
        stored = DEQUANTISE * (stored - QUANTISE_OFFSET);
    }
    let b = mix(stored, vec4<f32>(0.5), light.technique.moment_bias);
    let z = receiver_moment_depth(q);

    // LDLᵀ of the Hankel matrix (first column (1, b₁, b₂), d₁ = 1).
    let d2 = b.y - b.x * b.x;
    let l32 = (b.z - b.x * b.y) / d2;
    let d3 = b.w - b.y * b.y - l32 * l32 * d2;
    // Forward substitution, scaling, back substitution.
    let y2 = (z - b.x) / d2;
    let y3 = (z * z - b.y - l32 * (z - b.x)) / d3;
    let c2 = y3;
    let c1 = y2 - l32 * c2;
    let c0 = 1.0 - b.x * c1 - b.y * c2;
    // Roots of c0 + c1·x + c2·x².
    let p = c1 / c2;
    let disc = max(0.25 * p * p - c0 / c2, 0.0);
    let r = sqrt(disc);
    let z2 = -0.5 * p - r;
    let z3 = -0.5 * p + r;

    var intensity = 0.0;
    if z <= z2 {
        intensity = 0.0;
    } else if z <= z3 {
        intensity = atom_weight(z2, z, z3, b.x, b.y);
    } else {
        intensity = 1.0 - atom_weight(z, z2, z3, b.x, b.y);
    }
    if light.technique.hausdorff == 1u && (z2 < 0.0 || z3 > 1.0) {
        // Four atoms at {0, z, z_free, 1}. Weighting each atom by its depth gives a
        // measure on {1, z, z_free} with moments (b₁, b₂, b₃, b₄), whence z_free, and
        // the weights by Lagrange interpolation on its first three moments.
        let zc = clamp(z, 1e-4, 1.0 - 1e-4);
        let z_free = (b.w - (1.0 + zc) * b.z + zc * b.y) / (b.z - (1.0 + zc) * b.y + zc * b.x);
        let w_one = (b.z - (zc + z_free) * b.y + zc * z_free * b.x) / ((1.0 - zc) * (1.0 - z_free));
        let w_z = (b.z - (1.0 + z_free) * b.y + z_free * b.x) / (zc * (zc - 1.0) * (zc - z_free));
        let w_free = (b.z - (1.0 + zc) * b.y + zc * b.x) / (z_free * (z_free - 1.0) * (z_free - zc));
        let w_zero = 1.0 - w_one - w_z - w_free;
        // Rounding can leave the roots just outside [0, 1] when the moments are those
        // of three atoms {0, z, 1} (a flat occluder plus the moment bias): then the
        // four-atom system is degenerate (z_free = 0/0). Its answer is used only when
        // it is a distribution on [0, 1]; otherwise the three-atom bound, valid for
        // any support, stands.
        let weights = vec4<f32>(w_zero, w_one, w_z, w_free);
        let valid = z_free >= 0.0 && z_free <= 1.0 && all(weights >= vec4<f32>(-1e-3))
            && all(weights <= vec4<f32>(1.001));
        if valid {
            intensity = w_zero + select(0.0, w_free, z_free < zc);
        }
    }
    return 1.0 - clamp(intensity, 0.0, 1.0);
}
