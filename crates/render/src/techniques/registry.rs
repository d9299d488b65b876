//! The technique registry: the techniques a renderer knows by name, and the checks
//! that tie a technique to the light and the map it shadows. Every check and every
//! message is generated from the facts each technique states
//! ([`ShadowTechnique::cube_wgsl`], [`ShadowTechnique::maps`],
//! [`ShadowTechnique::validate`]), so a new technique is checked like the built-in ones.

use std::hash::{Hash, Hasher};

use gnomon_scene::{
    Light, Scene, Settings,
    settings::{ResolvedLight, SettingsError, ShadowSettings, Technique, WarpKind, value_name},
};

use super::{contract::ShadowTechnique, convolution, esm, msm, pcf, pcss, raytraced, variance};
use crate::{
    light_map::MapLookup,
    passes::wgsl_interfaces::{ENCODE_MOMENTS, SAMPLE_SHADOW, SAMPLE_SHADOW_CUBE, SAMPLE_SHADOW_VIRTUAL},
};

/// Every built-in technique, in the order the command line lists them. Adding one
/// is its module, its WGSL and one line here.
pub static BUILTIN: &[&dyn ShadowTechnique] = &[
    &pcf::HARD,
    &pcf::PCF2X2,
    &pcf::PCF_BOX,
    &pcf::PCF_TENT,
    &pcf::PCF_POISSON,
    &pcss::Pcss,
    &variance::VSM,
    &esm::Esm,
    &variance::EVSM2,
    &variance::EVSM4,
    &msm::HAMBURGER,
    &msm::HAUSDORFF,
    &convolution::Convolution,
    &raytraced::Raytraced,
];

/// A registered technique: a cheap handle that compares and hashes by name (names
/// are unique within a registry), for the pipeline caches' keys.
#[derive(Clone, Copy)]
pub struct TechniqueRef(&'static dyn ShadowTechnique);

impl TechniqueRef {
    /// The technique this handle refers to.
    pub fn get(self) -> &'static dyn ShadowTechnique {
        self.0
    }

    /// A built-in technique, for the keys of pipelines that do not depend on the
    /// technique (reading a screen-space mask): any one would do.
    pub(crate) fn any_builtin() -> Self {
        TechniqueRef(BUILTIN[0])
    }
}

impl std::ops::Deref for TechniqueRef {
    type Target = dyn ShadowTechnique;
    fn deref(&self) -> &Self::Target {
        self.0
    }
}

impl PartialEq for TechniqueRef {
    fn eq(&self, other: &Self) -> bool {
        self.0.technique() == other.0.technique()
    }
}

impl Eq for TechniqueRef {}

impl Hash for TechniqueRef {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.0.technique().hash(state);
    }
}

impl std::fmt::Debug for TechniqueRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0.technique())
    }
}

/// A technique that cannot be registered.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RegistryError {
    /// Another technique is registered under the same name.
    #[error("a technique named `{0}` is registered already")]
    Duplicate(String),
    /// The name is not one the settings could select.
    #[error("cannot register technique: {0}")]
    Name(SettingsError),
    /// Its WGSL does not implement the technique contract exactly once.
    #[error("cannot register technique `{name}`: {problem}")]
    Contract {
        /// The technique's name.
        name: String,
        /// What its WGSL lacks or has twice.
        problem: String,
    },
}

/// The techniques a renderer knows, by name, in the order they are listed.
#[derive(Clone)]
pub struct TechniqueRegistry {
    techniques: Vec<TechniqueRef>,
}

impl Default for TechniqueRegistry {
    fn default() -> Self {
        Self::builtin()
    }
}

