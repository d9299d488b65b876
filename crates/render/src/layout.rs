//! Where a light's shadow map looks: the GPU-free layout of its layers. Fitting a
//! sun's map to the scene or to the receivers, cascade splits and fits (tight, stable,
//! SDSM's sample bounds), warps, the filter margin a fitted cascade keeps, and the
//! depth range the camera sees. The renderer draws what this decides.

use glam::Vec3;
use gnomon_math::{
    Aabb, LightProjection, cascades, directional_light_projection,
    fitting::{Hexahedron, fit_directional_to_receivers, intersection_vertices},
    omni::{cube_face_projections, paraboloid_projections},
    spot_light_projection,
    warping::{Warp, WarpView, fit_warped},
};
use gnomon_scene::{
    Camera, Light, Settings,
    lights::ShadowView,
    settings::{CascadeFit, CascadeSelection, Fit, KernelUnit, OmniMap, Partition, SplitScheme, WarpKind},
};

use crate::techniques::TechniqueRef;

/// What SDSM measured of the camera's samples (Lauritzen, Salvi & Lefohn 2011).
#[derive(Clone, Debug, PartialEq)]
pub struct SampleDistribution {
    /// The nearest and farthest view depth seen.
    pub near: f32,
    pub far: f32,
    /// With --sdsm-bounds, per cascade: the light-space (min x, min y, max x, max y) of
    /// the samples it serves, its blend band included; None for a cascade that serves
    /// none.
    pub light_bounds: Option<Vec<Option<[f32; 4]>>>,
}

/// The layers of a light's shadow map: their projections, and the view depths
/// that bound them when they are cascades.
#[derive(Clone, Debug)]
pub struct ShadowLayout {
    /// One projection per layer: the cascades in order near to far, a cube's six faces in
    /// WebGPU's order, a paraboloid map's two hemispheres, or the single map.
    pub projections: Vec<LightProjection>,
    /// One more than the projections: cascade i covers view depths `splits[i]` to
    /// `splits[i + 1]`. A single map covers 0 to infinity.
    pub splits: Vec<f32>,
    /// Draw with depth clamping ("pancaking"): the projections' near planes sit at the
    /// nearest receiver, and casters before them are clamped onto them.
    pub depth_clamp: bool,
}

/// What the device and the light's technique allow its map.
#[derive(Clone, Copy, Debug)]
pub struct MapDrawing {
    /// The light's technique: its filter's reach is the margin a sample-fitted
    /// cascade keeps, and [`crate::techniques::MapSupport::clamped_depth`] says
    /// whether its map may be drawn with depth clamping.
    pub technique: TechniqueRef,
    /// The device can draw with unclipped depth (`DEPTH_CLIP_CONTROL`).
    pub unclipped_depth: bool,
    /// For a sun with a size whose penumbrae the mask pass classifies from its map
    /// (`rays::classifies_penumbrae`): the tangent of the sun's angular radius. The map
    /// then reaches past its receivers by the cone's radius across its depth range
    /// ([`penumbra_margin`]): a caster beyond the map's edge may shadow a receiver
    /// that far inside, and a classification that cannot see it must trace.
    pub penumbra_slope: Option<f32>,
}

/// How far past its receivers a sun's map reaches when its penumbrae are classified
/// from it (`MapDrawing::penumbra_slope`): the radius of the cone from a receiver at
/// the far end of its depth range to the sun at the near end, at most half the
/// window's size on each side, so that a wide sun at most halves the map's
/// resolution (receivers nearer the edge than the cone's reach are traced).
pub fn penumbra_margin(projection: &LightProjection, slope: f32) -> f32 {
    let Some((left, right, bottom, top)) = projection.orthographic_window() else { return 0.0 };
    let cap = 0.5 * (right - left).max(top - bottom);
    (slope * (projection.far - projection.near)).clamp(0.0, cap)
}

