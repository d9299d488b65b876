//! Virtual shadow maps for a sun, a spot or a point light: the clipmap's geometry
//! and the pages a pixel needs.
//!
//! A virtual map replaces the few large textures of cascades with a clipmap of
//! *virtual* levels around the camera, each [`ClipmapShape::virtual_resolution`]²
//! texels cut into pages of [`ClipmapShape::page_size`]², of which only the pages that
//! visible pixels read are given memory and drawn: resolution matched to the pixels'
//! footprint, as in Lefohn, Sengupta and Owens, "Resolution-Matched Shadow Maps" (ACM
//! TOG 26(4), 2007), laid out as a clipmap (Tanner, Migdal and Jones, "The Clipmap",
//! SIGGRAPH 1998) the way Unreal Engine 5's virtual shadow maps are.
//!
//! The geometry here is what the GPU passes and the page pool ([`pages`]) share:
//! - Every level projects the world into one *map space* ([`MapProjection`]): x and y
//!   in map units, and the depth the map stores. A sun's is orthographic along its rigid
//!   `light_from_world`, so its map units are world units; a spot's is its perspective
//!   frustum, so its map units are its normalized device coordinates and a texel's
//!   world size grows with the distance from the light ([`Clipmap::world_per_map`]);
//!   a point light's is six such frusta round a cube's faces, side by side ([`cube`]).
//!   Either way a plane in the world stays a plane in map space, so depth is affine
//!   in texels over a receiver's plane.
//! - Level `l`'s texels are `2^l` times level 0's, and level 0's are a power of two in
//!   map units. Pages are anchored at the map-space origin, not at the camera, so a
//!   page keeps its place in the world as the camera moves: a kept page stays valid,
//!   and the page of level `l + 1` over a point is the page of level `l` over it with
//!   its coordinates halved ([`PageKey::coarser`]).
//! - A sun's level windows of `pages_per_side`² pages are centred on the camera,
//!   snapped to whole pages ([`Clipmap::new`]). A spot's are fixed on its axis, level
//!   0's over its whole frustum: a mip chain ([`Clipmap::spot`]); a point light's hold
//!   its six faces' chains ([`Clipmap::point`]).
//! - A pixel asks for the finest level whose texels are no smaller than its footprint
//!   (about one texel per pixel), and for every page its filter and normal offset may
//!   reach ([`Clipmap::request`]).

pub mod cube;
mod map_space;
pub mod pages;
pub mod runs;

pub use map_space::{MapFrame, MapProjection};

use glam::{IVec2, Mat4, Vec2, Vec3};

use crate::{Aabb, LightProjection, ProjectionKind, projection::view_from_world_look_at};

/// The size of a virtual map: how many texels each level has and how they are paged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClipmapShape {
    /// Texels per side of each virtual level (a multiple of `page_size`).
    pub virtual_resolution: u32,
    /// Texels per side of a page.
    pub page_size: u32,
    /// Virtual levels, each covering twice the width of the one before: 1 to
    /// [`MAX_LEVELS`].
    pub levels: u32,
}

/// The most levels a clipmap may have (the GPU passes hold every level's origin in
/// one uniform).
pub const MAX_LEVELS: u32 = 16;

/// How many levels finer than [`Clipmap::search_level`]'s the refinement's search
/// over a sun's cone also reads, each in a grid [`AreaSearch::cap_texels`] round the
/// receiver (down to the receiver's own level): the search level's grid, its taps a
/// sixth of the cone apart, misses casters narrower than that, such as a post under a
/// 10° sun ([`Clipmap::finer_search_squares`]). Two: a measured
/// choice (docs/wide-suns.md). On `grazing`'s close view under a 10° sun, the
/// posts' penumbrae are as right with two as with every pixel traced, 26 % worse
/// with one; reading every finer level drew 36 % more pages than two.
pub const AREA_SEARCH_FINER_LEVELS: u32 = 2;

impl ClipmapShape {
    /// Unreal's shape: 16384² virtual texels per level in 128² pages, and 16 levels,
    /// from texels 2^15 times finer than the coarsest level's.
    pub const DEFAULT: ClipmapShape = ClipmapShape { virtual_resolution: 16384, page_size: 128, levels: 16 };

