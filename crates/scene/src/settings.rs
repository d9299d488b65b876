//! The one typed settings structure for a render: image size, camera, light and
//! shadows. The command-line flags (clap) and the file format (serde/TOML) are both
//! derived from these definitions, so their names, defaults and help text agree.
//!
//! Camera and light fields are optional overrides of the scene's own defaults. The
//! shadow settings are orthogonal axes: the filter (technique), the bias, the map,
//! and the partition of the light's view.

use clap::{Args, ValueEnum};
use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::{Camera, Light, Scene, sun_direction};

/// Everything that configures one render besides the scene itself.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    #[command(flatten)]
    pub scene: SceneOptions,
    #[command(flatten)]
    pub image: ImageSettings,
    #[command(flatten)]
    pub camera: CameraSettings,
    #[command(flatten)]
    pub light: LightSettings,
    #[command(flatten)]
    pub shadow: ShadowSettings,
    #[command(flatten)]
    pub screen: ScreenSpaceSettings,
    #[command(flatten)]
    pub reference: ReferenceSettings,
}

/// Where each pixel's shadow is resolved.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ShadowPath {
    /// The mask when any light has contact shadows (which march through its depth),
    /// forward otherwise.
    #[default]
    Auto,
    /// In the lighting pass, once per fragment drawn.
    Forward,
    /// Screen-space shadows, as in Unity URP: a depth-and-normal prepass, then one
    /// full-screen pass per light that reconstructs each pixel's position from depth,
    /// looks its shadow up once and stores it in a mask the lighting pass reads.
    Mask,
}

/// How shadows are resolved on screen: the frame-wide choice of path (contact
/// shadows, per light, are in the shadow settings).
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct ScreenSpaceSettings {
    /// Where each pixel's shadow lookup runs: forward, in the lighting pass, or once
    /// per pixel into a screen-space shadow mask.
    #[arg(long, value_enum, default_value_t, help_heading = "Screen-space shadows")]
    pub shadow_path: ShadowPath,
}

/// Contact shadows: a short ray marched in screen space from each pixel toward the
/// light through the depth prepass, to restore the shadows that a shadow map's bias
/// and resolution lose where objects meet (after Sousa, Kasyan & Schulz, "Secrets of
/// CryENGINE 3 graphics technology", 2011, and Unreal's screen-space shadows). The
/// result multiplies in as min(map, contact).
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ContactSettings {
    /// March contact shadows for this light (needs --shadow-path auto or mask).
    #[arg(long, help_heading = "Contact shadows")]
    pub contact_shadows: bool,
    /// Length of the ray toward the light, in world units (> 0, at most 10).
    #[arg(long, value_name = "DISTANCE", default_value_t = ContactSettings::default().contact_length, help_heading = "Contact shadows")]
    pub contact_length: f32,
    /// Depth-buffer samples along the ray, 1 to 64; the start is jittered per pixel by
    /// interleaved gradient noise.
    #[arg(long, value_name = "N", default_value_t = ContactSettings::default().contact_steps, help_heading = "Contact shadows")]
    pub contact_steps: u32,
    /// Assumed thickness of what the depth buffer holds, as a fraction of its view
    /// depth: a sample behind the depth buffer by less than this occludes the ray,
    /// one farther behind passes behind the surface. 0 to 1.
    #[arg(long, value_name = "FRACTION", default_value_t = ContactSettings::default().contact_thickness, help_heading = "Contact shadows")]
    pub contact_thickness: f32,
    /// The ray starts this far along the surface's normal, in world units, so that its
    /// first samples clear the receiver's own depth. ≥ 0.
    #[arg(long, value_name = "DISTANCE", default_value_t = ContactSettings::default().contact_bias, help_heading = "Contact shadows")]
    pub contact_bias: f32,
    /// View depth beyond which contact shadows are off; they fade out over its last
    /// quarter. > 0.
    #[arg(long, value_name = "DISTANCE", default_value_t = ContactSettings::default().contact_distance, help_heading = "Contact shadows")]
    pub contact_distance: f32,
}

impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            contact_shadows: false,
            contact_length: 0.3,
            contact_steps: 16,
            contact_thickness: 0.02,
            contact_bias: 0.02,
            contact_distance: 50.0,
        }
    }
}

impl ContactSettings {
    fn validate(&self) -> Result<(), SettingsError> {
        let finite = |x: f32| x.is_finite();
        check(
            finite(self.contact_length) && self.contact_length > 0.0 && self.contact_length <= 10.0,
            "--contact-length",
            self.contact_length,
            "a distance in (0, 10]",
        )?;
        check((1..=64).contains(&self.contact_steps), "--contact-steps", self.contact_steps, "1 to 64")?;
        check(
            finite(self.contact_thickness) && self.contact_thickness > 0.0 && self.contact_thickness <= 1.0,
            "--contact-thickness",
            self.contact_thickness,
            "a fraction of the view depth in (0, 1]",
        )?;
        check(
            finite(self.contact_bias) && self.contact_bias >= 0.0,
            "--contact-bias",
            self.contact_bias,
            "a distance ≥ 0",
        )?;
        check(
            finite(self.contact_distance) && self.contact_distance > 0.0,
            "--contact-distance",
            self.contact_distance,
            "a distance > 0",
        )?;
        Ok(())
    }
}

/// Changes to the scene itself.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct SceneOptions {
    /// Add a ground plane under the scene: at its lowest point, three times its
    /// width, for models that come without a floor to receive their shadows (the
    /// built-in scenes have one already).
    #[arg(long, help_heading = "Scene")]
    pub ground: bool,
}

/// The ray-traced reference.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReferenceSettings {
    /// Shadow rays per pixel for an area light (a spot with --spot-radius > 0 or a sun
    /// with --sun-angular-diameter > 0): 8 to 65536, stratified. A point light needs one.
    #[arg(long, value_name = "N", default_value_t = ReferenceSettings::default().samples, help_heading = "Reference")]
    pub samples: u32,
}

impl Default for ReferenceSettings {
    fn default() -> Self {
        Self { samples: 256 }
    }
}

/// A diagnostic view drawn over the lit image.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum DebugView {
    /// The lit image alone.
    #[default]
    None,
    /// Tint each pixel by the cascade that shades it: red, green, blue, yellow,
    /// magenta, cyan, orange, violet for cascades 0 to 7.
    Cascades,
}

/// The output image.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ImageSettings {
    /// Image width in pixels (1 to 16384).
    #[arg(long, default_value_t = ImageSettings::default().width, help_heading = "Image")]
    pub width: u32,
    /// Image height in pixels (1 to 16384).
    #[arg(long, default_value_t = ImageSettings::default().height, help_heading = "Image")]
    pub height: u32,
    /// A diagnostic view over the image.
    #[arg(long, value_enum, default_value_t, help_heading = "Image")]
    pub debug_view: DebugView,
}

impl Default for ImageSettings {
    fn default() -> Self {
        Self { width: 1280, height: 720, debug_view: DebugView::None }
    }
}

/// Overrides of the scene's camera. An absent field keeps the scene's value.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct CameraSettings {
    /// Camera position in world units, as X,Y,Z [default: the scene's].
    #[arg(long = "camera-eye", value_name = "X,Y,Z", value_parser = parse_vec3, help_heading = "Camera")]
    pub eye: Option<Vec3>,
    /// Point the camera looks at, as X,Y,Z [default: the scene's].
    #[arg(long = "camera-target", value_name = "X,Y,Z", value_parser = parse_vec3, help_heading = "Camera")]
    pub target: Option<Vec3>,
    /// Full vertical field of view in degrees, in (0, 180) [default: the scene's].
    #[arg(long = "fov", value_name = "DEGREES", help_heading = "Camera")]
    pub fov_y_degrees: Option<f32>,
    /// Near clip distance in world units, > 0 [default: the scene's].
    #[arg(long = "camera-near", value_name = "DISTANCE", help_heading = "Camera")]
    pub near: Option<f32>,
    /// Far clip distance in world units, > near [default: the scene's].
    #[arg(long = "camera-far", value_name = "DISTANCE", help_heading = "Camera")]
    pub far: Option<f32>,
}

