// pcf-poisson: `light.pcf.poisson_taps` taps of the shared Poisson disk over the kernel's radius.
import package::passes::light_binding::light;
import package::techniques::common::{ShadowQuery, kernel_width_texels, pcf_poisson};

fn pcf_poisson_sample_shadow(q: ShadowQuery) -> f32 {
    return pcf_poisson(q, vec2<f32>(0.5 * kernel_width_texels(q)), light.pcf.poisson_taps);
}
