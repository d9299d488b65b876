//! The spot light: a cone from a point (or a disk, for soft shadows), drawn with a
//! perspective map.

use glam::Vec3;

use super::{
    Area, Cone, Emission, Falloff, Kind, KindType, Light, LocalNumbers, Origin, ShadowView, Tint, shadow_near,
};
use crate::limits::{
    COORDINATE, LimitError, SPOT_INNER_ANGLE, SPOT_OUTER_ANGLE, check_direction, check_vec3,
};

/// A point light restricted to a cone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLight {
    /// Position of the light (the apex of the cone) in world space.
    pub position: Vec3,
    /// The cone's axis, unit length, pointing away from the light.
    pub direction: Vec3,
    /// Half-angle in degrees inside which the light is at full strength.
    pub inner_angle_degrees: f32,
    /// Half-angle in degrees outside which no light arrives.
    pub outer_angle_degrees: f32,
    /// Distance in world units beyond which no light arrives; also the shadow map's far plane.
    pub range: f32,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Brightness: lit surfaces receive `color · intensity` times the [`Falloff`] at
    /// their distance, and the cone's fade at its edge.
    pub intensity: f32,
    /// How the light weakens with distance inside `range`.
    pub falloff: Falloff,
    /// Radius in world units of the light's emitting disk, facing along `direction`;
    /// 0 is a point light (hard shadows). The reference samples this disk for soft shadows.
    pub radius: f32,
}

impl SpotLight {
    /// The shadow map's near plane: close enough for casters near the light, far
    /// enough to keep depth precision (a fixed fraction of the range).
    pub fn shadow_near(&self) -> f32 {
        shadow_near(self.range)
    }
}

kind_type!(SpotLight, Spot, "spot");

impl Kind for SpotLight {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn validate(&self) -> Result<(), LimitError> {
        check_vec3(&COORDINATE, "position", self.position)?;
        check_direction("direction", self.direction)?;
        let outer = SPOT_OUTER_ANGLE.check("outer_angle", self.outer_angle_degrees)?;
        let inner = SPOT_INNER_ANGLE.check("inner_angle", self.inner_angle_degrees)?;
        if inner > outer {
            return Err(LimitError::new("inner_angle", inner, format!("at most the outer angle {outer}")));
        }
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
            origin: Origin::Local {
                position: self.position,
                range: self.range,
                axis: self.direction.normalize(),
            },
            falloff: self.falloff,
            cone: Some(Cone {
                cos_inner: self.inner_angle_degrees.to_radians().cos(),
                cos_outer: self.outer_angle_degrees.to_radians().cos(),
            }),
            area: Area::Disk { radius: self.radius },
        }
    }

    fn shadow_view(&self) -> ShadowView {
        ShadowView::Frustum {
            position: self.position,
            axis: self.direction,
            half_angle: self.outer_angle_degrees.to_radians(),
            near: self.shadow_near(),
            far: self.range,
        }
    }
}