/// Which of the scene's lights is rendered.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum LightKind {
    /// The scene's directional light (sun), with an orthographic shadow map fitted to the scene.
    #[default]
    Sun,
    /// The scene's spot light, with a perspective shadow map covering its cone.
    Spot,
    /// The scene's point light, with a cube shadow map (six 90° faces).
    Point,
    /// Every light of the scene's light list at once (scene files' [[light]],
    /// glTF KHR_lights_punctual, the built-in `lamps`), each with its own shadow map
    /// and shadow settings.
    All,
}

/// The light, and overrides of the scene's light parameters.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct LightSettings {
    /// Which light casts the shadows.
    #[arg(long = "light", value_enum, default_value_t, help_heading = "Light")]
    pub kind: LightKind,
    /// Sun elevation above the horizon in degrees, in (0, 90] [default: the scene's].
    #[arg(long, value_name = "DEGREES", help_heading = "Light")]
    pub sun_elevation: Option<f32>,
    /// Sun azimuth in degrees, measured from +z toward +x [default: the scene's].
    #[arg(long, value_name = "DEGREES", help_heading = "Light")]
    pub sun_azimuth: Option<f32>,
    /// Spot light position, as X,Y,Z [default: the scene's].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, help_heading = "Light")]
    pub spot_position: Option<Vec3>,
    /// Point the spot light aims at, as X,Y,Z [default: the scene's].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, help_heading = "Light")]
    pub spot_target: Option<Vec3>,
    /// Spot cone outer half-angle in degrees, in (0, 89]: no light outside it [default: the scene's].
    #[arg(long, value_name = "DEGREES", help_heading = "Light")]
    pub spot_outer_angle: Option<f32>,
    /// Spot cone inner half-angle in degrees, in [0, outer]: full light inside it [default: 80% of outer].
    #[arg(long, value_name = "DEGREES", help_heading = "Light")]
    pub spot_inner_angle: Option<f32>,
    /// Spot light range in world units, > 0; also the shadow map's far plane [default: the scene's].
    #[arg(long, value_name = "DISTANCE", help_heading = "Light")]
    pub spot_range: Option<f32>,
    /// Radius of the spot light's emitting disk in world units, ≥ 0; 0 is a point
    /// light with hard shadows [default: the scene's, 0 for the built-ins].
    #[arg(long, value_name = "DISTANCE", help_heading = "Light")]
    pub spot_radius: Option<f32>,
    /// Angular diameter of the sun's disk in degrees, in [0, 30]; 0 gives hard
    /// shadows, the real sun is about 0.53 [default: the scene's, 0 for the built-ins].
    #[arg(long, value_name = "DEGREES", help_heading = "Light")]
    pub sun_angular_diameter: Option<f32>,
    /// Point light position, as X,Y,Z [default: the scene's].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, help_heading = "Light")]
    pub point_position: Option<Vec3>,
    /// Point light range in world units, > 0; also the cube faces' far plane [default: the scene's].
    #[arg(long, value_name = "DISTANCE", help_heading = "Light")]
    pub point_range: Option<f32>,
    /// Radius of the point light's emitting sphere in world units, ≥ 0; 0 gives hard
    /// shadows [default: the scene's, 0 for the built-ins].
    #[arg(long, value_name = "DISTANCE", help_heading = "Light")]
    pub point_radius: Option<f32>,
    /// With --light all: the light whose visibility the frame outputs and the
    /// reference traces, as an index into the scene's light list.
    #[arg(long, value_name = "N", default_value_t = 0, help_heading = "Light")]
    pub light_index: usize,
}

/// One light of a render, with the shadow settings it is drawn with.
#[derive(Clone, Debug, PartialEq)]
pub struct ResolvedLight {
    /// The light's name in the scene's list, or its type for a single light.
    pub name: String,
    pub light: Light,
    /// The render's shadow settings with the light's own laid over them.
    pub shadow: ShadowSettings,
}

/// How the shadow map is sampled and filtered.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Technique {
    /// One point-sampled depth comparison: Williams (1978), the textbook algorithm.
    Hard,
    /// The hardware comparison sampler with linear filtering: 2×2 bilinear PCF.
    #[default]
    #[value(name = "pcf2x2")]
    #[serde(rename = "pcf2x2")]
    Pcf2x2,
    /// Box PCF of width --pcf-kernel, from bilinear comparison taps with exact area
    /// weights (Castaño 2013): a W×W box in ⌈(W+1)/2⌉² taps.
    Pcf,
    /// Tent PCF of width --pcf-kernel from bilinear comparison taps (Castaño 2013):
    /// smoother edges than the box at the same cost.
    PcfTent,
    /// PCF over a Poisson disk of diameter --pcf-kernel, rotated per pixel by
    /// interleaved gradient noise (Jimenez 2014): noise instead of banding.
    PcfPoisson,
    /// Percentage-closer soft shadows (Fernando 2005): a blocker search, then PCF
    /// whose width follows the light's size and the blocker distance.
    Pcss,
    /// Variance shadow maps (Donnelly & Lauritzen 2006): blurred (d, d²) and
    /// Chebyshev's bound.
    Vsm,
    /// Exponential shadow maps (Annen et al. 2008): exp(c·d), filtered in log space.
    Esm,
    /// Exponential variance shadow maps, positive exponent only (Lauritzen 2008).
    Evsm2,
    /// Exponential variance shadow maps with positive and negative exponents.
    Evsm4,
    /// Moment shadow maps (Peters & Klein 2015), four moments, Hamburger bound.
    MsmHamburger,
    /// Moment shadow maps, four moments, Hausdorff bound (depths in [0, 1]).
    MsmHausdorff,
    /// Convolution shadow maps (Annen et al. 2007): a Fourier series of the depth test.
    Convolution,
}

impl Technique {
    /// The name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Technique::Hard => "hard",
            Technique::Pcf2x2 => "pcf2x2",
            Technique::Pcf => "pcf",
            Technique::PcfTent => "pcf-tent",
            Technique::PcfPoisson => "pcf-poisson",
            Technique::Pcss => "pcss",
            Technique::Vsm => "vsm",
            Technique::Esm => "esm",
            Technique::Evsm2 => "evsm2",
            Technique::Evsm4 => "evsm4",
            Technique::MsmHamburger => "msm-hamburger",
            Technique::MsmHausdorff => "msm-hausdorff",
            Technique::Convolution => "convolution",
        }
    }

    pub fn all() -> &'static [Technique] {
        Technique::value_variants()
    }

    /// Whether the technique can shadow a point light, from its cube map: the
    /// depth-comparison techniques, which sample the cube by direction.
    pub fn supports_point_lights(self) -> bool {
        matches!(
            self,
            Technique::Hard
                | Technique::Pcf2x2
                | Technique::Pcf
                | Technique::PcfTent
                | Technique::PcfPoisson
                | Technique::Pcss
        )
    }

    /// Whether the technique filters a map of moments (or other functions of depth)
    /// instead of comparing depths.
    pub fn is_filterable(self) -> bool {
        matches!(
            self,
            Technique::Vsm
                | Technique::Esm
                | Technique::Evsm2
                | Technique::Evsm4
                | Technique::MsmHamburger
                | Technique::MsmHausdorff
                | Technique::Convolution
        )
    }
}

/// The unit of a PCF kernel's width.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum KernelUnit {
    /// Shadow-map texels: the same blur everywhere in the map.
    #[default]
    Texels,
    /// World units at the receiver: the same softness in the world whatever the
    /// map's resolution or, for a spot light, the distance (capped at 32 texels).
    World,
}

