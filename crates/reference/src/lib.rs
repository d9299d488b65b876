//! Gnomon's ground truth, on the CPU: a ray tracer over a BVH of the scene's
//! triangles that computes the exact (hard) or Monte Carlo (area-light) visibility of
//! the light at the surface points the rasterizer shades, and the metrics that turn
//! a technique's difference from it into numbers and pictures.

#![warn(missing_docs)]

pub mod aliasing;
pub mod cross_check;
pub mod drawn;
mod emitter;
pub mod flicker;
pub mod heatmap;
pub mod metrics;
pub mod penumbra;
pub mod profile;
pub mod sampling;
mod shade;
pub mod texture;
mod tracer;
mod visibility;

pub use tracer::{CasterTriangles, Hit, TracedScene, offset_ray_origin};
pub use visibility::{ReferenceImage, ReferenceOptions, check_memory, reference_visibility};
