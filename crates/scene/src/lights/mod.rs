//! Light kinds: the light a render uses ([`Light`], one variant per kind) and the one
//! interface every kind answers ([`Kind`]): its name, its limits, what it emits
//! ([`Emission`], with the area the reference samples) and the view its shadow map
//! takes ([`ShadowView`]). Each kind is a file of its own (`sun.rs`, `spot.rs`,
//! `point.rs`, each also naming itself with `kind_type!`); the renderer, the
//! reference and the front ends ask these facts instead of matching on the kind, so
//! a new kind is its file, a variant and a line of [`Light::kind`] here, and its
//! branch in the shaders' `light_kinds.wgsl`
//! (docs/extending.md, "Walk-through: add a light kind").

/// A kind's struct as its variant of [`Light`]: `From<$kind> for Light` and
/// [`KindType`], written once for every kind (`kind_type!(SpotLight, Spot, "spot")`).
macro_rules! kind_type {
    ($kind:ident, $variant:ident, $name:literal) => {
        impl From<$kind> for Light {
            fn from(light: $kind) -> Light {
                Light::$variant(light)
            }
        }

        impl KindType for $kind {
            const NAME: &'static str = $name;

            fn of(light: &Light) -> Option<&Self> {
                // Any other kind is not this one: a new kind needs no case here.
                if let Light::$variant(this) = light { Some(this) } else { None }
            }

            fn of_mut(light: &mut Light) -> Option<&mut Self> {
                if let Light::$variant(this) = light { Some(this) } else { None }
            }
        }
    };
}

mod point;
mod spot;
mod sun;

use glam::Vec3;

pub use point::PointLight;
pub use spot::SpotLight;
pub use sun::DirectionalLight;

use crate::limits::{COLOR_CHANNEL, INTENSITY, LIGHT_RADIUS, LIGHT_RANGE, LimitError, check_vec3};

/// What every light kind tells the renderer, the reference and the front ends.
pub trait Kind {
    /// The kind's name, as the command line, scene files and messages write it.
    fn name(&self) -> &'static str;
    /// Checks every number of the light against its [`crate::limits::Limit`]; errors
    /// name the quantity as scene files do.
    fn validate(&self) -> Result<(), LimitError>;
    /// How and where it emits.
    fn emission(&self) -> Emission;
    /// Its colour and brightness.
    fn tint(&self) -> Tint;
    /// The view its shadow map takes.
    fn shadow_view(&self) -> ShadowView;
}

/// A kind's own type ([`DirectionalLight`], [`SpotLight`], [`PointLight`]) as one
/// variant of [`Light`]: what lets a scene hand out its light of a kind typed
/// ([`crate::Scene::light`]) without a match on the kind.
pub trait KindType: Copy + Into<Light> {
    /// The kind's name, as [`Kind::name`] and the command line write it.
    const NAME: &'static str;
    /// The light as this kind, or `None` for a light of another kind.
    fn of(light: &Light) -> Option<&Self>;
    /// The light as this kind, to change it, or `None` for a light of another kind.
    fn of_mut(light: &mut Light) -> Option<&mut Self>;
}

/// A light's colour and brightness, as a scene file writes them (and falls back on,
/// for a light that names neither).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tint {
    /// Linear RGB colour.
    pub color: Vec3,
    /// Brightness, in the kind's unit.
    pub intensity: f32,
}

/// How a light emits, in the terms every consumer shares: the GPU's emitter block,
/// the reference's sampler, the light list's tiles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    /// Linear RGB colour × intensity.
    pub radiance: Vec3,
    /// Where its light comes from, and where it can arrive.
    pub origin: Origin,
    /// How its light weakens with distance ([`Falloff::Constant`] for a sun).
    pub falloff: Falloff,
    /// Cosines of the cone's inner (full strength) and outer (no light beyond)
    /// half-angles about the axis; `None` for a light that shines every way.
    pub cone: Option<Cone>,
    /// The area it emits from, which soft shadows sample.
    pub area: Area,
}

/// Where a light's rays come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Origin {
    /// From infinitely far: parallel rays travelling along `travel`, unit length,
    /// reaching everywhere.
    Infinite {
        /// The direction the light travels, toward the scene.
        travel: Vec3,
    },
    /// From `position`, reaching no farther than `range`.
    Local {
        /// The light's centre in world space.
        position: Vec3,
        /// The distance beyond which no light arrives.
        range: f32,
        /// The axis its cone and disk face along (unit); zero for a light with neither.
        axis: Vec3,
    },
}

/// A spot's cone, as cosines of its half-angles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// cos of the half-angle inside which the light is at full strength.
    pub cos_inner: f32,
    /// cos of the half-angle outside which no light arrives.
    pub cos_outer: f32,
}