/// The filter axis: which technique, and its parameters.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FilterSettings {
    /// Shadow filtering technique.
    #[arg(long, value_enum, default_value_t, help_heading = "Shadow filter")]
    pub technique: Technique,
    /// Kernel width of `pcf`, `pcf-tent` and `pcf-poisson`, in --kernel-unit units:
    /// 1 to 32 texels, or a world width > 0.
    #[arg(long, value_name = "WIDTH", default_value_t = FilterSettings::default().pcf_kernel, help_heading = "Shadow filter")]
    pub pcf_kernel: f32,
    /// Unit of --pcf-kernel.
    #[arg(long, value_enum, default_value_t, help_heading = "Shadow filter")]
    pub kernel_unit: KernelUnit,
    /// Taps of `pcf-poisson` and of PCSS's filtering step: 8 to 64.
    #[arg(long, value_name = "N", default_value_t = FilterSettings::default().poisson_samples, help_heading = "Shadow filter")]
    pub poisson_samples: u32,
    /// Receiver-plane depth bias for the PCF family and PCSS: tilt the compared depth
    /// across the kernel along the receiver's plane, from the screen-space derivatives
    /// of its shadow coordinates, so wide kernels don't shadow their own receiver.
    #[arg(long, value_name = "BOOL", default_value_t = FilterSettings::default().receiver_plane_bias, action = clap::ArgAction::Set, help_heading = "Shadow filter")]
    pub receiver_plane_bias: bool,
    #[command(flatten)]
    pub pcss: PcssSettings,
    #[command(flatten)]
    pub moments: MomentSettings,
}

impl Default for FilterSettings {
    fn default() -> Self {
        Self {
            technique: Technique::default(),
            pcf_kernel: 3.0,
            kernel_unit: KernelUnit::default(),
            poisson_samples: 32,
            receiver_plane_bias: true,
            pcss: PcssSettings::default(),
            moments: MomentSettings::default(),
        }
    }
}

/// PCSS: the light's size comes from the light (--spot-radius or
/// --sun-angular-diameter), the same parameter the reference's area light uses.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PcssSettings {
    /// Depth taps of PCSS's blocker search: 8 to 64.
    #[arg(long, value_name = "N", default_value_t = PcssSettings::default().blocker_samples, help_heading = "PCSS")]
    pub blocker_samples: u32,
    /// Largest blocker-search and penumbra radius, in texels: 1 to 64. Wider
    /// penumbrae are clipped to it.
    #[arg(long, value_name = "TEXELS", default_value_t = PcssSettings::default().max_radius, help_heading = "PCSS")]
    pub max_radius: f32,
}

impl Default for PcssSettings {
    fn default() -> Self {
        Self { blocker_samples: 32, max_radius: 32.0 }
    }
}

/// Storage format of a filterable moment map.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum MomentFormat {
    /// 32-bit float where the adapter can filter it, else 16-bit (the GL backend).
    #[default]
    Auto,
    /// 32-bit float per channel (needs FLOAT32_FILTERABLE).
    Rgba32float,
    /// 16-bit float per channel: half the memory and bandwidth. MSM then stores its
    /// moments in Peters & Klein's optimised basis (use --moment-bias 6e-5), and EVSM
    /// exponents must be at most 5.54.
    Rgba16float,
}

/// Parameters of the filterable techniques: VSM, ESM, EVSM, MSM and convolution.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MomentSettings {
    /// Radius of the separable Gaussian blur of the moment map, in texels (σ = radius / 2):
    /// 0 (no blur) to 16.
    #[arg(long, value_name = "TEXELS", default_value_t = MomentSettings::default().blur_radius, help_heading = "Filterable maps")]
    pub blur_radius: u32,
    /// Build mipmaps of the moment map and sample them trilinearly (VSM, EVSM, MSM,
    /// convolution), against aliasing when the map is minified on screen.
    #[arg(long, help_heading = "Filterable maps")]
    pub mipmaps: bool,
    /// Texel format of the moment map.
    #[arg(long, value_enum, default_value_t, help_heading = "Filterable maps")]
    pub moment_format: MomentFormat,
    /// Smallest variance Chebyshev's bound may use (VSM, EVSM), in units of the
    /// normalised light depth squared: ≥ 0. Hides acne from quantisation.
    #[arg(long, value_name = "VARIANCE", default_value_t = MomentSettings::default().min_variance, help_heading = "Filterable maps")]
    pub min_variance: f32,
    /// Light-bleeding reduction (VSM, EVSM, MSM): the bound below this is cut to 0
    /// and the rest rescaled to [0, 1] (Lauritzen's linstep). In [0, 1).
    #[arg(long, value_name = "AMOUNT", default_value_t = MomentSettings::default().bleeding_reduction, help_heading = "Filterable maps")]
    pub bleeding_reduction: f32,
    /// ESM exponent c: visibility = exp(c·(d_occluder − d_receiver)). 1 to 88 (the map
    /// stores d and filters in log space, so c is not limited by the format).
    #[arg(long, value_name = "C", default_value_t = MomentSettings::default().esm_exponent, help_heading = "Filterable maps")]
    pub esm_exponent: f32,
    /// EVSM positive exponent: 0 to 42 (5.54 for 16-bit).
    #[arg(long, value_name = "C", default_value_t = MomentSettings::default().evsm_positive, help_heading = "Filterable maps")]
    pub evsm_positive: f32,
    /// EVSM negative exponent (evsm4): 0 to 42 (5.54 for 16-bit).
    #[arg(long, value_name = "C", default_value_t = MomentSettings::default().evsm_negative, help_heading = "Filterable maps")]
    pub evsm_negative: f32,
    /// MSM moment bias α: the moments are blended toward those of a two-point
    /// distribution by this fraction (Peters & Klein use 3e-5 at 32 bits, 6e-5 at 16).
    /// In [0, 0.1].
    #[arg(long, value_name = "ALPHA", default_value_t = MomentSettings::default().moment_bias, help_heading = "Filterable maps")]
    pub moment_bias: f32,
    /// Fourier terms M of convolution shadow maps: 1 to 16 (2M channels).
    #[arg(long, value_name = "M", default_value_t = MomentSettings::default().csm_terms, help_heading = "Filterable maps")]
    pub csm_terms: u32,
    /// Ringing attenuation α of convolution shadow maps: term k is weighted by
    /// exp(−α (k/M)²); 0 is the raw truncated series. ≥ 0.
    #[arg(long, value_name = "ALPHA", default_value_t = MomentSettings::default().csm_attenuation, help_heading = "Filterable maps")]
    pub csm_attenuation: f32,
    /// Scale s of the convolution reconstruction: visibility = s·(f − ½ + o) + ½. > 0.
    #[arg(long, value_name = "S", default_value_t = MomentSettings::default().csm_scale, help_heading = "Filterable maps")]
    pub csm_scale: f32,
    /// Offset o of the convolution reconstruction (see --csm-scale): in [−0.5, 0.5].
    #[arg(long, value_name = "O", default_value_t = MomentSettings::default().csm_offset, help_heading = "Filterable maps")]
    pub csm_offset: f32,
}

impl Default for MomentSettings {
    fn default() -> Self {
        Self {
            blur_radius: 2,
            mipmaps: false,
            moment_format: MomentFormat::default(),
            min_variance: 1e-6,
            bleeding_reduction: 0.2,
            esm_exponent: 80.0,
            evsm_positive: 40.0,
            evsm_negative: 5.0,
            moment_bias: 3e-5,
            csm_terms: 8,
            csm_attenuation: 2.0,
            csm_scale: 2.0,
            csm_offset: 0.25,
        }
    }
}

/// Which faces the shadow pass culls.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum CullMode {
    /// Cull faces turned away from the light: the usual choice.
    #[default]
    Back,
    /// Cull faces turned toward the light, so closed meshes store their back faces:
    /// the classic anti-acne trick, which can leak where meshes are open or thin.
    Front,
    /// Draw both sides.
    None,
}

