//! An integer hash for deterministic pseudo-random values: the CPU reference's
//! per-pixel sample patterns, and procedural scenes' layouts, which double as test
//! fixtures and must be the same in every build.

/// Chris Wellons' "lowbias32" integer hash (hash-prospector, 2018): every input bit
/// affects every output bit, with low bias, in two multiplies. The shaders' copy is
/// `lowbias32` in rays/light_sample.wgsl.
pub fn lowbias32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// A value in [0, 1) from `x`: the hash's top 24 bits, which an f32 holds exactly.
pub fn unit_from_hash(x: u32) -> f32 {
    (lowbias32(x) >> 8) as f32 / 16_777_216.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The values are pinned: the reference's sample patterns and the built-in
    /// scenes' layouts depend on them, so a change to the hash must show here first.
    #[test]
    fn the_hash_keeps_its_values_and_its_units_stay_below_one() {
        assert_eq!(lowbias32(0), 0);
        assert_eq!(lowbias32(1), 0x6889_90c0);
        assert_eq!(lowbias32(0xdead_beef), 0xe628_c683);
        assert!(
            (0..100_000u32)
                .map(|i| unit_from_hash(i.wrapping_mul(0x9e37_79b9)))
                .all(|u| (0.0..1.0).contains(&u))
        );
    }
}
