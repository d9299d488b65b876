// Filtering of moment maps: a separable Gaussian blur and a 2×2 mip reduction, both
// linear, or in log space for ESM (log Σ wᵢ exp(c·dᵢ), computed relative to the
// largest dᵢ so that it cannot overflow).
import package::constants::MAX_BLUR_TAPS;
import package::variant::MomentTarget;

struct FilterParams {
    direction: vec2<i32>,   // (1, 0) or (0, 1) for the blur
    radius: i32,            // blur taps on each side
    log_c: f32,             // > 0: filter channel x in log space with this exponent
    sigma: f32,             // blur standard deviation in texels
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
};

@group(0) @binding(0) var filter_source: texture_2d_array<f32>;
@group(0) @binding(1) var filter_target: MomentTarget;
@group(0) @binding(2) var<uniform> filter_params: FilterParams;

// Weighted average of up to MAX_BLUR_TAPS values in log space (channel x only).
fn log_average(values: ptr<function, array<f32, MAX_BLUR_TAPS>>, weights: ptr<function, array<f32, MAX_BLUR_TAPS>>, count: i32) -> f32 {
    var top = -1e30;
    for (var i = 0; i < count; i++) {
        top = max(top, (*values)[i]);
    }
    var sum = 0.0;
    for (var i = 0; i < count; i++) {
        sum += (*weights)[i] * exp(filter_params.log_c * ((*values)[i] - top));
    }
    return top + log(sum) / filter_params.log_c;
}

@compute @workgroup_size(8, 8, 1)
fn blur_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(filter_source));
    let p = vec2<i32>(id.xy);
    if p.x >= size.x || p.y >= size.y {
        return;
    }
    let layer = i32(id.z);
    var values: array<f32, MAX_BLUR_TAPS>;
    var weights: array<f32, MAX_BLUR_TAPS>;
    var sum = vec4<f32>(0.0);
    var total = 0.0;
    for (var i = -filter_params.radius; i <= filter_params.radius; i++) {
        let q = clamp(p + i * filter_params.direction, vec2<i32>(0), size - vec2<i32>(1));
        let w = exp(-0.5 * pow(f32(i) / filter_params.sigma, 2.0));
        let v = textureLoad(filter_source, q, layer, 0);
        sum += w * v;
        total += w;
        values[i + filter_params.radius] = v.x;
        weights[i + filter_params.radius] = w;
    }
    var result = sum / total;
    if filter_params.log_c > 0.0 {
        for (var i = 0; i < 2 * filter_params.radius + 1; i++) {
            weights[i] /= total;
        }
        result = vec4<f32>(log_average(&values, &weights, 2 * filter_params.radius + 1), 0.0, 0.0, 0.0);
    }
    textureStore(filter_target, p, layer, result);
}

@compute @workgroup_size(8, 8, 1)
fn downsample_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(filter_target));
    let p = vec2<i32>(id.xy);
    if p.x >= size.x || p.y >= size.y {
        return;
    }
    let layer = i32(id.z);
    let src_max = vec2<i32>(textureDimensions(filter_source)) - vec2<i32>(1);
    var values: array<f32, MAX_BLUR_TAPS>;
    var weights: array<f32, MAX_BLUR_TAPS>;
    var sum = vec4<f32>(0.0);
    for (var i = 0; i < 4; i++) {
        let q = min(2 * p + vec2<i32>(i % 2, i / 2), src_max);
        let v = textureLoad(filter_source, q, layer, 0);
        sum += v;
        values[i] = v.x;
        weights[i] = 0.25;
    }
    var result = 0.25 * sum;
    if filter_params.log_c > 0.0 {
        result = vec4<f32>(log_average(&values, &weights, 4), 0.0, 0.0, 0.0);
    }
    textureStore(filter_target, p, layer, result);
}
