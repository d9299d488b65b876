//! The point light: every direction from a point (or a sphere, for soft shadows),
//! drawn with a cube map or two paraboloids.

use glam::Vec3;

use super::{
    Area, Emission, Falloff, Kind, KindType, Light, LocalNumbers, Origin, ShadowView, Tint, shadow_near,
};
use crate::limits::{COORDINATE, LimitError, check_vec3};

/// A light emitting in every direction from a point, or from a sphere for soft shadows.
/// Its shadow map is a cube: six 90° views.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Position of the light (the centre of its sphere) in world space.
    pub position: Vec3,
    /// Distance in world units beyond which no light arrives; also the far plane of the
    /// cube's faces.
    pub range: f32,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Brightness: lit surfaces receive `color · intensity` times the [`Falloff`] at
    /// their distance.
    pub intensity: f32,
    /// How the light weakens with distance inside `range`.
    pub falloff: Falloff,
    /// Radius in world units of the emitting sphere; 0 is a point (hard shadows). The
    /// reference samples the sphere's solid angle for soft shadows.
    pub radius: f32,
}

impl PointLight {
    /// The cube faces' near plane: a fixed fraction of the range, as for a spot.
    pub fn shadow_near(&self) -> f32 {
        shadow_near(self.range)
    }
}

kind_type!(PointLight, Point, "point");

impl Kind for PointLight {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn validate(&self) -> Result<(), LimitError> {
        check_vec3(&COORDINATE, "position", self.position)?;
        LocalNumbers {
            range: self.range,
            radius: self.radius,
            color: self.color,
            intensity: self.intensity,
            falloff: self.falloff,
        }
        .validate()
    }

    fn tint(&self) -> Tint {
        Tint { color: self.color, intensity: self.intensity }
    }

    fn emission(&self) -> Emission {
        Emission {
            radiance: self.color * self.intensity,
            origin: Origin::Local { position: self.position, range: self.range, axis: Vec3::ZERO },
            falloff: self.falloff,
            cone: None,
            area: Area::Sphere { radius: self.radius },
        }
    }

    fn shadow_view(&self) -> ShadowView {
        ShadowView::Omni { position: self.position, near: self.shadow_near(), far: self.range }
    }
}
