//! What exists once the window is open: the window, its device and surface, the
//! renderer (away while a frame's work has it), and egui's state and painter.

use std::sync::Arc;

use gnomon_render::wgpu;
use winit::window::Window;

use super::job::Workshop;
use crate::ui::Images;

/// What exists once the window is open.
pub(crate) struct Live {
    pub(super) window: Arc<Window>,
    /// Kept for as long as its device: a browser loses the device (and each
    /// readback fails) once the instance it came from is collected.
    pub(super) _instance: wgpu::Instance,
    /// The window's device, which the renderer shares.
    pub(super) gpu: gnomon_render::Gpu,
    pub(super) surface: wgpu::Surface<'static>,
    pub(super) config: wgpu::SurfaceConfiguration,
    /// The renderer and the scene's upload; `None` while a frame's work has them.
    pub(super) workshop: Option<Workshop>,
    pub(super) egui: egui_winit::State,
    pub(super) painter: egui_wgpu::Renderer,
    /// The live frame's image as egui knows it.
    pub(super) view_texture: Option<egui::TextureId>,
    pub(super) maps_texture: Option<egui::TextureId>,
    pub(super) images: Images,
}
