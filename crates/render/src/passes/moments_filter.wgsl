// Filtering of moment maps: a separable Gaussian blur and a 2×2 mip reduction, both
// linear, or in log space for ESM (log Σ wᵢ exp(c·dᵢ), taken relative to the
// largest dᵢ so far so that it cannot overflow: `LogAverage`).
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

// A weighted average of values in log space (channel x only), log Σ wᵢ exp(c·dᵢ) / c
// over Σ wᵢ, taken one value at a time about the largest seen so far, so that no
// exp overflows (the streaming log-sum-exp): no array of the taps is kept. WGSL
// zeroes a function's array where it is declared, and two arrays of the widest
// blur's taps were zeroed at every texel of every blur and reduction, whatever the
// technique: under a moving sun on `contact` (lavapipe) the filter pass took
// 510–700 ms with them and 440–560 ms without, most of it the blur's reads.
struct LogAverage {
    // The largest value added, and Σ wᵢ exp(c·(dᵢ − top)).
    top: f32,
    sum: f32,
};

const LOG_AVERAGE_EMPTY: LogAverage = LogAverage(-1e30, 0.0);

fn log_average_add(a: LogAverage, value: f32, weight: f32) -> LogAverage {
    let c = filter_params.log_c;
    if value > a.top {
        return LogAverage(value, a.sum * exp(c * (a.top - value)) + weight);
    }
    return LogAverage(a.top, a.sum + weight * exp(c * (value - a.top)));
}

// The average, its weights summing to `total`.
fn log_average_of(a: LogAverage, total: f32) -> f32 {
    return a.top + log(a.sum / total) / filter_params.log_c;
}

@compute @workgroup_size(8, 8, 1)
fn blur_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(filter_source));
    let p = vec2<i32>(id.xy);
    if p.x >= size.x || p.y >= size.y {
        return;
    }
    let layer = i32(id.z);
    var sum = vec4<f32>(0.0);
    var total = 0.0;
    var logs = LOG_AVERAGE_EMPTY;
    for (var i = -filter_params.radius; i <= filter_params.radius; i++) {
        let q = clamp(p + i * filter_params.direction, vec2<i32>(0), size - vec2<i32>(1));
        let w = exp(-0.5 * pow(f32(i) / filter_params.sigma, 2.0));
        let v = textureLoad(filter_source, q, layer, 0);
        sum += w * v;
        total += w;
        if filter_params.log_c > 0.0 {
            logs = log_average_add(logs, v.x, w);
        }
    }
    var result = sum / total;
    if filter_params.log_c > 0.0 {
        result = vec4<f32>(log_average_of(logs, total), 0.0, 0.0, 0.0);
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
    var sum = vec4<f32>(0.0);
    var logs = LOG_AVERAGE_EMPTY;
    for (var i = 0; i < 4; i++) {
        let q = min(2 * p + vec2<i32>(i % 2, i / 2), src_max);
        let v = textureLoad(filter_source, q, layer, 0);
        sum += v;
        if filter_params.log_c > 0.0 {
            logs = log_average_add(logs, v.x, 1.0);
        }
    }
    var result = 0.25 * sum;
    if filter_params.log_c > 0.0 {
        result = vec4<f32>(log_average_of(logs, 4.0), 0.0, 0.0, 0.0);
    }
    textureStore(filter_target, p, layer, result);
}
