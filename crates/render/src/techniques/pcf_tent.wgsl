// pcf-tent: a tent kernel of the settings' width (pcf.wgsl's pcf_kernel, tent weights).
import package::techniques::common::{ShadowQuery, kernel_width_texels};
import package::techniques::pcf::pcf_kernel;

fn pcf_tent_sample_shadow(q: ShadowQuery) -> f32 {
    return pcf_kernel(q, kernel_width_texels(q), true);
}
