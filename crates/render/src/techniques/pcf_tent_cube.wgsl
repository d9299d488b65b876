// pcf-tent on a cube map: a tent grid across the direction (cube.wgsl).
import package::techniques::cube::{CubeQuery, cube_kernel_width_texels, cube_pcf_grid};

fn pcf_tent_sample_shadow_cube(q: CubeQuery) -> f32 {
    return cube_pcf_grid(q, cube_kernel_width_texels(q), true);
}
