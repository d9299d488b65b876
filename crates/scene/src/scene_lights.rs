//! A scene's lights: one list, each light with its kind and its role. The rule that
//! picks a kind's light (`--light sun`, `spot`, `point`) and the lights drawn
//! together (`--light all`) both read this list, and only this module decides them.
//!
//! **The rule.** A light is either *listed* (the scene defines it: a scene file's
//! `[[light]]`, a glTF file's KHR_lights_punctual light, a built-in's lamp) or the
//! scene's *default* of its kind (a built-in's teaching light, one placed over a
//! model that brings none, a scene file's `[sun]`). `--light all` draws the listed
//! lights in order. `--light spot` draws the scene's default spot if it has one,
//! else its first listed spot ([`Scene::light`]); a scene has at most one default
//! per kind ([`Scene::set_default`] replaces it).

use crate::lights::KindType;
use crate::{Light, Scene, SceneError};

/// Whether a light belongs to the scene's list or stands in for its kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightRole {
    /// Defined by the scene and drawn with every other listed light by `--light all`.
    Listed,
    /// The light its kind's `--light` draws; not drawn by `--light all`.
    Default,
}

/// One light of a scene: its name, the light, the shadow settings it changes from the
/// render's (a table in the shape of [`crate::settings::ShadowSettings`], laid over
/// them) and its role.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneLight {
    /// The light's name, for reports and messages (from the scene file, glTF light or built-in).
    pub name: String,
    /// The light itself.
    pub light: Light,
    /// This light's own shadow settings, laid over the render's; `None` to draw it with the
    /// render's settings unchanged.
    pub shadow: Option<crate::settings::ShadowOverrides>,
    /// Listed, or its kind's default.
    pub role: LightRole,
}

impl SceneLight {
    /// A listed light, drawn with the render's shadow settings unless `shadow` changes them.
    pub fn listed(name: impl Into<String>, light: impl Into<Light>) -> SceneLight {
        SceneLight { name: name.into(), light: light.into(), shadow: None, role: LightRole::Listed }
    }

    /// Its kind's default light, named by its kind.
    pub fn default_of_kind(light: impl Into<Light>) -> SceneLight {
        let light = light.into();
        SceneLight { name: light.type_name().into(), light, shadow: None, role: LightRole::Default }
    }
}

impl Scene {
    /// The scene's light of kind `K`, the one `--light <kind>` draws: its default of
    /// that kind, else its first listed light of that kind; `None` when it has neither.
    pub fn light<K: KindType>(&self) -> Option<&K> {
        K::of(self.light_of_kind(K::NAME)?)
    }

    /// [`Scene::light`] by the kind's name (`"spot"`, as [`Light::KIND_NAMES`] writes it).
    pub(crate) fn light_of_kind(&self, kind: &str) -> Option<&Light> {
        let index = self.chosen_index(Light::kind_id_of(kind)?)?;
        Some(&self.lights[index].light)
    }

    /// [`Scene::light`], to change it. Where the scene has no default of the kind this
    /// is its first listed light, which `--light all` then draws changed too.
    pub fn light_mut<K: KindType>(&mut self) -> Option<&mut K> {
        let index = self.chosen_index(Light::kind_id_of(K::NAME)?)?;
        K::of_mut(&mut self.lights[index].light)
    }

    /// Makes `light` its kind's default, in place of the default the scene had.
    pub fn set_default(&mut self, light: impl Into<Light>) {
        let light = light.into();
        let same_kind = |l: &SceneLight| l.role == LightRole::Default && l.light.kind_id() == light.kind_id();
        match self.lights.iter_mut().find(|l| same_kind(l)) {
            Some(default) => default.light = light,
            None => self.lights.push(SceneLight::default_of_kind(light)),
        }
    }

    /// The listed lights, in order: what `--light all` draws and `--light-index` counts.
    pub fn listed_lights(&self) -> impl Iterator<Item = &SceneLight> {
        self.lights.iter().filter(|l| l.role == LightRole::Listed)
    }

    /// [`Scene::listed_lights`], to change them (a light's own shadow settings).
    pub fn listed_lights_mut(&mut self) -> impl Iterator<Item = &mut SceneLight> {
        self.lights.iter_mut().filter(|l| l.role == LightRole::Listed)
    }

    /// Replaces the listed lights with `listed`. Each kind keeps the light it drew: a
    /// kind whose light was listed gets it as its default first.
    pub fn replace_listed_lights(&mut self, listed: impl IntoIterator<Item = SceneLight>) {
        let chosen: Vec<Light> = self
            .lights
            .iter()
            .enumerate()
            .filter(|(index, l)| l.role == LightRole::Listed && self.is_chosen(*index))
            .map(|(_, l)| l.light)
            .collect();
        chosen.into_iter().for_each(|light| self.set_default(light));
        self.lights.retain(|l| l.role == LightRole::Default);
        let defaults = std::mem::take(&mut self.lights);
        self.lights.extend(listed.into_iter().map(|l| SceneLight { role: LightRole::Listed, ..l }));
        self.lights.extend(defaults);
    }

