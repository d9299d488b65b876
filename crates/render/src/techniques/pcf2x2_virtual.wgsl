// pcf2x2 on a virtual map: one bilinear comparison tap through the page table.
import package::techniques::virtual_query::{VirtualQuery, virtual_compare_tap};

fn pcf2x2_sample_shadow_virtual(q: VirtualQuery) -> f32 {
    return virtual_compare_tap(q, vec2<f32>(0.0));
}
