//! The valid range of every number that describes a light or a camera, stated once.
//! Flags ([`crate::Settings::validate`]), scene files ([`crate::scene_file`]), glTF
//! lights and cameras and the built-in scenes ([`crate::Scene::validate`]) all check
//! their values against these, so a value refused in one place is refused in all.
//!
//! Every range is finite: an unbounded number is where nonsense hides (a sun disk of
//! 1e30 degrees, a colour of 1e38). The bounds are physical where physics gives one (an
//! elevation above the horizon, a cone narrower than a hemisphere) and otherwise where
//! `f32` stops being meaningful: at [`MAX_COORDINATE`] world units the spacing between
//! neighbouring `f32`s reaches a whole unit.

use glam::Vec3;

use crate::Camera;

/// The largest coordinate or distance, in world units: `f32`'s spacing is 1 there.
pub const MAX_COORDINATE: f32 = 1.0e7;

/// The most bytes a model file may make the loader hold: its buffers, its decoded
/// images and the vertex data it expands, together, each charged before it is
/// allocated (`gltf_loader::sources::Budget`). A file of a few kilobytes can declare
/// gigabytes; with this and the process's own use, loading any file stays under 2 GB.
/// Sponza, the largest scene tested, takes 9 MB of it.
pub const MAX_MODEL_BYTES: u64 = 1 << 30;

/// The largest scene file (TOML): a scene file describes models, lights and views in
/// a few kilobytes; a larger one is not a scene file (and a line of it would be
/// echoed whole into a parse error).
pub const MAX_SCENE_FILE_BYTES: u64 = 1 << 20;

/// A range of valid values for one quantity, and the words that describe it.
#[derive(Clone, Copy, Debug)]
pub struct Limit {
    /// What is valid, in words, for error messages ("in (0, 90] degrees").
    pub valid: &'static str,
    test: fn(f32) -> bool,
}

impl Limit {
    /// Whether `x` is finite and inside the range.
    pub fn allows(&self, x: f32) -> bool {
        x.is_finite() && (self.test)(x)
    }

    /// `x`, or an error naming the quantity, the value and the range.
    pub fn check(&self, quantity: &'static str, x: f32) -> Result<f32, LimitError> {
        if self.allows(x) { Ok(x) } else { Err(LimitError::new(quantity, shown(x), self.valid)) }
    }
}

/// A number as an error shows it. An infinity says why it may be one: a scene file's
/// or a flag's finite number past f32's range (`1e39`) is read as infinite, and the
/// error would otherwise quote a value nobody wrote.
pub fn shown(x: f32) -> String {
    if x.is_infinite() {
        format!("{x} (or a number past ±{:e}, which reads as infinite)", f32::MAX)
    } else {
        x.to_string()
    }
}

/// Elevation of the sun above the horizon, in degrees: a sun at or below the horizon
/// lights no surface a ground plane receives.
pub const SUN_ELEVATION: Limit = Limit { valid: "in (0, 90] degrees", test: |x| x > 0.0 && x <= 90.0 };
/// An angle of rotation, in degrees: one turn either way.
pub const ANGLE: Limit = Limit { valid: "in [-360, 360] degrees", test: |x| x.abs() <= 360.0 };
/// Azimuth of the sun, in degrees from +z toward +x.
pub const SUN_AZIMUTH: Limit = ANGLE;
/// Angular diameter of the sun's disk in degrees (the real sun's is 0.53); a wider
/// disk is no longer a sun, and PCSS's blocker search assumes a small one.
pub const SUN_ANGULAR_DIAMETER: Limit =
    Limit { valid: "in [0, 30] degrees", test: |x| (0.0..=30.0).contains(&x) };
/// A spot's outer half-angle, in degrees: its perspective shadow map covers less than
/// a hemisphere.
pub const SPOT_OUTER_ANGLE: Limit = Limit { valid: "in (0, 89] degrees", test: |x| x > 0.0 && x <= 89.0 };
/// A spot's inner half-angle, in degrees (also at most the outer angle, checked with it).
pub const SPOT_INNER_ANGLE: Limit =
    Limit { valid: "in [0, 89] degrees and at most the outer angle", test: |x| (0.0..=89.0).contains(&x) };
