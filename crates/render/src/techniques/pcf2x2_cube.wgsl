// pcf2x2 on a cube map: one bilinear comparison tap along the direction.
import package::techniques::cube::{CubeQuery, cube_compare_tap};

fn pcf2x2_sample_shadow_cube(q: CubeQuery) -> f32 {
    return cube_compare_tap(q, vec2<f32>(0.0));
}
