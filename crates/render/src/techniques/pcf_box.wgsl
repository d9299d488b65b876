// pcf: a box kernel of the settings' width (pcf.wgsl's pcf_kernel, box weights).
import package::techniques::common::{ShadowQuery, kernel_width_texels};
import package::techniques::pcf::pcf_kernel;

fn pcf_box_sample_shadow(q: ShadowQuery) -> f32 {
    return pcf_kernel(q, kernel_width_texels(q), false);
}
