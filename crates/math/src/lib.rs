//! Pure shadow-mapping math, with no GPU: bounding boxes, camera and light
//! projections, and the mapping from normalized device coordinates to shadow-map
//! texture coordinates; fitting, cascades and warps ([`fitting`], [`cascades`],
//! [`warping`]); point lights' cube and dual-paraboloid maps ([`omni`]); and the filter
//! kernels the shaders use ([`kernels`]); the light's samples and half-plane masks of a
//! penumbra beam ([`light_masks`]); the sun's path through the day ([`solar`]);
//! whether a mesh is closed, for face culling in the shadow pass ([`topology`]); and
//! which way a projection winds a triangle or a cluster of them ([`facing`]); and the
//! pixels a light's range can reach on screen ([`screen_bounds`]); and a virtual shadow
//! map's clipmap, its page requests and its page pool ([`virtual_map`]); and an
//! integer hash for deterministic patterns ([`hash`]).
//!
//! Conventions, used everywhere in Gnomon:
//! - World space is right-handed and y-up.
//! - View spaces look down −z (right-handed, as `glam::camera::rh`).
//! - Clip space follows WebGPU/D3D: NDC x and y in [−1, 1] with y up, depth z in [0, 1].
//! - Texture space has u to the right and v **down**, both in [0, 1]; texel (0, 0) is the
//!   top-left of the image. The y flip lives in [`texture_from_ndc`] and nowhere else.
//! - Matrices are named `to_from_from`: `clip_from_world` maps world points to clip space.

#![warn(missing_docs)]

mod aabb;
pub mod cascades;
pub mod culling;
pub mod facing;
pub mod fitting;
pub mod hash;
pub mod kernels;
mod light;
pub mod light_masks;
pub mod median_bvh;
pub mod octahedron;
pub mod omni;
mod projection;
pub mod screen_bounds;
pub mod solar;
#[cfg(test)]
mod test_rng;
pub mod topology;
pub mod virtual_map;
pub mod warping;

pub use aabb::Aabb;
pub use light::{LightProjection, ProjectionKind, directional_light_projection, spot_light_projection};
pub use projection::{
    camera_clip_from_view, linearize_perspective_depth, ndc_to_texture, texture_from_ndc, texture_to_ndc,
    view_from_world_look_at,
};

pub use glam;
