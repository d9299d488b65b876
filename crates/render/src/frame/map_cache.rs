//! Shadow maps kept across frames (`--map-cache still-casters`): each light's layers
//! keep what its still casters (`Motion::Static`) drew, and a layer draws them again
//! only when something they depend on changed. The casters that move
//! (`Motion::Dynamic`) are drawn every frame over a copy of the kept layer, so a
//! still scene under a still light draws no shadow pass at all.
//!
//! What a layer's still casters draw depends on the layer's uniform as the shadow
//! pass reads it (its projection, the light's position and range, the distance
//! bias), the pipeline state (bias, cull mode, depth target, clamping), and where
//! the still casters are: [`LayerKey`] holds all of it, the last as
//! `GpuScene::still_generation`, which moving a still caster renews. A key equal to
//! the kept one keeps the layer. One that differs only by a parallel projection
//! moved across the map by whole texels (a stable cascade following the camera)
//! scrolls it, clipmap style (Tanner, Migdal & Jones, "The clipmap", 1998), and
//! draws only the strips it newly covers. Any other difference draws the layer again.

use gnomon_scene::settings::BiasSettings;

use super::{derived_cache::DerivedCache, moment_cache::MomentCache, plan::LightPlan};
use crate::passes::SHADOW_FORMAT;
use crate::rays::{Pyramid, Touched};

/// Everything a layer's still casters' depth depends on: its projection, and the
/// rest as bytes compared whole.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct LayerKey {
    state: Vec<u8>,
    clip_from_world: glam::Mat4,
}

impl LayerKey {
    /// The key of layer `layer` of `light`, with the scene's still casters as
    /// `still_generation` names them.
    pub fn of(light: &LightPlan, layer: usize, still_generation: u64) -> LayerKey {
        // What the shadow pass reads of its layer's uniform (a test below holds
        // `shadow_depth.wgsl` to it): the projection, kept apart for scrolling, and
        // what the distance passes bias by.
        let uniform = light.light_gpu.for_layer(layer);
        let clip_from_world = uniform.clip_from_world;
        let emitter = uniform.emitter;
        let read = [emitter.position.x, emitter.position.y, emitter.position.z, emitter.range];
        let mut bytes: Vec<u8> = bytemuck::cast_slice(&read).to_vec();
        bytes.extend_from_slice(bytemuck::bytes_of(&uniform.bias.depth));
        bytes.extend_from_slice(bytemuck::bytes_of(&uniform.bias.slope));
        // The pipeline's state, and where the still casters are.
        let BiasSettings { depth_bias, slope_bias, normal_offset: _, cull } = light.settings.shadow.bias;
        let state = format!(
            "{still_generation} {depth_bias} {:x} {cull:?} {:?} {} {:?}",
            slope_bias.to_bits(),
            light.depth_target(),
            light.layout.depth_clamp,
            light.map_size(),
        );
        bytes.extend_from_slice(state.as_bytes());
        LayerKey { state: bytes, clip_from_world }
    }

    /// How far a layer drawn under `kept` must scroll to be this one, as the offset
    /// from a texel to the kept texel that holds its depth: where everything but the
    /// projection is the same, and the projection is the kept one's moved across the
    /// map by whole texels (a stable cascade following the camera, whose window snaps
    /// to texels; `gnomon_math::cascades`). None otherwise, or where it moved by the
    /// whole map or more.
    pub fn scroll_from(&self, kept: &LayerKey, resolution: u32) -> Option<[i32; 2]> {
        if self.state != kept.state {
            return None;
        }
        let (new, old) = (self.clip_from_world.transpose(), kept.clip_from_world.transpose());
        // Rows x, y, z, w of each matrix; a parallel projection has w = (0, 0, 0, 1).
        let (nx, ny, nz, nw) = (new.x_axis, new.y_axis, new.z_axis, new.w_axis);
        let (ox, oy, oz, ow) = (old.x_axis, old.y_axis, old.z_axis, old.w_axis);
        let close = |a: glam::Vec4, b: glam::Vec4| {
            (a - b).abs().max_element() <= 1e-6 * a.abs().max_element().max(f32::MIN_POSITIVE)
        };
        let axes = |row: glam::Vec4| row.truncate().extend(0.0);
        let same_axes = close(axes(nx), axes(ox)) && close(axes(ny), axes(oy)) && close(nz, oz);
        if nw != glam::Vec4::W || ow != glam::Vec4::W || !same_axes {
            return None;
        }
        // A world point moves by the change of the x and y rows' constant terms in
        // NDC: R/2 texels per NDC unit, with texture rows running down.
        let half = resolution as f32 / 2.0;
        let whole = |k: f32| {
            let rounded = k.round();
            ((k - rounded).abs() <= 1e-2 && rounded.abs() < resolution as f32).then_some(rounded as i32)
        };
        let (kx, ky) = (whole((nx.w - ox.w) * half)?, whole((ny.w - oy.w) * half)?);
        Some([-kx, ky])
    }
}

