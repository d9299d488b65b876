// pcf-poisson on a cube map: the Poisson disk across the direction (cube.wgsl).
import package::passes::light_binding::light;
import package::techniques::cube::{CubeQuery, cube_kernel_width_texels, cube_pcf_poisson};

fn pcf_poisson_sample_shadow_cube(q: CubeQuery) -> f32 {
    return cube_pcf_poisson(q, 0.5 * cube_kernel_width_texels(q), light.pcf.poisson_taps);
}
