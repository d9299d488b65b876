//! Scripted camera motion for temporal measurements: the camera at each frame of a
//! dolly, a truck (sideways translation) or an orbit, with the scene and light still.

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

use crate::Camera;

/// How the camera moves along a path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum CameraPathKind {
    /// Eye and target move together along the view direction, toward the target.
    Dolly,
    /// Eye and target move together sideways, along the camera's right axis.
    Truck,
    /// The eye circles the target about the up axis, still looking at it.
    Orbit,
}

/// The camera `fraction` of the way along a path from `start` (0 is `start` itself).
/// Over the whole path (fraction 1) the eye travels `travel` times its distance to
/// the target: along a line for a dolly or a truck, along the arc for an orbit (an
/// angle of `travel` radians).
pub fn camera_on_path(start: &Camera, kind: CameraPathKind, travel: f32, fraction: f32) -> Camera {
    let offset = start.eye - start.target;
    let distance = offset.length() * travel * fraction;
    let forward = -offset.normalize();
    let moved = |by: Vec3| Camera { eye: start.eye + by, target: start.target + by, ..*start };
    match kind {
        CameraPathKind::Dolly => moved(forward * distance),
        CameraPathKind::Truck => moved(forward.cross(start.up).normalize() * distance),
        CameraPathKind::Orbit => {
            let rotation = Quat::from_axis_angle(start.up.normalize(), travel * fraction);
            Camera { eye: start.target + rotation * offset, ..*start }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn start() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 2.0, 10.0),
            target: Vec3::new(0.0, 2.0, 0.0),
            up: Vec3::Y,
            fov_y_degrees: 50.0,
            near: 0.1,
            far: 100.0,
        }
    }

    #[test]
    fn each_path_moves_as_documented() {
        let c = start();
        assert_eq!(camera_on_path(&c, CameraPathKind::Truck, 0.1, 0.0), c);
        let dolly = camera_on_path(&c, CameraPathKind::Dolly, 0.1, 1.0);
        assert!((dolly.eye - Vec3::new(0.0, 2.0, 9.0)).length() < 1e-5, "{dolly:?}");
        assert!((dolly.target - Vec3::new(0.0, 2.0, -1.0)).length() < 1e-5);
        let truck = camera_on_path(&c, CameraPathKind::Truck, 0.1, 0.5);
        // Looking down −z with y up, right is +x.
        assert!((truck.eye - Vec3::new(0.5, 2.0, 10.0)).length() < 1e-5, "{truck:?}");
        let orbit = camera_on_path(&c, CameraPathKind::Orbit, std::f32::consts::FRAC_PI_2, 1.0);
        assert!((orbit.eye - Vec3::new(10.0, 2.0, 0.0)).length() < 1e-4, "{orbit:?}");
        assert_eq!(orbit.target, c.target);
    }
}
