// Moment-map encoding: every texel's stored depth, made linear (`moment_depth`),
// becomes the technique's RGBA layers (`encode_moments`).
import package::passes::light_binding::{light, moment_depth};
import package::techniques::bindings::shadow_map;
import package::variant::{MomentTarget, encode_moments};

@group(1) @binding(0) var encoded: MomentTarget;

@compute @workgroup_size(8, 8, 1)
fn encode_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(shadow_map);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    // id.z runs over cascades × the technique's layers.
    let per_cascade = light.map.moment_layers;
    let d = moment_depth(textureLoad(shadow_map, vec2<i32>(id.xy), id.z / per_cascade, 0));
    textureStore(encoded, vec2<i32>(id.xy), i32(id.z), encode_moments(d, id.z % per_cascade));
}