/// The bias axis: offsets that keep a surface from shadowing itself (acne) without
/// detaching shadows from their casters (peter-panning).
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BiasSettings {
    /// Rasterizer constant depth bias, in the depth format's units (D3D `DepthBias`).
    /// For Depth32Float one unit is 2^(e−23) for a primitive whose largest depth has
    /// exponent e: about 6e-8 at depth 0.5.
    #[arg(long, value_name = "UNITS", default_value_t = BiasSettings::default().depth_bias, help_heading = "Shadow bias")]
    pub depth_bias: i32,
    /// Rasterizer slope-scaled depth bias (D3D `SlopeScaledDepthBias`): multiplies the
    /// caster's depth slope per shadow texel, so 1 pushes a surface back by the depth
    /// it spans across one texel. Must be finite and ≥ 0.
    #[arg(long, value_name = "FACTOR", default_value_t = BiasSettings::default().slope_bias, help_heading = "Shadow bias")]
    pub slope_bias: f32,
    /// Normal-offset bias: the receiver is pushed along its surface normal by this many
    /// shadow texels (world size of a texel at the receiver) times 1 − N·L before the
    /// lookup, so surfaces facing the light are hardly moved and grazing ones fully
    /// (Holbert, "Normal offset shadows", 2011). ≥ 0.
    #[arg(long, value_name = "TEXELS", default_value_t = BiasSettings::default().normal_offset, help_heading = "Shadow bias")]
    pub normal_offset: f32,
    /// Faces culled when drawing casters into the shadow map.
    #[arg(long, value_enum, default_value_t, help_heading = "Shadow bias")]
    pub cull: CullMode,
}

impl BiasSettings {
    /// No bias at all, for demonstrating acne.
    pub fn none() -> Self {
        Self { depth_bias: 0, slope_bias: 0.0, normal_offset: 0.0, cull: CullMode::Back }
    }
}

impl Default for BiasSettings {
    fn default() -> Self {
        Self { depth_bias: 0, slope_bias: 1.5, normal_offset: 0.6, cull: CullMode::Back }
    }
}

/// The storage format of the shadow map.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum MapFormat {
    /// 32-bit float depth: exact enough for every technique here, and filterable by comparison.
    #[default]
    Depth32float,
}

/// What a directional light's map is fitted to.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Fit {
    /// The whole scene's bounds, whatever the camera sees: stable, but texels are
    /// spent on ground the camera never shows.
    Scene,
    /// The potential receivers: the intersection of the camera's view frustum with the
    /// scene's bounds in x and y, extended toward the light to every caster in z.
    #[default]
    Receivers,
}

/// The map axis: the shadow map's size and format.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapSettings {
    /// Shadow map width and height in texels: 256 to 8192, and at most the device's
    /// maximum 2D texture size.
    #[arg(long = "shadow-res", value_name = "TEXELS", default_value_t = MapSettings::default().resolution, help_heading = "Shadow map")]
    pub resolution: u32,
    /// Shadow map texel format.
    #[arg(long = "shadow-format", value_enum, default_value_t, help_heading = "Shadow map")]
    pub format: MapFormat,
    /// What a sun's map covers (a spot's map always covers its cone).
    #[arg(long, value_enum, default_value_t, help_heading = "Shadow map")]
    pub fit: Fit,
    /// Perspective warp of a sun's single map, fitted to the receivers. Warped maps store
    /// depth that is monotonic along each light ray but not linear in distance, so they
    /// take the depth-comparison techniques (hard and the PCF family) with kernels in
    /// texels; a spot's map is perspective already and ignores this.
    #[arg(long, value_enum, default_value_t, help_heading = "Shadow map")]
    pub warp: WarpKind,
    /// Depth clamping ("pancaking") where the device supports it (unclipped depth): a
    /// sun's map fitted to the receivers (--fit receivers, tight cascades) starts its
    /// depth range at the nearest receiver, and casters nearer the sun are clamped onto
    /// that plane, so the range, and the depth error, shrink. Never for PCSS, stable
    /// cascades or warps.
    #[arg(long, value_name = "BOOL", default_value_t = true, action = clap::ArgAction::Set, help_heading = "Shadow map")]
    pub depth_clamp: bool,
    /// How a point light's map covers every direction.
    #[arg(long, value_enum, default_value_t, help_heading = "Shadow map")]
    pub omni: OmniMap,
}

impl Default for MapSettings {
    fn default() -> Self {
        Self {
            resolution: 2048,
            format: MapFormat::default(),
            fit: Fit::default(),
            warp: WarpKind::default(),
            depth_clamp: true,
            omni: OmniMap::default(),
        }
    }
}

/// The parametrization of a point light's map.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum OmniMap {
    /// A cube: six 90° faces, sampled by direction; uniform texels within a factor
    /// of 3 in solid angle, six passes.
    #[default]
    Cube,
    /// Dual paraboloids (Brabec, Annen & Seidel 2002): two hemispheres, the lower
    /// one around the light's −y axis, in two passes. Cheaper to draw, but the
    /// parabolic mapping bends straight edges that the rasterizer draws straight,
    /// and texels grow 4× from the axis to the rim. Hard and PCF lookups only.
    Paraboloid,
}

/// Perspective warps of a sun's map.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum WarpKind {
    /// No warp: an orthographic map.
    #[default]
    None,
    /// Perspective shadow maps (Stamminger & Drettakis 2002): the map drawn in the
    /// camera's post-perspective space, the camera slid back to take in every caster.
    Psm,
    /// Light-space perspective shadow maps (Wimmer, Scherzer & Purgathofer 2004), with
    /// n_opt = (z_n + √(z_n·z_f)) / sin γ.
    Lispsm,
    /// Trapezoidal shadow maps (Martin & Tan 2004), with the 80 % rule.
    Tsm,
}

/// How the light's view is split into shadow maps.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Partition {
    /// One map covering what the light must see (see --fit).
    #[default]
    Single,
    /// Cascaded shadow maps for a sun: the view frustum split along its depth, one
    /// --shadow-res map per slice, in a depth texture array (a spot keeps one map).
    Cascades,
}

/// How the view depth range is divided among cascades.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum SplitScheme {
    /// Equal depth ranges.
    Uniform,
    /// Equal depth ratios, matching perspective texel density.
    Log,
    /// Parallel-split shadow maps: λ·log + (1 − λ)·uniform (λ = 1 is fully log).
    #[default]
    Practical,
}

/// How each cascade's map is placed over its slice.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum CascadeFit {
    /// The slice's potential receivers exactly: the most texels on screen, but the
    /// map's size and position change as the camera moves, so edges shimmer.
    Tight,
    /// The slice's bounding sphere, snapped to whole texels: a fixed size whatever the
    /// camera's orientation, moving in texel steps, so edges hold still.
    #[default]
    Stable,
}

/// How a pixel picks its cascade.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum CascadeSelection {
    /// By the pixel's view depth against the split distances.
    #[default]
    Depth,
    /// The first cascade whose map contains the pixel's projection: uses the finer
    /// maps wherever their (stable, larger) windows reach.
    Projection,
}

