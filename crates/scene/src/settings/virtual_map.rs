//! A virtual shadow map's settings (`--partition virtual`, issue 53): the size of its
//! levels, the pool of page tiles the pages a frame reads are drawn into, and how
//! finely it reads. The rest of the clipmap's shape (128² pages, 16 levels) is
//! `gnomon_math::virtual_map::ClipmapShape::DEFAULT`.

use serde::{Deserialize, Serialize};

use super::{SettingsError, ranges::SettingRange};

/// Texels per side of a virtual map's page (`gnomon_math::virtual_map::ClipmapShape`).
pub const PAGE_TEXELS: u32 = gnomon_math::virtual_map::ClipmapShape::DEFAULT.page_size;

/// The most page tiles per side of the pool: 64² tiles of 128² texels are one
/// 8192² depth texture, 256 MiB.
pub const MAX_POOL_SIDE: u32 = 64;

/// The most levels finer than a pixel's footprint a virtual map may read: 2 draws
/// texels a quarter of a pixel wide, 16× the pages.
pub const MAX_LOD_BIAS: u32 = 2;

/// `shadow.virtual_map.lod_bias`'s range.
pub const LOD_BIAS_RANGE: SettingRange =
    SettingRange::closed("shadow.virtual_map.lod_bias", 0.0, MAX_LOD_BIAS as f64, "levels");

/// The most levels finer than a pixel's footprint that the pages along a shadow
/// edge may be drawn at: 2 draws them with texels a quarter of the footprint wide.
pub const MAX_EDGE_LEVELS: u32 = 2;

/// `shadow.virtual_map.edge_levels`'s range.
pub const EDGE_LEVELS_RANGE: SettingRange =
    SettingRange::closed("shadow.virtual_map.edge_levels", 0.0, MAX_EDGE_LEVELS as f64, "levels");

/// The smallest and largest virtual levels: 1024² texels (8² pages) to 32768² (256²
/// pages; a page table of 16 such levels is 4 MiB).
pub const LEVEL_RESOLUTION_RANGE: SettingRange =
    SettingRange::closed("shadow.virtual_map.level_resolution", 1024.0, 32768.0, "texels");

/// `shadow.virtual_map.pool_side`'s range.
pub const POOL_SIDE_RANGE: SettingRange =
    SettingRange::closed("shadow.virtual_map.pool_side", 2.0, MAX_POOL_SIDE as f64, "tiles");

/// A virtual shadow map (--partition virtual).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(struct_patch::Patch)]
#[patch(attribute(derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)))]
#[patch(attribute(serde(default, deny_unknown_fields)))]
#[patch(attribute(allow(missing_docs)))]
#[patch(attribute(
    doc = "Overrides of [`VirtualMapSettings`], as a light's own shadow settings write them: each field as documented there, `None` to keep the value it is laid over."
))]
#[serde(default, deny_unknown_fields)]
pub struct VirtualMapSettings {
    /// Page tiles per side of the physical pool, one depth texture of (side · 128)²
    /// texels. The default, 32² tiles of 128², holds 1,024 pages: 16.8 M texels, as
    /// many as four 2048² cascades; the pages the pixels read at their footprints
    /// take 140–230 of them on the views, and those along shadow edges
    /// (`edge_levels`) the rest. When a frame asks for more pages than it holds,
    /// pixels read a coarser resident page instead, and pages along edges are left
    /// out first.
    #[cfg_attr(feature = "cli", arg(long = "page-pool", value_name = "TILES", default_value_t = VirtualMapSettings::default().pool_side, help_heading = "Virtual map"))]
    pub pool_side: u32,
    /// Levels finer than a pixel's footprint that its lookup reads: 0 reads texels
    /// as large as the footprint (half to one pixel), 1 texels half as large, for 4×
    /// the pages. Finer texels narrow the bands along shadow edges where the map is
    /// unsure, so rays decide fewer pixels.
    #[cfg_attr(feature = "cli", arg(long = "page-lod-bias", value_name = "LEVELS", default_value_t = VirtualMapSettings::default().lod_bias, help_heading = "Virtual map"))]
    pub lod_bias: u32,
    /// Levels finer still that the pages along shadow edges are drawn at, with the
    /// sun and casters still (adaptive shadow maps, Fernando, Fernandez, Bala and
    /// Greenberg, SIGGRAPH 2001). The pixels that rays decided in one frame ask for
    /// the pages one level finer around them for the next, up to this many levels,
    /// and a pixel reads the finest level whose pages hold its whole footprint: the
    /// band the map is unsure of, and so the pixels traced, narrows with each level
    /// (a still view settles in 1 + this many frames; `render` renders them). The
    /// pages are kept while the light stands still; a light that moves drops them.
    /// 0 turns it off.
    #[cfg_attr(feature = "cli", arg(long = "page-edge-levels", value_name = "LEVELS", default_value_t = VirtualMapSettings::default().edge_levels, help_heading = "Virtual map"))]
    pub edge_levels: u32,
    /// Texels per side of each virtual level, a multiple of the 128-texel page: 16384
    /// (Unreal's) by default. Each level's window is this many of its texels wide
    /// around the camera; a pixel outside its footprint's level's window reads the
    /// finest coarser level whose window holds it. Smaller levels make a smaller page
    /// table and coarser texels at the sides of wide views.
    #[cfg_attr(feature = "cli", arg(long = "virtual-res", value_name = "TEXELS", default_value_t = VirtualMapSettings::default().level_resolution, help_heading = "Virtual map"))]
    pub level_resolution: u32,
}

impl Default for VirtualMapSettings {
    fn default() -> Self {
        Self { pool_side: 32, lod_bias: 0, edge_levels: MAX_EDGE_LEVELS, level_resolution: PAGE_TEXELS * 128 }
    }
}

impl VirtualMapSettings {
    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        POOL_SIDE_RANGE.check(self.pool_side)?;
        LOD_BIAS_RANGE.check(self.lod_bias)?;
        EDGE_LEVELS_RANGE.check(self.edge_levels)?;
        LEVEL_RESOLUTION_RANGE.check(self.level_resolution)?;
        if !self.level_resolution.is_multiple_of(PAGE_TEXELS) {
            return Err(SettingsError {
                setting: "shadow.virtual_map.level_resolution",
                value: self.level_resolution.to_string(),
                valid: format!("a multiple of the {PAGE_TEXELS}-texel page"),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_levels_resolution_is_a_whole_number_of_pages_in_range() {
        let with =
            |level_resolution| VirtualMapSettings { level_resolution, ..Default::default() }.validate();
        assert_eq!(with(16384), Ok(()));
        assert_eq!(with(1024 + 128), Ok(()));
        let e = with(1100).unwrap_err();
        assert_eq!((e.setting, e.value.as_str()), ("shadow.virtual_map.level_resolution", "1100"));
        assert!(e.valid.contains("128-texel page"), "{e}");
        assert_eq!(with(65536).unwrap_err().setting, "shadow.virtual_map.level_resolution");
        assert_eq!(with(512).unwrap_err().setting, "shadow.virtual_map.level_resolution");
    }
}