/// The shadow layout of `light` under `settings`: one map, or for a sun with
/// `--partition cascades`, one per slice of the view frustum, all sharing one depth
/// range so that every layer stores depth the same way; for a point light, the six
/// faces of its cube.
///
/// `sampled`, for SDSM, is what [`crate::Renderer`]'s reductions measured of the camera's
/// samples: the cascades split the range of view depths it saw instead of the range
/// where the view frustum meets the scene's bounds, and with --sdsm-bounds each tight
/// cascade narrows to the light-space bounds of its own samples.
///
/// Where the device can draw with unclipped depth (`drawing`), with
/// `shadow.map.depth_clamp` (the default) and a technique that reads clamped depth
/// (not PCSS, whose blocker search reads the true distance to each blocker), a sun's
/// map that follows the receivers (`fit` receivers, tight cascades) moves its near
/// plane up to the nearest receiver ([`LightProjection::pancaked`]). Not for stable
/// cascades, whose depth range must not follow the camera, nor for warps, which rely
/// on clipping.
pub fn shadow_layout(
    scene_bounds: &Aabb,
    light: &Light,
    camera: &Camera,
    aspect: f32,
    settings: &Settings,
    sampled: Option<&SampleDistribution>,
    drawing: MapDrawing,
) -> ShadowLayout {
    let view = light.shadow_view();
    if let ShadowView::Omni { position, near, far } = view {
        // Six 90° faces from the light's position, or two paraboloids; near and far
        // from its range.
        return ShadowLayout {
            projections: match settings.shadow.map.omni {
                OmniMap::Cube => cube_face_projections(position, near, far).to_vec(),
                OmniMap::Paraboloid => paraboloid_projections(position, near, far).to_vec(),
            },
            splits: vec![0.0, f32::INFINITY],
            depth_clamp: false,
        };
    }
    let pancake =
        drawing.unclipped_depth && settings.shadow.map.depth_clamp && drawing.technique.maps().clamped_depth;
    let single = || {
        let fit = settings.shadow.map.fit;
        let clamped = pancake && fit == Fit::Receivers && matches!(view, ShadowView::Parallel { .. });
        let fitted = light_projection(scene_bounds, light, camera, aspect, fit, clamped);
        let widened = match (drawing.penumbra_slope, fit) {
            (Some(slope), Fit::Receivers) => fitted.widened(penumbra_margin(&fitted, slope)),
            // A map of the whole scene already holds every caster.
            (Some(_), Fit::Scene) | (None, _) => fitted,
        };
        ShadowLayout { projections: vec![widened], splits: vec![0.0, f32::INFINITY], depth_clamp: clamped }
    };
    if let (ShadowView::Parallel { travel }, Partition::Single, Some(warp)) =
        (view, settings.shadow.partition, warp_of(settings.shadow.map.warp))
    {
        return warped_layout(scene_bounds, travel, camera, aspect, warp).unwrap_or_else(single);
    }
    let (ShadowView::Parallel { travel }, Partition::Cascades) = (view, settings.shadow.partition) else {
        return single();
    };
    let Some(splits) =
        cascade_splits(scene_bounds, camera, aspect, settings, sampled.map(|s| (s.near, s.far)))
    else {
        return single();
    };
    let c = &settings.shadow.cascades;
    let bounds = *scene_bounds;
    let frustum = Hexahedron::from_clip_from_world(camera.clip_from_world(aspect));
    let view = cascades::PerspectiveView {
        eye: camera.eye,
        target: camera.target,
        up: camera.up,
        fov_y: camera.fov_y_degrees.to_radians(),
        aspect,
    };
    // With selection by depth, the lighting pass blends the far end of each cascade
    // into the next one, so each slice starts at its predecessor's blend band.
    let blend = match c.cascade_selection {
        CascadeSelection::Depth => c.cascade_blend,
        CascadeSelection::Projection => 0.0,
    };
    let fitting = CascadeFitting {
        bounds,
        travel,
        frustum,
        view,
        camera,
        settings,
        samples: sampled.and_then(|s| s.light_bounds.as_deref()),
        drawing,
        pancake,
    };
    let fitted: Vec<LightProjection> = (0..splits.len() - 1)
        .map(|i| {
            let from = if i == 0 { splits[0] } else { splits[i] - blend * (splits[i] - splits[i - 1]) };
            fitting.fit(i, from, splits[i + 1])
        })
        .collect();
    let near_plane = fitted.iter().map(|p| p.near).fold(f32::INFINITY, f32::min);
    let far_plane = fitted.iter().map(|p| p.far).fold(f32::NEG_INFINITY, f32::max);
    ShadowLayout {
        projections: fitted.iter().map(|p| p.with_depth_range(near_plane, far_plane)).collect(),
        splits,
        depth_clamp: pancake && c.cascade_fit == CascadeFit::Tight,
    }
}

