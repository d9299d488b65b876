//! Textures derived from a light's depth map and kept across frames: its depth
//! pyramid (`rays/pyramid.rs`) and its touched layer (`rays/touched.rs`). A light
//! whose depth map was kept whole this frame (`map_cache.rs`: every layer kept, no
//! caster moving over it) has the same depths and casters, so what was derived from
//! them last frame still holds, and the frame records no pass for it. Anything else
//! derives it again, into the same textures while their shape stays.

use crate::rays::{Pyramid, PyramidLayout, Touched, TouchedLayout};

/// Textures derived from a light's map: their shape, and how to make them.
pub(super) trait Derived: Clone {
    /// What the textures' shape depends on.
    type Layout: Copy + PartialEq;
    /// Textures one of them holds, for [`super::Renderer::creations`].
    const TEXTURES: u64;
    fn create(layout: &Self::Layout, device: &wgpu::Device) -> Self;
}

impl Derived for Pyramid {
    type Layout = PyramidLayout;
    const TEXTURES: u64 = 2;
    fn create(layout: &PyramidLayout, device: &wgpu::Device) -> Self {
        layout.create(device)
    }
}

impl Derived for Touched {
    type Layout = TouchedLayout;
    const TEXTURES: u64 = 1;
    fn create(layout: &TouchedLayout, device: &wgpu::Device) -> Self {
        layout.create(device)
    }
}

/// Every light's kept textures of one kind, by the light's index in the frame.
pub(super) struct DerivedCache<T: Derived> {
    lights: Vec<Option<(T::Layout, T)>>,
    /// Textures created, for [`super::Renderer::creations`].
    created: u64,
}

impl<T: Derived> Default for DerivedCache<T> {
    fn default() -> Self {
        Self { lights: Vec::new(), created: 0 }
    }
}

/// What a frame does with a light's derived textures.
pub(super) enum DerivedPlan<T> {
    /// Keep them: derived from the depths and casters the map holds now.
    Keep(T),
    /// Derive them into these textures.
    Build(T),
}

impl<T: Derived> DerivedCache<T> {
    /// Light `index`'s textures of `layout`: the kept ones where `depths_kept` (its
    /// depth map is the one they were derived from), else textures to derive them into.
    pub fn plan(
        &mut self,
        device: &wgpu::Device,
        index: usize,
        layout: T::Layout,
        depths_kept: bool,
    ) -> DerivedPlan<T> {
        if self.lights.len() <= index {
            self.lights.resize_with(index + 1, || None);
        }
        match &self.lights[index] {
            Some((kept, textures)) if *kept == layout && depths_kept => DerivedPlan::Keep(textures.clone()),
            Some((kept, textures)) if *kept == layout => DerivedPlan::Build(textures.clone()),
            Some(_) | None => {
                self.created += T::TEXTURES;
                let textures = T::create(&layout, device);
                self.lights[index] = Some((layout, textures.clone()));
                DerivedPlan::Build(textures)
            }
        }
    }

    /// Light `index` derives none this frame: what it kept no longer holds.
    pub fn forget(&mut self, index: usize) {
        if let Some(kept) = self.lights.get_mut(index) {
            *kept = None;
        }
    }

    /// Light `index`'s kept textures and their shape, for the tests that read them back.
    #[cfg(test)]
    pub fn kept(&self, index: usize) -> Option<(&T, T::Layout)> {
        self.lights.get(index)?.as_ref().map(|(layout, textures)| (textures, *layout))
    }

    /// How many textures it has created.
    pub fn created(&self) -> u64 {
        self.created
    }
}
