//! Which kind of shadow map a light draws and how its receivers look it up, decided in
//! one place from the view the light's kind takes (`Light::shadow_view`) and
//! the shadow settings (`shadow.map.omni`, `shadow.partition`): the frame's depth targets,
//! the registry's checks, the light uniform and the lighting passes' WGSL all ask
//! [`MapLookup::of`]. A leaf: it depends on nothing of the renderer.

use gnomon_scene::{
    Light,
    lights::ShadowView,
    settings::{OmniMap, Partition, ShadowSettings},
};

/// How a receiver is found in its light's own map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum MapLookup {
    /// Projected into 2D layers: a sun's map or cascades, a spot's map.
    Map,
    /// By direction in a point light's cube.
    Cube,
    /// Through a point light's dual paraboloids, into two 2D layers.
    Paraboloid,
    /// Through a virtual map (a sun's, a spot's or a point light's): the clipmap
    /// level of the receiver's footprint, its page found in the page table
    /// (`virtual_map/page_lookup.wgsl`).
    Virtual,
}

impl MapLookup {
    /// The map `light` draws under `shadow`: a virtual map where `shadow.partition`
    /// says so, whatever the light; otherwise `shadow.map.omni` for an
    /// omnidirectional view, and a 2D map (single or cascades) for a sun's or a
    /// spot's.
    pub fn of(light: &Light, shadow: &ShadowSettings) -> MapLookup {
        match (light.shadow_view(), shadow.map.omni, shadow.partition) {
            (_, _, Partition::Virtual) => MapLookup::Virtual,
            (ShadowView::Omni { .. }, OmniMap::Cube, Partition::Single | Partition::Cascades) => {
                MapLookup::Cube
            }
            (ShadowView::Omni { .. }, OmniMap::Paraboloid, Partition::Single | Partition::Cascades) => {
                MapLookup::Paraboloid
            }
            (
                ShadowView::Parallel { .. } | ShadowView::Frustum { .. },
                OmniMap::Cube | OmniMap::Paraboloid,
                Partition::Single | Partition::Cascades,
            ) => MapLookup::Map,
        }
    }
}
