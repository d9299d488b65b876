//! The frame's memory, charged before any of it is allocated
//! ([`gnomon_scene::memory`] declares the costs and the budget): the scene as the
//! renderer holds it, every light's maps, and the image's targets. An upload checks
//! the scene's part; every frame checks the whole against the renderer's budget.

use gnomon_scene::{
    Scene,
    lights::ShadowView,
    memory::{self, Charge, FrameBudget},
    settings::{Partition, Refine, Settings},
};

use super::Renderer;
use crate::RenderError;

impl Renderer {
    /// The bytes the renderer may hold for a frame, and where that limit came from.
    pub fn memory_budget(&self) -> &FrameBudget {
        &self.memory_budget
    }

    /// Sets the bytes the renderer may hold for a frame (a host that knows what its
    /// own device and application can spare); the default is
    /// [`memory::frame_budget`].
    pub fn set_memory_budget(&mut self, bytes: u64) {
        self.memory_budget = FrameBudget { bytes, source: "set by the host".into() };
    }

    /// Makes the budget [`memory::frame_budget_beside`] `window`: for a front end
    /// whose image is as large as a window the user sized (the viewer).
    pub fn make_room_for_window(&mut self, window: memory::Window) -> Result<(), RenderError> {
        self.memory_budget = memory::frame_budget_beside(Some(window)).map_err(RenderError::MemoryBudget)?;
        Ok(())
    }

    /// Refuses `scene` if holding it would pass the budget.
    pub(super) fn check_scene_memory(&self, scene: &Scene) -> Result<(), RenderError> {
        memory::refuse_over(&memory::scene_charges(scene), self.memory_budget())
            .map_err(|e| RenderError::OverBudget { scene: scene.name.clone(), over: e })
    }

    /// Refuses a frame of `scene` with `settings` if it would pass the budget: the
    /// scene, each light's maps and the image's targets.
    pub(super) fn check_frame_memory(&self, scene: &Scene, settings: &Settings) -> Result<(), RenderError> {
        let mut charges = memory::scene_charges(scene);
        let (width, height) = (settings.image.width, settings.image.height);
        charges.push(Charge {
            what: format!("the image's targets, {width}×{height}"),
            bytes: memory::pixels(width, height).saturating_mul(memory::BYTES_PER_PIXEL),
        });
        for light in settings.resolve_lights(scene)? {
            let shadow = &light.shadow;
            let side = u64::from(shadow.map.resolution);
            let cascades = match shadow.partition {
                Partition::Cascades => u64::from(shadow.cascades.count),
                Partition::Single | Partition::Virtual => 1,
            };
            let layers = match light.light.shadow_view() {
                ShadowView::Parallel { .. } => cascades,
                ShadowView::Frustum { .. } => 1,
                // A cube's six faces (two paraboloids take fewer: charged as a cube).
                ShadowView::Omni { .. } => 6,
            };
            // The light's own technique check first: a technique that cannot shadow it
            // is that error, not a budget's.
            let technique = self.techniques.check_light(shadow, &light.light, &light.name)?;
            let filterable = technique.filterable_map(&shadow.filter).is_some();
            // A 2D map that rays may refine has a touched layer beside it (charged
            // whether or not the frame's plan then draws one).
            let refined = match settings.screen.refine {
                Refine::Auto | Refine::Rays => true,
                Refine::Off | Refine::EveryPixel => false,
            };
            let two_d = match light.light.shadow_view() {
                ShadowView::Parallel { .. } | ShadowView::Frustum { .. } => true,
                ShadowView::Omni { .. } => false,
            };
            let paged = match shadow.partition {
                Partition::Virtual => true,
                Partition::Single | Partition::Cascades => false,
            };
            let touched = if refined && two_d && !paged { memory::BYTES_PER_TOUCHED_TEXEL } else { 0 };
            let per_texel = memory::BYTES_PER_MAP_TEXEL
                + touched
                + if filterable { memory::BYTES_PER_MOMENT_TEXEL } else { 0 };
            charges.push(Charge {
                what: format!("light `{}`'s map, {layers} × {side}²", light.name),
                bytes: (side * side * layers).saturating_mul(per_texel),
            });
        }
        memory::refuse_over(&charges, self.memory_budget())
            .map_err(|e| RenderError::OverBudget { scene: scene.name.clone(), over: e })
    }
}
