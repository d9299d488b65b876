// Probes a virtual shadow map at given world points and levels with
// `virtual_pcf2x2` (`page_lookup.wgsl`): what the tests hold the lookup to, one
// invocation per probe.

import package::virtual_map::page_lookup::virtual_pcf2x2;

struct Probe {
    world: vec3<f32>,
    level: u32,
}

// After the shadow resources (group 0, from binding 0 here) and the virtual map's.
@group(0) @binding(10) var<storage, read> probes: array<Probe>;
@group(0) @binding(11) var<storage, read_write> probe_visibility: array<f32>;

@compute @workgroup_size(64)
fn probe_virtual_map(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= arrayLength(&probes)) {
        return;
    }
    let probe = probes[id.x];
    probe_visibility[id.x] = virtual_pcf2x2(probe.world, probe.level);
}
