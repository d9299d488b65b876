//! Each light's penumbra history, kept across frames (rays/penumbra_mask.wgsl): what
//! the last frame's mask pass decided of each pixel and the beams its unsure pixels
//! gathered, which a frame starts from where nothing they depend on changed: the
//! camera (a pixel must see the same point), the light and its map, and where the
//! casters stand. [`HistoryKey`] holds all of it; any change throws the history away,
//! so that nothing a moved camera, light or caster made stale is shown, at the cost
//! of starting again (a quarter of the unsure pixels beamed, the rest filled).
//!
//! Two textures per light take turns: a frame reads the one the last frame wrote and
//! writes the other.

use super::plan::LightPlan;
use crate::{rays::HISTORY_FORMAT, uniforms::CameraGpu};

/// What a light's penumbra history depends on, as bytes compared whole: the camera's
/// uniform, the light's (less the history's own fields), where the casters stand, and
/// the image's size.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct HistoryKey(Vec<u8>);

impl HistoryKey {
    /// The key of `light`'s history under `camera`, with the casters as
    /// `caster_generation` names them.
    pub fn of(light: &LightPlan, camera: &CameraGpu, caster_generation: u64) -> HistoryKey {
        let mut uniform = light.light_gpu;
        uniform.rays.history = 0;
        uniform.rays.frame = 0;
        // How many frames a still view gathers says when to stop beaming, not what
        // the beams gathered so far answered: asking for more goes on from them.
        uniform.rays.penumbra_frames = 0;
        let mut bytes = bytemuck::bytes_of(&uniform).to_vec();
        bytes.extend_from_slice(bytemuck::bytes_of(camera));
        bytes.extend_from_slice(&caster_generation.to_le_bytes());
        HistoryKey(bytes)
    }
}

/// One light's two history textures and what they were kept under.
struct LightHistory {
    textures: [wgpu::Texture; 2],
    key: HistoryKey,
    /// Frames drawn into it, the last one counted.
    frames: u32,
}

/// Every light's penumbra history, by the light's index in the frame.
#[derive(Default)]
pub(super) struct PenumbraHistories {
    lights: Vec<Option<LightHistory>>,
    /// Textures created, for [`super::Renderer::creations`].
    created: u64,
}

/// A light's history for one frame.
pub(super) struct HistoryFrame {
    /// What the last frame left, read.
    pub read: wgpu::Texture,
    /// What this frame leaves, written.
    pub write: wgpu::Texture,
    /// Whether `read` holds the last frame's answers under the same key.
    pub held: bool,
    /// The frames drawn into the history, this one counted.
    pub frame: u32,
}

impl PenumbraHistories {
    /// Light `index`'s history for a frame of `key` on a `width` × `height` screen.
    pub fn begin(
        &mut self,
        device: &wgpu::Device,
        index: usize,
        key: HistoryKey,
        [width, height]: [u32; 2],
    ) -> HistoryFrame {
        if self.lights.len() <= index {
            self.lights.resize_with(index + 1, || None);
        }
        let fits = |h: &LightHistory| h.textures[0].width() == width && h.textures[0].height() == height;
        let history = match self.lights[index].take() {
            Some(mut kept) if fits(&kept) => {
                let held = kept.key == key;
                kept.key = key;
                kept.frames = if held { kept.frames.saturating_add(1) } else { 1 };
                (kept, held)
            }
            Some(_) | None => {
                self.created += 2;
                let texture = |label| create_history(device, label, width, height);
                let textures =
                    [texture("penumbra history, even frames"), texture("penumbra history, odd frames")];
                (LightHistory { textures, key, frames: 1 }, false)
            }
        };
        let (history, held) = history;
        let frame = history.frames;
        let write = history.textures[(frame % 2) as usize].clone();
        let read = history.textures[((frame + 1) % 2) as usize].clone();
        self.lights[index] = Some(history);
        HistoryFrame { read, write, held, frame }
    }

    /// Light `index` keeps no history this frame: what it kept no longer follows on.
    pub fn forget(&mut self, index: usize) {
        if let Some(kept) = self.lights.get_mut(index) {
            *kept = None;
        }
    }

    /// Every light keeps no history: the next frame of each starts afresh.
    pub fn forget_all(&mut self) {
        self.lights.iter_mut().for_each(|kept| *kept = None);
    }

    /// How many history textures it has created.
    pub fn created(&self) -> u64 {
        self.created
    }
}

fn create_history(device: &wgpu::Device, label: &str, width: u32, height: u32) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: HISTORY_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    })
}
