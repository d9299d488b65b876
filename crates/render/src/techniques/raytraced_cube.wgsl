// raytraced on a cube map: as raytraced.wgsl.
import package::techniques::cube::CubeQuery;

fn raytraced_sample_shadow_cube(q: CubeQuery) -> f32 {
    return 0.0;
}
