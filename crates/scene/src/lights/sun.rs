//! The sun: a light infinitely far away, whose parallel rays an orthographic (or
//! cascaded, or warped) map draws.

use glam::Vec3;

use super::{Area, Emission, Falloff, Kind, KindType, Light, Origin, ShadowView, Tint};
use crate::limits::{
    COLOR_CHANNEL, INTENSITY, LimitError, SUN_ANGULAR_DIAMETER, check_direction, check_vec3,
};

/// A light infinitely far away: parallel rays travelling along `direction`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// The direction the light travels (from the sun toward the scene), unit length.
    pub direction: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Irradiance scale on a surface facing the light.
    pub intensity: f32,
    /// Angular diameter of the sun's disk in degrees; 0 is a point at infinity (hard
    /// shadows). The reference samples this disk of directions for soft shadows.
    pub angular_diameter_degrees: f32,
}

kind_type!(DirectionalLight, Directional, "sun");

impl Kind for DirectionalLight {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn validate(&self) -> Result<(), LimitError> {
        check_direction("direction", self.direction)?;
        check_vec3(&COLOR_CHANNEL, "color", self.color)?;
        INTENSITY.check("intensity", self.intensity)?;
        SUN_ANGULAR_DIAMETER.check("angular_diameter", self.angular_diameter_degrees)?;
        Ok(())
    }

    fn tint(&self) -> Tint {
        Tint { color: self.color, intensity: self.intensity }
    }

    fn emission(&self) -> Emission {
        Emission {
            radiance: self.color * self.intensity,
            origin: Origin::Infinite { travel: self.direction.normalize() },
            falloff: Falloff::Constant,
            cone: None,
            area: Area::Directions { half_angle: 0.5 * self.angular_diameter_degrees.to_radians() },
        }
    }

    fn shadow_view(&self) -> ShadowView {
        ShadowView::Parallel { travel: self.direction }
    }
}
