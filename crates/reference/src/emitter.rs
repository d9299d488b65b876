//! An area light as the reference samples it: the directions and lengths of the
//! shadow rays toward it from a point, which points it reaches at all, and the cone
//! that holds every ray toward it.

use glam::{Vec2, Vec3};
use gnomon_scene::{
    Falloff, Light,
    lights::{Area, Origin},
};

use crate::{
    Hit,
    sampling::{concentric_disk, cone_direction},
    tracer::ball_cone,
};

/// The area of a light as the sampler sees it.
pub(crate) enum Emitter {
    /// Parallel rays toward `to_light`; with `half_angle` > 0, a cone of directions.
    Sun { to_light: Vec3, half_angle: f32 },
    /// A disk at `center` of `radius` facing along `axis`; 0 is a point. Each of its
    /// points falls off with distance as `falloff` says.
    Disk { center: Vec3, axis: Vec3, radius: f32, cos_outer: f32, range: f32, falloff: Falloff },
    /// A sphere at `center` of `radius` emitting in every direction; 0 is a point.
    Sphere { center: Vec3, radius: f32, range: f32 },
}

impl Emitter {
    pub(crate) fn new(light: &Light) -> Self {
        let emission = light.emission();
        // Which shapes a kind can have: its origin and its area, from its own file in
        // `gnomon_scene::lights`. An area that needs a local origin has one.
        let local = match emission.origin {
            Origin::Infinite { travel } => Err(travel),
            Origin::Local { position, range, axis } => Ok((position, range, axis)),
        };
        match (emission.area, local) {
            (Area::Directions { half_angle }, Err(travel)) => Emitter::Sun { to_light: -travel, half_angle },
            (Area::Disk { radius }, Ok((center, range, axis))) => Emitter::Disk {
                center,
                axis,
                radius,
                cos_outer: emission.cone.map_or(-1.0, |c| c.cos_outer),
                range,
                falloff: emission.falloff,
            },
            (Area::Sphere { radius }, Ok((center, range, _))) => Emitter::Sphere { center, radius, range },
            // `gnomon_scene::lights`' tests hold every kind to these pairs.
            (area, origin) => unreachable!("a light whose area {area:?} does not fit its origin {origin:?}"),
        }
    }

    pub(crate) fn is_point(&self) -> bool {
        match self {
            Emitter::Sun { half_angle, .. } => *half_angle <= 0.0,
            Emitter::Disk { radius, .. } | Emitter::Sphere { radius, .. } => *radius <= 0.0,
        }
    }

    /// Direction to the light's centre, and whether the point receives any light at
    /// all (inside a spot's cone and range).
    fn centre(&self, p: Vec3) -> (Vec3, bool) {
        match *self {
            Emitter::Sun { to_light, .. } => (to_light, true),
            Emitter::Disk { center, axis, cos_outer, range, .. } => {
                let to = center - p;
                let dist = to.length();
                let l = to / dist;
                (l, (-l).dot(axis) >= cos_outer && dist <= range)
            }
            Emitter::Sphere { center, range, .. } => {
                let to = center - p;
                let dist = to.length();
                (to / dist, dist <= range)
            }
        }
    }

    /// Whether light can reach `hit` at all: inside the light's cone and range, on the
    /// side of the surface (the camera-facing geometric normal) that faces the
    /// light's centre, as the rasterizer tests it.
    pub(crate) fn faces(&self, hit: &Hit) -> bool {
        let (centre, receives) = self.centre(hit.position);
        receives && hit.normal.dot(centre) > 0.0
    }

    /// The cone that holds every shadow ray [`Emitter::sample`] can give from `p`:
    /// (unit axis, half-angle, longest ray), each widened by a hair for rounding.
    /// None for a point light, and where `p` is so near the light that the cone
    /// would be too wide to be of use.
    pub(crate) fn bounding_cone(&self, p: Vec3) -> Option<(Vec3, f32, f32)> {
        match *self {
            Emitter::Sun { to_light, half_angle } => {
                (half_angle > 0.0).then_some((to_light, half_angle * (1.0 + 1e-4) + 1e-6, f32::INFINITY))
            }
            // A disk lies within the ball of its radius about its centre, whose
            // farthest point is the centre's distance plus the radius away.
            Emitter::Disk { center, radius, .. } => (radius > 0.0)
                .then(|| ball_cone(p, center, radius))
                .flatten()
                .map(|(axis, half_angle, distance)| (axis, half_angle, (distance + radius) * (1.0 + 1e-4))),
            // Rays end where they enter the sphere, nearer than its centre.
            Emitter::Sphere { center, radius, .. } => (radius > 0.0)
                .then(|| ball_cone(p, center, radius))
                .flatten()
                .map(|(axis, half_angle, distance)| (axis, half_angle, distance * (1.0 + 1e-4))),
        }
    }

    /// The weight in the light's visibility of a shadow ray of length `len` (from
    /// [`Emitter::sample`]), relative to the others: under an inverse-square falloff
    /// each point of a disk is a point light of that falloff, so nearer points count
    /// for more. A sphere's samples are uniform in the solid angle it subtends, which
    /// already falls off as the inverse square of the distance, so they count alike,
    /// as do a constant light's and a sun's. `light_sample_weight` on the GPU.
    pub(crate) fn weight(&self, len: f32) -> f32 {
        match *self {
            Emitter::Disk { falloff, .. } => falloff.at(len),
            Emitter::Sun { .. } | Emitter::Sphere { .. } => 1.0,
        }
    }

    /// A shadow ray toward the light sample `u` from `p`: (direction, length).
    pub(crate) fn sample(&self, p: Vec3, u: Vec2) -> (Vec3, f32) {
        match *self {
            Emitter::Sun { to_light, half_angle } => {
                let d = if half_angle > 0.0 { cone_direction(u, to_light, half_angle) } else { to_light };
                (d, f32::INFINITY)
            }
            Emitter::Disk { center, axis, radius, .. } => {
                let target = if radius > 0.0 {
                    let (a, b) = axis.any_orthonormal_pair();
                    let q = concentric_disk(u) * radius;
                    center + a * q.x + b * q.y
                } else {
                    center
                };
                let to = target - p;
                let len = to.length();
                (to / len, len)
            }
            Emitter::Sphere { center, radius, .. } => {
                let to = center - p;
                let dist = to.length();
                let axis = to / dist;
                if radius <= 0.0 || radius >= dist {
                    return (axis, dist);
                }
                // Uniform over the cone the sphere subtends, which is uniform over its
                // visible area as the receiver sees it (a sphere of uniform radiance);
                // the ray ends where it enters the sphere.
                let d = cone_direction(u, axis, (radius / dist).asin());
                let along = d.dot(to);
                let entry = along - (radius * radius - (dist * dist - along * along)).max(0.0).sqrt();
                (d, entry.max(0.0))
            }
        }
    }
}
