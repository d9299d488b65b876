//! The one typed settings structure for a render: image size, camera, light and
//! shadows. The command-line flags (clap) and the file format (serde/TOML) are both
//! derived from these definitions, so their names, defaults and help text agree.
//!
//! Camera and light fields are optional overrides of the scene's own defaults. The
//! shadow settings are orthogonal axes: the filter (technique), the bias, the map,
//! and the partition of the light's view.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::{Camera, Light, Scene, limits, sun_direction};

mod error;
mod filter;
mod light;
pub mod ranges;
mod screen;
mod shadow;
mod unused;
mod virtual_map;
// The tests parse flags: they need the `cli` feature, which `cargo test --workspace`
// turns on (the `gnomon` binary asks for it).
#[cfg(all(test, feature = "cli"))]
mod tests;

#[cfg(feature = "cli")]
pub use error::in_flags;
pub use error::{SettingsError, value_name};
use error::{check, check_limit, check_vec};
pub use filter::*;
pub use light::*;
pub use screen::*;
pub use shadow::*;
pub use unused::UnusedSetting;
pub use virtual_map::*;

/// Everything that configures one render besides the scene itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    /// Changes to the scene itself (a ground plane).
    #[cfg_attr(feature = "cli", command(flatten))]
    pub scene: SceneOptions,
    /// The output image: size and debug view.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub image: ImageSettings,
    /// Overrides of the scene's camera.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub camera: CameraSettings,
    /// Which light is rendered, and overrides of its parameters.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub light: LightSettings,
    /// How shadows are drawn: filter, bias, map, partition, cascades, contact shadows.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub shadow: ShadowSettings,
    /// Where shadows are resolved: in the lighting pass, or in a screen-space mask first.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub screen: ScreenSpaceSettings,
    /// The ray-traced reference the render is compared with.
    #[cfg_attr(feature = "cli", command(flatten))]
    pub reference: ReferenceSettings,
}

/// Changes to the scene itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[serde(default, deny_unknown_fields)]
pub struct SceneOptions {
    /// Add a ground plane under the scene: at its lowest point, three times its
    /// width, for models that come without a floor to receive their shadows (the
    /// built-in scenes have one already).
    #[cfg_attr(feature = "cli", arg(long, help_heading = "Scene"))]
    pub ground: bool,
}

/// The ray-traced reference.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[serde(default, deny_unknown_fields)]
pub struct ReferenceSettings {
    /// Shadow rays per pixel for an area light (a spot with --spot-radius > 0 or a sun
    /// with --sun-angular-diameter > 0), stratified. A point light needs one.
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", default_value_t = ReferenceSettings::default().samples, help_heading = "Reference"))]
    pub samples: u32,
}

impl Default for ReferenceSettings {
    fn default() -> Self {
        Self { samples: 256 }
    }
}

/// A diagnostic view drawn over the lit image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum DebugView {
    /// The lit image alone.
    #[default]
    None,
    /// Tint each pixel by the cascade that shades it: red, green, blue, yellow,
    /// magenta, cyan, orange, violet for cascades 0 to 7.
    Cascades,
    /// Tint magenta each pixel whose shadow rays decided (`screen.refine`): where the
    /// map was unsure, or every pixel with `every-pixel`.
    Traced,
    /// For a virtual map (`shadow.partition = "virtual"`): tint each pixel by the
    /// clipmap level it reads (the cascades' tints in turn), darken its page's
    /// borders, lighten the pages drawn this frame (new or stale; a kept page keeps
    /// its tint) and redden the pixels whose page a coarser one stands in for
    /// (the pool was full). Other maps: tinted by layer, as `cascades`.
    Pages,
}

/// The output image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[serde(default, deny_unknown_fields)]
pub struct ImageSettings {
    /// Image width in pixels, at most as the device allows too (its largest texture,
    /// and its largest buffer for 16 bytes a pixel), checked before rendering.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = ImageSettings::default().width, help_heading = "Image"))]
    pub width: u32,
    /// Image height in pixels, at most as the device allows too (see `--width`).
    #[cfg_attr(feature = "cli", arg(long, default_value_t = ImageSettings::default().height, help_heading = "Image"))]
    pub height: u32,
    /// A diagnostic view over the image.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Image"))]
    pub debug_view: DebugView,
}

impl Default for ImageSettings {
    fn default() -> Self {
        Self { width: 1280, height: 720, debug_view: DebugView::None }
    }
}

