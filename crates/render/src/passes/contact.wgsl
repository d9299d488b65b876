// Contact shadows: a short ray from the pixel toward the light, marched through the
// prepass's view depth (after Sousa, Kasyan & Schulz 2011, and Unreal's screen-space
// shadows). A sample behind the depth buffer, but by less than the thickness assumed
// of what the buffer holds (a fraction of its view depth), is an occluder. The first
// sample is jittered per pixel by `interleaved_gradient_noise` (techniques/common.wgsl).
// A sample whose depth lies on the receiver's own plane is the receiver itself and
// never occludes: the depth buffer holds each texel's depth at its centre, half a
// pixel from where the ray crosses it, which on a surface seen at a slant is more
// than the ray rises over a step.
import package::passes::camera_binding::camera;
import package::passes::light_binding::light;
import package::passes::light_kinds::emitter_ray_length;
import package::passes::screen_common::{plane_point, prepass_surface};
import package::techniques::common::interleaved_gradient_noise;

// Relative depth difference within which a depth sample is on the receiver's plane.
const CONTACT_OWN_PLANE: f32 = 1e-3;

// Fraction of the screen over which a hit fades out toward the edges, where the
// depth buffer stops and occluders just off screen go unseen.
const CONTACT_EDGE_FADE: f32 = 0.05;

// 1 when the ray from `world` toward the light (unit `l`) meets nothing in the depth
// buffer within `light.contact.length`; down to 0 where it does, faded near the screen's
// edges and over the last quarter of `light.contact.distance` in view depth.
fn contact_visibility(world: vec3<f32>, geometric_n: vec3<f32>, l: vec3<f32>, pixel: vec2<f32>, view_depth: f32) -> f32 {
    let far = light.contact.distance;
    let distance_fade = 1.0 - smoothstep(0.75 * far, far, view_depth);
    if distance_fade <= 0.0 {
        return 1.0;
    }
    // Never past a spot or point light.
    let ray_length = min(light.contact.length, emitter_ray_length(light.emitter, world));
    let start_world = world + geometric_n * light.contact.bias;
    let start = (camera.view_from_world * vec4<f32>(start_world, 1.0)).xyz;
    var end = (camera.view_from_world * vec4<f32>(start_world + l * ray_length, 1.0)).xyz;
    // Keep the ray in front of the camera's near plane.
    let near = camera.near;
    if end.z > -near {
        end = mix(start, end, (-near - start.z) / (end.z - start.z) * 0.999);
    }
    let steps = light.contact.steps;
    let jitter = interleaved_gradient_noise(pixel);
    let own = vec2<i32>(pixel);
    for (var i = 0u; i < steps; i++) {
        let p = mix(start, end, (f32(i) + jitter) / f32(steps));
        let ray_depth = -p.z;
        let ndc = p.xy * vec2<f32>(camera.scale_x, camera.scale_y) / ray_depth;
        let uv = ndc * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5);
        if any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0)) {
            break;
        }
        let texel = vec2<i32>(uv * vec2<f32>(camera.width, camera.height));
        if all(texel == own) {
            // The receiver itself.
            continue;
        }
        let scene_depth = textureLoad(prepass_surface, texel, 0).w;
        let on_plane = plane_point(vec2<f32>(texel) + vec2<f32>(0.5), world, geometric_n);
        let plane_depth = -(camera.view_from_world * vec4<f32>(on_plane, 1.0)).z;
        if abs(scene_depth - plane_depth) <= CONTACT_OWN_PLANE * scene_depth {
            continue;
        }
        let behind = ray_depth - scene_depth;
        if scene_depth > 0.0 && behind > 0.0 && behind < light.contact.thickness * scene_depth {
            let edge = min(min(uv.x, 1.0 - uv.x), min(uv.y, 1.0 - uv.y));
            return 1.0 - smoothstep(0.0, CONTACT_EDGE_FADE, edge) * distance_fade;
        }
    }
    return 1.0;
}
