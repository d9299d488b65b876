//! A point light's virtual map: its six cube faces side by side in one map space,
//! each a spot's perspective map round one face, so that everything paged about a
//! spot (a mip chain of fixed windows, pages drawn through a perspective window,
//! texels growing with the distance) holds face by face.
//!
//! The faces lie in slots of 2 × 2 map units, four across and two down ([`face_slot`]),
//! inside a square window 8 map units wide. So level 0's texel is a power of two in
//! map units (`8 / virtual_resolution`: a face is a quarter of the level's texels
//! across, 4096 in a 16384² level) and every slot's border is a page border at every
//! level. A slot holds its face's frustum a little wider than the face
//! ([`CUBE_FACE_TAN_HALF_FOV`]): a guard band round the face, drawn through the same
//! projection, so that a filter tap or a footprint test of a point near the face's
//! border reads depths of the same face's projection rather than the neighbouring
//! slot's, which hold other directions. No page, run or dirty rectangle crosses a
//! slot's border; the chain stops where a face is 2 × 2 pages.
//!
//! Each face's view is a rotation (determinant +1, so its pages are drawn with the
//! same winding as any map's), not the mirrored frame of a cube texture's faces
//! ([`crate::omni::cube_face_view`]): nothing here samples a cube texture.

use glam::{IVec2, Mat3, Mat4, Vec2, Vec3};

use super::{Clipmap, ClipmapShape, MapFrame, MapProjection, PageKey, PageRect};
use crate::{Aabb, omni::CubeFace};

/// The tangent of the half-angle of each face's frustum in its slot: 1 would be the
/// face itself (90°); 1/8 more is a guard band of an eighteenth of the slot on each
/// side, 14 texels of the coarsest level's (a face of 2 × 2 pages of 128²), wider
/// than a pcf kernel, its footprint test's ring and normal offset reach there.
pub const CUBE_FACE_TAN_HALF_FOV: f32 = 1.125;

/// Map units across a face's slot: its frustum's normalized device coordinates.
const SLOT_WIDTH: f32 = 2.0;

/// Slots across the map's window; the faces fill two rows of them.
const SLOT_COLUMNS: u32 = 4;

/// Map units across each level's window: four slots.
const WINDOW_WIDTH: f32 = SLOT_WIDTH * SLOT_COLUMNS as f32;

/// Face `face`'s view axes in the light's (world-aligned) space: x, y and the
/// direction it looks in, right-handed (x × y = −look, since views look down −z).
fn face_axes(face: CubeFace) -> [Vec3; 3] {
    match face {
        CubeFace::PositiveX => [Vec3::Z, Vec3::Y, Vec3::X],
        CubeFace::NegativeX => [Vec3::NEG_Z, Vec3::Y, Vec3::NEG_X],
        CubeFace::PositiveY => [Vec3::X, Vec3::Z, Vec3::Y],
        CubeFace::NegativeY => [Vec3::X, Vec3::NEG_Z, Vec3::NEG_Y],
        CubeFace::PositiveZ => [Vec3::NEG_X, Vec3::Y, Vec3::Z],
        CubeFace::NegativeZ => [Vec3::X, Vec3::Y, Vec3::NEG_Z],
    }
}

/// The centre of `face`'s slot in map space: layers 0 to 3 across the upper row
/// (y in [0, 2]), 4 and 5 on the left of the lower one (`map_frame` in
/// map_space.wgsl).
pub fn face_slot(face: CubeFace) -> Vec2 {
    let (column, row) = (face.layer() % SLOT_COLUMNS, face.layer() / SLOT_COLUMNS);
    let half = SLOT_WIDTH / 2.0;
    Vec2::new(-WINDOW_WIDTH / 2.0 + half + SLOT_WIDTH * column as f32, half - SLOT_WIDTH * row as f32)
}

/// The centre of the slot that map-space point `xy` lies in (its lower and left
/// borders included).
fn slot_of(xy: Vec2) -> Vec2 {
    (xy / SLOT_WIDTH).floor() * SLOT_WIDTH + Vec2::splat(SLOT_WIDTH / 2.0)
}