    /// Pages per side of a level.
    pub fn pages_per_side(&self) -> u32 {
        self.virtual_resolution / self.page_size
    }
}

/// One virtual page: its level and its place in that level's grid of pages, in
/// whole pages from the light-space origin (x right, y up in light space).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PageKey {
    /// Its level, 0 the finest.
    pub level: u32,
    /// Its column, in pages from the light-space origin (x right).
    pub x: i32,
    /// Its row, in pages from the light-space origin (y up).
    pub y: i32,
}

impl PageKey {
    /// The page of the next coarser level that covers this one.
    pub fn coarser(self) -> PageKey {
        PageKey { level: self.level + 1, x: self.x.div_euclid(2), y: self.y.div_euclid(2) }
    }
}

/// A rectangle of pages of one level, both ends included.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PageRect {
    /// The level of its pages.
    pub level: u32,
    /// Its first column and row.
    pub min: IVec2,
    /// Its last column and row (included).
    pub max: IVec2,
}

impl PageRect {
    /// Whether `page` lies in the rectangle.
    pub fn contains(&self, page: PageKey) -> bool {
        page.level == self.level
            && (self.min.x..=self.max.x).contains(&page.x)
            && (self.min.y..=self.max.y).contains(&page.y)
    }

    /// Every page of the rectangle.
    pub fn pages(&self) -> impl Iterator<Item = PageKey> + '_ {
        (self.min.y..=self.max.y)
            .flat_map(move |y| (self.min.x..=self.max.x).map(move |x| PageKey { level: self.level, x, y }))
    }
}

/// The refinement's search over the cone from a receiver to the light's area (its
/// footprint test's, under a light with a size whose penumbrae rays refine): the
/// cone's radius at the map's near plane ([`Clipmap::cone_radius`]), read in the
/// level whose texels it spans in at most `cap_texels` ([`Clipmap::search_level`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaSearch {
    /// The light's size: the tangent of a sun's angular radius, a spot's disk's
    /// radius in world units.
    pub light_size: f32,
    /// PCSS's `shadow.filter.pcss.max_radius`: the most texels the search spans.
    pub cap_texels: f32,
}

/// A lookup that reads the cone from its receiver to the light's area in coarser
/// levels, as PCSS's blocker search and filter do on a virtual map: a cone `c` map
/// units wide at the near plane ([`Clipmap::cone_radius`]) is read in the levels from the pixel's own up to the one whose texels
/// it spans in at most `level_cap_texels` ([`Clipmap::search_level`]), and in each of
/// them as many texels as it spans there, at most `reach_cap_texels` and at least
/// one ([`Clipmap::cone_requests`]). So a wide penumbra is read as a mip chain is,
/// in a level where it spans a bounded number of texels, however fine the pixel's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConeReach {
    /// The light's size, as [`AreaSearch::light_size`].
    pub light_size: f32,
    /// The most texels of its level the coarsest read spans: the smaller of the
    /// lookup's caps (PCSS's search's and its filter's).
    pub level_cap_texels: f32,
    /// The most texels of any level a read reaches: the larger of the caps.
    pub reach_cap_texels: f32,
}

/// Where the refinement's search over a sun's cone reads for one pixel
/// ([`Clipmap::search_square`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchSquare {
    /// The level it reads.
    pub level: u32,
    /// The pixel's map-space point, x and y: the square's centre.
    pub centre: Vec2,
    /// The cone's radius at the near plane, map units.
    pub cone: f32,
    /// The square's half-width, map units.
    pub reach: f32,
}

/// One frame's clipmap for a sun, a spot or a point light: where each level lies,
/// and its depth range.
#[derive(Clone, Debug, PartialEq)]
pub struct Clipmap {
    /// Its levels' size and paging.
    pub shape: ClipmapShape,
    /// World to the light's view space: rigid, looking along the light's travel
    /// (−z), so that light-space distances are world units.
    pub light_from_world: Mat4,
    /// How the light's view space projects into map space.
    pub projection: MapProjection,
    /// Map-space size of one texel of level 0, a power of two; level `l`'s is `2^l`
    /// times it.
    pub finest_texel: f32,
    /// Each level's first page: the level covers pages `origin .. origin +
    /// pages_per_side` in x and y.
    pub origins: Vec<IVec2>,
    /// Distance along the light's view axis of the depth-0 plane: in front of every
    /// caster a page may draw (a sun's: the whole scene).
    pub near: f32,
    /// Distance along the light's view axis of the depth-1 plane: behind the scene.
    pub far: f32,
}

