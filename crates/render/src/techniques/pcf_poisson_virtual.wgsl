// pcf-poisson on a virtual map: the rotated Poisson disk, each tap through the page
// table.
import package::passes::light_binding::light;
import package::techniques::virtual_query::{VirtualQuery, virtual_kernel_width_texels, virtual_pcf_poisson};

fn pcf_poisson_sample_shadow_virtual(q: VirtualQuery) -> f32 {
    return virtual_pcf_poisson(q, 0.5 * virtual_kernel_width_texels(q), light.pcf.poisson_taps);
}
