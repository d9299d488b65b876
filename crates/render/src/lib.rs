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

#![warn(missing_docs)]

mod clusters;
mod device;
mod frame;
mod gpu_scene;
mod gpu_types;
mod layout;
mod light_map;
mod passes;
mod pool;
pub mod rays;
mod readback;
pub mod techniques;
pub mod timing;
pub mod uniforms;
pub mod virtual_map;

pub use clusters::CLUSTERS_BUILT;
pub use device::{DeferredErrors, Gpu, GpuInfo};
pub use frame::{
    CpuTimings, Creations, DrawStats, Frame, FrameCost, LayerCache, LightShadows, LightStats, LiveFrame,
    OutputRequest, PageStats, PassTimings, ReceiverVariant, Renderer, ShadowMapImage, Shadows, VirtualLevels,
};
pub use gpu_scene::{GpuCullUnavailable, GpuScene};
pub use layout::{ShadowLayout, light_projection};
pub use passes::blit::HostTarget;
pub use passes::depth_baseline::DepthBaselineScene;
#[cfg(not(target_arch = "wasm32"))]
pub use readback::read_texture;
pub use readback::read_texture_async;
pub use wgpu;

use gnomon_scene::{SceneError, settings::SettingsError};

/// Everything that can go wrong in the renderer. Each message names the input at
/// fault and what would be valid.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No GPU adapter is available (for the backends `WGPU_BACKEND` allows, if set).
    #[error(
        "no GPU adapter found{backends}. Gnomon needs a Vulkan, Metal or DX12 driver. \
         On Debian or Ubuntu without a GPU, install the CPU Vulkan driver lavapipe: \
         `sudo apt-get install mesa-vulkan-drivers`"
    )]
    NoAdapter {
        /// The message's mention of `WGPU_BACKEND` when that variable narrowed the search, or of
        /// the OpenGL adapter that was refused; empty otherwise.
        backends: String,
    },
    /// The adapter was found but refused to open a device with the limits and features asked for.
    #[error("could not open the GPU device on adapter `{adapter}`: {reason}")]
    DeviceRequest {
        /// Name of the adapter, as wgpu reports it.
        adapter: String,
        /// wgpu's reason for refusing the device.
        reason: String,
    },
    /// The shadow map resolution exceeds the device's largest 2D texture.
    #[error(
        "a shadow map of {requested}² texels (`shadow.map.resolution`) is larger than this device \
         allows: adapter `{adapter}` supports 2D textures up to {max} texels (and Gnomon up to {})",
        gnomon_scene::settings::MAX_SHADOW_RESOLUTION
    )]
    ShadowMapTooLarge {
        /// The requested map resolution, in texels a side.
        requested: u32,
        /// The device's largest 2D texture, in texels a side.
        max: u32,
        /// Name of the adapter, as wgpu reports it.
        adapter: String,
    },
    /// A virtual map's page pool is wider than the device's largest 2D texture.
    #[error(
        "a virtual map's page pool of {pages_per_side} pages a row (`shadow.virtual_map.pool_side`) is \
         {texels} texels wide, more than adapter `{adapter}` allows: 2D textures up to {max} texels a side"
    )]
    PagePoolTooLarge {
        /// The pool's pages per row.
        pages_per_side: u32,
        /// Its texels per row.
        texels: u64,
        /// The device's largest 2D texture, in texels a side.
        max: u32,
        /// Name of the adapter, as wgpu reports it.
        adapter: String,
    },
    /// The image width or height exceeds the device's largest 2D texture.
    #[error(
        "an image of {width}×{height} is larger than adapter `{adapter}` allows: at most {max} pixels a side"
    )]
    ImageTooLarge {
        /// The requested image width, in pixels.
        width: u32,
        /// The requested image height, in pixels.
        height: u32,
        /// The device's largest 2D texture, in texels a side.
        max: u32,
        /// Name of the adapter, as wgpu reports it.
        adapter: String,
    },
    /// An image whose largest target holds more bytes than the device's largest
    /// buffer, through which it is read back (16 bytes a pixel: the position and
    /// normal outputs, and the prepass's surface).
    #[error(
        "an image of {width}×{height} takes {bytes} bytes in each of its largest targets, more than adapter \
         `{adapter}` allows in one buffer ({max_buffer} bytes): at most {max_pixels} pixels in all"
    )]
    ImageTooManyBytes {
        /// The requested image width, in pixels.
        width: u32,
        /// The requested image height, in pixels.
        height: u32,
        /// Bytes of its largest target.
        bytes: u64,
        /// The device's largest buffer (`max_buffer_size`), in bytes.
        max_buffer: u64,
        /// The most pixels an image may have on this device.
        max_pixels: u64,
        /// Name of the adapter, as wgpu reports it.
        adapter: String,
    },
    /// The device cannot hold the lighting pass's colour targets: too few attachment bytes per pixel.
    #[error(
        "adapter `{adapter}` allows {available} bytes of colour attachments per pixel; the lighting \
         pass needs {needed}"
    )]
    AttachmentsTooLarge {
        /// The device's limit on colour attachment bytes per pixel (per sample).
        available: u32,
        /// The bytes per pixel the lighting pass's colour targets take together.
        needed: u32,
        /// Name of the adapter, as wgpu reports it.
        adapter: String,
    },
    /// rgba32float moment maps were asked for on a device without 32-bit float filtering.
    #[error(
        "the moment format rgba32float (`shadow.filter.moments.moment_format`) needs 32-bit float \
         filtering, which adapter `{adapter}` does not have; choose rgba16float or auto"
    )]
    MomentFormatUnsupported {
        /// Name of the adapter, as wgpu reports it.
        adapter: String,
    },
    /// A host's shader reads each light's own shadow map ([`Renderer::record_shadows`]);
    /// the mask path (a screen-space mask, contact shadows) needs Gnomon's depth
    /// prepass, and rays asked for by name are traced in Gnomon's own passes.
    #[error(
        "the shadow receiver reads each light's shadow map, but these settings shade through \
         Gnomon's own passes: its screen-space mask (`screen.shadow_path = \"mask\"`, or \
         `shadow.contact.contact_shadows` on for a light), which needs Gnomon's own depth \
         prepass, or shadow rays (`screen.refine` rays or every-pixel), which Gnomon traces in \
         its mask or lighting pass; set `screen.shadow_path` to forward or auto with contact \
         shadows off and `screen.refine` auto or off, or let Gnomon draw the image"
    )]
    ReceiverNeedsMapPath,
    /// A host's shader reads shadow maps ([`Renderer::record_shadows`]), and a
    /// technique that is rays ([`techniques::ShadowTechnique::rays`]) has none to read.
    #[error(
        "the shadow receiver reads each light's shadow map, but light `{light}`'s technique \
         `{technique}` (`shadow.filter.technique`) traces a shadow ray at every pixel in \
         Gnomon's own passes and leaves no map to read; choose a shadow-map technique for a \
         host's shader, or let Gnomon draw the image"
    )]
    ReceiverCannotTrace {
        /// The light, by its name in the render's list.
        light: String,
        /// Its technique.
        technique: String,
    },
    /// A technique that is rays ([`techniques::ShadowTechnique::rays`]) on a device
    /// that cannot trace this scene or image: unlike refinement, it has no map to fall
    /// back to.
    #[error(
        "light `{light}`'s technique `{technique}` (`shadow.filter.technique`) traces a shadow \
         ray at every pixel, but {why}; choose a shadow-map technique, which falls back to its \
         map where rays cannot run"
    )]
    TechniqueNeedsRays {
        /// The light, by its name in the render's list.
        light: String,
        /// Its technique.
        technique: String,
        /// Why the device cannot trace.
        why: rays::RaysUnavailable,
    },
    /// A setting is out of its valid range.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The frame (or the scene alone) would take more memory than the budget allows
    /// ([`gnomon_scene::memory`]).
    #[error("scene `{scene}`: {over}")]
    OverBudget {
        /// The scene's name.
        scene: String,
        /// What it would take, the budget and the largest items.
        over: gnomon_scene::memory::OverBudget,
    },
    /// The memory budget asked for is not valid (its variable and the valid range).
    #[error("{0}")]
    MemoryBudget(String),
    /// The scene is not well formed (checked before upload).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The scene (named by the field) has nothing to draw: no instances or triangles, or, for a
    /// [`DepthBaselineScene`], no shadow casters.
    #[error("scene `{0}` has nothing to draw")]
    EmptyScene(String),
    /// The scene's instance data does not fit in one storage buffer binding on this device.
    #[error(
        "scene `{scene}`: its {instances} instances need {bytes} bytes of instance data, but this \
         device binds at most {limit} bytes in one storage buffer: at most {max_instances} instances"
    )]
    SceneTooLarge {
        /// Name of the scene.
        scene: String,
        /// Number of instances uploaded.
        instances: usize,
        /// Size of their per-instance data, in bytes.
        bytes: u64,
        /// The most bytes the device binds in one storage buffer.
        limit: u64,
        /// The most instances that fit in `limit`.
        max_instances: u64,
    },
    /// An instance to move is not one of the uploaded scene's.
    #[error(
        "scene `{scene}` has {count} instances, numbered 0 to {count} − 1: there is no instance {index} to move"
    )]
    UnknownInstance {
        /// Name of the scene.
        scene: String,
        /// The index asked for.
        index: usize,
        /// How many instances the scene has.
        count: usize,
    },
    /// Instances were added to or removed from a scene since it was uploaded: a move
    /// cannot follow that.
    #[error(
        "scene `{scene}` has {now} instances but was uploaded with {uploaded}: moving instances \
         changes transforms only; a scene whose instances were added or removed needs a new upload"
    )]
    InstancesChanged {
        /// Name of the scene.
        scene: String,
        /// How many instances it had when uploaded.
        uploaded: usize,
        /// How many it has now.
        now: usize,
    },
    /// The GPU ray tracer cannot take the scene or the frame on this device
    /// ([`crate::rays::RaysUnavailable`]). A frame that asked for refinement by rays
    /// does not fail for it: it is drawn unrefined and reports why
    /// ([`LightStats::refine_fallback`]); [`crate::rays::ShadowRays`] does.
    #[error(transparent)]
    RaysUnavailable(#[from] rays::RaysUnavailable),
    /// Ray queries were asked for by name where the device cannot run them
    /// ([`crate::rays::RayQueriesUnavailable`]). A frame does not fail for it: the
    /// shader traces instead, and the frame says why ([`LightStats::tracer_fallback`]);
    /// [`crate::rays::ShadowRays::with_tracer`] does.
    #[error(transparent)]
    RayQueriesUnavailable(#[from] rays::RayQueriesUnavailable),
    /// wgpu reported a validation, out-of-memory or internal error, or a wait or readback failed.
    #[error("the GPU reported an error while {during}: {message}")]
    Gpu {
        /// What the renderer was doing, for the message ("reading back", say).
        during: &'static str,
        /// wgpu's description of the error.
        message: String,
    },
}