/// Cascaded shadow maps (--partition cascades).
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CascadeSettings {
    /// Number of cascades: 1 to 8.
    #[arg(long = "cascades", value_name = "N", default_value_t = CascadeSettings::default().count, help_heading = "Cascades")]
    pub count: u32,
    /// Split scheme of the view depth range.
    #[arg(long, value_enum, default_value_t, help_heading = "Cascades")]
    pub split: SplitScheme,
    /// λ of the practical split scheme, in [0, 1]: 1 is fully logarithmic.
    #[arg(long, value_name = "LAMBDA", default_value_t = CascadeSettings::default().split_lambda, help_heading = "Cascades")]
    pub split_lambda: f32,
    /// Farthest view depth the cascades cover, in world units, > 0 [default: the
    /// camera's far plane]. Beyond it a sun casts no shadow.
    #[arg(long, value_name = "DISTANCE", help_heading = "Cascades")]
    pub shadow_distance: Option<f32>,
    /// How each cascade's map is fitted to its slice.
    #[arg(long, value_enum, default_value_t, help_heading = "Cascades")]
    pub cascade_fit: CascadeFit,
    /// How a pixel chooses its cascade.
    #[arg(long, value_enum, default_value_t, help_heading = "Cascades")]
    pub cascade_selection: CascadeSelection,
    /// Width of the band at the far end of each cascade over which it blends into the
    /// next, as a fraction of the cascade's depth range: 0 to 0.5.
    #[arg(long, value_name = "FRACTION", default_value_t = CascadeSettings::default().cascade_blend, help_heading = "Cascades")]
    pub cascade_blend: f32,
    /// Keep the cascades fitted to the first frame while the camera moves (along
    /// `compare --camera-path`, or in the viewer), to see what refitting buys.
    #[arg(long = "freeze-cascades", help_heading = "Cascades")]
    pub freeze: bool,
    /// Sample-distribution shadow maps (Lauritzen, Salvi & Lefohn 2011): split the view
    /// depths the camera actually sees, reduced on the GPU from a depth prepass of the
    /// shadow casters, instead of the depths where the view frustum meets the scene's
    /// bounds. Costs a prepass and a read back of two numbers before the shadow pass.
    #[arg(long, help_heading = "Cascades")]
    pub sdsm: bool,
    /// With --sdsm, also fit each tight cascade in x and y to the light-space bounds of
    /// the samples it serves (a second reduction of the same depth buffer), instead of
    /// to its whole slice of the view frustum.
    #[arg(long, help_heading = "Cascades")]
    pub sdsm_bounds: bool,
}

impl Default for CascadeSettings {
    fn default() -> Self {
        Self {
            count: 4,
            split: SplitScheme::default(),
            split_lambda: 0.8,
            shadow_distance: None,
            cascade_fit: CascadeFit::default(),
            cascade_selection: CascadeSelection::default(),
            cascade_blend: 0.1,
            freeze: false,
            sdsm: false,
            sdsm_bounds: false,
        }
    }
}

/// Shadow settings, one field per orthogonal axis.
#[derive(Args, Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct ShadowSettings {
    #[command(flatten)]
    pub filter: FilterSettings,
    #[command(flatten)]
    pub bias: BiasSettings,
    #[command(flatten)]
    pub map: MapSettings,
    /// Partition of the light's view into maps.
    #[arg(long, value_enum, default_value_t, help_heading = "Shadow map")]
    pub partition: Partition,
    #[command(flatten)]
    pub cascades: CascadeSettings,
    #[command(flatten)]
    pub contact: ContactSettings,
}

/// A setting outside its valid range. The message names the flag and what is valid.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("{flag} = {value} is invalid: {valid}")]
pub struct SettingsError {
    pub flag: &'static str,
    pub value: String,
    pub valid: String,
}

fn check(
    ok: bool,
    flag: &'static str,
    value: impl ToString,
    valid: impl Into<String>,
) -> Result<(), SettingsError> {
    if ok { Ok(()) } else { Err(SettingsError { flag, value: value.to_string(), valid: valid.into() }) }
}

fn check_opt(
    v: Option<f32>,
    flag: &'static str,
    ok: impl Fn(f32) -> bool,
    valid: &str,
) -> Result<(), SettingsError> {
    match v {
        Some(x) => check(x.is_finite() && ok(x), flag, x, valid),
        None => Ok(()),
    }
}

impl MomentSettings {
    fn validate(&self, technique: Technique) -> Result<(), SettingsError> {
        let in_range = |x: f32, lo: f32, hi: f32| x.is_finite() && x >= lo && x <= hi;
        check(self.blur_radius <= 16, "--blur-radius", self.blur_radius, "0 to 16 texels")?;
        check(in_range(self.min_variance, 0.0, 1.0), "--min-variance", self.min_variance, "0 to 1")?;
        check(
            self.bleeding_reduction.is_finite() && (0.0..1.0).contains(&self.bleeding_reduction),
            "--bleeding-reduction",
            self.bleeding_reduction,
            "in [0, 1)",
        )?;
        // Only EVSM stores exponentials, so only its exponents are bounded by the
        // format (with `auto` on a 16-bit adapter the renderer clamps them).
        let evsm = matches!(technique, Technique::Evsm2 | Technique::Evsm4);
        let half = evsm && self.moment_format == MomentFormat::Rgba16float;
        // ESM stores d itself and exponentiates in the shader, so only EVSM, which
        // stores exp(c·d) and its square, is limited by the storage format's range.
        let (esm_max, evsm_max) = (88.0, if half { 5.54 } else { 42.0 });
        let precision = if half { "with --moment-format rgba16float" } else { "at 32 bits" };
        check(
            in_range(self.esm_exponent, 1.0, esm_max),
            "--esm-exponent",
            self.esm_exponent,
            format!("1 to {esm_max} {precision}"),
        )?;
        check(
            in_range(self.evsm_positive, 0.0, evsm_max),
            "--evsm-positive",
            self.evsm_positive,
            format!("0 to {evsm_max} {precision}"),
        )?;
        check(
            in_range(self.evsm_negative, 0.0, evsm_max),
            "--evsm-negative",
            self.evsm_negative,
            format!("0 to {evsm_max} {precision}"),
        )?;
        check(in_range(self.moment_bias, 0.0, 0.1), "--moment-bias", self.moment_bias, "0 to 0.1")?;
        check((1..=16).contains(&self.csm_terms), "--csm-terms", self.csm_terms, "1 to 16")?;
        check(
            in_range(self.csm_attenuation, 0.0, 1e3),
            "--csm-attenuation",
            self.csm_attenuation,
            "0 to 1000",
        )?;
        check(self.csm_scale.is_finite() && self.csm_scale > 0.0, "--csm-scale", self.csm_scale, "> 0")?;
        check(in_range(self.csm_offset, -0.5, 0.5), "--csm-offset", self.csm_offset, "-0.5 to 0.5")?;
        Ok(())
    }
}

impl ShadowSettings {
    /// Checks every shadow value against its documented range.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let s = self;
        let f = &s.filter;
        match f.kernel_unit {
            KernelUnit::Texels => check(
                f.pcf_kernel.is_finite() && (1.0..=MAX_KERNEL_TEXELS).contains(&f.pcf_kernel),
                "--pcf-kernel",
                f.pcf_kernel,
                format!("1 to {MAX_KERNEL_TEXELS} texels (or a world width with --kernel-unit world)"),
            )?,
            KernelUnit::World => check(
                f.pcf_kernel.is_finite() && f.pcf_kernel > 0.0,
                "--pcf-kernel",
                f.pcf_kernel,
                "a world width > 0",
            )?,
        }
        check((8..=64).contains(&f.poisson_samples), "--poisson-samples", f.poisson_samples, "8 to 64")?;
        check(
            (8..=64).contains(&f.pcss.blocker_samples),
            "--blocker-samples",
            f.pcss.blocker_samples,
            "8 to 64",
        )?;
        check(
            f.pcss.max_radius.is_finite() && (1.0..=64.0).contains(&f.pcss.max_radius),
            "--max-radius",
            f.pcss.max_radius,
            "1 to 64 texels",
        )?;
        f.moments.validate(f.technique)?;
        if s.map.warp != WarpKind::None {
            let warp = s.map.warp.to_possible_value().map(|v| v.get_name().to_string()).unwrap_or_default();
            check(
                s.partition == Partition::Single,
                "--warp",
                &warp,
                "a warp of a single map: with --partition cascades use --warp none",
            )?;
            check(
                matches!(
                    f.technique,
                    Technique::Hard
                        | Technique::Pcf2x2
                        | Technique::Pcf
                        | Technique::PcfTent
                        | Technique::PcfPoisson
                ),
                "--warp",
                &warp,
                format!(
                    "with --technique {}: a warped map takes hard, pcf2x2, pcf, pcf-tent or pcf-poisson (its depth is not linear in distance)",
                    f.technique.name()
                ),
            )?;
            check(
                f.kernel_unit == KernelUnit::Texels,
                "--warp",
                &warp,
                "with --kernel-unit world: a warped map's kernels are in texels",
            )?;
        }
        let c = &s.cascades;
        check((1..=MAX_CASCADES).contains(&c.count), "--cascades", c.count, format!("1 to {MAX_CASCADES}"))?;
        check(
            c.split_lambda.is_finite() && (0.0..=1.0).contains(&c.split_lambda),
            "--split-lambda",
            c.split_lambda,
            "0 to 1",
        )?;
        check(
            c.cascade_blend.is_finite() && (0.0..=0.5).contains(&c.cascade_blend),
            "--cascade-blend",
            c.cascade_blend,
            "0 to 0.5",
        )?;
        check_opt(c.shadow_distance, "--shadow-distance", |x| x > 0.0, "a distance > 0")?;
        if c.sdsm_bounds {
            check(c.sdsm, "--sdsm-bounds", "set", "only with --sdsm, whose depth prepass it reduces")?;
            check(
                c.cascade_fit == CascadeFit::Tight,
                "--sdsm-bounds",
                "set",
                "only with --cascade-fit tight: bounds that follow every pixel cannot keep a stable cascade still",
            )?;
        }
        let b = &s.bias;
        check(
            b.slope_bias.is_finite() && b.slope_bias >= 0.0,
            "--slope-bias",
            b.slope_bias,
            "a finite factor ≥ 0",
        )?;
        check(
            b.normal_offset.is_finite() && b.normal_offset >= 0.0,
            "--normal-offset",
            b.normal_offset,
            "a finite number of texels ≥ 0",
        )?;
        let r = s.map.resolution;
        check(
            (MIN_SHADOW_RESOLUTION..=MAX_SHADOW_RESOLUTION).contains(&r),
            "--shadow-res",
            r,
            format!("{MIN_SHADOW_RESOLUTION} to {MAX_SHADOW_RESOLUTION} texels"),
        )?;
        s.contact.validate()?;
        Ok(())
    }
}