/// How a shadow-map layer was drawn in a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayerCache {
    /// Every caster was drawn (`--map-cache off`, or a technique that reads no map).
    Off,
    /// Its still casters were drawn into its cache, which had nothing valid to keep.
    Drawn,
    /// Its cache was kept: only the casters that move were drawn, if any.
    Kept,
    /// Its cache was moved by whole texels, and its still casters drawn only into the
    /// strips it newly covers.
    Scrolled,
}

/// What a frame does with a layer's cache.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum LayerPlan {
    /// Draw its still casters into it, cleared.
    Draw,
    /// Keep it as it is.
    Keep,
    /// Move it so that each texel takes the depth of the texel this offset away, then
    /// draw its still casters into the strips no texel covered.
    Scroll([i32; 2]),
}

impl LayerPlan {
    /// What [`LightStats::layer_cache`](super::LightStats::layer_cache) reports.
    pub fn reported(self) -> LayerCache {
        match self {
            LayerPlan::Draw => LayerCache::Drawn,
            LayerPlan::Keep => LayerCache::Kept,
            LayerPlan::Scroll(_) => LayerCache::Scrolled,
        }
    }
}

/// One light's kept layers.
struct CachedMap {
    texture: wgpu::Texture,
    /// Each layer's key when it was drawn; None for one never drawn.
    keys: Vec<Option<LayerKey>>,
}

/// Every light's kept map, by the light's index in the frame.
#[derive(Default)]
pub(super) struct MapCache {
    lights: Vec<Option<CachedMap>>,
    /// What the last recorded frame did with each light's layers.
    uses: Vec<Vec<LayerCache>>,
    /// Whether each light's map this frame is its kept map unchanged: every layer
    /// kept, and no caster moving over it.
    kept_whole: Vec<bool>,
    /// Cache textures created, for [`super::Renderer::creations`].
    created: u64,
    /// The moment maps filtered from the kept maps.
    pub moments: MomentCache,
    /// The depth pyramids built from them.
    pub pyramids: DerivedCache<Pyramid>,
    /// The touched layers drawn with them (`rays/touched.rs`).
    pub touched: DerivedCache<Touched>,
}

impl MapCache {
    /// A new frame of `lights` lights: forgets what the last one did.
    pub fn begin_frame(&mut self, lights: usize) {
        self.uses = vec![Vec::new(); lights];
        self.kept_whole = vec![false; lights];
        self.lights.resize_with(lights.max(self.lights.len()), || None);
    }

    /// Light `index`'s map this frame is its kept map unchanged.
    pub fn mark_kept_whole(&mut self, index: usize) {
        self.kept_whole[index] = true;
    }

    /// Whether light `index`'s map this frame is its kept map unchanged.
    pub fn kept_whole(&self, index: usize) -> bool {
        self.kept_whole.get(index).copied().unwrap_or(false)
    }

    /// Light `index` drew its `layers` layers without the cache: its kept map is
    /// dropped.
    pub fn bypass(&mut self, index: usize, layers: usize) {
        self.lights[index] = None;
        self.uses[index] = vec![LayerCache::Off; layers];
    }

    /// Light `index`'s kept map for `keys` (one per layer): the texture, created
    /// where none of `size` is kept, and per layer whether it is kept or must be
    /// drawn. The keys are taken as drawn: the caller draws every `Drawn` layer.
    pub fn take(
        &mut self,
        device: &wgpu::Device,
        index: usize,
        size: wgpu::Extent3d,
        keys: Vec<LayerKey>,
    ) -> (wgpu::Texture, Vec<LayerPlan>) {
        let fits = |kept: &CachedMap| kept.texture.size() == size;
        let cached = match self.lights[index].take() {
            Some(kept) if fits(&kept) => kept,
            _ => {
                self.created += 1;
                CachedMap {
                    texture: create_cache(device, size),
                    keys: vec![None; size.depth_or_array_layers as usize],
                }
            }
        };
        let plans: Vec<LayerPlan> = keys
            .iter()
            .zip(&cached.keys)
            .map(|(key, kept)| match kept {
                Some(kept) if kept == key => LayerPlan::Keep,
                Some(kept) => key.scroll_from(kept, size.width).map_or(LayerPlan::Draw, LayerPlan::Scroll),
                None => LayerPlan::Draw,
            })
            .collect();
        let texture = cached.texture.clone();
        self.lights[index] =
            Some(CachedMap { texture: cached.texture, keys: keys.into_iter().map(Some).collect() });
        self.uses[index] = plans.iter().map(|p| p.reported()).collect();
        (texture, plans)
    }

