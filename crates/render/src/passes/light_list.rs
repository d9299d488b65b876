//! The light-list lighting pass (tiled forward shading, after Olsson & Assarsson,
//! "Tiled shading", JGT 2011): on the mask path, one pass draws the scene once and
//! each pixel sums every light whose range reaches its tile, reading each light's
//! visibility from its layer of the shadow mask, instead of one pass per light. Owns
//! the emitter array, the per-tile light bits (built on the CPU from each light's
//! screen bounds, [`gnomon_math::screen_bounds`]) and the pipeline.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use gnomon_math::screen_bounds::{PerspectiveCamera, PixelRect, Viewport};
use gnomon_scene::{Light, lights::Origin, settings::MAX_LIGHTS};

use super::{
    Layouts, compose_wgsl, fragment_entry,
    lighting::{self, SurfaceDepth, SurfacePipeline, TARGETS},
    texture, uniform_entry,
};

/// Pixels per side of a tile of the light list.
pub(crate) const LIGHT_TILE: u32 = 16;
/// 32-bit words of light bits per tile: one bit per light a frame may have.
pub(crate) const LIGHT_WORDS: usize = MAX_LIGHTS.div_ceil(32);

/// The light-list pass's uniform (`LightList` in light_list.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightListGpu {
    /// The ambient light, added once.
    pub ambient: Vec3,
    /// The reported light, whose visibility the pass writes.
    pub shown: u32,
    /// Tiles per row of the image.
    pub tiles_x: u32,
    /// Padding to WGSL's 16-byte struct alignment.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// Where a light can reach: everywhere (a sun), or a ball (a spot's or point
/// light's range; a spot's cone lies inside it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Reach {
    Everywhere,
    Ball { centre: Vec3, radius: f32 },
}

impl Reach {
    pub fn of(light: &Light) -> Self {
        match light.emission().origin {
            Origin::Infinite { .. } => Reach::Everywhere,
            Origin::Local { position, range, .. } => Reach::Ball { centre: position, radius: range },
        }
    }

    /// The pixels it can light, seen by `camera`; `None` for none.
    pub fn rect(&self, camera: &PerspectiveCamera) -> Option<PixelRect> {
        match *self {
            Reach::Everywhere => Some(PixelRect::whole(camera.viewport)),
            Reach::Ball { centre, radius } => camera.sphere_rect(centre, radius),
        }
    }
}

/// Which lights each tile of the image lists: a bit per light, [`LIGHT_WORDS`] words
/// per tile, row by row; and each light's pixel rectangle, widened to whole tiles (and
/// cut to the image), so that a pass that writes a light's rectangle writes every pixel
/// that the list reads for it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct LightTiles {
    pub tiles_x: u32,
    pub tiles_y: u32,
    pub bits: Vec<u32>,
    /// Each light's pixels, `None` where it reaches none.
    pub rects: Vec<Option<PixelRect>>,
}

impl LightTiles {
    /// The tiles of `camera`'s image that each of `reaches` (at most `MAX_LIGHTS`)
    /// can light: every tile its rectangle touches.
    pub fn new(camera: &PerspectiveCamera, reaches: &[Reach]) -> Self {
        debug_assert!(reaches.len() <= MAX_LIGHTS, "the settings hold a frame to MAX_LIGHTS lights");
        let Viewport { width, height } = camera.viewport;
        let (tiles_x, tiles_y) = (width.div_ceil(LIGHT_TILE), height.div_ceil(LIGHT_TILE));
        let mut bits = vec![0u32; (tiles_x * tiles_y) as usize * LIGHT_WORDS];
        let mut rects = Vec::with_capacity(reaches.len());
        for (light, reach) in reaches.iter().enumerate() {
            let Some(rect) = reach.rect(camera) else {
                rects.push(None);
                continue;
            };
            let (word, bit) = (light / 32, 1u32 << (light % 32));
            let columns = rect.x / LIGHT_TILE..(rect.x + rect.width).div_ceil(LIGHT_TILE);
            let rows = rect.y / LIGHT_TILE..(rect.y + rect.height).div_ceil(LIGHT_TILE);
            for ty in rows.clone() {
                for tx in columns.clone() {
                    bits[(ty * tiles_x + tx) as usize * LIGHT_WORDS + word] |= bit;
                }
            }
            let (x, y) = (columns.start * LIGHT_TILE, rows.start * LIGHT_TILE);
            rects.push(Some(PixelRect {
                x,
                y,
                width: (columns.end * LIGHT_TILE).min(width) - x,
                height: (rows.end * LIGHT_TILE).min(height) - y,
            }));
        }
        Self { tiles_x, tiles_y, bits, rects }
    }

    /// The lights tile (`tx`, `ty`) lists, in order.
    #[cfg(test)]
    pub fn listed(&self, tx: u32, ty: u32) -> Vec<usize> {
        let first = (ty * self.tiles_x + tx) as usize * LIGHT_WORDS;
        let words = &self.bits[first..first + LIGHT_WORDS];
        (0..LIGHT_WORDS * 32).filter(|&i| words[i / 32] & (1 << (i % 32)) != 0).collect()
    }
}

