// A virtual map's map space (`gnomon_math::virtual_map::MapProjection`): where a
// world point lies on its levels, x and y in map units, and the depth it stores. A
// sun's is orthographic, its map units light-space world units; a spot's is its
// perspective frustum, its map units its normalized device coordinates, a texel's
// world size growing with the distance from the light. Every virtual-map pass reads
// points through these functions, so that the passes themselves never ask which.
// Either way a plane in the world is a plane in map space, so a receiver's depth is
// affine in texels over its plane.

struct MapSpace {
    // World to the light's view space: rigid, looking down −z.
    light_from_world: mat4x4<f32>,
    // Distances along the light's axis of the depth-0 and depth-1 planes.
    near: f32,
    far: f32,
    // A spot's frustum's half-angle's tangent: world units per map unit per unit of
    // distance along its axis. Unused for a sun.
    tan_half_fov: f32,
    // 1 for a spot's perspective map space, 0 for a sun's orthographic one.
    perspective: u32,
}

// A world point in map space: x and y in map units, z the depth its map stores (0 at
// the near plane, 1 at the far one), and w the world units per map unit there (1 for
// a sun; for a spot, the frustum's half-width at the point's distance).
fn map_point(m: MapSpace, world: vec3<f32>) -> vec4<f32> {
    let light = (m.light_from_world * vec4<f32>(world, 1.0)).xyz;
    let distance = -light.z;
    if m.perspective == 0u {
        return vec4<f32>(light.xy, (distance - m.near) / (m.far - m.near), 1.0);
    }
    let per_unit = m.tan_half_fov * distance;
    return vec4<f32>(light.xy / per_unit, m.far * (distance - m.near) / (distance * (m.far - m.near)), per_unit);
}

// Whether the map sees world point `world`: a sun's every point, a spot's those in
// front of it within its frustum (`Clipmap::sees`).
fn map_sees(m: MapSpace, world: vec3<f32>) -> bool {
    if m.perspective == 0u {
        return true;
    }
    let light = (m.light_from_world * vec4<f32>(world, 1.0)).xyz;
    let half = m.tan_half_fov * -light.z;
    return half > 0.0 && all(abs(light.xy) <= vec2<f32>(half));
}

// The distance along the light's axis of world point `world`.
fn map_axis_distance(m: MapSpace, world: vec3<f32>) -> f32 {
    return -(m.light_from_world * vec4<f32>(world, 1.0)).z;
}

// The distance along the light's axis of a point of stored depth `depth`: linear for
// a sun's map, the perspective depth's inverse for a spot's.
fn map_distance(m: MapSpace, depth: f32) -> f32 {
    if m.perspective == 0u {
        return m.near + depth * (m.far - m.near);
    }
    return m.near * m.far / (m.far - depth * (m.far - m.near));
}

// The radius in map units of a disk `world_radius` world units wide at `distance`
// along the light's axis: a sun's map units are world units; a spot's are
// tan_half_fov × distance wide there.
fn map_radius_at(m: MapSpace, world_radius: f32, distance: f32) -> f32 {
    if m.perspective == 0u {
        return world_radius;
    }
    return world_radius / (m.tan_half_fov * distance);
}

// `map_radius_at` the near plane, where a cone to the light's area is measured
// (`Clipmap::cone_radius`).
fn map_near_radius(m: MapSpace, world_radius: f32) -> f32 {
    return map_radius_at(m, world_radius, m.near);
}

// The change of stored depth along the light's ray over `texel` map units' worth of
// world length at world point `world` (a texel's length along the ray, in depth).
fn map_texel_along_ray(m: MapSpace, world: vec3<f32>, texel: f32) -> f32 {
    if m.perspective == 0u {
        return texel / (m.far - m.near);
    }
    let d = map_axis_distance(m, world);
    // depth = f / (f − n) − f n / ((f − n) d): ∂depth/∂d = f n / ((f − n) d²).
    return texel * m.tan_half_fov * d * m.far * m.near / ((m.far - m.near) * d * d);
}

// How a world displacement `direction` at world point `world` moves its map point:
// x and y in map units, z in stored depth (the projection's derivative there; a
// sun's is constant).
fn map_delta(m: MapSpace, world: vec3<f32>, direction: vec3<f32>) -> vec3<f32> {
    let v = (m.light_from_world * vec4<f32>(direction, 0.0)).xyz;
    if m.perspective == 0u {
        return v * vec3<f32>(1.0, 1.0, -1.0 / (m.far - m.near));
    }
    let light = (m.light_from_world * vec4<f32>(world, 1.0)).xyz;
    let d = -light.z;
    let dd = -v.z;
    // x / (t d) and f (d − n) / (d (f − n)) = f / (f − n) − f n / ((f − n) d).
    let xy = (v.xy * d - light.xy * dd) / (m.tan_half_fov * d * d);
    let depth = m.far * m.near / (m.far - m.near) * dd / (d * d);
    return vec3<f32>(xy, depth);
}

// The depth gradient per texel (x, y) of texels `texel` map units wide, of the plane
// through world point `world` with unit normal `n`, and in z whether it is defined:
// 0 where the light sees the plane edge-on (a sun's rays along it, a spot's centre
// in it).
fn map_plane_gradient(m: MapSpace, world: vec3<f32>, n: vec3<f32>, texel: f32) -> vec3<f32> {
    // The plane a·x + b·y + c·z = e in light space (looking down −z).
    let plane = (m.light_from_world * vec4<f32>(n, 0.0)).xyz;
    if m.perspective == 0u {
        // Depth (−z − near) / range changes by (a, b) / c / range per world unit.
        if abs(plane.z) < 1e-6 {
            return vec3<f32>(0.0);
        }
        return vec3<f32>(plane.xy / plane.z * texel / (m.far - m.near), 1.0);
    }
    // With x = X t d, y = Y t d, z = −d on the plane, 1 / d = (a t X + b t Y − c) / e,
    // and depth = f / (f − n) − f n / ((f − n) d).
    let light = (m.light_from_world * vec4<f32>(world, 1.0)).xyz;
    let e = dot(plane, light);
    if abs(e) < 1e-6 * length(light) {
        return vec3<f32>(0.0);
    }
    let scale = -m.far * m.near / (m.far - m.near) * m.tan_half_fov / e;
    return vec3<f32>(plane.xy * scale * texel, 1.0);
}