impl Clipmap {
    /// The clipmap of a sun travelling along `travel`, around `camera` (the eye's
    /// world position), for a scene within `bounds` whose farthest visible pixel has
    /// a footprint of `farthest_footprint` world units. The coarsest level's texels
    /// are no finer than that footprint, so that every pixel finds its level without
    /// being clamped to one finer than it needs, and its window covers the scene
    /// twice over; each finer level halves the texel. The levels change only when the
    /// farthest footprint crosses a power of two (a turn of the light or a change of
    /// levels re-draws every page: [`pages::PagePool::invalidate_all`]).
    pub fn new(
        shape: ClipmapShape,
        travel: Vec3,
        camera: Vec3,
        bounds: &Aabb,
        farthest_footprint: f32,
    ) -> Clipmap {
        let light_from_world = view_from_world_look_at(Vec3::ZERO, travel.normalize(), Vec3::Y);
        let in_light = bounds.transformed(light_from_world);
        let width = in_light.extent().truncate().max_element().max(1e-6);
        let coarsest = (2.0 * width / shape.virtual_resolution as f32).max(farthest_footprint);
        let coarsest_exponent = coarsest.log2().ceil() as i32;
        let finest_texel = 2f32.powi(coarsest_exponent - (shape.levels as i32 - 1));
        let centre = light_from_world.transform_point3(camera).truncate();
        let half = (shape.pages_per_side() / 2) as i32;
        let origins = (0..shape.levels)
            .map(|level| {
                let page = page_world_size(shape, finest_texel, level);
                (centre / page).floor().as_ivec2() - IVec2::splat(half)
            })
            .collect();
        // Light space looks down −z: the nearest point has the largest z.
        let margin = 1e-3 * in_light.extent().z.max(1e-6);
        let (near, far) = (-in_light.max.z - margin, -in_light.min.z + margin);
        let projection = MapProjection::Orthographic;
        Clipmap { shape, light_from_world, projection, finest_texel, origins, near, far }
    }

    /// The clipmap of a spot looking along `-z` of `light_from_world` (rigid) through a
    /// square frustum whose half-angle has tangent `tan_half_fov`, from `near` to `far`
    /// along its axis: a mip chain in its normalized device coordinates. Level 0's
    /// window is the whole frustum, `[−1, 1]²` in `virtual_resolution`² texels, and
    /// each coarser level halves the texels over it, down to 2 × 2 pages (the windows
    /// stay centred on the axis); its windows are fixed, so no move of the camera
    /// invalidates a page. `shape.levels` is cut to those levels
    /// (`log2(pages_per_side)`, at least 1). A pixel reads the level whose texels,
    /// which grow with the distance from the light, match its footprint.
    pub fn spot(
        shape: ClipmapShape,
        light_from_world: Mat4,
        tan_half_fov: f32,
        near: f32,
        far: f32,
    ) -> Clipmap {
        let chain = shape.pages_per_side().max(2).ilog2();
        let shape = ClipmapShape { levels: shape.levels.min(chain), ..shape };
        let finest_texel = 2.0 / shape.virtual_resolution as f32;
        let half = (shape.pages_per_side() / 2) as i32;
        let origins = vec![IVec2::splat(-half); shape.levels as usize];
        let projection = MapProjection::Perspective { tan_half_fov };
        Clipmap { shape, light_from_world, projection, finest_texel, origins, near, far }
    }

    /// Map-space size of a texel of `level`.
    pub fn texel_size(&self, level: u32) -> f32 {
        self.finest_texel * 2f32.powi(level as i32)
    }

    /// Map-space size of a page of `level`.
    pub fn page_size(&self, level: u32) -> f32 {
        page_world_size(self.shape, self.finest_texel, level)
    }