/// What keeps `technique`'s WGSL from implementing the technique contract
/// (`passes::wgsl_interfaces::TECHNIQUE_CONTRACT`) exactly once: its lookup, its cube
/// and virtual-map lookups where it has them, and at most one encoding of moments.
/// `None` if nothing.
fn contract_problem(technique: &dyn ShadowTechnique) -> Option<String> {
    let sources = technique.wgsl();
    let lookup = SAMPLE_SHADOW.implementation_in(sources);
    let encoding = ENCODE_MOMENTS.implementation_in(sources);
    let cube = technique.cube_wgsl().map(|cube| SAMPLE_SHADOW_CUBE.implementation_in(cube));
    let virtual_map = technique.virtual_wgsl().map(|v| SAMPLE_SHADOW_VIRTUAL.implementation_in(v));
    let missing = |name: &str| format!("its WGSL defines neither `{name}` nor `<module>_{name}`");
    match (lookup, encoding, cube, virtual_map) {
        (Err(twice), ..) | (_, Err(twice), ..) | (_, _, Some(Err(twice)), _) | (.., Some(Err(twice))) => {
            Some(twice)
        }
        (Ok(None), ..) => Some(missing(SAMPLE_SHADOW.name)),
        (_, _, Some(Ok(None)), _) => Some(missing(SAMPLE_SHADOW_CUBE.name)),
        (.., Some(Ok(None))) => Some(missing(SAMPLE_SHADOW_VIRTUAL.name)),
        (Ok(Some(_)), Ok(_), None | Some(Ok(Some(_))), None | Some(Ok(Some(_)))) => None,
    }
}

impl TechniqueRegistry {
    /// The built-in techniques ([`BUILTIN`]).
    pub fn builtin() -> Self {
        Self { techniques: BUILTIN.iter().map(|t| TechniqueRef(*t)).collect() }
    }

    /// This registry and `technique`, listed last. Its name must be well formed
    /// ([`Technique`]'s rules) and not taken.
    pub fn with(mut self, technique: &'static dyn ShadowTechnique) -> Result<Self, RegistryError> {
        let name = technique.technique();
        Technique::try_from(name.name().to_owned()).map_err(RegistryError::Name)?;
        if self.techniques.iter().any(|t| t.technique() == name) {
            return Err(RegistryError::Duplicate(name.to_string()));
        }
        contract_problem(technique)
            .map_or(Ok(()), |problem| Err(RegistryError::Contract { name: name.to_string(), problem }))?;
        self.techniques.push(TechniqueRef(technique));
        Ok(self)
    }

