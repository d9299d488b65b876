//! The renderer's GPU tests, as one test binary: one device for all of them, one
//! link instead of one per file, and the test harness free to run any two of them
//! at once (`cargo test` runs test binaries one after another, the tests within a
//! binary in parallel). Each module is one topic; `support` holds what they share.

mod support;

mod analytic_shadows;
mod bias;
mod custom_technique;
mod depth_baseline;
mod embedding;
mod filterable;
mod gpu_culling;
mod indirect;
mod light_list;
mod limits;
mod live;
mod map_cache;
mod persistence;
mod submission;
mod techniques;
mod virtual_frames;
mod virtual_pages;