    /// The level a pixel whose footprint is `footprint` map units reads: the
    /// coarsest whose texels are no larger than the footprint (level 0 where even
    /// its texels are larger, the coarsest level where every level's are smaller).
    pub fn level_for_footprint(&self, footprint: f32) -> u32 {
        let ratio = footprint / self.finest_texel;
        if ratio.is_nan() || ratio < 1.0 {
            return 0;
        }
        (ratio.log2().floor() as u32).min(self.shape.levels.saturating_sub(1))
    }

    /// The page of `level` over the light-space point `xy`, if it lies in the level's
    /// window.
    pub fn page_at(&self, level: u32, xy: Vec2) -> Option<PageKey> {
        let page = (xy / self.page_size(level)).floor().as_ivec2();
        self.in_window(level, page).then_some(PageKey { level, x: page.x, y: page.y })
    }

    /// Whether page `page` of `level` lies in the level's window.
    fn in_window(&self, level: u32, page: IVec2) -> bool {
        let window = self.level_window(level);
        page.cmpge(window.min).all() && page.cmple(window.max).all()
    }

    /// Every page of `level`'s window: `pages_per_side`² pages from its origin.
    pub fn level_window(&self, level: u32) -> PageRect {
        let min = self.origins[level as usize];
        PageRect { level, min, max: min + IVec2::splat(self.shape.pages_per_side() as i32 - 1) }
    }

    /// The pages of `level` over the light-space rectangle `low..=high`, clipped to
    /// the level's window; None where it lies outside it.
    pub fn pages_over(&self, level: u32, low: Vec2, high: Vec2) -> Option<PageRect> {
        let size = self.page_size(level);
        let window = self.level_window(level);
        let min = (low / size).floor().as_ivec2().max(window.min);
        let max = (high / size).floor().as_ivec2().min(window.max);
        (min.x <= max.x && min.y <= max.y).then_some(PageRect { level, min, max })
    }

    /// The pages of `level` that a caster within `bounds` can write: those over its
    /// shadow in map space, the rectangle its corners cover seen from the light (for
    /// a spot, the whole window where a corner lies before its near plane, where the
    /// projection stops bounding it; for a point light, such a rectangle in each face,
    /// `cube_pages_under` in `cube.rs`). A caster that moves dirties these pages where
    /// it was and where it is.
    pub fn pages_under(&self, level: u32, bounds: &Aabb) -> Vec<PageRect> {
        let in_light = bounds.transformed(self.light_from_world);
        match self.projection {
            MapProjection::Orthographic => {
                self.pages_over(level, in_light.min.truncate(), in_light.max.truncate()).into_iter().collect()
            }
            MapProjection::Perspective { .. } if -in_light.max.z < self.near => {
                vec![self.level_window(level)]
            }
            MapProjection::Perspective { .. } => {
                let corners = bounds.corners().map(|c| self.map_xy(c));
                let low = corners.iter().copied().fold(Vec2::INFINITY, Vec2::min);
                let high = corners.iter().copied().fold(Vec2::NEG_INFINITY, Vec2::max);
                self.pages_over(level, low, high).into_iter().collect()
            }
            MapProjection::Cube => self.cube_pages_under(level, bounds),
        }
    }

    /// The level a pixel at map-space point `xy` whose footprint is `footprint`
    /// map units reads: its footprint's ([`Clipmap::level_for_footprint`]), or the
    /// finest coarser level whose window holds the point. A level's window is
    /// `virtual_resolution` of its texels wide around the camera: a pixel far to the
    /// side of a small one reads a coarser level, as in a clipmap's outer rings. None
    /// where no level's window holds it.
    pub fn level_for_point(&self, xy: Vec2, footprint: f32) -> Option<u32> {
        (self.level_for_footprint(footprint)..self.shape.levels)
            .find(|&level| self.page_at(level, xy).is_some())
    }

    /// Every page a pixel at world point `point` whose footprint is `footprint`
    /// world units reads, through a filter that reaches `reach_texels` texels of its
    /// level from the point (the kernel's radius, the normal offset's, a texel for
    /// bilinear taps): the rectangle of pages of its level ([`Clipmap::level_for_point`])
    /// over that square. Nothing for a point outside every level's window, or that the
    /// map does not see ([`Clipmap::sees`]).
    pub fn request(&self, point: Vec3, footprint: f32, reach_texels: f32) -> Option<PageRect> {
        if !self.sees(point) {
            return None;
        }
        let xy = self.map_xy(point);
        let level = self.level_for_point(xy, self.map_footprint(point, footprint))?;
        self.pages_around(level, xy, reach_texels * self.texel_size(level))
    }

