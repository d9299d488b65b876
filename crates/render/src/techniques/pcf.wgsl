// The PCF family (Reeves, Salesin & Cook 1987), on the comparison sampler:
// light.params.x = 0: one bilinear comparison tap (hardware 2×2 PCF);
// light.params.x = N > 0: an N×N box of bilinear taps one texel apart.

fn sample_shadow(coords: vec3<f32>) -> f32 {
    let n = i32(light.params.x);
    if n <= 0 {
        return textureSampleCompareLevel(shadow_map, shadow_compare, coords.xy, coords.z);
    }
    let texel = 1.0 / light.texel.w;
    let r = (n - 1) / 2;
    var sum = 0.0;
    for (var y = -r; y <= r; y++) {
        for (var x = -r; x <= r; x++) {
            let uv = coords.xy + vec2<f32>(f32(x), f32(y)) * texel;
            sum += textureSampleCompareLevel(shadow_map, shadow_compare, uv, coords.z);
        }
    }
    return sum / f32(n * n);
}