    /// Every registered technique, in order.
    pub fn iter(&self) -> impl Iterator<Item = TechniqueRef> + '_ {
        self.techniques.iter().copied()
    }

    /// Each technique's name and summary, for a command line's possible values
    /// (`gnomon_scene::settings::offer_techniques`).
    pub fn choices(&self) -> Vec<(String, String)> {
        self.iter().map(|t| (t.technique().to_string(), t.summary().to_owned())).collect()
    }

    /// The technique registered as `technique`.
    pub fn get(&self, technique: &Technique) -> Result<TechniqueRef, SettingsError> {
        self.iter().find(|t| t.technique() == *technique).ok_or_else(|| SettingsError {
            setting: "shadow.filter.technique",
            value: technique.to_string(),
            valid: format!("one of the registered techniques: {}", self.names(|_| true)),
        })
    }

    /// The technique `shadow` selects, checked against the map `shadow` asks for and
    /// the technique's own needs. The light's kind is checked by
    /// [`TechniqueRegistry::check_light`].
    pub fn check(&self, shadow: &ShadowSettings) -> Result<TechniqueRef, SettingsError> {
        let technique = self.get(&shadow.filter.technique)?;
        if shadow.map.warp != WarpKind::None && !technique.maps().warped {
            return Err(SettingsError {
                setting: "shadow.map.warp",
                value: value_name(&shadow.map.warp),
                valid: format!(
                    "with `shadow.filter.technique` {}: a warped map takes {} (its depth is not linear in distance)",
                    technique.technique(),
                    self.names(|t| t.maps().warped)
                ),
            });
        }
        technique.validate(&shadow.filter)?;
        Ok(technique)
    }

    /// [`TechniqueRegistry::check`], and that the technique can shadow `light`
    /// (called `name` in messages): a point light's cube map takes the techniques
    /// with a cube lookup, its paraboloids those that read [`MapSupport::paraboloid`](super::MapSupport::paraboloid).
    pub fn check_light(
        &self,
        shadow: &ShadowSettings,
        light: &Light,
        name: &str,
    ) -> Result<TechniqueRef, SettingsError> {
        let technique = self.check(shadow)?;
        let refuse = |map: &str, fits: &dyn Fn(&TechniqueRef) -> bool| SettingsError {
            setting: "shadow.filter.technique",
            value: technique.technique().to_string(),
            valid: format!("for point light `{name}` {map}: {}", self.names(fits)),
        };
        match MapLookup::of(light, shadow) {
            MapLookup::Cube if technique.cube_wgsl().is_none() => {
                Err(refuse("(a cube map)", &|t| t.cube_wgsl().is_some()))
            }
            MapLookup::Paraboloid if !technique.maps().paraboloid => {
                Err(refuse("with `shadow.map.omni` paraboloid", &|t| t.maps().paraboloid))
            }
            MapLookup::Virtual if technique.virtual_wgsl().is_none() => Err(SettingsError {
                setting: "shadow.filter.technique",
                value: technique.technique().to_string(),
                valid: format!(
                    "for light `{name}` with `shadow.partition` virtual: {}",
                    self.names(|t: &TechniqueRef| t.virtual_wgsl().is_some())
                ),
            }),
            MapLookup::Map | MapLookup::Cube | MapLookup::Paraboloid | MapLookup::Virtual => Ok(technique),
        }
    }

    /// The render's lights ([`Settings::resolve_lights`]), each checked against its
    /// technique ([`TechniqueRegistry::check_light`]) and told how the technique uses
    /// rays ([`ShadowTechnique::rays`]), which decides its refinement
    /// ([`Settings::light_refine`]) and the frame's path.
    pub fn resolve_lights(
        &self,
        settings: &Settings,
        scene: &Scene,
    ) -> Result<Vec<ResolvedLight>, SettingsError> {
        let mut lights = settings.resolve_lights(scene)?;
        for light in &mut lights {
            light.rays = self.check_light(&light.shadow, &light.light, &light.name)?.rays();
        }
        Ok(lights)
    }

    /// The names of the techniques that `fits`, as a list for a message ("pcf,
    /// pcf-tent or pcf-poisson"; "none" when none fits).
    pub fn names(&self, fits: impl Fn(&TechniqueRef) -> bool) -> String {
        let names: Vec<String> = self.iter().filter(|t| fits(t)).map(|t| t.technique().to_string()).collect();
        match names.as_slice() {
            [] => "none".to_owned(),
            [one] => one.clone(),
            [rest @ .., last] => format!("{} or {last}", rest.join(", ")),
        }
    }
}

#[cfg(test)]
mod tests {
    use gnomon_scene::{
        PointLight,
        settings::{FilterSettings, OmniMap},
    };

    use super::*;
    use crate::techniques::MapSupport;

    #[test]
    fn every_builtin_is_registered_once_under_a_well_formed_name() {
        let registry = TechniqueRegistry::builtin();
        for t in registry.iter() {
            let n = registry.iter().filter(|r| r.technique() == t.technique()).count();
            assert_eq!(n, 1, "{t:?} is registered {n} times");
            assert_eq!(t.technique().name().parse::<Technique>(), Ok(t.technique()));
            assert!(!t.summary().is_empty(), "{t:?} has a summary");
        }
        assert_eq!(registry.get(&Technique::default()).map(|t| t.technique()), Ok(Technique::default()));
    }

    #[test]
    fn a_name_is_registered_once() {
        let again = TechniqueRegistry::builtin().with(BUILTIN[0]);
        assert_eq!(again.err(), Some(RegistryError::Duplicate("hard".into())));
    }