/// The area a light emits from; of size 0, a point (hard shadows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Area {
    /// A disk of directions about the light's travel: the sun's, of `half_angle` radians.
    Directions {
        /// The angular radius of the disk.
        half_angle: f32,
    },
    /// A disk of `radius` about the light's position, facing along its axis.
    Disk {
        /// Its radius in world units.
        radius: f32,
    },
    /// A sphere of `radius` about the light's position, of uniform radiance.
    Sphere {
        /// Its radius in world units.
        radius: f32,
    },
}

impl Area {
    /// The size shaders and PCSS scale penumbrae by: a disk's or sphere's radius in
    /// world units, the tangent of a disk of directions' angular radius.
    pub fn size(self) -> f32 {
        match self {
            Area::Directions { half_angle } => half_angle.tan(),
            Area::Disk { radius } | Area::Sphere { radius } => radius,
        }
    }
}

/// The view a light's shadow map takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowView {
    /// Parallel rays travelling along `travel`: an orthographic map fitted to the
    /// scene, which cascades, SDSM and warps may split or reshape.
    Parallel {
        /// The light's direction of travel, unit length.
        travel: Vec3,
    },
    /// A perspective frustum from `position` along `axis`.
    Frustum {
        /// The apex.
        position: Vec3,
        /// The view axis, unit length.
        axis: Vec3,
        /// The half-angle the map must cover, in radians.
        half_angle: f32,
        /// Near and far planes.
        near: f32,
        /// The far plane: the light's range.
        far: f32,
    },
    /// Every direction from `position`: a cube map, or two paraboloids.
    Omni {
        /// The centre.
        position: Vec3,
        /// Near plane of each face.
        near: f32,
        /// Far plane of each face: the light's range.
        far: f32,
    },
}

/// The numbers a spot and a point light share, checked in the same order for both.
pub(crate) struct LocalNumbers {
    pub range: f32,
    pub radius: f32,
    pub color: Vec3,
    pub intensity: f32,
    pub falloff: Falloff,
}

impl LocalNumbers {
    /// Each against its [`crate::limits::Limit`].
    pub(crate) fn validate(&self) -> Result<(), LimitError> {
        LIGHT_RANGE.check("range", self.range)?;
        LIGHT_RADIUS.check("radius", self.radius)?;
        check_vec3(&COLOR_CHANNEL, "color", self.color)?;
        INTENSITY.check("intensity", self.intensity)?;
        self.falloff.validate()
    }
}

/// The shadow map's near plane for a light of `range`: close enough for casters
/// near the light, far enough to keep depth precision (a fixed fraction of the range).
pub(crate) fn shadow_near(range: f32) -> f32 {
    (range * 2e-3).max(1e-3)
}

/// How a spot or point light's irradiance changes with distance `d` inside its range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Falloff {
    /// The same irradiance at every distance, cut to nothing at the range: the
    /// teaching light of the shadow tutorials, whose pools of light have hard rims.
    /// `intensity` is then the irradiance itself.
    Constant,
    /// Physical falloff as glTF's `KHR_lights_punctual` specifies it: `intensity` is a
    /// luminous intensity in candela, and a surface facing the light at `d` metres
    /// receives `intensity / d²` lux, times the extension's window
    /// `clamp(1 − (d / window)⁴, 0, 1)` that brings it smoothly to 0 at `window`
    /// (no window when `None`: a file light without a range). One lux shades a white
    /// surface as a sun of intensity 1 does, the mapping the Khronos sample viewer
    /// uses (docs/lights.md).
    InverseSquare {
        /// The distance at which the window reaches 0; `None` for no window.
        window: Option<f32>,
    },
}

impl Falloff {
    /// Distances below this count as this, so that a surface touching a light gets a
    /// large but finite irradiance (1 mm, where glTF's metres are the unit).
    pub const MIN_DISTANCE: f32 = 1e-3;

    /// The factor on `color · intensity` at `distance` from the light.
    pub fn at(self, distance: f32) -> f32 {
        match self {
            Falloff::Constant => 1.0,
            Falloff::InverseSquare { window } => {
                let windowed = window.map_or(1.0, |w| (1.0 - (distance / w).powi(4)).clamp(0.0, 1.0));
                windowed / distance.max(Self::MIN_DISTANCE).powi(2)
            }
        }
    }
}

impl Falloff {
    /// A falloff's window is a distance, as a range is.
    fn validate(self) -> Result<(), LimitError> {
        match self {
            Falloff::Constant | Falloff::InverseSquare { window: None } => Ok(()),
            Falloff::InverseSquare { window: Some(window) } => LIGHT_RANGE.check("range", window).map(|_| ()),
        }
    }
}

/// The light a render uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A sun: parallel rays, drawn with an orthographic (or cascaded, or warped) shadow map.
    Directional(DirectionalLight),
    /// A spot light: a cone from a point, drawn with a perspective shadow map.
    Spot(SpotLight),
    /// A point light: every direction, drawn with a cube (or dual-paraboloid) shadow map.
    Point(PointLight),
}

