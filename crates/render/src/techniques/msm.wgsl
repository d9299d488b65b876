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
// params[0]: x: moment bias α, y: 1 for the Hausdorff bound.

fn encode_moments(d: f32, layer: u32) -> vec4<f32> {
    let d2 = d * d;
    return vec4<f32>(d, d2, d2 * d, d2 * d2);
}

// Weight of the atom at `a` of a three-atom distribution on {a, u, v} with
// moments 1, m1, m2.
fn atom_weight(a: f32, u: f32, v: f32, m1: f32, m2: f32) -> f32 {
    return (m2 - (u + v) * m1 + u * v) / ((a - u) * (a - v));
}

fn sample_shadow(q: ShadowQuery) -> f32 {
    // The moment bias pulls the moments toward those of ½δ₀ + ½δ₁, strictly inside
    // the moment space, so the system stays well-conditioned after quantisation.
    let b = mix(sample_moments(q, 0u), vec4<f32>(0.5), light.params[0].x);
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
    if light.params[0].y > 0.5 && (z2 < 0.0 || z3 > 1.0) {
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
