// Per-cascade light-space bounds of the samples the camera sees (Lauritzen, Salvi &
// Lefohn, "Sample distribution shadow maps", I3D 2011, §3.2): every pixel of the
// camera's depth buffer is taken back to world space, assigned the cascade its view
// depth falls in, and moved into the light's view, where each cascade keeps the
// smallest and largest x and y. Each workgroup reduces its 16×16 tile in shared
// memory, then folds it into the global bounds with atomics. Floats are stored in an
// order-preserving u32 encoding so that atomicMin/atomicMax compare them.
import package::constants::MAX_CASCADES;
import package::passes::depth_buffer_binding::depth_buffer;

struct BoundsParams {
    world_from_clip: mat4x4<f32>,
    light_from_world: mat4x4<f32>,
    // The view depths bounding the cascades: splits[0] to splits[count].
    splits: array<vec4<f32>, 3>,
    near: f32,            // the camera's planes
    far: f32,
    cascade_count: u32,
    // The blend band, as a fraction of a cascade's depth range over which the lighting
    // pass also reads the next cascade (0 when it picks cascades by projection).
    blend: f32,
}

// Per cascade: min x, min y, max x, max y, encoded.
@group(0) @binding(1) var<storage, read_write> bounds: array<atomic<u32>, 4u * MAX_CASCADES>;
@group(0) @binding(2) var<uniform> bounds_params: BoundsParams;

var<workgroup> tile: array<atomic<u32>, 4u * MAX_CASCADES>;

// Flips the sign bit of a positive float and every bit of a negative one, so that the
// encoded u32s order like the floats.
fn encode(f: f32) -> u32 {
    let bits = bitcast<u32>(f);
    return select(bits | 0x80000000u, ~bits, (bits & 0x80000000u) != 0u);
}

fn split(i: u32) -> f32 {
    return bounds_params.splits[i / 4u][i % 4u];
}

@compute @workgroup_size(16, 16)
fn bounds_of_samples(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    if local < 32u {
        // Slots 0, 1 of each cascade hold minima, 2, 3 maxima.
        atomicStore(&tile[local], select(0u, 0xffffffffu, local % 4u < 2u));
    }
    workgroupBarrier();
    let size = textureDimensions(depth_buffer);
    if all(id.xy < size) {
        let d = textureLoad(depth_buffer, vec2<i32>(id.xy), 0);
        if d < 1.0 {
            let n = bounds_params.near;
            let f = bounds_params.far;
            let count = bounds_params.cascade_count;
            let view_depth = n * f / (f - d * (f - n));
            // The pixel's centre in NDC (y up), back to world space.
            let uv = (vec2<f32>(id.xy) + 0.5) / vec2<f32>(size);
            let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, d, 1.0);
            let world = bounds_params.world_from_clip * ndc;
            let light = (bounds_params.light_from_world * vec4<f32>(world.xyz / world.w, 1.0)).xy;
            let encoded = vec4<u32>(encode(light.x), encode(light.y), encode(light.x), encode(light.y));
            for (var i = 0u; i < count; i += 1u) {
                // A cascade serves its own depths and, for blending, the band at the far
                // end of the previous one.
                var start = split(i);
                if i > 0u {
                    start -= bounds_params.blend * (split(i) - split(i - 1u));
                }
                if view_depth >= start && view_depth <= split(i + 1u) {
                    atomicMin(&tile[i * 4u], encoded.x);
                    atomicMin(&tile[i * 4u + 1u], encoded.y);
                    atomicMax(&tile[i * 4u + 2u], encoded.z);
                    atomicMax(&tile[i * 4u + 3u], encoded.w);
                }
            }
        }
    }
    workgroupBarrier();
    if local < 32u {
        let value = atomicLoad(&tile[local]);
        if local % 4u < 2u {
            if value != 0xffffffffu {
                atomicMin(&bounds[local], value);
            }
        } else if value != 0u {
            atomicMax(&bounds[local], value);
        }
    }
}
