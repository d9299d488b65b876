//! Loading scenes (glTF files and TOML scene files), as one test binary; `common`
//! holds what the modules share.

mod common;

mod gltf;
mod gltf_coverage;
mod hostile;
mod hostile_round3;
mod scene_file;