fn check_vec(v: Option<Vec3>, flag: &'static str) -> Result<(), SettingsError> {
    match v {
        Some(p) => check(p.is_finite(), flag, format!("{},{},{}", p.x, p.y, p.z), "three finite numbers"),
        None => Ok(()),
    }
}

/// The largest shadow map Gnomon allows, whatever the device.
pub const MAX_SHADOW_RESOLUTION: u32 = 8192;

/// The most cascades a light may have: the renderer sizes its uniforms by it.
pub const MAX_CASCADES: u32 = 8;

/// The widest PCF kernel, in texels (a world-unit kernel is clamped to it too).
pub const MAX_KERNEL_TEXELS: f32 = 32.0;
/// The smallest shadow map Gnomon allows.
pub const MIN_SHADOW_RESOLUTION: u32 = 256;

impl Settings {
    /// Checks every value against its documented range. Device-dependent limits (the
    /// largest texture) are checked by the renderer, which knows the device.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let i = &self.image;
        check((1..=16384).contains(&i.width), "--width", i.width, "1 to 16384 pixels")?;
        check((1..=16384).contains(&i.height), "--height", i.height, "1 to 16384 pixels")?;
        let c = &self.camera;
        check_vec(c.eye, "--camera-eye")?;
        check_vec(c.target, "--camera-target")?;
        check_opt(
            c.fov_y_degrees,
            "--fov",
            |x| x > 0.0 && x < 180.0,
            "between 0 and 180 degrees, exclusive",
        )?;
        check_opt(c.near, "--camera-near", |x| x > 0.0, "a distance > 0")?;
        check_opt(c.far, "--camera-far", |x| x > 0.0, "a distance > 0 and > the near distance")?;
        let l = &self.light;
        check_opt(l.sun_elevation, "--sun-elevation", |x| x > 0.0 && x <= 90.0, "in (0, 90] degrees")?;
        check_opt(l.sun_azimuth, "--sun-azimuth", |_| true, "a finite angle in degrees")?;
        check_vec(l.spot_position, "--spot-position")?;
        check_vec(l.spot_target, "--spot-target")?;
        check_opt(l.spot_outer_angle, "--spot-outer-angle", |x| x > 0.0 && x <= 89.0, "in (0, 89] degrees")?;
        check_opt(
            l.spot_inner_angle,
            "--spot-inner-angle",
            |x| (0.0..=89.0).contains(&x),
            "in [0, outer angle] degrees",
        )?;
        check_opt(l.spot_range, "--spot-range", |x| x > 0.0, "a distance > 0")?;
        check_opt(l.spot_radius, "--spot-radius", |x| x >= 0.0, "a distance ≥ 0")?;
        check_vec(l.point_position, "--point-position")?;
        check_opt(l.point_range, "--point-range", |x| x > 0.0, "a distance > 0")?;
        check_opt(l.point_radius, "--point-radius", |x| x >= 0.0, "a distance ≥ 0")?;
        check_opt(
            l.sun_angular_diameter,
            "--sun-angular-diameter",
            |x| (0.0..=30.0).contains(&x),
            "in [0, 30] degrees",
        )?;
        self.shadow.validate()?;
        let n = self.reference.samples;
        check((8..=65536).contains(&n), "--samples", n, "8 to 65536 shadow rays per pixel")?;
        Ok(())
    }

    /// Whether a frame with these lights resolves its shadows in a screen-space mask:
    /// as --shadow-path says, and with `auto` when any light marches contact shadows.
    /// Contact shadows with --shadow-path forward are refused: they need the prepass.
    pub fn uses_shadow_mask(&self, lights: &[ResolvedLight]) -> Result<bool, SettingsError> {
        let contact = lights.iter().find(|l| l.shadow.contact.contact_shadows);
        match (self.screen.shadow_path, contact) {
            (ShadowPath::Forward, Some(light)) => Err(SettingsError {
                flag: "--contact-shadows",
                value: format!("on for light `{}`", light.name),
                valid: "only with --shadow-path auto or mask: contact shadows march through the mask path's depth prepass"
                    .into(),
            }),
            (ShadowPath::Forward, None) => Ok(false),
            (ShadowPath::Mask, _) => Ok(true),
            (ShadowPath::Auto, contact) => Ok(contact.is_some()),
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
            "--camera-far",
            cam.far,
            format!("greater than the near distance {}", cam.near),
        )?;
        check(
            (cam.target - cam.eye).length() > 1e-6,
            "--camera-target",
            "the eye position",
            "a point different from the camera position",
        )?;
        Ok(cam)
    }

    /// The light whose visibility a frame outputs and the reference traces: the
    /// scene's light of the chosen kind with these settings' overrides, or with
    /// --light all the one at --light-index.
    pub fn resolve_light(&self, scene: &Scene) -> Result<Light, SettingsError> {
        let l = &self.light;
        Ok(match l.kind {
            LightKind::All => {
                let lights = self.scene_light_list(scene)?;
                check(
                    l.light_index < lights.len(),
                    "--light-index",
                    l.light_index,
                    format!("below {}, the number of lights scene `{}` lists", lights.len(), scene.name),
                )?;
                lights[l.light_index].light
            }
            LightKind::Point => {
                let mut point = scene.point;
                point.position = l.point_position.unwrap_or(point.position);
                point.range = l.point_range.unwrap_or(point.range);
                point.radius = l.point_radius.unwrap_or(point.radius);
                Light::Point(point)
            }
            LightKind::Sun => {
                let mut sun = scene.sun;
                if l.sun_elevation.is_some() || l.sun_azimuth.is_some() {
                    let to_sun = -sun.direction;
                    let elevation = to_sun.y.clamp(-1.0, 1.0).asin().to_degrees();
                    let azimuth = to_sun.x.atan2(to_sun.z).to_degrees();
                    sun.direction = -sun_direction(
                        l.sun_elevation.unwrap_or(elevation),
                        l.sun_azimuth.unwrap_or(azimuth),
                    );
                }
                sun.angular_diameter_degrees = l.sun_angular_diameter.unwrap_or(sun.angular_diameter_degrees);
                Light::Directional(sun)
            }
            LightKind::Spot => {
                let mut spot = scene.spot;
                let target = spot.position + spot.direction;
                spot.position = l.spot_position.unwrap_or(spot.position);
                if l.spot_position.is_some() || l.spot_target.is_some() {
                    let aim = l.spot_target.unwrap_or(target) - spot.position;
                    check(
                        aim.length() > 1e-6,
                        "--spot-target",
                        "the spot position",
                        "a point different from the spot light's position",
                    )?;
                    spot.direction = aim.normalize();
                }
                if let Some(outer) = l.spot_outer_angle {
                    spot.outer_angle_degrees = outer;
                    spot.inner_angle_degrees = 0.8 * outer;
                }
                if let Some(inner) = l.spot_inner_angle {
                    spot.inner_angle_degrees = inner;
                }
                check(
                    spot.inner_angle_degrees <= spot.outer_angle_degrees,
                    "--spot-inner-angle",
                    spot.inner_angle_degrees,
                    format!("at most the outer angle {}", spot.outer_angle_degrees),
                )?;
                spot.range = l.spot_range.unwrap_or(spot.range);
                spot.radius = l.spot_radius.unwrap_or(spot.radius);
                Light::Spot(spot)
            }
        })
    }

    /// Every light of the render, each with its shadow settings: the one light of
    /// --light sun, spot or point with these shadow settings, or with --light all the
    /// scene's list, each light's own settings laid over these.
    pub fn resolve_lights(&self, scene: &Scene) -> Result<Vec<ResolvedLight>, SettingsError> {
        if self.light.kind != LightKind::All {
            let light = self.resolve_light(scene)?;
            check_light_type(&light, &self.shadow, light.type_name())?;
            return Ok(vec![ResolvedLight {
                name: light.type_name().into(),
                light,
                shadow: self.shadow.clone(),
            }]);
        }
        self.resolve_light(scene)?;
        self.scene_light_list(scene)?
            .iter()
            .map(|entry| {
                let shadow = match &entry.shadow {
                    None => self.shadow.clone(),
                    Some(table) => self.shadow_with(table).map_err(|problem| SettingsError {
                        flag: "[light.shadow]",
                        value: entry.name.clone(),
                        valid: problem,
                    })?,
                };
                check_light_type(&entry.light, &shadow, &entry.name)?;
                Ok(ResolvedLight { name: entry.name.clone(), light: entry.light, shadow })
            })
            .collect()
    }

    /// These shadow settings with `table` laid over them.
    fn shadow_with(&self, table: &toml::Table) -> Result<ShadowSettings, String> {
        let mut merged = toml::Value::try_from(&self.shadow).map_err(|e| e.to_string())?;
        crate::scene_file::overlay(&mut merged, &toml::Value::Table(table.clone()));
        let shadow: ShadowSettings = merged.try_into().map_err(|e: toml::de::Error| e.to_string())?;
        shadow.validate().map_err(|e| e.to_string())?;
        Ok(shadow)
    }

    fn scene_light_list<'s>(&self, scene: &'s Scene) -> Result<&'s [crate::SceneLight], SettingsError> {
        check(
            !scene.lights.is_empty(),
            "--light",
            "all",
            format!(
                "a scene with a light list; `{}` has none (scene files list [[light]], glTF files KHR_lights_punctual lights, and the built-in `lamps` has eight)",
                scene.name
            ),
        )?;
        check(
            scene.lights.len() <= MAX_LIGHTS,
            "--light",
            "all",
            format!("at most {MAX_LIGHTS} lights; `{}` lists {}", scene.name, scene.lights.len()),
        )?;
        Ok(&scene.lights)
    }
}

