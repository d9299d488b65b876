//! Gnomon's scene model (meshes, materials, instances, camera, lights), the typed
//! render settings, and the built-in procedural scenes. No GPU.

#![warn(missing_docs)]

pub mod builtin;
pub mod camera_path;
pub mod geometry;
pub mod gltf_loader;
mod model;
pub mod scene_file;
pub mod settings;

pub use model::{
    AlphaMode, Camera, DirectionalLight, Instance, Light, Material, Mesh, PointLight, Scene, SceneError,
    SceneLight, SpotLight, Texture, Wrap, sun_direction,
};
pub use settings::Settings;
