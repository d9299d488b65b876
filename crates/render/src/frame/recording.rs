//! The types the frame's recording steps share, below every step: what each step
//! appends to ([`Recording`]), a light's bind groups and map views for the passes from
//! the camera, the draw counts, and what recording leaves for the frame to read. The
//! steps (`record.rs`, `screen.rs`, `light_passes.rs`, `depth_pass.rs`) and the
//! outputs (`outputs.rs`) all read these, and these read none of them, so the frame's
//! files import one another in one direction.

use web_time::Instant;

use super::bindings::{ShadowViews, VirtualBuffers};
use crate::{
    passes::lighting::MapLookup,
    readback::PendingReadback,
    timing::{PassClock, PendingTimes},
};

/// What a frame submitted: the CPU-side cost of drawing the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawStats {
    /// Draws in the shadow passes, every layer of every light together.
    pub shadow_draws: u32,
    /// Draw commands recorded into the shadow passes: one per draw, or one per
    /// multi-draw where draws come from a buffer of arguments (`DrawSubmission`).
    pub shadow_commands: u32,
    /// Draw calls in the lighting pass.
    pub lighting_draws: u32,
    /// Draw calls in the mask path's prepass.
    pub prepass_draws: u32,
    /// Pipeline changes, every pass together.
    pub pipeline_changes: u32,
    /// Bind group changes, every pass together.
    pub bind_group_changes: u32,
    /// Instances drawn into shadow maps, every layer of every light together.
    pub shadow_instances: u32,
    /// Triangles drawn into shadow maps, every layer of every light together.
    pub shadow_triangles: u64,
    /// Instances the camera sees, drawn by the lighting pass.
    pub lighting_instances: u32,
}

impl DrawStats {
    pub(crate) fn add(&mut self, other: &DrawStats) {
        self.shadow_draws += other.shadow_draws;
        self.shadow_commands += other.shadow_commands;
        self.lighting_draws += other.lighting_draws;
        self.prepass_draws += other.prepass_draws;
        self.pipeline_changes += other.pipeline_changes;
        self.bind_group_changes += other.bind_group_changes;
        self.shadow_instances += other.shadow_instances;
        self.shadow_triangles += other.shadow_triangles;
        self.lighting_instances += other.lighting_instances;
    }
}

/// What every recording step appends to: the encoder (the renderer's own, or the
/// host's), the pass clock and the counts.
pub(super) struct Recording<'e> {
    pub encoder: &'e mut wgpu::CommandEncoder,
    pub clock: PassClock,
    pub stats: DrawStats,
    pub layer_commands: LayerCommands,
}

/// What was recorded into each layer of each light, every pass of a layer together
/// (its still casters, its strips, its moving casters): draw commands, and texels
/// rasterized.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct LayerCommands(Vec<Vec<LayerWork>>);

/// One layer's recorded work.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct LayerWork {
    /// Draw commands recorded into it.
    pub commands: u32,
    /// Texels its passes covered: the area of each pass that cleared its target or
    /// drew into it (the whole layer, or the strips a scrolled layer newly covers).
    pub texels: u64,
}

impl LayerCommands {
    /// Counts `work` more for layer `layer` of light `light`.
    pub fn add(&mut self, light: usize, layer: usize, work: LayerWork) {
        if self.0.len() <= light {
            self.0.resize(light + 1, Vec::new());
        }
        let layers = &mut self.0[light];
        if layers.len() <= layer {
            layers.resize(layer + 1, LayerWork::default());
        }
        layers[layer].commands += work.commands;
        layers[layer].texels += work.texels;
    }

    /// Light `light`'s work per layer, for its `layers` layers (nothing for a layer
    /// that recorded nothing).
    pub fn of(&self, light: usize, layers: usize) -> Vec<LayerWork> {
        let recorded = self.0.get(light).map(Vec::as_slice).unwrap_or(&[]);
        (0..layers).map(|l| recorded.get(l).copied().unwrap_or_default()).collect()
    }
}

/// A light's groups for its passes from the camera.
pub(super) struct LightBindings {
    /// Group 0: the instances and the light's uniform.
    pub scene: wgpu::BindGroup,
    /// Its uniform, which the mask pass's groups bind too.
    pub lighting: wgpu::BindGroup,
    /// The mask pass's shadow group, on the mask path.
    pub mask: Option<wgpu::BindGroup>,
    pub lookup: MapLookup,
}

/// A light's uniform and the views of its maps, for the passes from the camera.
pub(super) struct LightMaps {
    pub light_buffer: wgpu::Buffer,
    /// The depth map, every layer.
    pub map: wgpu::TextureView,
    /// The filterable techniques' moment map.
    pub moments: Option<wgpu::TextureView>,
    /// A point light's map as a cube.
    pub cube: Option<wgpu::TextureView>,
    /// A sun's virtual map's uniform and page table (its pool is `map`).
    pub virtual_map: Option<VirtualBuffers>,
    /// The depth map's pyramid, for a light whose penumbrae the mask pass
    /// classifies (`rays/pyramid.rs`).
    pub pyramid: Option<PyramidViews>,
    /// The depth map's touched layer, where its rays refine a 2D map under the
    /// footprint test (`rays/touched.rs`).
    pub touched: Option<wgpu::TextureView>,
    pub lookup: MapLookup,
}

impl LightMaps {
    /// The views of a shadow group, with the light's layer of the mask where it has one.
    pub fn views<'a>(&'a self, mask: Option<&'a wgpu::TextureView>) -> ShadowViews<'a> {
        ShadowViews {
            map: &self.map,
            moments: self.moments.as_ref(),
            cube: self.cube.as_ref(),
            mask,
            virtual_map: self.virtual_map.as_ref(),
            pyramid: self.pyramid.as_ref(),
            touched: self.touched.as_ref(),
        }
    }
}

/// The views of a depth pyramid's two textures, every level and layer.
pub(super) struct PyramidViews {
    pub planes: wgpu::TextureView,
    pub ranges: wgpu::TextureView,
}

/// The copies a frame recorded, waiting for its submission.
#[derive(Default)]
pub(super) struct FrameReadbacks {
    /// Every render target, in `lighting::TARGETS` order; empty when not asked for.
    pub targets: Vec<PendingReadback>,
    /// The reported light's map, every layer.
    pub shadow_map: Option<PendingReadback>,
    /// With refinement by rays, a copy of the lights' counters (`rays::RefineLists`).
    pub refine_counters: Option<wgpu::Buffer>,
}

/// What recording left for the frame to read.
pub(super) struct Recorded {
    pub readbacks: FrameReadbacks,
    /// Taken by the frame's timing once submitted.
    pub times: Option<PendingTimes>,
    pub stats: DrawStats,
    pub layer_commands: LayerCommands,
    pub color: wgpu::Texture,
    pub shadow_map: wgpu::Texture,
    /// Frames each light's penumbra history holds, this one counted (None: it keeps
    /// none).
    pub penumbra_frames: Vec<Option<u32>>,
    pub submitted_at: Instant,
}