impl Light {
    /// Every kind's name, in the order of the kinds' ids ([`Light::kind_id`]).
    pub const KIND_NAMES: [&'static str; 3] = ["sun", "spot", "point"];

    /// The light's kind: the one place that matches on it.
    pub fn kind(&self) -> &dyn Kind {
        match self {
            Light::Directional(sun) => sun,
            Light::Spot(spot) => spot,
            Light::Point(point) => point,
        }
    }

    /// The light's kind as a number: its name's index in [`Light::KIND_NAMES`], which
    /// the shaders compare with (`LIGHT_SUN`, … in WGSL).
    pub fn kind_id(&self) -> u32 {
        Light::kind_id_of(self.type_name()).expect("every kind's name is in KIND_NAMES")
    }

    /// A kind's id from its name, or `None` for a name that is no kind's.
    pub fn kind_id_of(name: &str) -> Option<u32> {
        Light::KIND_NAMES.iter().position(|n| *n == name).map(|index| index as u32)
    }

    /// A local light's range, to give one to a light loaded without it; `None` for a
    /// light from infinitely far.
    pub(crate) fn range_mut(&mut self) -> Option<&mut f32> {
        match self {
            Light::Directional(_) => None,
            Light::Spot(spot) => Some(&mut spot.range),
            Light::Point(point) => Some(&mut point.range),
        }
    }

    /// The light's type, as the command line and scene files name it.
    pub fn type_name(&self) -> &'static str {
        self.kind().name()
    }

    /// Checks every number of the light against its [`crate::limits::Limit`]. Errors
    /// name the quantity as scene files do.
    pub fn validate(&self) -> Result<(), LimitError> {
        self.kind().validate()
    }

    /// How and where it emits.
    pub fn emission(&self) -> Emission {
        self.kind().emission()
    }

    /// The view its shadow map takes.
    pub fn shadow_view(&self) -> ShadowView {
        self.kind().shadow_view()
    }

    /// Whether the light is a point source (a sun of no angular diameter, a spot or
    /// point of no radius), whose hard shadow one ray per pixel decides; a light with
    /// an area casts a penumbra, which takes many rays over its area
    /// (`ScreenSpaceSettings::penumbra_rays`).
    pub fn is_hard(&self) -> bool {
        self.emission().area.size() == 0.0
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn one_of_each() -> [Light; 3] {
        let sun = DirectionalLight {
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            angular_diameter_degrees: 0.5,
        };
        let spot = SpotLight {
            position: Vec3::Y,
            direction: Vec3::NEG_Y,
            inner_angle_degrees: 20.0,
            outer_angle_degrees: 30.0,
            range: 10.0,
            color: Vec3::ONE,
            intensity: 1.0,
            falloff: Falloff::Constant,
            radius: 0.0,
        };
        let point = PointLight {
            position: Vec3::Y,
            range: 10.0,
            color: Vec3::ONE,
            intensity: 1.0,
            falloff: Falloff::Constant,
            radius: 0.25,
        };
        [Light::Directional(sun), Light::Spot(spot), Light::Point(point)]
    }

    /// Every kind has its own name and id, in `KIND_NAMES`' order, so the shaders'
    /// constants (generated from the names) tell every kind apart.
    #[test]
    fn every_kind_has_its_own_name_and_id() {
        let lights = one_of_each();
        assert_eq!(lights.len(), Light::KIND_NAMES.len());
        for (i, light) in lights.iter().enumerate() {
            assert_eq!(light.kind_id(), i as u32);
            assert_eq!(light.type_name(), Light::KIND_NAMES[i]);
        }
    }

    /// A kind's facts agree with one another: a local light's map is centred on its
    /// position and reaches its range, a sun's map looks along its travel, and a light
    /// is hard exactly when its area has no size.
    #[test]
    fn a_kinds_emission_and_shadow_view_agree() {
        for light in one_of_each() {
            let emission = light.emission();
            match (emission.origin, light.shadow_view()) {
                (Origin::Infinite { travel }, ShadowView::Parallel { travel: view }) => {
                    assert!((travel - view.normalize()).length() < 1e-6);
                }
                (Origin::Local { position, range, .. }, ShadowView::Frustum { position: p, far, .. })
                | (Origin::Local { position, range, .. }, ShadowView::Omni { position: p, far, .. }) => {
                    assert_eq!((position, range), (p, far), "{}", light.type_name());
                }
                (origin, view) => panic!("{}: {origin:?} drawn as {view:?}", light.type_name()),
            }
            // The reference's sampler pairs a disk of directions with an infinite
            // origin, and a disk or sphere with a local one.
            let infinite = matches!(emission.origin, Origin::Infinite { .. });
            assert_eq!(infinite, matches!(emission.area, Area::Directions { .. }), "{}", light.type_name());
            assert_eq!(light.is_hard(), emission.area.size() == 0.0);
            assert!(light.validate().is_ok(), "{}", light.type_name());
        }
        let [sun, _, point] = one_of_each();
        assert!(!sun.is_hard() && !point.is_hard());
        assert!((sun.emission().area.size() - (0.25f32).to_radians().tan()).abs() < 1e-9);
    }
}
