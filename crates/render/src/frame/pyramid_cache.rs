//! Depth pyramids kept across frames: a light whose depth map was kept whole this
//! frame (`map_cache.rs`: every layer kept, no caster moving over it) has the same
//! depths, so the pyramid built from them last frame (`rays/pyramid.rs`) still holds,
//! and the frame records no pyramid pass for it. Anything else builds it again, into
//! the same texture while the map's shape stays.

use crate::rays::PyramidLayout;

/// One light's kept pyramid.
struct KeptPyramid {
    layout: PyramidLayout,
    texture: wgpu::Texture,
}

/// Every light's kept pyramid, by the light's index in the frame.
#[derive(Default)]
pub(super) struct PyramidCache {
    lights: Vec<Option<KeptPyramid>>,
    /// Textures created, for [`super::Renderer::creations`].
    created: u64,
}

/// What a frame does with a light's pyramid.
pub(super) enum PyramidPlan {
    /// Keep it: built from the depths the map holds now.
    Keep(wgpu::Texture),
    /// Build it into this texture.
    Build(wgpu::Texture),
}

impl PyramidCache {
    /// Light `index`'s pyramid of `layout`: the kept one where `depths_kept` (its
    /// depth map is the one it was built from), else a texture to build it into.
    pub fn plan(&mut self, device: &wgpu::Device, index: usize, layout: PyramidLayout, depths_kept: bool) -> PyramidPlan {
        if self.lights.len() <= index {
            self.lights.resize_with(index + 1, || None);
        }
        match &self.lights[index] {
            Some(kept) if kept.layout == layout && depths_kept => PyramidPlan::Keep(kept.texture.clone()),
            Some(kept) if kept.layout == layout => PyramidPlan::Build(kept.texture.clone()),
            Some(_) | None => {
                self.created += 1;
                let texture = layout.create(device);
                self.lights[index] = Some(KeptPyramid { layout, texture: texture.clone() });
                PyramidPlan::Build(texture)
            }
        }
    }

    /// Light `index` has no pyramid this frame: what it kept no longer holds.
    pub fn forget(&mut self, index: usize) {
        if let Some(kept) = self.lights.get_mut(index) {
            *kept = None;
        }
    }

    /// How many pyramid textures it has created.
    pub fn created(&self) -> u64 {
        self.created
    }
}