/// What each of a sun's cascades is fitted from.
struct CascadeFitting<'a> {
    bounds: Aabb,
    travel: Vec3,
    frustum: Hexahedron,
    view: cascades::PerspectiveView,
    camera: &'a Camera,
    settings: &'a Settings,
    /// SDSM's light-space bounds of each cascade's samples (`--sdsm-bounds`).
    samples: Option<&'a [Option<[f32; 4]>]>,
    drawing: MapDrawing,
    pancake: bool,
}

impl CascadeFitting<'_> {
    /// Cascade `i`'s projection, serving view depths `from` to `to`.
    fn fit(&self, i: usize, from: f32, to: f32) -> LightProjection {
        let (settings, drawing) = (self.settings, self.drawing);
        let resolution = settings.shadow.map.resolution;
        let slice = cascades::frustum_slice(&self.frustum, self.camera.near, self.camera.far, from, to);
        // A stable cascade's size follows its slice's: built exactly, so that it stays
        // put while the camera moves (`cascades::view_slice`).
        let exact_slice = || cascades::view_slice(&self.view, from, to);
        match settings.shadow.cascades.cascade_fit {
            CascadeFit::Tight => {
                let tight = cascades::fit_cascade_tight(self.travel, &self.bounds, &slice, self.pancake);
                let fitted = match self.samples.and_then(|s| s.get(i).copied().flatten()) {
                    Some(window) => cascades::fit_cascade_to_samples(
                        &tight,
                        window,
                        filter_margin_texels(settings, drawing.technique, &tight),
                        resolution,
                    ),
                    None => tight,
                };
                match drawing.penumbra_slope {
                    Some(slope) => fitted.widened(penumbra_margin(&fitted, slope)),
                    None => fitted,
                }
            }
            CascadeFit::Stable => {
                // The margin grows the window before it is placed on the texel grid: its
                // depth range spans the whole scene, so the margin stays put too.
                let margin = drawing.penumbra_slope.map_or(0.0, |slope| {
                    let unwidened =
                        cascades::fit_cascade_stable(self.travel, &self.bounds, &exact_slice(), resolution);
                    penumbra_margin(&unwidened, slope)
                });
                cascades::fit_cascade_stable_with_margin(
                    self.travel,
                    &self.bounds,
                    &exact_slice(),
                    resolution,
                    margin,
                )
            }
        }
    }
}

/// The view depths bounding a sun's cascades: the range where the view frustum meets
/// the scene's bounds, or `sampled` (SDSM), cut at the shadow distance, quantized for
/// stable cascades, and split by the scheme. None when the camera sees none of the
/// scene.
pub(crate) fn cascade_splits(
    scene_bounds: &Aabb,
    camera: &Camera,
    aspect: f32,
    settings: &Settings,
    sampled: Option<(f32, f32)>,
) -> Option<Vec<f32>> {
    let c = &settings.shadow.cascades;
    let frustum = Hexahedron::from_clip_from_world(camera.clip_from_world(aspect));
    // The view depths that hold any of the scene: beyond them a cascade would cover
    // nothing.
    let receivers = intersection_vertices(&frustum, &Hexahedron::from_aabb(scene_bounds));
    let (near, far) = seen_depth_range(camera, &receivers)?;
    let (near, far) = match sampled {
        Some((lo, hi)) => (lo.max(camera.near), hi.min(camera.far).max(lo.max(camera.near) * 1.001)),
        None => (near, far),
    };
    let far = far.min(c.shadow_distance.unwrap_or(f32::INFINITY)).max(near * 1.001);
    // Stable cascades split a range that moves in steps, so that their slices do not
    // change size with every move of the camera. Not clamped to the camera's planes:
    // those follow the eye's distance to the scene, and would move the splits with
    // every step (a slice that starts before the near plane covers a little more).
    let (near, far) = match c.cascade_fit {
        CascadeFit::Stable => cascades::quantized_depth_range(near, far),
        CascadeFit::Tight => (near, far),
    };
    let scheme = match c.split {
        SplitScheme::Uniform => cascades::SplitScheme::Uniform,
        SplitScheme::Log => cascades::SplitScheme::Logarithmic,
        SplitScheme::Practical => cascades::SplitScheme::Practical { lambda: c.split_lambda },
    };
    Some(cascades::split_distances(scheme, c.count as usize, near, far))
}

