//! Screen-space settings: where each pixel's shadow is resolved (forward or the
//! shadow mask), and contact shadows.

use super::ranges::SettingRange;
use super::*;

/// Where each pixel's shadow is resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum ShadowPath {
    /// The mask when any light has contact shadows (which march through its depth),
    /// refines its shadow by rays (traced there in a pass of their own), or when the
    /// frame has more than one light and lights them from a light list (one lighting
    /// pass for them all reads their mask layers); forward otherwise.
    #[default]
    Auto,
    /// In the lighting pass, once per fragment drawn; rays asked for by name are
    /// traced there too, per fragment, without the mask path's penumbra filter.
    Forward,
    /// Screen-space shadows, as in Unity URP: a depth-and-normal prepass, then one
    /// full-screen pass per light that reconstructs each pixel's position from depth,
    /// looks its shadow up once and stores it in a mask the lighting pass reads.
    Mask,
}

/// How a frame of several lights is lit on the mask path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Lighting {
    /// One lighting pass for every light (tiled forward shading, after Olsson &
    /// Assarsson, "Tiled shading", 2011): the scene is drawn once, and each pixel sums
    /// the lights whose range reaches its 16 × 16 tile, reading each one's visibility
    /// from its layer of the mask. Each light's mask pass covers only the tiles its
    /// range can reach. A frame of one light draws that light's own pass.
    #[default]
    LightList,
    /// One lighting pass per light, each drawing the scene again and adding its light:
    /// the cost grows with the number of lights. For comparison, and the only way on the
    /// forward path.
    PerLight,
}

/// Which pixels trace shadow rays on the GPU, over the casters' BVH, in place of
/// their shadow-map answer (hybrid ray-traced shadows, after Story's HFTS and
/// Unreal's shadow-map ray tracing). On the mask path the shadow-mask pass lists the
/// pixels and a compute pass traces them; on the forward path (rays asked for by name
/// with `--shadow-path forward`) the lighting pass traces each fragment's rays where it
/// shades it. A hard light's pixel traces
/// one ray to the light; a light with an area (a sun's angular diameter, a spot's or
/// point's radius) traces `penumbra_rays` stratified rays over its area, then a small
/// edge-aware filter smooths their noise.
///
/// The default, `auto`, is `rays` for hard lights wherever they can run: no shadow
/// map resolves a caster finer than its texel, and on the 36 measured glTF cases the
/// map alone left up to 2 % of light-facing pixels wrong where the rays leave at most
/// 0.06 % (docs/defaults.md). A light with an area is refined too: the map's pyramid
/// finds its unsure penumbra pixels and they are beamed over the light's area
/// (docs/soft-shadows.md). Pass `off` to see a technique's own answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Refine {
    /// `rays` for every light, hard or with an area, when the frame takes the mask
    /// path (under --shadow-path auto, which then takes it for them, or mask); `off`
    /// with --shadow-path forward (ask for `rays` by name to trace there).
    #[default]
    Auto,
    /// Every pixel keeps its shadow map's answer.
    Off,
    /// Pixels the map is unsure of (taps that disagree, a receiver within a few
    /// texels' depth of the stored depth) trace one ray; under a light with an area,
    /// those the map's pyramid cannot classify are beamed over 128 samples of it on
    /// the mask path, or trace `penumbra_rays` rays on the forward path. The rest keep
    /// the map's answer.
    Rays,
    /// Every pixel that faces the light traces its rays: exact (up to the penumbra's
    /// sampling noise), and the upper baseline of cost.
    EveryPixel,
}

/// Which tracer answers the shadow rays that `refine` and the `raytraced` technique
/// cast. Both trace the same casters and give the CPU reference's answers
/// (docs/rays-tracers.md, "Two tracers").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Tracer {
    /// `ray-query` on a GPU that has ray queries, `shader` elsewhere (lavapipe's
    /// ray queries, in software, are slower than the shader's BVH).
    #[default]
    Auto,
    /// Gnomon's own BVH, built on the CPU and walked by a WGSL shader: any adapter,
    /// no ray-tracing hardware needed.
    Shader,
    /// The adapter's own acceleration structures, through ray queries (wgpu's
    /// `EXPERIMENTAL_RAY_QUERY`, Vulkan's `VK_KHR_ray_query`): ray-tracing hardware
    /// where the GPU has it. Where the device has no ray queries, or a scene exceeds
    /// what its structures take, the shader traces instead and the frame says why.
    RayQuery,
}