/// Overrides of the scene's camera. An absent field keeps the scene's value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[serde(default, deny_unknown_fields)]
pub struct CameraSettings {
    /// Camera position in world units, as X,Y,Z [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long = "camera-eye", value_name = "X,Y,Z", value_parser = parse_vec3, help_heading = "Camera"))]
    pub eye: Option<Vec3>,
    /// Point the camera looks at, as X,Y,Z [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long = "camera-target", value_name = "X,Y,Z", value_parser = parse_vec3, help_heading = "Camera"))]
    pub target: Option<Vec3>,
    /// Full vertical field of view in degrees, in [0.01, 180) [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long = "fov", value_name = "DEGREES", help_heading = "Camera"))]
    pub fov_y_degrees: Option<f32>,
    /// Near clip distance in world units, > 0 [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long = "camera-near", value_name = "DISTANCE", help_heading = "Camera"))]
    pub near: Option<f32>,
    /// Far clip distance in world units, > near [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long = "camera-far", value_name = "DISTANCE", help_heading = "Camera"))]
    pub far: Option<f32>,
}

impl CameraSettings {
    /// Every field set from `camera`: the view stays exactly there, with no plane
    /// refitted to the scene (a camera path's frames, a calibration's views).
    pub fn pinned(camera: &Camera) -> Self {
        Self {
            eye: Some(camera.eye),
            target: Some(camera.target),
            fov_y_degrees: Some(camera.fov_y_degrees),
            near: Some(camera.near),
            far: Some(camera.far),
        }
    }
}

/// The largest image side Gnomon allows, whatever the device (the renderer also
/// holds an image to what the device can hold).
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// The largest shadow map Gnomon allows, whatever the device.
pub const MAX_SHADOW_RESOLUTION: u32 = 8192;

/// The most cascades a light may have: the renderer sizes its uniforms by it.
pub const MAX_CASCADES: u32 = 8;

/// The widest PCF kernel, in texels (a world-unit kernel is clamped to it too).
pub const MAX_KERNEL_TEXELS: f32 = 32.0;
/// The smallest shadow map Gnomon allows.
pub const MIN_SHADOW_RESOLUTION: u32 = 256;

/// `image.width`'s range.
pub const WIDTH_RANGE: ranges::SettingRange =
    ranges::SettingRange::closed("image.width", 1.0, MAX_IMAGE_SIDE as f64, "pixels");
/// `image.height`'s range.
pub const HEIGHT_RANGE: ranges::SettingRange =
    ranges::SettingRange::closed("image.height", 1.0, MAX_IMAGE_SIDE as f64, "pixels");
/// `reference.samples`' range.
pub const REFERENCE_SAMPLES_RANGE: ranges::SettingRange =
    ranges::SettingRange::closed("reference.samples", 8.0, 65536.0, "shadow rays per pixel");

