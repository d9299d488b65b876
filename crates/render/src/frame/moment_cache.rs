//! Moment maps kept across frames (VSM, ESM, EVSM, MSM, convolution maps): a light
//! whose depth map was kept whole this frame (`map_cache.rs`: every layer kept, no
//! caster moving over it) filters the same depths again into the same moments, unless
//! something else the filter reads changed. So its moment map is kept too, and the
//! frame records no moment pass for it. [`MomentKey`] holds what the filter reads
//! besides the depths: the light's uniform, the technique, its filter settings and
//! the map's format and size.

use super::plan::LightPlan;
use crate::passes::moments::{MomentInput, MomentLayout};

/// What a moment map depends on besides its light's depth map, as bytes compared
/// whole.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct MomentKey(Vec<u8>);

impl MomentKey {
    /// The key of `light`'s moment map filtered from `input`.
    pub fn of(light: &LightPlan, input: &MomentInput) -> MomentKey {
        let mut bytes = bytemuck::bytes_of(&light.light_gpu).to_vec();
        let MomentInput { technique, map, settings, format, resolution, cascades, .. } = *input;
        let described = format!("{technique:?} {map:?} {settings:?} {format:?} {resolution} {cascades}");
        bytes.extend_from_slice(described.as_bytes());
        MomentKey(bytes)
    }
}

/// One light's kept moment map.
struct KeptMoments {
    key: MomentKey,
    layout: MomentLayout,
    texture: wgpu::Texture,
}

/// Every light's kept moment map, by the light's index in the frame.
#[derive(Default)]
pub(super) struct MomentCache {
    lights: Vec<Option<KeptMoments>>,
    /// Textures created, for [`super::Renderer::creations`].
    created: u64,
}

/// What a frame does with a light's moment map.
pub(super) enum MomentPlan {
    /// Keep it: its depths and its key are the ones it was filtered from.
    Keep(wgpu::Texture),
    /// Filter into this texture, kept for the frames after.
    Filter(wgpu::Texture),
}

impl MomentCache {
    /// Light `index`'s moment map for `key` and `layout`: the kept one where
    /// `depths_kept` (its depth map is the one it was filtered from) and the key is
    /// the same, else a texture to filter into, kept from now on under `key`.
    pub fn plan(
        &mut self,
        device: &wgpu::Device,
        index: usize,
        key: MomentKey,
        layout: MomentLayout,
        depths_kept: bool,
    ) -> MomentPlan {
        if self.lights.len() <= index {
            self.lights.resize_with(index + 1, || None);
        }
        match self.lights[index].take() {
            Some(kept) if depths_kept && kept.key == key && kept.layout == layout => {
                let texture = kept.texture.clone();
                self.lights[index] = Some(kept);
                MomentPlan::Keep(texture)
            }
            kept => {
                let texture = match kept {
                    Some(kept) if kept.layout == layout => kept.texture,
                    Some(_) | None => {
                        self.created += 1;
                        create_moments(device, layout)
                    }
                };
                self.lights[index] = Some(KeptMoments { key, layout, texture: texture.clone() });
                MomentPlan::Filter(texture)
            }
        }
    }

    /// Light `index` keeps no moment map (its depth map is not kept).
    pub fn forget(&mut self, index: usize) {
        if let Some(kept) = self.lights.get_mut(index) {
            *kept = None;
        }
    }

    /// How many moment textures it has created.
    pub fn created(&self) -> u64 {
        self.created
    }
}

fn create_moments(device: &wgpu::Device, layout: MomentLayout) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("moment map, kept"),
        size: layout.size,
        mip_level_count: layout.mip_levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: layout.format,
        usage: MomentLayout::USAGE,
        view_formats: &[],
    })
}