/// How a light's technique uses shadow rays: a fact of the technique, which the
/// renderer's technique registry states (`ShadowTechnique::rays`) and lays into each
/// [`ResolvedLight`]. Most techniques answer from their map and leave rays to
/// `screen.refine`; `raytraced` is a ray at every pixel whatever it says.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum RayUse {
    /// The light is refined as `screen.refine` says.
    #[default]
    AsSettingsSay,
    /// Every pixel of the light traces its rays: `screen.refine` every-pixel for this
    /// light alone.
    EveryPixel,
}

/// How shadows are resolved on screen: the frame-wide choice of path (contact
/// shadows, per light, are in the shadow settings).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[serde(default, deny_unknown_fields)]
pub struct ScreenSpaceSettings {
    /// Where each pixel's shadow lookup runs: forward, in the lighting pass, or once
    /// per pixel into a screen-space shadow mask.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_enum, default_value_t, help_heading = "Screen-space shadows")
    )]
    pub shadow_path: ShadowPath,
    /// Which pixels trace a shadow ray instead of trusting the map: auto (rays, where
    /// the frame takes the mask path), off, rays (where the map is unsure) or
    /// every-pixel, on either path.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_enum, default_value_t, help_heading = "Screen-space shadows")
    )]
    pub refine: Refine,
    /// Which tracer casts the rays: auto (ray queries on a GPU that has them),
    /// shader (Gnomon's BVH walked by a shader, on any adapter) or ray-query.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_enum, default_value_t, help_heading = "Screen-space shadows")
    )]
    pub tracer: Tracer,
    /// How several lights are lit on the mask path: light-list (one pass over a tiled
    /// list of the lights) or per-light (one pass each).
    #[cfg_attr(
        feature = "cli",
        arg(long, value_enum, default_value_t, help_heading = "Screen-space shadows")
    )]
    pub lighting: Lighting,
    /// Shadow rays per refined pixel under a light with an area on the forward path,
    /// stratified over the light's disk, cone or sphere as the CPU reference samples
    /// it: 1 to 256 (docs/rays.md). The mask path beams an area light's unsure pixels
    /// instead, over the penumbra beam's fixed 128 samples of the light, whatever this
    /// says (docs/soft-shadows.md).
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "N", default_value_t = ScreenSpaceSettings::default().penumbra_rays, help_heading = "Screen-space shadows")
    )]
    pub penumbra_rays: u32,
    /// Frames a still image's penumbrae gather under a light with an area whose
    /// unsure pixels are beamed (`render`, `compare`, Python's `render`): each frame
    /// beams a quarter of them and keeps what the frames before found where nothing
    /// moved, so 4 frames beam every one once and 16 four times (512 samples each),
    /// and then beams them no more until something moves. A live view (the viewer,
    /// the lab) gathers them as it goes; 1 returns the first frame, a quarter beamed
    /// and the rest filled from their neighbours.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "N", default_value_t = ScreenSpaceSettings::default().penumbra_frames, help_heading = "Screen-space shadows")
    )]
    pub penumbra_frames: u32,
}

/// `screen.penumbra_frames`' range.
pub const PENUMBRA_FRAMES_RANGE: SettingRange =
    SettingRange::closed("screen.penumbra_frames", 1.0, 256.0, "frames a still image's penumbrae gather");

/// The most shadow rays a refined pixel casts under a light with an area.
pub const MAX_PENUMBRA_RAYS: u32 = 256;
/// `screen.penumbra_rays`' range.
pub const PENUMBRA_RAYS_RANGE: SettingRange = SettingRange::closed(
    "screen.penumbra_rays",
    1.0,
    MAX_PENUMBRA_RAYS as f64,
    "shadow rays per refined pixel",
);
/// `shadow.contact.contact_length`'s range.
pub const CONTACT_LENGTH_RANGE: SettingRange =
    SettingRange::above("shadow.contact.contact_length", 0.0, 10.0, "world units");