impl Settings {
    /// Checks every value against its documented range. Device-dependent limits (the
    /// largest texture) are checked by the renderer, which knows the device.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let i = &self.image;
        WIDTH_RANGE.check(i.width)?;
        HEIGHT_RANGE.check(i.height)?;
        let c = &self.camera;
        check_vec(c.eye, "camera.eye")?;
        check_vec(c.target, "camera.target")?;
        check_limit(c.fov_y_degrees, "camera.fov_y_degrees", &limits::FIELD_OF_VIEW)?;
        check_limit(c.near, "camera.near", &limits::CLIP_DISTANCE)?;
        check_limit(c.far, "camera.far", &limits::CLIP_DISTANCE)?;
        let l = &self.light;
        check_limit(l.sun_elevation, "light.sun_elevation", &limits::SUN_ELEVATION)?;
        check_limit(l.sun_azimuth, "light.sun_azimuth", &limits::SUN_AZIMUTH)?;
        check_limit(l.sun_angular_diameter, "light.sun_angular_diameter", &limits::SUN_ANGULAR_DIAMETER)?;
        check_vec(l.spot_position, "light.spot_position")?;
        check_vec(l.spot_target, "light.spot_target")?;
        check_limit(l.spot_outer_angle, "light.spot_outer_angle", &limits::SPOT_OUTER_ANGLE)?;
        check_limit(l.spot_inner_angle, "light.spot_inner_angle", &limits::SPOT_INNER_ANGLE)?;
        check_limit(l.spot_range, "light.spot_range", &limits::LIGHT_RANGE)?;
        check_limit(l.spot_radius, "light.spot_radius", &limits::LIGHT_RADIUS)?;
        check_vec(l.point_position, "light.point_position")?;
        check_limit(l.point_range, "light.point_range", &limits::LIGHT_RANGE)?;
        check_limit(l.point_radius, "light.point_radius", &limits::LIGHT_RADIUS)?;
        self.shadow.validate()?;
        PENUMBRA_RAYS_RANGE.check(self.screen.penumbra_rays)?;
        PENUMBRA_FRAMES_RANGE.check(self.screen.penumbra_frames)?;
        REFERENCE_SAMPLES_RANGE.check(self.reference.samples)?;
        Ok(())
    }

    /// The refinement by rays `light` asks for: `screen.refine`, or every pixel where
    /// its technique is a ray at every pixel (`raytraced`, [`RayUse::EveryPixel`]).
    pub fn light_refine(&self, light: &ResolvedLight) -> Refine {
        match light.rays {
            RayUse::AsSettingsSay => self.screen.refine,
            RayUse::EveryPixel => Refine::EveryPixel,
        }
    }

    /// Whether a frame with these lights resolves its shadows in a screen-space mask:
    /// as --shadow-path says, and with `auto` when any light marches contact shadows
    /// or refines its shadow by rays (any light under `auto` refinement or rays asked
    /// for by name, or one traced by its technique), which run best
    /// on the mask path, and when several lights are lit from a light list. Rays
    /// asked for with --shadow-path forward are traced in the lighting pass instead;
    /// contact shadows with it are refused: they march through the mask path's depth
    /// prepass.
    pub fn uses_shadow_mask(&self, lights: &[ResolvedLight]) -> Result<bool, SettingsError> {
        let rays = lights.iter().any(|l| match self.light_refine(l) {
            Refine::Off => false,
            Refine::Auto | Refine::Rays | Refine::EveryPixel => true,
        });
        let contact = lights.iter().find(|l| l.shadow.contact.contact_shadows);
        match (self.screen.shadow_path, contact) {
            (ShadowPath::Forward, Some(light)) => Err(SettingsError {
                setting: "shadow.contact.contact_shadows",
                value: format!("on for light `{}`", light.name),
                valid: "only with --shadow-path auto or mask: contact shadows march through the mask path's depth prepass"
                    .into(),
            }),
            (ShadowPath::Forward, None) => Ok(false),
            (ShadowPath::Mask, _) => Ok(true),
            (ShadowPath::Auto, contact) => {
                let listed = lights.len() > 1 && self.screen.lighting == Lighting::LightList;
                Ok(contact.is_some() || rays || listed)
            }
        }
    }

    /// The camera: the scene's, with these settings' overrides applied.
    pub fn resolve_camera(&self, scene: &Scene) -> Result<Camera, SettingsError> {
        let c = &self.camera;
        let mut cam = scene.camera;
        cam.eye = c.eye.unwrap_or(cam.eye);
        cam.target = c.target.unwrap_or(cam.target);
        cam.fov_y_degrees = c.fov_y_degrees.unwrap_or(cam.fov_y_degrees);
        if c.eye.is_some() || c.target.is_some() {
            // The scene's planes were chosen for its own viewpoint; from a new one,
            // fit them to the scene's bounds: far past the farthest corner, near a
            // small fraction of that (Depth32Float keeps ample precision at 1e4).
            let bounds = scene.bounds();
            let farthest = bounds.corners().iter().map(|p| p.distance(cam.eye)).fold(0.0f32, f32::max);
            cam.far = 1.01 * farthest.max(1e-3);
            cam.near = cam.far * 1e-4;
        }
        cam.near = c.near.unwrap_or(cam.near);
        cam.far = c.far.unwrap_or(cam.far);
        check(
            cam.far > cam.near,
            "camera.far",
            cam.far,
            format!("greater than the near distance {}", cam.near),
        )?;
        check(
            (cam.target - cam.eye).length() > 1e-6,
            "camera.target",
            "the eye position",
            "a point different from the camera position",
        )?;
        Ok(cam)
    }
}

/// `command` with every option that takes a value accepting one that starts with a
/// minus: a negative number (`--sun-azimuth -56`) and a vector (`--camera-target
/// -5,5,0`) need no `=`. Options whose values are names are left alone, so that a
/// forgotten value before the next flag is still reported as one.
#[cfg(feature = "cli")]
pub fn accept_negative_values(command: clap::Command) -> clap::Command {
    command
        .mut_args(|arg| {
            let takes_a_value = arg.get_num_args().is_none_or(|n| n.takes_values()) && !arg.is_positional();
            let is_vector =
                arg.get_value_names().is_some_and(|names| names.iter().any(|n| n.as_str().contains(',')));
            let is_number = arg.get_possible_values().is_empty();
            match (takes_a_value, is_vector, is_number) {
                (true, true, _) => arg.allow_hyphen_values(true),
                (true, false, true) => arg.allow_negative_numbers(true),
                _ => arg,
            }
        })
        .mut_subcommands(accept_negative_values)
}

/// Parses `X,Y,Z` into a vector.
pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("expected three comma-separated numbers X,Y,Z, got `{s}`"));
    }
    let mut v = [0.0f32; 3];
    for (slot, part) in v.iter_mut().zip(&parts) {
        *slot = part.parse().map_err(|_| format!("`{part}` in `{s}` is not a number"))?;
        if !slot.is_finite() {
            return Err(format!("`{part}` in `{s}` is not finite"));
        }
    }
    Ok(Vec3::from_array(v))
}

/// Copies every value of `from` into `into`, recursing into tables.
pub(crate) fn overlay(into: &mut toml::Value, from: &toml::Value) {
    match (into, from) {
        (toml::Value::Table(a), toml::Value::Table(b)) => {
            for (k, v) in b {
                match a.get_mut(k) {
                    Some(slot) => overlay(slot, v),
                    None => {
                        a.insert(k.clone(), v.clone());
                    }
                }
            }
        }
        (slot, v) => *slot = v.clone(),
    }
}