    /// The level in whose texels a search `radius` map units wide round a pixel of
    /// `level` spans at most `cap_texels`: `level`, or as many levels coarser as it
    /// takes, up to the coarsest.
    pub fn search_level(&self, level: u32, radius: f32, cap_texels: f32) -> u32 {
        let texels = radius / (self.texel_size(level) * cap_texels);
        let coarser = texels.log2().ceil().max(0.0) as u32;
        (level + coarser).min(self.shape.levels - 1)
    }

    /// The square that the refinement's search over a sun's cone reads for a pixel
    /// of `level` at world point `point` whose own lookup reaches `reach_texels` of
    /// `level`: the cone from the point to the light's area at the near plane, in the
    /// search's level ([`Clipmap::search_level`]), a texel more for the taps'
    /// rounding, and the lookup's reach in that level's texels.
    pub fn search_square(
        &self,
        point: Vec3,
        level: u32,
        search: AreaSearch,
        reach_texels: f32,
    ) -> SearchSquare {
        let cone = self.cone_radius(point, search.light_size);
        let read = self.search_level(level, cone, search.cap_texels);
        let texel = self.texel_size(read);
        let radius = (cone / texel).clamp(1.0, search.cap_texels);
        let reach = (radius + 1.0 + reach_texels / 2f32.powi((read - level) as i32)) * texel;
        SearchSquare { level: read, centre: self.map_xy(point), cone, reach }
    }

    /// The squares of the finer levels' grids that the same search also reads
    /// ([`AREA_SEARCH_FINER_LEVELS`] at most, none finer than `level`): each
    /// [`AreaSearch::cap_texels`] round the point, a texel more for the taps'
    /// rounding, and the lookup's reach in that level's texels. Finest first.
    pub fn finer_search_squares(
        &self,
        square: &SearchSquare,
        level: u32,
        search: AreaSearch,
        reach_texels: f32,
    ) -> Vec<SearchSquare> {
        let first = square.level.saturating_sub(AREA_SEARCH_FINER_LEVELS).max(level);
        (first..square.level)
            .map(|l| {
                let reach = (search.cap_texels + 1.0 + reach_texels / 2f32.powi((l - level) as i32))
                    * self.texel_size(l);
                SearchSquare { level: l, reach, ..*square }
            })
            .collect()
    }

    /// The pages of [`Clipmap::search_square`]'s square and of
    /// [`Clipmap::finer_search_squares`]', a rectangle a level. Nothing in a level
    /// whose window does not hold the point.
    pub fn search_requests(
        &self,
        point: Vec3,
        level: u32,
        search: AreaSearch,
        reach_texels: f32,
    ) -> Vec<PageRect> {
        let square = self.search_square(point, level, search, reach_texels);
        let mut squares = self.finer_search_squares(&square, level, search, reach_texels);
        squares.push(square);
        squares
            .iter()
            .filter_map(|square| {
                self.page_at(square.level, square.centre)?;
                self.pages_around(square.level, square.centre, square.reach)
            })
            .collect()
    }

    /// The pages a lookup of `cone` reads for a pixel of `level` at world point
    /// `point` whose own lookup reaches `reach_texels` (its normal offset, its
    /// bilinear taps) in each level's texels: a rectangle in each level from `level`
    /// to the coarsest `cone` reads, over the square of as many texels as the cone
    /// spans there (at most [`ConeReach::reach_cap_texels`], at least one), a texel
    /// more for the taps' rounding, and the lookup's reach. Nothing in a level whose
    /// window does not hold the point.
    pub fn cone_requests(
        &self,
        point: Vec3,
        level: u32,
        cone: ConeReach,
        reach_texels: f32,
    ) -> Vec<PageRect> {
        let radius = self.cone_radius(point, cone.light_size);
        let coarsest = self.search_level(level, radius, cone.level_cap_texels);
        let centre = self.map_xy(point);
        (level..=coarsest)
            .filter_map(|l| {
                self.page_at(l, centre)?;
                let texel = self.texel_size(l);
                let spans = (radius / texel).clamp(1.0, cone.reach_cap_texels);
                self.pages_around(l, centre, (spans + 1.0 + reach_texels) * texel)
            })
            .collect()
    }

