//! A clipmap's map space: where a world point lies on its levels (x and y in map
//! units) and the depth its map stores, for a sun's orthographic levels and a spot's
//! perspective ones; `map_space.wgsl` in gnomon-render holds the same arithmetic.

use glam::{Mat4, Vec2, Vec3};

use super::Clipmap;

/// How a clipmap's levels project the world into map space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MapProjection {
    /// A sun's parallel rays along light-space −z: map units are light-space x and y,
    /// world units, and the depth is linear from the near plane to the far one.
    Orthographic,
    /// A spot's rays from its origin: map units are its normalized device coordinates
    /// over a square frustum whose half-angle has tangent `tan_half_fov`, [−1, 1]²
    /// across it, and the depth is the perspective one a 2D spot map stores
    /// (`f (d − n) / (d (f − n))` at distance `d`).
    Perspective {
        /// The tangent of the frustum's half-angle.
        tan_half_fov: f32,
    },
}

impl Clipmap {
    /// The light's view space to map space: x and y in map units after the divide
    /// by w, z the stored depth (WebGPU's [0, 1] from the near plane to the far one).
    /// A sun's is the identity on x and y (w is 1), a spot's its perspective
    /// projection, as a 2D map of either is drawn with.
    pub fn map_from_light(&self) -> Mat4 {
        match self.projection {
            MapProjection::Orthographic => {
                glam::camera::rh::proj::directx::orthographic(-1.0, 1.0, -1.0, 1.0, self.near, self.far)
            }
            MapProjection::Perspective { tan_half_fov } => glam::camera::rh::proj::directx::perspective(
                2.0 * tan_half_fov.atan(),
                1.0,
                self.near,
                self.far,
            ),
        }
    }

    /// World to map space, before the divide by w: what the GPU passes read points
    /// with (`map_from_world` in page_lookup.wgsl).
    pub fn map_from_world(&self) -> Mat4 {
        self.map_from_light() * self.light_from_world
    }

    /// A world point in map space: x and y in map units, z its stored depth.
    pub fn map_point(&self, world: Vec3) -> Vec3 {
        self.map_from_world().project_point3(world)
    }

    /// World units per map unit at world point `world`: 1 for a sun; for a spot,
    /// the frustum's half-width at the point's distance along the axis.
    pub fn world_per_map(&self, world: Vec3) -> f32 {
        match self.projection {
            MapProjection::Orthographic => 1.0,
            MapProjection::Perspective { tan_half_fov } => {
                tan_half_fov * -self.light_from_world.transform_point3(world).z
            }
        }
    }

    /// World units per map unit on the near plane ([`Clipmap::world_per_map`] there),
    /// where a cone to the light's area is measured.
    pub fn world_per_map_at_near(&self) -> f32 {
        match self.projection {
            MapProjection::Orthographic => 1.0,
            MapProjection::Perspective { tan_half_fov } => tan_half_fov * self.near,
        }
    }

    /// Whether the map sees world point `world` at all: a sun's sees every point; a
    /// spot's only those in front of it, within its frustum's [−1, 1]². Its pixels
    /// ask for no pages elsewhere (a spot lights nothing outside its cone).
    pub fn sees(&self, world: Vec3) -> bool {
        match self.projection {
            MapProjection::Orthographic => true,
            MapProjection::Perspective { .. } => {
                let clip = self.map_from_world() * world.extend(1.0);
                clip.w > 0.0 && clip.x.abs() <= clip.w && clip.y.abs() <= clip.w
            }
        }
    }

    /// A world point's place in map space, x and y.
    pub fn map_xy(&self, world: Vec3) -> Vec2 {
        self.map_point(world).truncate()
    }

    /// The footprint in map units at world point `world` of a pixel whose footprint
    /// there is `world_footprint` world units.
    pub fn map_footprint(&self, world: Vec3, world_footprint: f32) -> f32 {
        world_footprint / self.world_per_map(world)
    }

    /// The radius at the near plane, in map units, of the cone from world point
    /// `point` to the light's area of size `size`: for a sun (`size` the tangent of its
    /// angular radius), `size` times the point's distance behind the plane; for a
    /// spot (`size` its disk's radius), `size · (d − near) / d` at distance `d`, by
    /// similar triangles (`emitter_cone_radius` in light_kinds.wgsl).
    pub fn cone_radius(&self, point: Vec3, size: f32) -> f32 {
        let distance = -self.light_from_world.transform_point3(point).z;
        let reach = size * (distance - self.near).max(0.0);
        let world = match self.projection {
            MapProjection::Orthographic => reach,
            MapProjection::Perspective { .. } => reach / distance.max(f32::MIN_POSITIVE),
        };
        world / self.world_per_map_at_near()
    }
}