/// `shadow.contact.contact_steps`' range.
pub const CONTACT_STEPS_RANGE: SettingRange =
    SettingRange::closed("shadow.contact.contact_steps", 1.0, 64.0, "steps");
/// `shadow.contact.contact_thickness`'s range.
pub const CONTACT_THICKNESS_RANGE: SettingRange =
    SettingRange::above("shadow.contact.contact_thickness", 0.0, 1.0, "of the view depth");

impl Default for ScreenSpaceSettings {
    fn default() -> Self {
        Self {
            shadow_path: ShadowPath::Auto,
            refine: Refine::Auto,
            tracer: Tracer::Auto,
            lighting: Lighting::LightList,
            penumbra_rays: 16,
            penumbra_frames: 16,
        }
    }
}

/// Contact shadows: a short ray marched in screen space from each pixel toward the
/// light through the depth prepass, to restore the shadows that a shadow map's bias
/// and resolution lose where objects meet (after Sousa, Kasyan & Schulz, "Secrets of
/// CryENGINE 3 graphics technology", 2011, and Unreal's screen-space shadows). The
/// result multiplies in as min(map, contact).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(struct_patch::Patch)]
#[patch(attribute(derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)))]
#[patch(attribute(serde(default, deny_unknown_fields)))]
#[patch(attribute(allow(missing_docs)))]
#[patch(attribute(
    doc = "Overrides of [`ContactSettings`], as a light's own shadow settings write them: each field as documented there, `None` to keep the value it is laid over."
))]
#[serde(default, deny_unknown_fields)]
pub struct ContactSettings {
    /// March contact shadows for this light (needs --shadow-path auto or mask).
    #[cfg_attr(feature = "cli", arg(long, help_heading = "Contact shadows"))]
    pub contact_shadows: bool,
    /// Length of the ray toward the light, in world units (> 0, at most 10).
    #[cfg_attr(feature = "cli", arg(long, value_name = "DISTANCE", default_value_t = ContactSettings::default().contact_length, help_heading = "Contact shadows"))]
    pub contact_length: f32,
    /// Depth-buffer samples along the ray; the start is jittered per pixel by
    /// interleaved gradient noise.
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", default_value_t = ContactSettings::default().contact_steps, help_heading = "Contact shadows"))]
    pub contact_steps: u32,
    /// Assumed thickness of what the depth buffer holds, as a fraction of its view
    /// depth: a sample behind the depth buffer by less than this occludes the ray,
    /// one farther behind passes behind the surface.
    #[cfg_attr(feature = "cli", arg(long, value_name = "FRACTION", default_value_t = ContactSettings::default().contact_thickness, help_heading = "Contact shadows"))]
    pub contact_thickness: f32,
    /// The ray starts this far along the surface's normal, in world units, so that its
    /// first samples clear the receiver's own depth. In [0, 1e7].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DISTANCE", default_value_t = ContactSettings::default().contact_bias, help_heading = "Contact shadows"))]
    pub contact_bias: f32,
    /// View depth beyond which contact shadows are off; they fade out over its last
    /// quarter. In (0, 1e7].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DISTANCE", default_value_t = ContactSettings::default().contact_distance, help_heading = "Contact shadows"))]
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
    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        CONTACT_LENGTH_RANGE.check(self.contact_length)?;
        CONTACT_STEPS_RANGE.check(self.contact_steps)?;
        CONTACT_THICKNESS_RANGE.check(self.contact_thickness)?;
        check(
            crate::limits::LIGHT_RADIUS.allows(self.contact_bias),
            "shadow.contact.contact_bias",
            self.contact_bias,
            crate::limits::LIGHT_RADIUS.valid,
        )?;
        check(
            crate::limits::CLIP_DISTANCE.allows(self.contact_distance),
            "shadow.contact.contact_distance",
            self.contact_distance,
            crate::limits::CLIP_DISTANCE.valid,
        )?;
        Ok(())
    }
}
