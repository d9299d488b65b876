// hard on a cube map: one nearest comparison tap along the direction.
import package::techniques::bindings::{shadow_compare_nearest, shadow_cube};
import package::techniques::cube::CubeQuery;

fn hard_sample_shadow_cube(q: CubeQuery) -> f32 {
    return textureSampleCompareLevel(shadow_cube, shadow_compare_nearest, q.offset, q.depth);
}