impl Clipmap {
    /// The clipmap of a point light at `position` whose casters lie from `near` to
    /// `far` of it along each face's axis: six spot-like mip chains, one a face, each
    /// level's window holding all six slots (`8 × 8` map units). Level 0's texels are
    /// `8 / virtual_resolution` map units; each coarser level halves the texels over a
    /// face, down to 2 × 2 pages a face; `shape.levels` is cut to those levels
    /// (`log2(pages_per_side / 4)`, at least 1: a shape of fewer than 8 pages a side
    /// has faces of less than 2 × 2 pages and only one level).
    pub fn point(shape: ClipmapShape, position: Vec3, near: f32, far: f32) -> Clipmap {
        let chain = (shape.pages_per_side() / 4).max(2).ilog2();
        let shape = ClipmapShape { levels: shape.levels.min(chain), ..shape };
        let finest_texel = WINDOW_WIDTH / shape.virtual_resolution as f32;
        let half = (shape.pages_per_side() / 2) as i32;
        let origins = vec![IVec2::splat(-half); shape.levels as usize];
        let light_from_world = Mat4::from_translation(-position);
        Clipmap { shape, light_from_world, projection: MapProjection::Cube, finest_texel, origins, near, far }
    }

    /// The frame of cube face `face` of a point light's map.
    pub fn face_frame(&self, face: CubeFace) -> MapFrame {
        let [x, y, look] = face_axes(face);
        let view_from_light = Mat4::from_mat3(Mat3::from_cols(x, y, -look).transpose());
        MapFrame { view_from_world: view_from_light * self.light_from_world, slot: face_slot(face) }
    }

    /// The frame that draws the pages of `rect` (which lie in one face's slot for a
    /// point light: the face whose slot's centre is nearest theirs), or the light's
    /// for a sun or a spot.
    pub(super) fn rect_frame(&self, rect: &PageRect) -> MapFrame {
        match self.projection {
            MapProjection::Cube => {
                let size = self.page_size(rect.level);
                let centre = (rect.min + rect.max + IVec2::ONE).as_vec2() * 0.5 * size;
                let nearest = |f: &CubeFace| face_slot(*f).distance_squared(centre);
                let faces = CubeFace::ALL.into_iter();
                self.face_frame(
                    faces.min_by(|a, b| nearest(a).total_cmp(&nearest(b))).unwrap_or(CubeFace::PositiveX),
                )
            }
            MapProjection::Orthographic | MapProjection::Perspective { .. } => {
                MapFrame { view_from_world: self.light_from_world, slot: Vec2::ZERO }
            }
        }
    }

    /// The pages of `level` in the slot centred at `slot`.
    fn slot_pages(&self, level: u32, slot: Vec2) -> PageRect {
        let size = self.page_size(level);
        let half = SLOT_WIDTH / 2.0;
        // Slot borders are whole pages at every level (a face is at least 2 pages).
        let min = ((slot - half) / size).round().as_ivec2();
        let max = ((slot + half) / size).round().as_ivec2() - IVec2::ONE;
        PageRect { level, min, max }
    }

    /// The pages of `level` over the square `half` map units round `centre`, clipped
    /// to the level's window and, for a point light, to the slot of the face that
    /// holds `centre`: its filter's taps past the slot would read other directions.
    pub(super) fn pages_around(&self, level: u32, centre: Vec2, half: f32) -> Option<PageRect> {
        let rect = self.pages_over(level, centre - Vec2::splat(half), centre + Vec2::splat(half))?;
        match self.projection {
            MapProjection::Cube => intersect(rect, self.slot_pages(level, slot_of(centre))),
            MapProjection::Orthographic | MapProjection::Perspective { .. } => Some(rect),
        }
    }