    /// What the last recorded frame did with each light's layers.
    pub fn uses(&self) -> &[Vec<LayerCache>] {
        &self.uses
    }

    /// How many cache textures it has created, moment maps, pyramids and touched
    /// layers included.
    pub fn created(&self) -> u64 {
        self.created + self.moments.created() + self.pyramids.created() + self.touched.created()
    }
}

/// A cache texture: kept across frames, made again only when the map's size changes,
/// so not a per-frame resource of the pool's (but counted in the renderer's
/// creations).
fn create_cache(device: &wgpu::Device, size: wgpu::Extent3d) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("shadow map cache"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: SHADOW_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

#[cfg(test)]
mod tests {
    /// What [`super::LayerKey`] holds of the light's uniform.
    const KEYED: [&str; 5] =
        ["clip_from_world", "emitter.position", "emitter.range", "bias.depth", "bias.slope"];

    /// [`super::LayerKey`] keeps only the fields of the light's uniform that the
    /// shadow pass reads: sound only while `shadow_depth.wgsl` reads no other, and
    /// calls none of the functions of the light's modules (`light_binding.wgsl`'s,
    /// the light kinds' and their shapes', which read more).
    #[test]
    fn the_shadow_pass_reads_only_what_the_key_holds() {
        let wgsl = include_str!("../passes/shadow_depth.wgsl");
        for (at, _) in wgsl.match_indices("light.") {
            let before = wgsl[..at].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            let path: String = wgsl[at + 6..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == '.')
                .collect();
            let field = path.trim_end_matches('.');
            if field.is_empty() {
                continue; // the end of a sentence in a comment
            }
            assert!(KEYED.contains(&field), "shadow_depth.wgsl reads light.{field}, which no key holds");
        }
        let light_modules =
            ["passes::light", "passes::light_binding", "passes::light_kinds", "passes::light_shapes"];
        let sources: Vec<&str> = crate::passes::link::MODULES
            .iter()
            .filter(|m| light_modules.contains(&m.path))
            .map(|m| m.source)
            .collect();
        assert_eq!(sources.len(), light_modules.len(), "the light's modules moved");
        for line in sources.iter().flat_map(|s| s.lines()).filter_map(|l| l.strip_prefix("fn ")) {
            let name: String = line.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            assert!(!wgsl.contains(&format!("{name}(")), "shadow_depth.wgsl calls the light's {name}");
        }
    }

    /// A parallel layer moved by whole texels scrolls; anything else is drawn again.
    #[test]
    fn a_key_scrolls_from_one_moved_by_whole_texels() {
        use glam::{Mat4, Vec3};
        let ortho = |x: f32, y: f32| {
            let window = (x - 4.0, x + 4.0, y - 4.0, y + 4.0);
            gnomon_math::LightProjection::orthographic(Mat4::IDENTITY, window, 0.1, 10.0).clip_from_world()
        };
        let key = |clip_from_world| super::LayerKey { state: vec![1, 2, 3], clip_from_world };
        // 8 world units over 64 texels: one texel is 0.125.
        let kept = key(ortho(0.0, 0.0));
        assert_eq!(key(ortho(0.25, 0.0)).scroll_from(&kept, 64), Some([2, 0]));
        assert_eq!(key(ortho(0.0, 0.375)).scroll_from(&kept, 64), Some([0, -3]));
        assert_eq!(key(ortho(0.1, 0.0)).scroll_from(&kept, 64), None, "not whole texels");
        assert_eq!(key(ortho(9.0, 0.0)).scroll_from(&kept, 64), None, "off the map");
        let mut other = key(ortho(0.25, 0.0));
        other.state = vec![1, 2, 4];
        assert_eq!(other.scroll_from(&kept, 64), None, "another state");
        let perspective = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 10.0);
        let moved = perspective * Mat4::from_translation(Vec3::X * 0.25);
        assert_eq!(key(moved).scroll_from(&key(perspective), 64), None, "perspective layers do not scroll");
    }
}