/// The most lights one render draws.
pub const MAX_LIGHTS: usize = 32;

/// Checks that a light's type and its shadow settings go together: a point light's
/// cube map takes the depth-comparison techniques and a single map.
fn check_light_type(light: &Light, shadow: &ShadowSettings, name: &str) -> Result<(), SettingsError> {
    if let (Light::Point(_), OmniMap::Paraboloid) = (light, shadow.map.omni) {
        check(
            shadow.filter.technique.supports_point_lights() && shadow.filter.technique != Technique::Pcss,
            "--technique",
            shadow.filter.technique.name(),
            format!(
                "for point light `{name}` with --omni paraboloid: hard, pcf2x2, pcf, pcf-tent or pcf-poisson"
            ),
        )?;
    }
    if let Light::Point(_) = light {
        check(
            shadow.filter.technique.supports_point_lights(),
            "--technique",
            shadow.filter.technique.name(),
            format!(
                "for point light `{name}` (a cube map): hard, pcf2x2, pcf, pcf-tent, pcf-poisson or pcss"
            ),
        )?;
    }
    Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        settings: Settings,
    }

    #[test]
    fn flag_defaults_equal_struct_defaults() {
        let parsed = Cli::try_parse_from(["gnomon"]).unwrap().settings;
        assert_eq!(parsed, Settings::default());
        parsed.validate().unwrap();
    }

    #[test]
    fn flags_and_toml_agree() {
        let parsed = Cli::try_parse_from([
            "gnomon",
            "--technique",
            "pcf",
            "--pcf-kernel",
            "5",
            "--shadow-res",
            "1024",
            "--slope-bias",
            "2.5",
            "--cull",
            "front",
            "--light",
            "spot",
            "--camera-eye",
            "1,2,3",
            "--kernel-unit",
            "world",
            "--receiver-plane-bias",
            "false",
            "--blur-radius",
            "4",
            "--mipmaps",
            "--moment-format",
            "rgba16float",
            "--csm-terms",
            "12",
            "--shadow-path",
            "mask",
            "--contact-shadows",
            "--contact-length",
            "0.5",
            "--contact-steps",
            "24",
        ])
        .unwrap()
        .settings;
        let text = r#"
            [camera]
            eye = [1.0, 2.0, 3.0]
            [light]
            kind = "spot"
            [shadow.filter]
            technique = "pcf"
            pcf_kernel = 5
            kernel_unit = "world"
            receiver_plane_bias = false
            [shadow.filter.moments]
            blur_radius = 4
            mipmaps = true
            moment_format = "rgba16float"
            csm_terms = 12
            [shadow.bias]
            slope_bias = 2.5
            cull = "front"
            [shadow.map]
            resolution = 1024
            [shadow.contact]
            contact_shadows = true
            contact_length = 0.5
            contact_steps = 24
            [screen]
            shadow_path = "mask"
        "#;
        let from_file: Settings = toml::from_str(text).unwrap();
        assert_eq!(parsed, from_file);
        // And a round trip through TOML keeps everything.
        let again: Settings = toml::from_str(&toml::to_string(&parsed).unwrap()).unwrap();
        assert_eq!(again, parsed);
    }

    #[test]
    fn invalid_values_name_the_flag_and_the_range() {
        let mut s = Settings::default();
        s.shadow.map.resolution = 100;
        let e = s.validate().unwrap_err();
        assert_eq!(e.flag, "--shadow-res");
        assert!(e.to_string().contains("256 to 8192"), "{e}");
        let mut s = Settings::default();
        s.shadow.filter.pcf_kernel = 40.0;
        assert_eq!(s.validate().unwrap_err().flag, "--pcf-kernel");
        let mut s = Settings::default();
        s.camera.fov_y_degrees = Some(180.0);
        assert_eq!(s.validate().unwrap_err().flag, "--fov");
        assert!(parse_vec3("1,2").is_err() && parse_vec3("1,x,3").is_err() && parse_vec3("1,inf,2").is_err());
        assert_eq!(parse_vec3(" 1, 2.5,-3").unwrap(), Vec3::new(1.0, 2.5, -3.0));
    }

    #[test]
    fn warps_take_a_single_map_and_a_depth_comparison() {
        let mut s = Settings::default();
        s.shadow.map.warp = WarpKind::Lispsm;
        s.validate().unwrap();
        s.shadow.partition = Partition::Cascades;
        let e = s.validate().unwrap_err();
        assert_eq!(e.flag, "--warp");
        assert!(e.to_string().contains("--warp none"), "{e}");
        let mut s = Settings::default();
        s.shadow.map.warp = WarpKind::Tsm;
        s.shadow.filter.technique = Technique::Vsm;
        let e = s.validate().unwrap_err();
        assert!(e.to_string().contains("with --technique vsm"), "{e}");
        s.shadow.filter.technique = Technique::PcfPoisson;
        s.validate().unwrap();
        s.shadow.filter.kernel_unit = KernelUnit::World;
        assert!(s.validate().unwrap_err().to_string().contains("--kernel-unit world"));
    }

    #[test]
    fn sdsm_bounds_need_sdsm_and_tight_cascades() {
        let mut s = Settings::default();
        s.shadow.partition = Partition::Cascades;
        s.shadow.cascades.sdsm_bounds = true;
        let e = s.validate().unwrap_err();
        assert!(e.flag == "--sdsm-bounds" && e.to_string().contains("only with --sdsm"), "{e}");
        s.shadow.cascades.sdsm = true;
        s.shadow.cascades.cascade_fit = CascadeFit::Stable;
        assert!(s.validate().unwrap_err().to_string().contains("--cascade-fit tight"));
        s.shadow.cascades.cascade_fit = CascadeFit::Tight;
        s.validate().unwrap();
    }

    #[test]
    fn technique_names_are_the_flag_values() {
        let names: Vec<_> = Technique::all().iter().map(|t| t.name()).collect();
        assert_eq!(
            names,
            [
                "hard",
                "pcf2x2",
                "pcf",
                "pcf-tent",
                "pcf-poisson",
                "pcss",
                "vsm",
                "esm",
                "evsm2",
                "evsm4",
                "msm-hamburger",
                "msm-hausdorff",
                "convolution"
            ]
        );
        for t in Technique::all() {
            let parsed = <Technique as ValueEnum>::from_str(t.name(), false).unwrap();
            assert_eq!(parsed, *t);
            let toml_name: toml::Value = toml::Value::try_from(t).unwrap();
            assert_eq!(toml_name.as_str(), Some(t.name()), "serde and clap agree");
        }
    }

    #[test]
    fn sun_overrides_keep_the_other_angle() {
        let scene = crate::builtin::spheres();
        let mut s = Settings::default();
        s.light.sun_elevation = Some(30.0);
        let Light::Directional(sun) = s.resolve_light(&scene).unwrap() else { panic!() };
        assert!(((-sun.direction.y).asin().to_degrees() - 30.0).abs() < 1e-3);
        let (a0, a1) =
            (scene.sun.direction.x.atan2(scene.sun.direction.z), sun.direction.x.atan2(sun.direction.z));
        assert!((a0 - a1).abs() < 1e-4, "azimuth unchanged");
    }

    #[test]
    fn point_light_flags_override_the_scenes_and_are_checked() {
        let scene = crate::builtin::spheres();
        let parsed = Cli::try_parse_from([
            "gnomon",
            "--light",
            "point",
            "--point-position",
            "1,2,3",
            "--point-range",
            "7",
            "--point-radius",
            "0.2",
        ])
        .unwrap()
        .settings;
        parsed.validate().unwrap();
        let Light::Point(p) = parsed.resolve_light(&scene).unwrap() else { panic!("a point light") };
        assert_eq!((p.position, p.range, p.radius), (Vec3::new(1.0, 2.0, 3.0), 7.0, 0.2));
        assert_eq!(p.color, scene.point.color, "what no flag names stays the scene's");
        let lights = parsed.resolve_lights(&scene).unwrap();
        assert_eq!((lights.len(), lights[0].name.as_str()), (1, "point"));

        let mut bad = parsed.clone();
        bad.light.point_range = Some(0.0);
        assert_eq!(bad.validate().unwrap_err().flag, "--point-range");
        bad.light.point_range = None;
        bad.light.point_radius = Some(-1.0);
        assert_eq!(bad.validate().unwrap_err().flag, "--point-radius");
        // A cube map is compared by direction: the moment techniques are refused.
        let mut vsm = parsed;
        vsm.shadow.filter.technique = Technique::Vsm;
        let e = vsm.resolve_lights(&scene).unwrap_err();
        assert_eq!(e.flag, "--technique");
        assert!(e.valid.contains("pcf-poisson or pcss"), "{e}");
        // Dual paraboloids take the 2D lookups, without PCSS.
        let mut paraboloid = vsm;
        paraboloid.shadow.map.omni = OmniMap::Paraboloid;
        paraboloid.shadow.filter.technique = Technique::Pcss;
        let e = paraboloid.resolve_lights(&scene).unwrap_err();
        assert!(e.valid.contains("--omni paraboloid"), "{e}");
        paraboloid.shadow.filter.technique = Technique::PcfPoisson;
        paraboloid.resolve_lights(&scene).unwrap();
    }

    #[test]
    fn light_all_takes_each_lights_own_shadow_settings() {
        let scene = crate::builtin::lamps();
        let mut s = Settings::default();
        s.light.kind = LightKind::All;
        s.shadow.bias.slope_bias = 2.5;
        let lights = s.resolve_lights(&scene).unwrap();
        assert_eq!(lights.len(), 8);
        assert_eq!(lights[0].shadow.partition, Partition::Cascades);
        assert_eq!(lights[2].shadow.filter.technique, Technique::Pcss);
        assert!(
            lights.iter().all(|l| l.shadow.bias.slope_bias == 2.5),
            "the render's, where a light says nothing"
        );
        // A light whose own table is invalid over these settings is named.
        let mut broken = scene.clone();
        broken.lights[3].shadow = Some("[map]\nresolution = 100".parse().unwrap());
        let e = s.resolve_lights(&broken).unwrap_err();
        assert!(e.to_string().contains("spot 2") && e.to_string().contains("--shadow-res"), "{e}");
        // No list: a clear error naming where lists come from.
        let e = s.resolve_lights(&crate::builtin::spheres()).unwrap_err();
        assert!(e.valid.contains("[[light]]") && e.valid.contains("lamps"), "{e}");
    }

    #[test]
    fn contact_shadows_choose_the_mask_path_and_are_checked() {
        let scene = crate::builtin::lamps();
        let mut s = Settings::default();
        let lights = s.resolve_lights(&scene).unwrap();
        assert!(!s.uses_shadow_mask(&lights).unwrap(), "auto without contact shadows is forward");
        s.screen.shadow_path = ShadowPath::Mask;
        assert!(s.uses_shadow_mask(&lights).unwrap());
        // One light with contact shadows is enough for auto to take the mask...
        s.screen.shadow_path = ShadowPath::Auto;
        s.light.kind = LightKind::All;
        let mut lit = scene.clone();
        lit.lights[5].shadow = Some("[contact]\ncontact_shadows = true".parse().unwrap());
        let lights = s.resolve_lights(&lit).unwrap();
        assert!(lights[5].shadow.contact.contact_shadows && !lights[4].shadow.contact.contact_shadows);
        assert!(s.uses_shadow_mask(&lights).unwrap());
        // ...and forward refuses it, naming the light.
        s.screen.shadow_path = ShadowPath::Forward;
        let e = s.uses_shadow_mask(&lights).unwrap_err();
        assert!(e.flag == "--contact-shadows" && e.to_string().contains(&lit.lights[5].name), "{e}");
        // Each parameter's range is checked, naming the flag.
        for (flag, set) in [
            (
                "--contact-length",
                (|c: &mut ContactSettings| c.contact_length = 0.0) as fn(&mut ContactSettings),
            ),
            ("--contact-steps", |c| c.contact_steps = 0),
            ("--contact-steps", |c| c.contact_steps = 65),
            ("--contact-thickness", |c| c.contact_thickness = f32::NAN),
            ("--contact-bias", |c| c.contact_bias = -0.1),
            ("--contact-distance", |c| c.contact_distance = 0.0),
        ] {
            let mut s = Settings::default();
            set(&mut s.shadow.contact);
            assert_eq!(s.validate().unwrap_err().flag, flag);
        }
    }
}
