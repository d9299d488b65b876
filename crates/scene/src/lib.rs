//! Gnomon's scene model (meshes, materials, instances, camera, lights), the typed
//! render settings, and the built-in procedural scenes. No GPU.

#![warn(missing_docs)]

pub mod builtin;
pub mod camera_path;
mod casters;
pub mod files;
#[cfg(feature = "cli")]
pub mod flags;
pub mod framing;
pub mod geometry;
pub mod gltf_loader;
pub mod lights;
pub mod limits;
pub mod memory;
mod model;
mod scene_error;
pub mod scene_file;
pub mod scene_lights;
pub mod settings;

pub use casters::OpenCasters;
pub use lights::{DirectionalLight, Falloff, Light, PointLight, SpotLight};
pub use model::{AlphaMode, Camera, Instance, Material, Mesh, Motion, Scene, Texture, Wrap, sun_direction};
pub use scene_error::SceneError;
pub use scene_lights::{LightRole, SceneLight};
pub use settings::Settings;