/// A light's range (the far plane of its shadow map), in world units.
pub const LIGHT_RANGE: Limit =
    Limit { valid: "a distance in (0, 1e7] world units", test: |x| x > 0.0 && x <= MAX_COORDINATE };
/// The radius of a light's emitting disk or sphere, in world units; 0 is a point.
pub const LIGHT_RADIUS: Limit =
    Limit { valid: "a distance in [0, 1e7] world units", test: |x| (0.0..=MAX_COORDINATE).contains(&x) };
/// One coordinate of a position, in world units.
pub const COORDINATE: Limit =
    Limit { valid: "three numbers in [-1e7, 1e7] world units", test: |x| x.abs() <= MAX_COORDINATE };
/// One channel of a light's linear RGB colour: no negative light, and no more than
/// 1000 times white, already far past what the tonemapper shows.
pub const COLOR_CHANNEL: Limit =
    Limit { valid: "three linear RGB channels in [0, 1000]", test: |x| (0.0..=1000.0).contains(&x) };
/// A light's intensity: a scale on its colour.
pub const INTENSITY: Limit = Limit { valid: "in [0, 1e6]", test: |x| (0.0..=1.0e6).contains(&x) };
/// A model's uniform scale in a scene file: positive, and no further from 1 than
/// [`MAX_COORDINATE`] allows.
pub const MODEL_SCALE: Limit =
    Limit { valid: "in [1e-7, 1e7]", test: |x| (1.0e-7..=MAX_COORDINATE).contains(&x) };
/// A camera's full vertical field of view, in degrees: at least [`MIN_FIELD_OF_VIEW`].
pub const FIELD_OF_VIEW: Limit =
    Limit { valid: "at least 0.01 degrees and below 180", test: |x| (MIN_FIELD_OF_VIEW..180.0).contains(&x) };

/// The narrowest field of view, in degrees. Below it the math breaks down in `f32`:
/// over 720 rows a pixel of a 0.01° view spans 2.4e-7 radians, two `f32` steps of a
/// unit ray direction, so neighbouring pixels' rays and receivers collapse onto one
/// another; the shadow map cannot tell them apart, nearly every pixel is unsure, and
/// the refinement traced for over 120 s at 1e-5° (0.01° renders in 2.4 s at 1280×720).
pub const MIN_FIELD_OF_VIEW: f32 = 0.01;
/// A camera's near or far clip distance, in world units (the far also beyond the near).
pub const CLIP_DISTANCE: Limit =
    Limit { valid: "a distance in (0, 1e7] world units", test: |x| x > 0.0 && x <= MAX_COORDINATE };

/// A value outside its [`Limit`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("`{quantity}` = {value} is invalid: {valid}")]
pub struct LimitError {
    /// The quantity, as scene files name it (`inner_angle`, `color`).
    pub quantity: &'static str,
    /// The value given, as text.
    pub value: String,
    /// What is valid, in words.
    pub valid: String,
}

impl LimitError {
    pub(crate) fn new(
        quantity: &'static str,
        value: impl std::fmt::Display,
        valid: impl Into<String>,
    ) -> Self {
        Self { quantity, value: value.to_string(), valid: valid.into() }
    }
}

/// `v`, or an error unless every component is within `limit`.
pub fn check_vec3(limit: &Limit, quantity: &'static str, v: Vec3) -> Result<Vec3, LimitError> {
    if v.to_array().iter().all(|&x| limit.allows(x)) {
        Ok(v)
    } else {
        Err(LimitError::new(quantity, format!("[{}, {}, {}]", v.x, v.y, v.z), limit.valid))
    }
}

/// A unit direction: finite and of length 1 (within rounding).
pub(crate) fn check_direction(quantity: &'static str, d: Vec3) -> Result<(), LimitError> {
    if d.is_finite() && (d.length() - 1.0).abs() < 1e-3 {
        Ok(())
    } else {
        Err(LimitError::new(quantity, format!("[{}, {}, {}]", d.x, d.y, d.z), "a unit direction"))
    }
}