/// The light-list pass's WGSL, composed.
pub(crate) fn light_list_wgsl() -> String {
    let mut parts = lighting::camera_shading_wgsl();
    parts.push(lighting::SURFACE_WGSL.to_owned());
    parts.push(lighting::LIGHTING_COMMON_WGSL.to_owned());
    parts.extend(lighting::seen_surface_wgsl(lighting::Lookup::Mask));
    parts.push(include_str!("light_list.wgsl").to_owned());
    let refs: Vec<&str> = parts.iter().map(String::as_str).collect();
    compose_wgsl(&refs)
}

/// The light-list pipeline, built on first use (a host's device opened with wgpu's
/// default limits has too few colour-attachment bytes for it, and never draws it), and
/// the layout of its group 2.
pub(crate) struct LightListPass {
    /// Group 2: the list's uniform, the emitters, the tiles' light bits and the mask.
    pub group_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    pipeline: Option<wgpu::RenderPipeline>,
}

impl LightListPass {
    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let mask = texture(
            wgpu::TextureSampleType::Float { filterable: false },
            wgpu::TextureViewDimension::D2Array,
        );
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("light list"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::FRAGMENT),
                fragment_entry(1, storage),
                fragment_entry(2, storage),
                fragment_entry(3, mask),
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("light list"),
            bind_group_layouts: &[
                Some(&layouts.scene),
                Some(&layouts.screen),
                Some(&group_layout),
                Some(&layouts.material),
            ],
            immediate_size: 0,
        });
        Self { group_layout, layout, pipeline: None }
    }

    /// The pipeline: groups 0 (the scene and the first light), 1 (the camera and the
    /// prepass's outputs), 2 (`group_layout`) and 3 (each draw's material).
    pub fn pipeline(&mut self, device: &wgpu::Device) -> &wgpu::RenderPipeline {
        let layout = &self.layout;
        self.pipeline.get_or_insert_with(|| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("light list"),
                source: wgpu::ShaderSource::Wgsl(light_list_wgsl().into()),
            });
            let targets: Vec<Option<wgpu::ColorTargetState>> =
                TARGETS.iter().map(|&format| Some(wgpu::ColorTargetState::from(format))).collect();
            // The prepass drew the depths: each pixel shades exactly the surface the mask
            // passes saw.
            SurfacePipeline {
                label: "light list",
                layout,
                module: &module,
                fragment_entry: "fs_light_list",
                targets: &targets,
                depth: SurfaceDepth::Equal,
            }
            .create(device)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;

    fn camera() -> PerspectiveCamera {
        PerspectiveCamera {
            view_from_world: Mat4::IDENTITY,
            fov_y: 90f32.to_radians(),
            near: 0.1,
            viewport: Viewport { width: 100, height: 60 },
        }
    }

    #[test]
    fn a_tile_lists_exactly_the_lights_whose_rect_touches_it() {
        let reaches = [
            Reach::Ball { centre: Vec3::new(0.0, 0.0, -10.0), radius: 1.0 },
            Reach::Everywhere,
            Reach::Ball { centre: Vec3::new(0.0, 0.0, 10.0), radius: 1.0 },
            Reach::Ball { centre: Vec3::new(-8.0, 4.0, -10.0), radius: 1.0 },
        ];
        let tiles = LightTiles::new(&camera(), &reaches);
        assert_eq!((tiles.tiles_x, tiles.tiles_y), (7, 4));
        assert_eq!(tiles.rects[2], None, "the ball behind the eye reaches no pixel");
        for ty in 0..tiles.tiles_y {
            for tx in 0..tiles.tiles_x {
                let touches = |rect: &PixelRect| {
                    let (x0, y0) = (tx * LIGHT_TILE, ty * LIGHT_TILE);
                    rect.x < x0 + LIGHT_TILE
                        && x0 < rect.x + rect.width
                        && rect.y < y0 + LIGHT_TILE
                        && y0 < rect.y + rect.height
                };
                let expected: Vec<usize> =
                    (0..reaches.len()).filter(|&i| tiles.rects[i].as_ref().is_some_and(touches)).collect();
                assert_eq!(tiles.listed(tx, ty), expected, "tile ({tx}, {ty})");
                for rect in tiles.rects.iter().flatten() {
                    // Whole tiles: a tile is inside a light's rectangle or outside it.
                    let inside = touches(rect) && rect.contains(tx * LIGHT_TILE, ty * LIGHT_TILE);
                    assert_eq!(touches(rect), inside, "tile ({tx}, {ty}) straddles {rect:?}");
                }
                assert!(expected.contains(&1), "the sun reaches every tile");
            }
        }
        // The centred ball and the one up and to the left land in different tiles.
        assert!(tiles.listed(3, 2).contains(&0) && !tiles.listed(3, 2).contains(&3));
        assert!(tiles.listed(1, 1).contains(&3) && !tiles.listed(1, 1).contains(&0));
    }

    #[test]
    fn the_last_light_a_frame_may_have_gets_its_own_bit() {
        let mut reaches = vec![Reach::Ball { centre: Vec3::new(0.0, 0.0, 10.0), radius: 1.0 }; MAX_LIGHTS];
        reaches[MAX_LIGHTS - 1] = Reach::Everywhere;
        let tiles = LightTiles::new(&camera(), &reaches);
        assert_eq!(tiles.listed(0, 0), vec![MAX_LIGHTS - 1]);
    }
}