    /// A technique whose WGSL implements `sample_shadow` twice, or not at all.
    struct Broken(&'static [&'static str]);
    impl ShadowTechnique for Broken {
        fn technique(&self) -> Technique {
            Technique::named("broken")
        }
        fn summary(&self) -> &'static str {
            "implements the contract wrongly"
        }
        fn maps(&self) -> MapSupport {
            MapSupport::LINEAR_DEPTH
        }
        fn tunables(&self) -> crate::techniques::Tunables {
            crate::techniques::Tunables::NONE
        }
        fn filter_reach_texels(&self, _: &FilterSettings, _: f32) -> f32 {
            0.0
        }
        fn wgsl(&self) -> &'static [&'static str] {
            self.0
        }
    }

    #[test]
    fn a_technique_implements_the_contract_once_or_is_refused() {
        static TWICE: Broken = Broken(&[
            "fn a_sample_shadow(q: ShadowQuery) -> f32 { return 1.0; }",
            "fn b_sample_shadow(q: ShadowQuery) -> f32 { return 0.0; }",
        ]);
        static NONE: Broken = Broken(&["fn sample_shadows(q: ShadowQuery) -> f32 { return 1.0; }"]);
        static OWN: Broken = Broken(&["fn sample_shadow(q: ShadowQuery) -> f32 { return 1.0; }"]);
        let twice = TechniqueRegistry::builtin().with(&TWICE).err().expect("refused").to_string();
        assert!(twice.contains("`a_sample_shadow` and `b_sample_shadow`"), "{twice}");
        let none = TechniqueRegistry::builtin().with(&NONE).err().expect("refused").to_string();
        assert!(none.contains("neither `sample_shadow` nor `<module>_sample_shadow`"), "{none}");
        assert!(
            TechniqueRegistry::builtin().with(&OWN).is_ok(),
            "the contract's own name is an implementation"
        );
    }

    #[test]
    fn an_unknown_name_lists_the_registered_ones() {
        let e = TechniqueRegistry::builtin().get(&Technique::named("nope")).unwrap_err();
        assert_eq!(e.setting, "shadow.filter.technique");
        assert!(e.valid.contains("hard, pcf2x2") && e.valid.ends_with("convolution or raytraced"), "{e}");
    }

    fn point() -> Light {
        Light::Point(PointLight {
            position: glam::Vec3::Y,
            range: 5.0,
            color: glam::Vec3::ONE,
            intensity: 1.0,
            falloff: gnomon_scene::Falloff::Constant,
            radius: 0.0,
        })
    }

    fn shadow(technique: Technique) -> ShadowSettings {
        ShadowSettings {
            filter: FilterSettings { technique, ..FilterSettings::default() },
            ..Default::default()
        }
    }

    #[test]
    fn messages_list_the_techniques_whose_facts_fit() {
        let registry = TechniqueRegistry::builtin();
        let cube = registry.check_light(&shadow(Technique::VSM), &point(), "lamp").unwrap_err();
        assert_eq!(
            cube.valid,
            "for point light `lamp` (a cube map): hard, pcf2x2, pcf, pcf-tent, pcf-poisson, pcss or raytraced"
        );
        let mut paraboloid = shadow(Technique::PCSS);
        paraboloid.map.omni = OmniMap::Paraboloid;
        let e = registry.check_light(&paraboloid, &point(), "lamp").unwrap_err();
        assert!(e.valid.ends_with(": hard, pcf2x2, pcf, pcf-tent, pcf-poisson or raytraced"), "{e}");
        paraboloid.filter.technique = Technique::PCF_POISSON;
        registry.check_light(&paraboloid, &point(), "lamp").unwrap();

        let mut warped = shadow(Technique::VSM);
        warped.map.warp = WarpKind::Lispsm;
        let e = registry.check(&warped).unwrap_err();
        assert_eq!((e.setting, e.value.as_str()), ("shadow.map.warp", "lispsm"));
        assert!(e.valid.contains("takes hard, pcf2x2, pcf, pcf-tent, pcf-poisson or raytraced"), "{e}");
    }

    #[test]
    fn a_technique_checks_its_own_settings() {
        let mut evsm = shadow(Technique::EVSM4);
        evsm.filter.moments.moment_format = gnomon_scene::settings::MomentFormat::Rgba16float;
        evsm.filter.moments.evsm_positive = 20.0;
        let e = TechniqueRegistry::builtin().check(&evsm).unwrap_err();
        assert_eq!(e.setting, "shadow.filter.moments.evsm_positive");
        evsm.filter.technique = Technique::VSM;
        TechniqueRegistry::builtin().check(&evsm).unwrap();
    }

    #[test]
    fn point_lights_take_the_techniques_with_a_cube_lookup() {
        let registry = TechniqueRegistry::builtin();
        for t in registry.iter() {
            let cube = t.cube_wgsl();
            assert_eq!(registry.check_light(&shadow(t.technique()), &point(), "p").is_ok(), cube.is_some());
            if let Some(sources) = cube {
                let found = SAMPLE_SHADOW_CUBE.implementation_in(sources);
                assert!(
                    matches!(found, Ok(Some(ref name)) if name.ends_with("_sample_shadow_cube")),
                    "{t:?}: {found:?}"
                );
            }
        }
    }

    #[test]
    fn virtual_maps_take_the_techniques_with_a_virtual_lookup() {
        let registry = TechniqueRegistry::builtin();
        let mut virtual_sun = shadow(Technique::VSM);
        virtual_sun.partition = gnomon_scene::settings::Partition::Virtual;
        let sun = Light::Directional(gnomon_scene::DirectionalLight {
            direction: glam::Vec3::NEG_Y,
            color: glam::Vec3::ONE,
            intensity: 1.0,
            angular_diameter_degrees: 0.0,
        });
        let e = registry.check_light(&virtual_sun, &sun, "sun").unwrap_err();
        assert_eq!((e.setting, e.value.as_str()), ("shadow.filter.technique", "vsm"));
        assert_eq!(
            e.valid,
            "for light `sun` with `shadow.partition` virtual: pcf2x2, pcf, pcf-tent, pcf-poisson or pcss"
        );
        for t in registry.iter() {
            virtual_sun.filter.technique = t.technique();
            let lookup = t.virtual_wgsl();
            assert_eq!(registry.check_light(&virtual_sun, &sun, "sun").is_ok(), lookup.is_some(), "{t:?}");
            if let Some(sources) = lookup {
                let found = SAMPLE_SHADOW_VIRTUAL.implementation_in(sources);
                assert!(
                    matches!(found, Ok(Some(ref name)) if name.ends_with("_sample_shadow_virtual")),
                    "{t:?}: {found:?}"
                );
            }
        }
        // A spot and a point light take a virtual map as a sun does, whatever the
        // point light's `shadow.map.omni`; a technique without a virtual lookup is
        // refused for them by name.
        virtual_sun.filter.technique = Technique::PCF2X2;
        let spot = Light::Spot(gnomon_scene::SpotLight {
            position: glam::Vec3::Y,
            direction: glam::Vec3::NEG_Y,
            inner_angle_degrees: 20.0,
            outer_angle_degrees: 30.0,
            range: 5.0,
            color: glam::Vec3::ONE,
            intensity: 1.0,
            falloff: gnomon_scene::Falloff::Constant,
            radius: 0.0,
        });
        assert!(registry.check_light(&virtual_sun, &spot, "spot").is_ok());
        assert!(registry.check_light(&virtual_sun, &point(), "lamp").is_ok());
        virtual_sun.map.omni = gnomon_scene::settings::OmniMap::Paraboloid;
        assert!(registry.check_light(&virtual_sun, &point(), "lamp").is_ok());
        virtual_sun.filter.technique = Technique::ESM;
        let e = registry.check_light(&virtual_sun, &point(), "lamp").unwrap_err();
        assert_eq!((e.setting, e.value.as_str()), ("shadow.filter.technique", "esm"));
        assert!(e.valid.starts_with("for light `lamp` with `shadow.partition` virtual"), "{}", e.valid);
    }

    #[test]
    fn every_technique_defines_its_entry_points() {
        let settings = FilterSettings::default();
        for t in TechniqueRegistry::builtin().iter() {
            assert_eq!(contract_problem(t.get()), None, "{t:?}");
            // Built-ins implement the contract under their modules' names.
            let lookup = SAMPLE_SHADOW.implementation_in(t.wgsl());
            assert!(
                matches!(lookup, Ok(Some(ref name)) if name.ends_with("_sample_shadow")),
                "{t:?}: {lookup:?}"
            );
            let filterable = t.filterable_map(&settings).is_some();
            assert_eq!(
                ENCODE_MOMENTS.implementation_in(t.wgsl()).is_ok_and(|found| found.is_some()),
                filterable,
                "{t:?}: a filterable technique encodes its map, and only it"
            );
            if filterable {
                assert_eq!(t.maps(), MapSupport::LINEAR_DEPTH, "{t:?}: a filtered map needs linear depth");
            }
        }
    }
}
