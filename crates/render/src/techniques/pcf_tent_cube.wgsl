// pcf-tent on a cube map: a tent grid across the direction (cube.wgsl).

fn pcf_tent_sample_shadow_cube(q: CubeQuery) -> f32 {
    return cube_pcf_grid(q, cube_kernel_width_texels(q), true);
}
