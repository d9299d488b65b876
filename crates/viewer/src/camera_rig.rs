//! The viewer's cameras: an orbit camera that turns about a target, and a fly camera
//! that turns about its own eye and moves through the scene. Both are one rig (an
//! eye, a target and the direction between them), so switching between them keeps
//! the view.

use glam::Vec3;

/// How mouse drags and keys move the camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraMode {
    /// Drag turns the camera about the target; scroll moves it closer or further.
    Orbit,
    /// Drag turns the camera about its eye; W, A, S, D, Q, E move it.
    Fly,
}

/// Radians turned per pixel dragged.
const TURN_PER_PIXEL: f32 = 0.006;
/// Pitch stays this far from straight up or down, where yaw is undefined.
const PITCH_LIMIT: f32 = 1.54;

/// An eye looking at a target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRig {
    pub mode: CameraMode,
    pub target: Vec3,
    /// Angle about +y of the direction from the target to the eye, from +z toward +x.
    yaw: f32,
    /// Angle of that direction above the horizontal plane.
    pitch: f32,
    distance: f32,
}

impl CameraRig {
    pub fn looking(eye: Vec3, target: Vec3) -> Self {
        let offset = eye - target;
        let distance = offset.length().max(1e-3);
        let d = offset / distance;
        Self {
            mode: CameraMode::Orbit,
            target,
            yaw: d.x.atan2(d.z),
            pitch: d.y.clamp(-1.0, 1.0).asin().clamp(-PITCH_LIMIT, PITCH_LIMIT),
            distance,
        }
    }

    /// Unit direction from the target to the eye.
    fn backward(&self) -> Vec3 {
        Vec3::new(self.yaw.sin() * self.pitch.cos(), self.pitch.sin(), self.yaw.cos() * self.pitch.cos())
    }

    pub fn eye(&self) -> Vec3 {
        self.target + self.backward() * self.distance
    }

    pub fn distance(&self) -> f32 {
        self.distance
    }

    /// The camera's right and up directions in the world.
    pub fn right_up(&self) -> (Vec3, Vec3) {
        let forward = -self.backward();
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        (right, right.cross(forward))
    }

    /// A drag of (dx, dy) pixels: about the target (orbit) or about the eye (fly).
    pub fn turn(&mut self, dx: f32, dy: f32) {
        let eye = self.eye();
        self.yaw -= dx * TURN_PER_PIXEL;
        self.pitch = (self.pitch + dy * TURN_PER_PIXEL).clamp(-PITCH_LIMIT, PITCH_LIMIT);
        if self.mode == CameraMode::Fly {
            // The eye stays; the target swings round it.
            self.target = eye - self.backward() * self.distance;
        }
    }

    /// Slides eye and target together across the view, by (dx, dy) pixels of a view
    /// `view_height` pixels tall with vertical field of view `fov` (radians).
    pub fn pan(&mut self, dx: f32, dy: f32, fov: f32, view_height: f32) {
        let world_per_pixel = 2.0 * self.distance * (0.5 * fov).tan() / view_height.max(1.0);
        let (right, up) = self.right_up();
        self.target += (-dx * right + dy * up) * world_per_pixel;
    }

    /// Scroll: closer for positive `steps`, further for negative, by 10 % a step.
    pub fn zoom(&mut self, steps: f32) {
        self.distance = (self.distance * 0.9f32.powf(steps)).clamp(1e-3, 1e6);
    }

    /// Moves eye and target together by `forward`, `right` and `up` world units.
    pub fn fly(&mut self, forward: f32, right: f32, up: f32) {
        let (r, _) = self.right_up();
        let f = -self.backward();
        self.target += f * forward + r * right + Vec3::Y * up;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-4 * (1.0 + a.length())
    }

    #[test]
    fn the_rig_reproduces_the_view_it_was_made_from() {
        let (eye, target) = (Vec3::new(3.0, 2.0, -4.0), Vec3::new(0.5, 0.0, 1.0));
        let rig = CameraRig::looking(eye, target);
        assert!(close(rig.eye(), eye), "{}", rig.eye());
        assert!(close(rig.target, target));
    }

    #[test]
    fn orbiting_keeps_the_target_and_the_distance() {
        let mut rig = CameraRig::looking(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO);
        let d = rig.eye().length();
        rig.turn(120.0, -40.0);
        assert!(close(rig.target, Vec3::ZERO));
        assert!((rig.eye().length() - d).abs() < 1e-4);
        assert!(!close(rig.eye(), Vec3::new(0.0, 1.0, 5.0)));
    }

    #[test]
    fn flying_turns_about_the_eye_and_moves_along_the_view() {
        let mut rig = CameraRig::looking(Vec3::new(0.0, 1.0, 5.0), Vec3::new(0.0, 1.0, 0.0));
        rig.mode = CameraMode::Fly;
        let eye = rig.eye();
        rig.turn(200.0, 30.0);
        assert!(close(rig.eye(), eye), "{} vs {eye}", rig.eye());
        let mut level = CameraRig::looking(Vec3::new(0.0, 1.0, 5.0), Vec3::new(0.0, 1.0, 0.0));
        level.fly(2.0, 0.0, 0.0);
        assert!(close(level.eye(), Vec3::new(0.0, 1.0, 3.0)), "{}", level.eye());
        level.fly(0.0, 1.0, 0.5);
        assert!(close(level.eye(), Vec3::new(1.0, 1.5, 3.0)), "{}", level.eye());
    }

    #[test]
    fn pitch_stops_short_of_the_poles() {
        let mut rig = CameraRig::looking(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        rig.turn(0.0, 1e5);
        let (right, up) = rig.right_up();
        assert!(right.is_finite() && up.is_finite() && up.y > 0.0);
        assert!(rig.eye().y < 5.0);
    }

    #[test]
    fn panning_moves_a_pixel_by_a_pixel_at_the_target() {
        let mut rig = CameraRig::looking(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO);
        // 90° vertical field of view, 200 pixels tall: the view spans 20 world units at
        // the target, 0.1 per pixel. Dragging right slides the scene right: target left.
        rig.pan(10.0, 0.0, 90f32.to_radians(), 200.0);
        assert!(close(rig.target, Vec3::new(-1.0, 0.0, 0.0)), "{}", rig.target);
    }
}