impl Camera {
    /// Checks the camera: positions, field of view and clip distances within their
    /// [`Limit`]s, the far plane beyond the near one, and a view direction.
    pub fn validate(&self) -> Result<(), LimitError> {
        check_vec3(&COORDINATE, "eye", self.eye)?;
        check_vec3(&COORDINATE, "target", self.target)?;
        FIELD_OF_VIEW.check("fov", self.fov_y_degrees)?;
        let near = CLIP_DISTANCE.check("near", self.near)?;
        let far = CLIP_DISTANCE.check("far", self.far)?;
        if far <= near {
            return Err(LimitError::new("far", far, format!("greater than the near distance {near}")));
        }
        if (self.target - self.eye).length() <= 1e-6 {
            return Err(LimitError::new("target", "the eye position", "a point different from the eye"));
        }
        // An up parallel to the view is fine: the look-at picks another axis.
        if !self.up.is_finite() || self.up.length() < 1e-6 {
            return Err(LimitError::new("up", self.up, "a finite, non-zero direction"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Falloff, Light, SpotLight};

    #[test]
    fn every_limit_refuses_non_finite_values_and_accepts_its_documented_edges() {
        let all = [
            ANGLE,
            MODEL_SCALE,
            SUN_ELEVATION,
            SUN_AZIMUTH,
            SUN_ANGULAR_DIAMETER,
            SPOT_OUTER_ANGLE,
            SPOT_INNER_ANGLE,
            LIGHT_RANGE,
            LIGHT_RADIUS,
            COORDINATE,
            COLOR_CHANNEL,
            INTENSITY,
            FIELD_OF_VIEW,
            CLIP_DISTANCE,
        ];
        for limit in all {
            for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30] {
                assert!(!limit.allows(x), "{} allows {x}", limit.valid);
            }
        }
        assert!(SUN_ELEVATION.allows(90.0) && !SUN_ELEVATION.allows(0.0) && !SUN_ELEVATION.allows(-30.0));
        assert!(SPOT_INNER_ANGLE.allows(0.0) && !SPOT_INNER_ANGLE.allows(-50.0));
        assert!(LIGHT_RADIUS.allows(0.0) && !LIGHT_RANGE.allows(0.0));
        assert!(!FIELD_OF_VIEW.allows(0.0) && !CLIP_DISTANCE.allows(-1.0));
    }

    /// A finite number past f32's range is read as infinite: the error says so
    /// rather than quote a bare `inf` that nobody wrote.
    #[test]
    fn a_number_past_f32s_range_is_refused_saying_why_it_reads_as_infinite() {
        let written: f32 = "1e39".parse().unwrap();
        let e = INTENSITY.check("intensity", written).unwrap_err();
        assert!(e.value.starts_with("inf (or a number past ±3.4028235e38"), "{e}");
        assert_eq!(INTENSITY.check("intensity", -5.0).unwrap_err().value, "-5");
    }

    #[test]
    fn a_light_with_a_nonsense_colour_or_angle_is_refused_by_name() {
        let spot = SpotLight {
            position: Vec3::ONE,
            direction: Vec3::NEG_Y,
            inner_angle_degrees: 20.0,
            outer_angle_degrees: 30.0,
            range: 10.0,
            color: Vec3::ONE,
            intensity: 1.0,
            falloff: Falloff::InverseSquare { window: Some(10.0) },
            radius: 0.0,
        };
        assert!(Light::Spot(spot).validate().is_ok());
        let bad_window = SpotLight { falloff: Falloff::InverseSquare { window: Some(-1.0) }, ..spot };
        assert_eq!(Light::Spot(bad_window).validate().unwrap_err().quantity, "range");
        let bad_colour = SpotLight { color: Vec3::new(f32::NAN, -1.0, 1e38), ..spot };
        assert_eq!(Light::Spot(bad_colour).validate().unwrap_err().quantity, "color");
        let inner_past_outer = SpotLight { inner_angle_degrees: 40.0, ..spot };
        assert_eq!(Light::Spot(inner_past_outer).validate().unwrap_err().quantity, "inner_angle");
        let camera = Camera {
            eye: Vec3::Z,
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_degrees: 0.0,
            near: 0.1,
            far: 10.0,
        };
        assert_eq!(camera.validate().unwrap_err().quantity, "fov");
        let behind_near = Camera { fov_y_degrees: 45.0, near: -1.0, ..camera };
        assert_eq!(behind_near.validate().unwrap_err().quantity, "near");
    }
}