    /// A kind with two defaults is refused ([`Scene::validate`]): which of them
    /// `--light <kind>` drew would depend on their order.
    pub(crate) fn check_one_default_per_kind(&self) -> Result<(), SceneError> {
        let defaults: Vec<&SceneLight> =
            self.lights.iter().filter(|l| l.role == LightRole::Default).collect();
        for (i, first) in defaults.iter().enumerate() {
            let same_kind = |l: &&&SceneLight| l.light.kind_id() == first.light.kind_id();
            if let Some(second) = defaults[i + 1..].iter().find(same_kind) {
                return Err(SceneError::TwoDefaults {
                    scene: self.name.clone(),
                    kind: first.light.type_name(),
                    first: first.name.clone(),
                    second: second.name.clone(),
                });
            }
        }
        Ok(())
    }

    /// Whether the light at `index` is the one its kind's `--light` draws.
    fn is_chosen(&self, index: usize) -> bool {
        let kind = self.lights[index].light.kind_id();
        self.chosen_index(kind) == Some(index)
    }

    /// The rule of this module: the kind's default, else its first listed light.
    fn chosen_index(&self, kind: u32) -> Option<usize> {
        let of_kind =
            |role: LightRole| self.lights.iter().position(|l| l.role == role && l.light.kind_id() == kind);
        of_kind(LightRole::Default).or_else(|| of_kind(LightRole::Listed))
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use crate::{Camera, DirectionalLight, PointLight, Scene, SpotLight, builtin};

    use super::*;

    fn empty() -> Scene {
        let camera = Camera {
            eye: Vec3::new(0.0, 2.0, 5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_degrees: 45.0,
            near: 0.1,
            far: 50.0,
        };
        let sun = DirectionalLight {
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            angular_diameter_degrees: 0.0,
        };
        Scene::new("empty", camera, sun)
    }

    fn spot_at(x: f32) -> SpotLight {
        SpotLight { position: Vec3::new(x, 5.0, 0.0), ..*empty().light::<SpotLight>().unwrap() }
    }

    #[test]
    fn a_kinds_default_wins_over_its_listed_lights_and_the_first_listed_stands_in_without_one() {
        let mut scene = empty();
        let default_spot = *scene.light::<SpotLight>().unwrap();
        scene.replace_listed_lights([
            SceneLight::listed("a", spot_at(1.0)),
            SceneLight::listed("b", spot_at(2.0)),
        ]);
        assert_eq!(*scene.light::<SpotLight>().unwrap(), default_spot, "the default wins");
        scene.lights.retain(|l| l.role == LightRole::Listed);
        assert_eq!(*scene.light::<SpotLight>().unwrap(), spot_at(1.0), "the first listed stands in");
        assert_eq!(scene.light::<PointLight>(), None, "no point light at all");
        let names: Vec<&str> = scene.listed_lights().map(|l| l.name.as_str()).collect();
        assert_eq!(names, ["a", "b"]);
    }

    #[test]
    fn replacing_the_list_keeps_each_kinds_light_and_set_default_replaces_only_its_kind() {
        let mut scene = builtin::build("lamps").unwrap();
        let before: Vec<Light> = [
            (*scene.light::<DirectionalLight>().unwrap()).into(),
            (*scene.light::<SpotLight>().unwrap()).into(),
            (*scene.light::<PointLight>().unwrap()).into(),
        ]
        .into();
        scene.replace_listed_lights([SceneLight::listed("late", spot_at(3.0))]);
        let after: Vec<Light> = [
            (*scene.light::<DirectionalLight>().unwrap()).into(),
            (*scene.light::<SpotLight>().unwrap()).into(),
            (*scene.light::<PointLight>().unwrap()).into(),
        ]
        .into();
        assert_eq!(after, before, "each kind draws what it drew before the list changed");
        assert_eq!(scene.listed_lights().count(), 1);
        scene.set_default(spot_at(4.0));
        scene.set_default(spot_at(5.0));
        let defaults = scene.lights.iter().filter(|l| l.role == LightRole::Default);
        assert_eq!(defaults.count(), 3, "one default per kind");
        assert_eq!(*scene.light::<SpotLight>().unwrap(), spot_at(5.0));
    }

    #[test]
    fn a_second_default_of_one_kind_is_refused_by_validate() {
        let mut scene = empty();
        scene.validate().unwrap();
        scene.lights.push(SceneLight::default_of_kind(spot_at(6.0)));
        let e = scene.validate().unwrap_err().to_string();
        assert!(e.contains("two default spot lights"), "{e}");
    }
}
