// A virtual map's map space (`gnomon_math::virtual_map::MapProjection`): where a
// world point lies on its levels, x and y in map units, and the depth it stores. A
// sun's is orthographic, its map units light-space world units; a spot's is its
// perspective frustum, its map units its normalized device coordinates, a texel's
// world size growing with the distance from the light; a point light's is six such
// frusta, one round each cube face, side by side (`virtual_map::cube`), a point read
// in the face its direction falls in. Every virtual-map pass reads points through
// these functions, so that the passes themselves never ask which. Either way a plane
// in the world is a plane in map space (within a face), so a receiver's depth is
// affine in texels over its plane.

import package::constants::{MAP_CUBE, MAP_ORTHOGRAPHIC};

struct MapSpace {
    // World to the light's view space: rigid, looking down −z (a point light's:
    // world-aligned, from its position).
    light_from_world: mat4x4<f32>,
    // Distances along the light's axis (a face's) of the depth-0 and depth-1 planes.
    near: f32,
    far: f32,
    // A spot's or each cube face's frustum's half-angle's tangent: world units per
    // map unit per unit of distance along its axis. Unused for a sun.
    tan_half_fov: f32,
    // MAP_ORTHOGRAPHIC (a sun), MAP_PERSPECTIVE (a spot) or MAP_CUBE (a point light).
    kind: u32,
}

// A world point in the view it is projected from (`Clipmap::frame`): the light's,
// or a point light's face's, as the rotation from the light's view space and where
// the face's slot lies in map space (the origin for a sun or a spot).
struct MapView {
    point: vec3<f32>,
    from_light: mat3x3<f32>,
    slot: vec2<f32>,
}

// World point `world` in its view. A point light's face is its direction's major
// axis (`CubeFace::of_direction`: ties to x, then y), the face's view axes and slot
// those of `face_axes` and `face_slot` in gnomon_math::virtual_map::cube: layers 0
// to 3 (+x, −x, +y, −y) across the upper row, 4 and 5 (+z, −z) on the lower one.
fn map_view(m: MapSpace, world: vec3<f32>) -> MapView {
    let light = (m.light_from_world * vec4<f32>(world, 1.0)).xyz;
    if m.kind != MAP_CUBE {
        return MapView(light, mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0)), vec2<f32>(0.0));
    }
    let a = abs(light);
    var x: vec3<f32>;
    var y: vec3<f32>;
    var look: vec3<f32>;
    var face: u32;
    if a.x >= a.y && a.x >= a.z {
        let s = select(-1.0, 1.0, light.x >= 0.0);
        x = vec3<f32>(0.0, 0.0, s);
        y = vec3<f32>(0.0, 1.0, 0.0);
        look = vec3<f32>(s, 0.0, 0.0);
        face = select(1u, 0u, light.x >= 0.0);
    } else if a.y >= a.z {
        let s = select(-1.0, 1.0, light.y >= 0.0);
        x = vec3<f32>(1.0, 0.0, 0.0);
        y = vec3<f32>(0.0, 0.0, s);
        look = vec3<f32>(0.0, s, 0.0);
        face = select(3u, 2u, light.y >= 0.0);
    } else {
        let s = select(-1.0, 1.0, light.z >= 0.0);
        x = vec3<f32>(-s, 0.0, 0.0);
        y = vec3<f32>(0.0, 1.0, 0.0);
        look = vec3<f32>(0.0, 0.0, s);
        face = select(5u, 4u, light.z >= 0.0);
    }
    // Rows: the view's x, y and z (the view looks down −z).
    let from_light = transpose(mat3x3<f32>(x, y, -look));
    let slot = vec2<f32>(-3.0 + 2.0 * f32(face % 4u), 1.0 - 2.0 * f32(face / 4u));
    return MapView(from_light * light, from_light, slot);
}

// A world direction in view `v` of map space `m`.
fn map_view_direction(m: MapSpace, v: MapView, direction: vec3<f32>) -> vec3<f32> {
    let light = (m.light_from_world * vec4<f32>(direction, 0.0)).xyz;
    if m.kind != MAP_CUBE {
        return light;
    }
    return v.from_light * light;
}

// A world point in map space: x and y in map units, z the depth its map stores (0 at
// the near plane, 1 at the far one), and w the world units per map unit there (1 for
// a sun; for a spot or a cube face, the frustum's half-width at the point's distance).
fn map_point(m: MapSpace, world: vec3<f32>) -> vec4<f32> {
    let v = map_view(m, world);
    let distance = -v.point.z;
    if m.kind == MAP_ORTHOGRAPHIC {
        return vec4<f32>(v.point.xy, (distance - m.near) / (m.far - m.near), 1.0);
    }
    let per_unit = m.tan_half_fov * distance;
    let depth = m.far * (distance - m.near) / (distance * (m.far - m.near));
    return vec4<f32>(v.point.xy / per_unit + v.slot, depth, per_unit);
}

