// Octahedral unit-vector encoding (Cigolle et al., "A Survey of Efficient
// Representations for Independent Unit Vectors", JCGT 2014): a unit vector as two
// numbers in [−1, 1], for the prepass's normals.

fn octahedron_wrap(v: vec2<f32>) -> vec2<f32> {
    let s = select(vec2<f32>(-1.0), vec2<f32>(1.0), v >= vec2<f32>(0.0));
    return (vec2<f32>(1.0) - abs(v.yx)) * s;
}

fn octahedron_encode(n: vec3<f32>) -> vec2<f32> {
    let p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    return select(octahedron_wrap(p), p, n.z >= 0.0);
}

fn octahedron_decode(e: vec2<f32>) -> vec3<f32> {
    var n = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    // The lower hemisphere folds over the diagonals (Cigolle et al., listing 1).
    let t = max(-n.z, 0.0);
    n.x += select(t, -t, n.x >= 0.0);
    n.y += select(t, -t, n.y >= 0.0);
    return normalize(n);
}
