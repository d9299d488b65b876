//! The tests that judge the renderer against the CPU reference (the ground truth),
//! and the reference against analytic results, as one test binary: one device for
//! all of them, one link instead of one per file, and the test harness free to run
//! any two of them at once. Each module is one topic; `common` holds what they share.

mod common;

mod against_raster;
mod aliasing;
mod alpha;
mod analytic;
mod canyon;
mod clusters;
mod falloff;
mod gpu_rays;
mod many_lights;
mod one_surface;
mod penumbra;
mod point_lights;
mod ray_queries;
mod raytraced;
mod refine;
mod refine_forward;
mod refine_soft;
mod screen_space;
mod soft_shadows;
mod thin_casters;
mod virtual_local_lights;
mod virtual_maps;
