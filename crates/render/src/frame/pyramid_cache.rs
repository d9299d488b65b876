//! Depth pyramids kept across frames: a light whose depth map was kept whole this
//! frame (`map_cache.rs`: every layer kept, no caster moving over it) has the same
//! depths, so the pyramid built from them last frame (`rays/pyramid.rs`) still holds,
//! and the frame records no pyramid pass for it. Anything else builds it again, into
//! the same texture while the map's shape stays.

use crate::rays::{Pyramid, PyramidLayout};

/// One light's kept pyramid.
struct KeptPyramid {
    layout: PyramidLayout,
    pyramid: Pyramid,
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
    Keep(Pyramid),
    /// Build it into this texture.
    Build(Pyramid),
}

impl PyramidCache {
    /// Light `index`'s pyramid of `layout`: the kept one where `depths_kept` (its
    /// depth map is the one it was built from), else textures to build it into.
    pub fn plan(
        &mut self,
        device: &wgpu::Device,
        index: usize,
        layout: PyramidLayout,
        depths_kept: bool,
    ) -> PyramidPlan {
        if self.lights.len() <= index {
            self.lights.resize_with(index + 1, || None);
        }
        match &self.lights[index] {
            Some(kept) if kept.layout == layout && depths_kept => PyramidPlan::Keep(kept.pyramid.clone()),
            Some(kept) if kept.layout == layout => PyramidPlan::Build(kept.pyramid.clone()),
            Some(_) | None => {
                self.created += 2;
                let pyramid = layout.create(device);
                self.lights[index] = Some(KeptPyramid { layout, pyramid: pyramid.clone() });
                PyramidPlan::Build(pyramid)
            }
        }
    }

    /// Light `index` has no pyramid this frame: what it kept no longer holds.
    pub fn forget(&mut self, index: usize) {
        if let Some(kept) = self.lights.get_mut(index) {
            *kept = None;
        }
    }

    /// Light `index`'s kept pyramid and its shape, for the tests that read it back.
    #[cfg(test)]
    pub fn kept(&self, index: usize) -> Option<(&Pyramid, PyramidLayout)> {
        self.lights.get(index)?.as_ref().map(|kept| (&kept.pyramid, kept.layout))
    }

    /// How many pyramid textures it has created.
    pub fn created(&self) -> u64 {
        self.created
    }
}
