//! A clipmap's map space: where a world point lies on its levels (x and y in map
//! units) and the depth its map stores, for a sun's orthographic levels, a spot's
//! perspective ones and a point light's cube faces; `map_space.wgsl` in gnomon-render
//! holds the same arithmetic.

use glam::{Mat4, Vec2, Vec3};

use super::{Clipmap, cube::CUBE_FACE_TAN_HALF_FOV};

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
    /// A point light's rays from its origin, in six perspective frusta, one round
    /// each face of a cube, side by side in one map space ([`super::cube`]): a
    /// point's map units are the normalized device coordinates of the face its
    /// direction falls in (a frustum a little wider than the face,
    /// [`CUBE_FACE_TAN_HALF_FOV`]), moved to the face's slot, and its depth the one
    /// that face's perspective stores, as a spot's.
    Cube,
}

/// The view a world point is projected from: the light's, or under a point light
/// the view of the cube face the point's direction falls in ([`Clipmap::frame`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapFrame {
    /// World to the frame's view space: rigid, looking down −z.
    pub view_from_world: Mat4,
    /// Where the frame's normalized device coordinates' origin lies in map space: a
    /// cube face's slot's centre; the origin for a sun or a spot.
    pub slot: Vec2,
}

impl Clipmap {
    /// The tangent of the half-angle of each perspective frustum the map is drawn
    /// through (a spot's, or each cube face's); None for a sun's orthographic map.
    pub fn tan_half_fov(&self) -> Option<f32> {
        match self.projection {
            MapProjection::Orthographic => None,
            MapProjection::Perspective { tan_half_fov } => Some(tan_half_fov),
            MapProjection::Cube => Some(CUBE_FACE_TAN_HALF_FOV),
        }
    }

    /// The view world point `world` is projected from: a cube face's for a point
    /// light (the face its direction from the light falls in,
    /// [`crate::omni::CubeFace::of_direction`]), the light's otherwise.
    pub fn frame(&self, world: Vec3) -> MapFrame {
        match self.projection {
            MapProjection::Cube => {
                let direction = self.light_from_world.transform_point3(world);
                self.face_frame(crate::omni::CubeFace::of_direction(direction))
            }
            MapProjection::Orthographic | MapProjection::Perspective { .. } => {
                MapFrame { view_from_world: self.light_from_world, slot: Vec2::ZERO }
            }
        }
    }

    /// A frame's view space to its map: x and y in map units about the frame's slot
    /// after the divide by w, z the stored depth (WebGPU's [0, 1] from the near plane
    /// to the far one). A sun's is the identity on x and y (w is 1); a spot's or a
    /// cube face's its perspective projection, as a 2D map of it is drawn with.
    pub fn map_from_view(&self) -> Mat4 {
        match self.tan_half_fov() {
            None => glam::camera::rh::proj::directx::orthographic(-1.0, 1.0, -1.0, 1.0, self.near, self.far),
            Some(tan_half_fov) => glam::camera::rh::proj::directx::perspective(
                2.0 * tan_half_fov.atan(),
                1.0,
                self.near,
                self.far,
            ),
        }
    }

    /// A world point in map space: x and y in map units, z its stored depth.
    pub fn map_point(&self, world: Vec3) -> Vec3 {
        let frame = self.frame(world);
        (self.map_from_view() * frame.view_from_world).project_point3(world) + frame.slot.extend(0.0)
    }

    /// The distance along its frame's axis of world point `world`: along the light's
    /// travel for a sun, along a spot's axis, along the axis of a point light's face.
    pub fn axis_distance(&self, world: Vec3) -> f32 {
        -self.frame(world).view_from_world.transform_point3(world).z
    }

    /// World units per map unit at world point `world`: 1 for a sun; for a spot or a
    /// cube face, its frustum's half-width at the point's distance along its axis.
    pub fn world_per_map(&self, world: Vec3) -> f32 {
        self.tan_half_fov().map_or(1.0, |tan_half_fov| tan_half_fov * self.axis_distance(world))
    }

    /// World units per map unit on the near plane ([`Clipmap::world_per_map`] there),
    /// where a cone to the light's area is measured.
    pub fn world_per_map_at_near(&self) -> f32 {
        self.tan_half_fov().map_or(1.0, |tan_half_fov| tan_half_fov * self.near)
    }

    /// Whether the map sees world point `world` at all: a sun's sees every point; a
    /// spot's only those in front of it, within its frustum's [−1, 1]²; a point
    /// light's every point but its own position. Its pixels ask for no pages
    /// elsewhere (a spot lights nothing outside its cone).
    pub fn sees(&self, world: Vec3) -> bool {
        let Some(tan_half_fov) = self.tan_half_fov() else {
            return true;
        };
        let view = self.frame(world).view_from_world.transform_point3(world);
        let half = tan_half_fov * -view.z;
        half > 0.0 && view.x.abs() <= half && view.y.abs() <= half
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
    /// spot or a point light (`size` its disk's or sphere's radius),
    /// `size · (d − near) / d` at distance `d` along the axis, by similar triangles
    /// (`emitter_cone_radius` in light_kinds.wgsl).
    pub fn cone_radius(&self, point: Vec3, size: f32) -> f32 {
        let distance = self.axis_distance(point);
        let reach = size * (distance - self.near).max(0.0);
        let world = match self.projection {
            MapProjection::Orthographic => reach,
            MapProjection::Perspective { .. } | MapProjection::Cube => {
                reach / distance.max(f32::MIN_POSITIVE)
            }
        };
        world / self.world_per_map_at_near()
    }
}
