// pcf2x2: one hardware 2×2 bilinear comparison tap.
import package::techniques::bindings::{shadow_compare, shadow_map};
import package::techniques::common::ShadowQuery;

fn pcf2x2_sample_shadow(q: ShadowQuery) -> f32 {
    return textureSampleCompareLevel(shadow_map, shadow_compare, q.coords.xy, q.layer, q.coords.z);
}