// Whether the map sees world point `world`: a sun's every point, a spot's those in
// front of it within its frustum, a point light's every point but its own position
// (`Clipmap::sees`).
fn map_sees(m: MapSpace, world: vec3<f32>) -> bool {
    if m.kind == MAP_ORTHOGRAPHIC {
        return true;
    }
    let light = map_view(m, world).point;
    let half = m.tan_half_fov * -light.z;
    return half > 0.0 && all(abs(light.xy) <= vec2<f32>(half));
}

// The distance along its view's axis of world point `world`: the light's, or a
// point light's face's.
fn map_axis_distance(m: MapSpace, world: vec3<f32>) -> f32 {
    return -map_view(m, world).point.z;
}

// The distance along the view's axis of a point of stored depth `depth`: linear for
// a sun's map, the perspective depth's inverse for a spot's or a cube face's.
fn map_distance(m: MapSpace, depth: f32) -> f32 {
    if m.kind == MAP_ORTHOGRAPHIC {
        return m.near + depth * (m.far - m.near);
    }
    return m.near * m.far / (m.far - depth * (m.far - m.near));
}

// The radius in map units of a disk `world_radius` world units wide at `distance`
// along the view's axis: a sun's map units are world units; a spot's or a cube
// face's are tan_half_fov × distance wide there.
fn map_radius_at(m: MapSpace, world_radius: f32, distance: f32) -> f32 {
    if m.kind == MAP_ORTHOGRAPHIC {
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
    if m.kind == MAP_ORTHOGRAPHIC {
        return texel / (m.far - m.near);
    }
    let d = map_axis_distance(m, world);
    // depth = f / (f − n) − f n / ((f − n) d): ∂depth/∂d = f n / ((f − n) d²).
    return texel * m.tan_half_fov * d * m.far * m.near / ((m.far - m.near) * d * d);
}

// How a world displacement `direction` at world point `world` moves its map point:
// x and y in map units, z in stored depth (the projection's derivative there, in the
// point's own view; a sun's is constant).
fn map_delta(m: MapSpace, world: vec3<f32>, direction: vec3<f32>) -> vec3<f32> {
    let view = map_view(m, world);
    let v = map_view_direction(m, view, direction);
    if m.kind == MAP_ORTHOGRAPHIC {
        return v * vec3<f32>(1.0, 1.0, -1.0 / (m.far - m.near));
    }
    let light = view.point;
    let d = -light.z;
    let dd = -v.z;
    // x / (t d) and f (d − n) / (d (f − n)) = f / (f − n) − f n / ((f − n) d).
    let xy = (v.xy * d - light.xy * dd) / (m.tan_half_fov * d * d);
    let depth = m.far * m.near / (m.far - m.near) * dd / (d * d);
    return vec3<f32>(xy, depth);
}

// The depth gradient per texel (x, y) of texels `texel` map units wide, of the plane
// through world point `world` with unit normal `n`, and in z whether it is defined:
// 0 where the light sees the plane edge-on (a sun's rays along it, a spot's or a
// face's centre in it).
fn map_plane_gradient(m: MapSpace, world: vec3<f32>, n: vec3<f32>, texel: f32) -> vec3<f32> {
    // The plane a·x + b·y + c·z = e in the point's view space (looking down −z).
    let view = map_view(m, world);
    let plane = map_view_direction(m, view, n);
    if m.kind == MAP_ORTHOGRAPHIC {
        // Depth (−z − near) / range changes by (a, b) / c / range per world unit.
        if abs(plane.z) < 1e-6 {
            return vec3<f32>(0.0);
        }
        return vec3<f32>(plane.xy / plane.z * texel / (m.far - m.near), 1.0);
    }
    // With x = X t d, y = Y t d, z = −d on the plane, 1 / d = (a t X + b t Y − c) / e,
    // and depth = f / (f − n) − f n / ((f − n) d).
    let light = view.point;
    let e = dot(plane, light);
    if abs(e) < 1e-6 * length(light) {
        return vec3<f32>(0.0);
    }
    let scale = -m.far * m.near / (m.far - m.near) * m.tan_half_fov / e;
    return vec3<f32>(plane.xy * scale * texel, 1.0);
}
