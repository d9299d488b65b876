//! `pcss`: percentage-closer soft shadows (Fernando 2005). The light's size is the
//! light's own (spot disk radius, point light sphere radius or sun angular diameter), the same parameter the
//! reference's area light uses; the search settings are carried in `light.light_size`, `blocker_taps`, `max_search_texels` and `max_penumbra_texels`.

use gnomon_scene::settings::{FilterSettings, Technique};

use super::contract::{MapSupport, ShadowTechnique, Tunables, VirtualReach};

pub struct Pcss;

impl ShadowTechnique for Pcss {
    fn technique(&self) -> Technique {
        Technique::PCSS
    }

    fn summary(&self) -> &'static str {
        "Percentage-closer soft shadows (Fernando 2005): a blocker search, then PCF whose width follows the light's size and the blocker distance."
    }

    /// The blocker search turns stored depths into distances to the light: it needs
    /// the true, unwarped and unclamped depth of a planar projection.
    fn maps(&self) -> MapSupport {
        MapSupport { paraboloid: false, warped: false, clamped_depth: false }
    }

    /// The bias moves its edges; it has no kernel of `pcf_kernel`.
    fn tunables(&self) -> Tunables {
        Tunables::BIAS
    }

    /// The farther of its two reaches: the blocker search's cap and the penumbra's.
    fn filter_reach_texels(&self, s: &FilterSettings, _: f32) -> f32 {
        s.pcss.max_radius.max(s.pcss.max_penumbra)
    }

    /// On a virtual map its blocker search reads the cone in the level where it
    /// spans at most the search's cap, and its filter a penumbra in the level where
    /// it spans at most the filter's (pcss_virtual.wgsl).
    fn virtual_reach(&self, s: &FilterSettings, _: f32) -> VirtualReach {
        let (search, filter) = (s.pcss.max_radius, s.pcss.max_penumbra);
        VirtualReach::Cone { level_cap: search.min(filter), reach_cap: search.max(filter) }
    }

    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("pcss.wgsl")]
    }

    fn virtual_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("pcss_virtual.wgsl")])
    }

    fn cube_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("pcss_cube.wgsl")])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample-fitted cascade keeps a margin as wide as the reach: the blocker
    /// search's taps and the filter's both read there, whichever cap is the larger.
    /// On a virtual map each reads the light's cone in the level where it spans at most
    /// its cap: the coarsest level read is the smaller cap's, and no read reaches
    /// further than the larger cap.
    #[test]
    fn the_reach_covers_the_search_and_the_filter() {
        let mut f = FilterSettings::default();
        for (search, penumbra, reach, smaller) in
            [(48.0, 16.0, 48.0, 16.0), (16.0, 48.0, 48.0, 16.0), (32.0, 32.0, 32.0, 32.0)]
        {
            (f.pcss.max_radius, f.pcss.max_penumbra) = (search, penumbra);
            assert_eq!(Pcss.filter_reach_texels(&f, 3.0), reach, "search {search}, penumbra {penumbra}");
            assert_eq!(
                Pcss.virtual_reach(&f, 3.0),
                VirtualReach::Cone { level_cap: smaller, reach_cap: reach },
                "search {search}, penumbra {penumbra}"
            );
        }
    }
}
