// raytraced: the answer of pixels that trace no ray. Every pixel that faces the
// light and lies in its cone and range traces (`ray_decides`,
// rays/refine_classify.wgsl); the rest receive no light, so they are shadowed, and
// no map is read (the frame draws none).
import package::techniques::common::ShadowQuery;

fn raytraced_sample_shadow(q: ShadowQuery) -> f32 {
    return 0.0;
}
