// pcf on a virtual map: the box kernel, each tap through the page table.
import package::techniques::virtual_query::{VirtualQuery, virtual_kernel_width_texels, virtual_pcf_kernel};

fn pcf_box_sample_shadow_virtual(q: VirtualQuery) -> f32 {
    return virtual_pcf_kernel(q, virtual_kernel_width_texels(q), false);
}