/// Texels a sample-fitted cascade keeps around its samples: the technique's filter
/// reach and the normal offset, plus two for the bilinear footprint and the pixel's
/// own extent.
fn filter_margin_texels(settings: &Settings, technique: TechniqueRef, tight: &LightProjection) -> f32 {
    let f = &settings.shadow.filter;
    let texel = tight.texel_world_size(settings.shadow.map.resolution, 0.0).max(1e-9);
    let kernel = match f.kernel_unit {
        KernelUnit::Texels => f.pcf_kernel,
        KernelUnit::World => f.pcf_kernel / texel,
    };
    // Each technique states its own reach (`ShadowTechnique::filter_reach_texels`).
    let reach = technique.filter_reach_texels(f, kernel);
    2.0 + reach + settings.shadow.bias.normal_offset
}

fn warp_of(kind: WarpKind) -> Option<Warp> {
    match kind {
        WarpKind::None => None,
        WarpKind::Psm => Some(Warp::Perspective),
        WarpKind::Lispsm => Some(Warp::LightSpacePerspective),
        WarpKind::Tsm => Some(Warp::Trapezoidal),
    }
}

/// A sun's single map warped over the receivers the camera sees; None when it sees
/// none of the scene.
fn warped_layout(
    scene_bounds: &Aabb,
    direction: Vec3,
    camera: &Camera,
    aspect: f32,
    warp: Warp,
) -> Option<ShadowLayout> {
    let bounds = *scene_bounds;
    let frustum = Hexahedron::from_clip_from_world(camera.clip_from_world(aspect));
    let receivers = intersection_vertices(&frustum, &Hexahedron::from_aabb(&bounds));
    let (near, far) = seen_depth_range(camera, &receivers)?;
    let view = WarpView { eye: camera.eye, forward: (camera.target - camera.eye).normalize(), near, far };
    Some(ShadowLayout {
        projections: vec![fit_warped(warp, direction, &bounds, &receivers, &view)],
        splits: vec![0.0, f32::INFINITY],
        depth_clamp: false,
    })
}

/// The view depths, within the camera's planes, that hold any of `receivers`.
fn seen_depth_range(camera: &Camera, receivers: &[Vec3]) -> Option<(f32, f32)> {
    if receivers.is_empty() {
        return None;
    }
    let view_from_world = camera.view_from_world();
    let depths = receivers.iter().map(|p| -view_from_world.transform_point3(*p).z);
    let (seen_near, seen_far) = depths.fold((f32::INFINITY, 0.0f32), |(lo, hi), d| (lo.min(d), hi.max(d)));
    let near = seen_near.max(camera.near);
    Some((near, seen_far.min(camera.far).max(near * 1.001)))
}

/// The shadow projection of `light`: for a sun, an orthographic box fitted to the
/// scene's bounds or to the receivers `camera` can see ([`Fit`]); for a spot, the
/// perspective frustum of its cone out to its range; for a point light, its cube's
/// first face (+x; `shadow_layout` has all six). `depth_clamp` pancakes a
/// receiver-fitted sun map ([`LightProjection::pancaked`]).
pub fn light_projection(
    scene_bounds: &Aabb,
    light: &Light,
    camera: &Camera,
    aspect: f32,
    fit: Fit,
    depth_clamp: bool,
) -> LightProjection {
    match light.shadow_view() {
        ShadowView::Parallel { travel } if fit == Fit::Receivers => {
            let bounds = *scene_bounds;
            let frustum = Hexahedron::from_clip_from_world(camera.clip_from_world(aspect));
            let receivers = intersection_vertices(&frustum, &Hexahedron::from_aabb(&bounds));
            let fitted = fit_directional_to_receivers(travel, &bounds, &receivers);
            if depth_clamp { fitted.pancaked(&receivers) } else { fitted }
        }
        ShadowView::Parallel { travel } => directional_light_projection(travel, scene_bounds),
        ShadowView::Frustum { position, axis, half_angle, near, far } => {
            spot_light_projection(position, axis, half_angle, near, far)
        }
        ShadowView::Omni { position, near, far } => cube_face_projections(position, near, far)[0],
    }
}
