//! Examples of embedding Gnomon in another program, each a file in this folder:
//!
//! - `headless.rs`: render a glTF file to a PNG through the library, with no window.
//!
//! Run one with `cargo run --release -p gnomon-examples --example headless -- FILE.gltf OUT.png`.
//! `.ci/run` runs each on `data/box-on-ground.gltf`, a box on a ground plane.
