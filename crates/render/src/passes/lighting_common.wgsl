// What the lighting passes share: their outputs, in `lighting::TARGETS` order, and
// the cascade debug view's tint of each shadow-map layer.

struct FragmentOut {
    @location(0) color: vec4<f32>,
    @location(1) visibility: f32,
    @location(2) position: vec4<f32>,
    @location(3) normal: vec4<f32>,
    @location(4) object_id: u32,
};

// The tints are indexed only under their view: a dynamically indexed constant array costs a
// copy per invocation on some compilers (on lavapipe, 8–17 ms of a frame when the light
// list indexed it for every light).
const CASCADE_TINTS: array<vec3<f32>, MAX_CASCADES> = array<vec3<f32>, MAX_CASCADES>(
    vec3<f32>(1.0, 0.35, 0.35), vec3<f32>(0.35, 1.0, 0.35), vec3<f32>(0.4, 0.5, 1.0), vec3<f32>(1.0, 1.0, 0.3),
    vec3<f32>(1.0, 0.35, 1.0), vec3<f32>(0.3, 1.0, 1.0), vec3<f32>(1.0, 0.65, 0.2), vec3<f32>(0.65, 0.4, 1.0),
);
