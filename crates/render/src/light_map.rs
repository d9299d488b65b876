//! Which kind of shadow map a light draws and how its receivers look it up, decided in
//! one place from the view the light's kind takes (`Light::shadow_view`) and
//! `shadow.map.omni`: the frame's depth targets,
//! the registry's checks, the light uniform and the lighting passes' WGSL all ask
//! [`MapLookup::of`]. A leaf: it depends on nothing of the renderer.

use gnomon_scene::{Light, lights::ShadowView, settings::OmniMap};

/// How a receiver is found in its light's own map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum MapLookup {
    /// Projected into 2D layers: a sun's map or cascades, a spot's map.
    Map,
    /// By direction in a point light's cube.
    Cube,
    /// Through a point light's dual paraboloids, into two 2D layers.
    Paraboloid,
}

impl MapLookup {
    /// The map `light` draws under `omni` (which only an omnidirectional view reads).
    pub fn of(light: &Light, omni: OmniMap) -> MapLookup {
        match (light.shadow_view(), omni) {
            (ShadowView::Omni { .. }, OmniMap::Cube) => MapLookup::Cube,
            (ShadowView::Omni { .. }, OmniMap::Paraboloid) => MapLookup::Paraboloid,
            (
                ShadowView::Parallel { .. } | ShadowView::Frustum { .. },
                OmniMap::Cube | OmniMap::Paraboloid,
            ) => MapLookup::Map,
        }
    }
}