    /// The pages of `level` that a caster within `bounds` can write in a point
    /// light's faces: in each face, the rectangle that the part of the box beyond the
    /// face's near plane covers (clipped to the face's slot); nothing where no part is.
    /// A face's view only permutes and flips the world's axes, so the box stays a box
    /// in it, and clipping it at the near plane is clamping its depth.
    pub(super) fn cube_pages_under(&self, level: u32, bounds: &Aabb) -> Vec<PageRect> {
        let tan_half_fov = CUBE_FACE_TAN_HALF_FOV;
        CubeFace::ALL
            .into_iter()
            .filter_map(|face| {
                let frame = self.face_frame(face);
                let mut view = bounds.transformed(frame.view_from_world);
                // The view looks down −z: beyond the near plane is z ≤ −near.
                view.max.z = view.max.z.min(-self.near);
                if view.min.z > view.max.z {
                    return None;
                }
                let map = view.corners().map(|c| c.truncate() / (tan_half_fov * -c.z) + frame.slot);
                let low = map.iter().copied().fold(Vec2::INFINITY, Vec2::min);
                let high = map.iter().copied().fold(Vec2::NEG_INFINITY, Vec2::max);
                intersect(self.pages_over(level, low, high)?, self.slot_pages(level, frame.slot))
            })
            .collect()
    }

    /// Whether `page` is the first of its row in its layer ([`Clipmap::layers`]):
    /// the left border of a point light's face's slot, where a run of pages drawn
    /// through one projection must stop ([`super::runs::runs`]). Never for a sun or a
    /// spot, whose level is one layer.
    pub fn starts_layer(&self, page: PageKey) -> bool {
        match self.projection {
            MapProjection::Cube => {
                let left = page.x as f32 * self.page_size(page.level);
                (left / SLOT_WIDTH).fract() == 0.0
            }
            MapProjection::Orthographic | MapProjection::Perspective { .. } => false,
        }
    }

    /// The map's layers, each a rectangle of pages one projection draws: each
    /// level's window for a sun or a spot (finest first); for a point light, each
    /// level's six faces' slots, level by level, faces in layer order.
    pub fn layers(&self) -> Vec<PageRect> {
        (0..self.shape.levels)
            .flat_map(|level| match self.projection {
                MapProjection::Cube => CubeFace::ALL.map(|f| self.slot_pages(level, face_slot(f))).to_vec(),
                MapProjection::Orthographic | MapProjection::Perspective { .. } => {
                    vec![self.level_window(level)]
                }
            })
            .collect()
    }

    /// The window of `pages_per_side`² pages centred on layer `layer` (one of
    /// [`Clipmap::layers`]): a sun's or a spot's level's own window; round a point
    /// light's face's slot, its projection reaching on past the slot in the face's
    /// frustum. So every layer's window is `virtual_resolution` texels across, as one
    /// texture of it would be.
    pub fn layer_window(&self, layer: &PageRect) -> PageRect {
        let half = (self.shape.pages_per_side() / 2) as i32;
        let centre = (layer.min + layer.max + IVec2::ONE).div_euclid(IVec2::splat(2));
        PageRect {
            level: layer.level,
            min: centre - IVec2::splat(half),
            max: centre + IVec2::splat(half - 1),
        }
    }

    /// The index in [`Clipmap::layers`] of `level`'s layer that holds world point
    /// `world`.
    pub fn layer_of(&self, level: u32, world: Vec3) -> usize {
        match self.projection {
            MapProjection::Cube => {
                let direction = self.light_from_world.transform_point3(world);
                level as usize * CubeFace::ALL.len() + CubeFace::of_direction(direction).layer() as usize
            }
            MapProjection::Orthographic | MapProjection::Perspective { .. } => level as usize,
        }
    }
}

/// The pages two rectangles of one level share; None where they share none.
fn intersect(a: PageRect, b: PageRect) -> Option<PageRect> {
    let (min, max) = (a.min.max(b.min), a.max.min(b.max));
    (a.level == b.level && min.cmple(max).all()).then_some(PageRect { level: a.level, min, max })
}
