// Sample-distribution reduction (Lauritzen, Salvi & Lefohn, "Sample distribution
// shadow maps", I3D 2011): the smallest and largest view depth of the camera's depth
// buffer. Each workgroup reduces its 16×16 tile in shared memory, then folds it into
// the global range with one atomic pair. Positive floats order like their bit
// patterns as u32, so atomicMin/atomicMax on the bits compare the depths.
import package::passes::depth_buffer_binding::depth_buffer;

@group(0) @binding(1) var<storage, read_write> depth_range: array<atomic<u32>, 2>;
struct Planes {
    near: f32,
    far: f32,
    _pad0: f32,
    _pad1: f32,
};
@group(0) @binding(2) var<uniform> planes: Planes;

var<workgroup> tile_min: atomic<u32>;
var<workgroup> tile_max: atomic<u32>;

@compute @workgroup_size(16, 16)
fn reduce(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    if local == 0u {
        atomicStore(&tile_min, 0xffffffffu);
        atomicStore(&tile_max, 0u);
    }
    workgroupBarrier();
    let size = textureDimensions(depth_buffer);
    if all(id.xy < size) {
        let d = textureLoad(depth_buffer, vec2<i32>(id.xy), 0);
        // Depth 1 is the cleared background: no sample there.
        if d < 1.0 {
            // The camera's D3D-style depth d = f(z − n) / (z (f − n)), inverted.
            let n = planes.near;
            let f = planes.far;
            let z = n * f / (f - d * (f - n));
            atomicMin(&tile_min, bitcast<u32>(z));
            atomicMax(&tile_max, bitcast<u32>(z));
        }
    }
    workgroupBarrier();
    if local == 0u {
        let lo = atomicLoad(&tile_min);
        let hi = atomicLoad(&tile_max);
        if lo <= hi {
            atomicMin(&depth_range[0], lo);
            atomicMax(&depth_range[1], hi);
        }
    }
}
