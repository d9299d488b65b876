// hard on a cube map: one nearest comparison tap along the direction.

fn hard_sample_shadow_cube(q: CubeQuery) -> f32 {
    return textureSampleCompareLevel(shadow_cube, shadow_compare_nearest, q.offset, q.depth);
}
