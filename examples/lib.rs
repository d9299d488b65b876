//! Examples of embedding Gnomon in another program, each a file in this folder:
//!
//! - `headless.rs`: render a glTF file to a PNG through the library, with no window.
//! - `window.rs`: a winit application with its own mesh, camera and WGSL shader,
//!   which asks Gnomon for its light's shadows and calls `shadow_visibility` from its
//!   own fragment shader ([`host`]).
//!
//! Run one with `cargo run --release -p gnomon-examples --example headless -- FILE.gltf OUT.png`
//! or `cargo run --release -p gnomon-examples --example window`.
//! `.ci/run` runs the headless one on `data/box-on-ground.gltf`, a box on a ground
//! plane, and the window one under Xvfb for a few frames.

pub mod host;
