//! Settings given a value that the render cannot use: a sun's elevation while a spot
//! is drawn, a light index without the light list, a point light's map with no point
//! light. Each becomes a warning that says what the setting needs, instead of being
//! ignored without a word.

use super::*;
use crate::lights::ShadowView;

/// A setting changed from its default that has no effect on this render.
#[derive(Clone, Debug, PartialEq)]
pub struct UnusedSetting {
    /// The setting, by its path in scene files (`light.light_index`).
    pub setting: &'static str,
    /// What it would need to have an effect, in words, other settings named in backticks.
    pub needs: &'static str,
}

impl std::fmt::Display for UnusedSetting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}` has no effect here: it needs {}", self.setting, self.needs)
    }
}

/// Whether the render uses a setting, given its settings and its lights.
type Uses = fn(&Settings, &[ResolvedLight]) -> bool;

/// Each setting that matters only in some modes: its path, when it is used, and
/// the words for that. A setting in no rule is used in every mode.
const RULES: &[(&str, Uses, &str)] = &[
    ("light.light_index", |s, _| s.light.kind == LightKind::All, "`light.kind` all"),
    ("light.sun_elevation", |s, _| s.light.kind == LightKind::Sun, "`light.kind` sun"),
    ("light.sun_azimuth", |s, _| s.light.kind == LightKind::Sun, "`light.kind` sun"),
    ("light.sun_angular_diameter", |s, _| s.light.kind == LightKind::Sun, "`light.kind` sun"),
    ("light.spot_position", |s, _| s.light.kind == LightKind::Spot, "`light.kind` spot"),
    ("light.spot_target", |s, _| s.light.kind == LightKind::Spot, "`light.kind` spot"),
    ("light.spot_outer_angle", |s, _| s.light.kind == LightKind::Spot, "`light.kind` spot"),
    ("light.spot_inner_angle", |s, _| s.light.kind == LightKind::Spot, "`light.kind` spot"),
    ("light.spot_range", |s, _| s.light.kind == LightKind::Spot, "`light.kind` spot"),
    ("light.spot_radius", |s, _| s.light.kind == LightKind::Spot, "`light.kind` spot"),
    ("light.point_position", |s, _| s.light.kind == LightKind::Point, "`light.kind` point"),
    ("light.point_range", |s, _| s.light.kind == LightKind::Point, "`light.kind` point"),
    ("light.point_radius", |s, _| s.light.kind == LightKind::Point, "`light.kind` point"),
    (
        "shadow.map.omni",
        |_, lights| lights.iter().any(|l| matches!(l.light.shadow_view(), ShadowView::Omni { .. })),
        "a point light",
    ),
    (
        "shadow.map.resolution",
        |s, lights| lights.iter().any(|l| l.shadow.map.resolution == s.shadow.map.resolution),
        "a light that does not set its own (each light here sets its own `shadow.map.resolution` in the scene)",
    ),
    ("shadow.virtual_map.pool_side", uses_virtual, VIRTUAL),
    ("shadow.virtual_map.lod_bias", uses_virtual, VIRTUAL),
    ("shadow.virtual_map.edge_levels", uses_virtual, VIRTUAL),
    ("shadow.virtual_map.level_resolution", uses_virtual, VIRTUAL),
    ("shadow.cascades.count", uses_cascades, CASCADES),
    ("shadow.cascades.split", uses_cascades, CASCADES),
    ("shadow.cascades.split_lambda", uses_cascades, CASCADES),
    ("shadow.cascades.shadow_distance", uses_cascades, CASCADES),
    ("shadow.cascades.cascade_fit", uses_cascades, CASCADES),
    ("shadow.cascades.cascade_selection", uses_cascades, CASCADES),
    ("shadow.cascades.cascade_blend", uses_cascades, CASCADES),
    ("shadow.cascades.sdsm", uses_cascades, CASCADES),
    (
        "image.debug_view",
        |s, lights| match s.image.debug_view {
            DebugView::Traced => traces_rays(s, lights),
            DebugView::Pages => lights.iter().any(|l| l.shadow.partition == Partition::Virtual),
            DebugView::None | DebugView::Cascades => true,
        },
        "`screen.refine` rays or every-pixel, or auto on the mask path, or the raytraced technique (for the traced \
         view); `shadow.partition` virtual (for the pages view)",
    ),
    (
        "screen.penumbra_rays",
        |s, lights| {
            lights
                .iter()
                .any(|l| matches!(s.light_refine(l), Refine::Rays | Refine::EveryPixel) && !l.light.is_hard())
        },
        "`screen.refine` rays or every-pixel, or the raytraced technique, and a light with an area",
    ),
    (
        "screen.tracer",
        traces_rays,
        "`screen.refine` rays or every-pixel, or auto on the mask path, or the raytraced technique",
    ),
];

/// Whether any light of the render traces shadow rays.
fn traces_rays(s: &Settings, lights: &[ResolvedLight]) -> bool {
    lights.iter().any(|l| match s.light_refine(l) {
        Refine::Off => false,
        // `auto` traces on the mask path only.
        Refine::Auto => s.uses_shadow_mask(lights).unwrap_or(false),
        Refine::Rays | Refine::EveryPixel => true,
    })
}

const CASCADES: &str = "`shadow.partition` cascades and a sun";

const VIRTUAL: &str = "`shadow.partition` virtual";

fn uses_virtual(_: &Settings, lights: &[ResolvedLight]) -> bool {
    lights.iter().any(|l| l.shadow.partition == Partition::Virtual)
}

fn uses_cascades(_: &Settings, lights: &[ResolvedLight]) -> bool {
    lights.iter().any(|l| {
        l.shadow.partition == Partition::Cascades
            && matches!(l.light.shadow_view(), ShadowView::Parallel { .. })
    })
}

impl Settings {
    /// The settings changed from their defaults that this render, with `lights`, does
    /// not use. A light's own shadow settings count: cascades set for one sun of the
    /// light list are used.
    pub fn unused(&self, lights: &[ResolvedLight]) -> Vec<UnusedSetting> {
        let (Ok(given), Ok(defaults)) =
            (toml::Value::try_from(self), toml::Value::try_from(Settings::default()))
        else {
            return Vec::new();
        };
        let at = |table: &toml::Value, path: &str| {
            path.split('.').try_fold(table.clone(), |t, k| t.get(k).cloned())
        };
        RULES
            .iter()
            .filter(|(path, uses, _)| at(&given, path) != at(&defaults, path) && !uses(self, lights))
            .map(|&(setting, _, needs)| UnusedSetting { setting, needs })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;

    #[test]
    fn a_light_index_without_the_light_list_and_a_paraboloid_with_a_sun_are_reported() {
        let scene = builtin::build("columns").unwrap();
        let mut s = Settings::default();
        let lights = s.resolve_lights(&scene).unwrap();
        assert!(s.unused(&lights).is_empty(), "the defaults are all used");
        s.light.light_index = 2;
        s.shadow.map.omni = OmniMap::Paraboloid;
        s.light.spot_range = Some(4.0);
        let unused: Vec<&str> = s.unused(&lights).iter().map(|u| u.setting).collect();
        assert_eq!(unused, ["light.light_index", "light.spot_range", "shadow.map.omni"]);
        s.light.kind = LightKind::Point;
        let lights = s.resolve_lights(&scene).unwrap();
        let unused: Vec<&str> = s.unused(&lights).iter().map(|u| u.setting).collect();
        assert_eq!(unused, ["light.light_index", "light.spot_range"], "a point light uses the paraboloid");
    }

    /// Issue 49: `lamps:64 --light all --shadow-res 8192` drew every lamp's cube at
    /// its own 256² without a word.
    #[test]
    fn a_resolution_every_light_overrides_is_reported() {
        let scene = builtin::build("lamps:4").unwrap();
        let mut s = Settings::default();
        s.light.kind = LightKind::All;
        s.shadow.map.resolution = 8192;
        let lights = s.resolve_lights(&scene).unwrap();
        let unused: Vec<&str> = s.unused(&lights).iter().map(|u| u.setting).collect();
        assert_eq!(unused, ["shadow.map.resolution"]);
        s.light.kind = LightKind::Sun;
        let lights = s.resolve_lights(&scene).unwrap();
        assert!(s.unused(&lights).is_empty(), "the sun alone takes the render's resolution");
    }

    #[test]
    fn penumbra_rays_need_refinement_and_a_light_with_an_area() {
        let scene = builtin::build("contact").unwrap();
        let mut s = Settings::default();
        s.screen.penumbra_rays = 32;
        let unused = |s: &Settings| -> Vec<&str> {
            s.unused(&s.resolve_lights(&scene).unwrap()).iter().map(|u| u.setting).collect()
        };
        assert_eq!(unused(&s), ["screen.penumbra_rays"], "a hard sun");
        s.light.sun_angular_diameter = Some(1.0);
        assert_eq!(unused(&s), ["screen.penumbra_rays"], "auto leaves an area light's penumbrae to the map");
        s.screen.refine = Refine::Rays;
        assert!(unused(&s).is_empty(), "refined penumbrae");
    }

    #[test]
    fn a_tracer_needs_rays() {
        let scene = builtin::build("contact").unwrap();
        let mut s = Settings::default();
        s.screen.tracer = Tracer::Shader;
        let unused = |s: &Settings| -> Vec<&str> {
            s.unused(&s.resolve_lights(&scene).unwrap()).iter().map(|u| u.setting).collect()
        };
        assert!(unused(&s).is_empty(), "the default refines a hard sun on the mask path");
        s.screen.refine = Refine::Off;
        assert_eq!(unused(&s), ["screen.tracer"]);
        s.screen.refine = Refine::Rays;
        s.screen.shadow_path = ShadowPath::Forward;
        assert!(unused(&s).is_empty(), "rays asked for by name trace on the forward path");
    }

    #[test]
    fn every_rule_names_a_real_setting() {
        let defaults = toml::Value::try_from(Settings::default()).unwrap();
        let mut all = Settings::default();
        all.light.sun_elevation = Some(1.0);
        all.light.sun_azimuth = Some(1.0);
        all.light.sun_angular_diameter = Some(1.0);
        all.light.spot_position = Some(Vec3::ONE);
        all.light.spot_target = Some(Vec3::ONE);
        all.light.spot_outer_angle = Some(1.0);
        all.light.spot_inner_angle = Some(1.0);
        all.light.spot_range = Some(1.0);
        all.light.spot_radius = Some(1.0);
        all.light.point_position = Some(Vec3::ONE);
        all.light.point_range = Some(1.0);
        all.light.point_radius = Some(1.0);
        all.shadow.cascades.shadow_distance = Some(1.0);
        let all = toml::Value::try_from(all).unwrap();
        for (path, _, _) in RULES {
            let found = path
                .split('.')
                .try_fold(&all, |t, k| t.get(k))
                .or(path.split('.').try_fold(&defaults, |t, k| t.get(k)));
            assert!(found.is_some(), "`{path}` is not a setting");
        }
    }
}