    /// World to the clip space of page `page` alone: the projection of its map-space
    /// window over the clipmap's depth range, which a page's depth
    /// pass draws with into its physical page.
    pub fn page_clip_from_world(&self, page: PageKey) -> Mat4 {
        self.run_clip_from_world(page, 1)
    }

    /// World to the clip space of the `columns` pages of a level's row from `first`
    /// rightwards: a run of pages drawn as one ([`runs::PageRun`]). Each page's texels
    /// are where [`Clipmap::page_clip_from_world`] puts them, its projection scaled by
    /// `columns` across.
    pub fn run_clip_from_world(&self, first: PageKey, columns: u32) -> Mat4 {
        let end = first.x + columns as i32 - 1;
        self.rect_clip_from_world(&PageRect {
            level: first.level,
            min: IVec2::new(first.x, first.y),
            max: IVec2::new(end, first.y),
        })
    }

    /// World to the clip space of the pages of `rect`: a map of its level over them
    /// at full resolution, each page's texels where [`Clipmap::page_clip_from_world`]
    /// puts them.
    pub fn rect_clip_from_world(&self, rect: &PageRect) -> Mat4 {
        self.rect_projection(rect).clip_from_world()
    }

    /// The projection of the pages of `rect` over the clipmap's depth range: a sun's
    /// orthographic one of their light-space window; a spot's or a cube face's
    /// perspective, followed by the scale and offset of their window in its
    /// normalized device coordinates onto [−1, 1]² (a point light's `rect` lies in one
    /// face's slot). Page `(x, y)` of it covers its columns `(x − min.x) · page_size …`
    /// and, v down, its rows `(max.y − y) · page_size …`.
    pub fn rect_projection(&self, rect: &PageRect) -> LightProjection {
        let size = self.page_size(rect.level);
        let frame = self.rect_frame(rect);
        let (left, bottom) =
            (rect.min.x as f32 * size - frame.slot.x, rect.min.y as f32 * size - frame.slot.y);
        let (right, top) =
            ((rect.max.x + 1) as f32 * size - frame.slot.x, (rect.max.y + 1) as f32 * size - frame.slot.y);
        let Some(tan_half_fov) = self.tan_half_fov() else {
            return LightProjection::orthographic(
                frame.view_from_world,
                (left, right, bottom, top),
                self.near,
                self.far,
            );
        };
        // Map x in left..right to −1..1: scale by 2 / width, centre on the window's.
        let (width, height) = (right - left, top - bottom);
        let window_from_map = Mat4::from_cols(
            glam::Vec4::new(2.0 / width, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, 2.0 / height, 0.0, 0.0),
            glam::Vec4::Z,
            glam::Vec4::new(-(left + right) / width, -(bottom + top) / height, 0.0, 1.0),
        );
        LightProjection {
            light_from_world: frame.view_from_world,
            clip_from_light: window_from_map * self.map_from_view(),
            // A texel's world size, 2 d tan(fov / 2) / resolution, is the window's
            // width over its texels at distance d.
            kind: ProjectionKind::Perspective { fov: 2.0 * (tan_half_fov * 0.5 * width.max(height)).atan() },
            near: self.near,
            far: self.far,
        }
    }

    /// World to the clip space of `level`'s whole window ([`Clipmap::level_window`]):
    /// what a full-resolution (`virtual_resolution`²) map of the level would be drawn
    /// with.
    pub fn level_clip_from_world(&self, level: u32) -> Mat4 {
        self.rect_clip_from_world(&self.level_window(level))
    }
}

/// World size of a page of `level` for texels of `finest_texel` at level 0.
fn page_world_size(shape: ClipmapShape, finest_texel: f32, level: u32) -> f32 {
    finest_texel * 2f32.powi(level as i32) * shape.page_size as f32
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod spot_tests;

#[cfg(test)]
mod point_tests;
