//! Gnomon's GPU renderer on wgpu: headless device selection, scene upload, the shadow
//! (depth-from-light) pass, the lighting pass, and the shadow techniques, each a
//! module with its WGSL beside it.
//!
//! ```no_run
//! # fn main() -> Result<(), gnomon_render::RenderError> {
//! let gpu = gnomon_render::Gpu::new_headless()?;
//! let scene = gnomon_scene::builtin::spheres();
//! let mut renderer = gnomon_render::Renderer::new(&gpu)?;
//! let frame = renderer.render(&scene, &gnomon_scene::Settings::default(), &Default::default())?;
//! println!("{} of {} pixels lit", frame.visibility.iter().filter(|v| **v > 0.5).count(), frame.pixel_count());
//! # Ok(()) }
//! ```

mod device;
mod frame;
mod gpu_scene;
mod gpu_types;
mod layout;
mod passes;
mod pool;
mod readback;
pub mod techniques;
pub mod timing;
pub mod uniforms;

pub use device::{Gpu, GpuInfo};
pub use frame::{
    CpuTimings, Creations, DrawStats, Frame, FrameCost, LightStats, LiveFrame, OutputRequest, PassTimings,
    Renderer, ShadowMapImage,
};
pub use gpu_scene::GpuScene;
pub use layout::{ShadowLayout, light_projection};
pub use passes::depth_baseline::DepthBaselineScene;
pub use readback::read_texture;
pub use wgpu;

use gnomon_scene::{SceneError, settings::SettingsError};

/// Everything that can go wrong in the renderer. Each message names the input at
/// fault and what would be valid.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(
        "no GPU adapter found{backends}. Gnomon needs a Vulkan, Metal, DX12 or GL driver. \
         On Debian or Ubuntu without a GPU, install the CPU Vulkan driver lavapipe: \
         `sudo apt-get install mesa-vulkan-drivers`"
    )]
    NoAdapter { backends: String },
    #[error("could not open the GPU device on adapter `{adapter}`: {reason}")]
    DeviceRequest { adapter: String, reason: String },
    #[error(
        "a shadow map of {requested}² texels (`shadow.map.resolution`) is larger than this device \
         allows: adapter `{adapter}` supports 2D textures up to {max} texels (and Gnomon up to {})",
        gnomon_scene::settings::MAX_SHADOW_RESOLUTION
    )]
    ShadowMapTooLarge { requested: u32, max: u32, adapter: String },
    #[error(
        "an image of {width}×{height} is larger than adapter `{adapter}` allows: at most {max} pixels a side"
    )]
    ImageTooLarge { width: u32, height: u32, max: u32, adapter: String },
    #[error(
        "adapter `{adapter}` allows {available} bytes of colour attachments per pixel; the lighting \
         pass needs {needed}"
    )]
    AttachmentsTooLarge { available: u32, needed: u32, adapter: String },
    #[error(
        "the moment format rgba32float (`shadow.filter.moments.moment_format`) needs 32-bit float \
         filtering, which adapter `{adapter}` does not have; choose rgba16float or auto"
    )]
    MomentFormatUnsupported { adapter: String },
    #[error(transparent)]
    Settings(#[from] SettingsError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("scene `{0}` has nothing to draw")]
    EmptyScene(String),
    #[error(
        "scene `{scene}`: its {instances} instances need {bytes} bytes of instance data, but this \
         device binds at most {limit} bytes in one storage buffer; render fewer instances"
    )]
    SceneTooLarge { scene: String, instances: usize, bytes: u64, limit: u64 },
    #[error("the GPU reported an error while {during}: {message}")]
    Gpu { during: &'static str, message: String },
}
