// The host application's own shader: its camera, its vertex layout, its shading. The
// only thing it takes from Gnomon is the light and its shadows, through the receiver
// module composed before this file (`ReceiverVariant::wgsl`): `shadow_visibility`,
// `shadow_light_direction` and `shadow_light_radiance`, reading Gnomon's group 1.

struct HostCamera {
    clip_from_world: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> host_camera: HostCamera;

struct HostVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
};

@vertex
fn host_vs(
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
) -> HostVertex {
    var out: HostVertex;
    out.clip = host_camera.clip_from_world * vec4<f32>(position, 1.0);
    out.world = position;
    out.normal = normal;
    out.albedo = albedo;
    return out;
}

struct HostTargets {
    @location(0) color: vec4<f32>,
    @location(1) visibility: f32,
};

const HOST_AMBIENT: f32 = 0.12;

@fragment
fn host_fs(in: HostVertex, @builtin(front_facing) front: bool) -> HostTargets {
    // The shading normal on the side the camera sees, for the host's own lighting
    // (the receiver turns the normal it is given to that side itself).
    let n = select(-1.0, 1.0, front) * normalize(in.normal);
    // Gnomon's shadows, called in uniform control flow.
    let visibility = shadow_visibility(in.world, n, in.clip);
    let light = shadow_light_direction(in.world);
    let direct = shadow_light_radiance() * light.w * max(dot(n, light.xyz), 0.0);
    var out: HostTargets;
    out.color = vec4<f32>(in.albedo * (HOST_AMBIENT + visibility * direct), 1.0);
    out.visibility = visibility;
    return out;
}
