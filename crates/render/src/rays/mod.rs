//! Shadow rays on the GPU, on any adapter: the scene's casters in a BVH built on
//! the CPU and flattened into storage buffers (`bvh.rs`), walked by a WGSL shader
//! (`trace_bvh.wgsl`) that gives the CPU reference's answers; and, where the device
//! has ray queries, the same casters in the adapter's own acceleration structures
//! (`accel.rs`, `trace_query.wgsl`). [`Traversal`] says which traces a frame.
//! [`ShadowRays`] answers batches of rays, for a host or a test; the renderer's trace
//! pass (`refine.rs`) binds the same resources where it refines a shadow.

mod accel;
pub(crate) mod bvh;
mod forward;
pub(crate) mod pyramid;
pub(crate) mod query;
pub(crate) mod refine;
pub(crate) mod touched;
mod traversal;

pub(crate) use forward::{forward_group, forward_layouts, forward_refine_wgsl};
pub(crate) use pyramid::{
    PLANES_FORMAT, Pyramid, PyramidInput, PyramidLayout, PyramidParams, PyramidPass, RANGES_FORMAT,
};
pub use query::{ShadowRay, ShadowRays};
#[cfg(test)]
pub(crate) use refine::trace_pass_wgsl;
pub(crate) use refine::{
    HISTORY_FORMAT, LightSize, ListAccess, RefineLists, TraceGroups, TracePasses, TraceStage,
    classifies_penumbrae, history_layout, mask_refine_wgsl, refined_mask_layout,
    screen_layout as refine_screen_layout,
};
pub(crate) use touched::{Touched, TouchedInput, TouchedLayout, TouchedPass, reads_touched};
pub use traversal::{RayQueriesUnavailable, Traversal};
pub(crate) use traversal::{TracerLayouts, trace_wgsl};

use gnomon_scene::settings::Refine;
use std::sync::OnceLock;
use wgpu::util::DeviceExt;

use crate::{Gpu, RenderError};
use accel::CasterAccel;
use bvh::CasterBvh;
use traversal::FIRST_BINDING;

/// The bind group slot the tracer's buffers take in every pipeline that traces.
pub(crate) const GROUP: u32 = 3;

/// The refinement a light gets on the mask path: `refine`, with `auto` resolved to
/// `rays`, for a hard light (a ray where the map is unsure) and for a light with an
/// area alike (a penumbra beam where the map cannot say the pixel is lit or in umbra,
/// a quarter of them a frame: `penumbra_mask.wgsl`).
pub(crate) fn light_refine(refine: Refine) -> Refine {
    match refine {
        Refine::Auto => Refine::Rays,
        Refine::Off | Refine::Rays | Refine::EveryPixel => refine,
    }
}

/// The refinement a light gets on the forward path, where its lighting pass traces
/// (`forward.rs`): only rays asked for by name. `auto` asks for rays where they run
/// best, on the mask path, which `--shadow-path auto` then takes
/// (`Settings::uses_shadow_mask`); a frame told to stay forward is drawn unrefined.
pub(crate) fn forward_light_refine(refine: Refine) -> Refine {
    match refine {
        Refine::Auto | Refine::Off => Refine::Off,
        Refine::Rays | Refine::EveryPixel => refine,
    }
}

/// The layouts of the tracer's group, for each traversal the device runs: bindings
/// 2–6 (0 and 1 stay free for the material texture that passes sharing
/// `scene_common.wgsl` declare).
pub(crate) fn layouts(device: &wgpu::Device) -> TracerLayouts {
    TracerLayouts::new(device, |traversal| {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow rays"),
            entries: &traversal::entries(
                wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
                traversal,
            ),
        })
    })
}

/// Why the GPU ray tracer cannot take a scene or a frame on a device: each names the
/// limit it meets. A frame asked to refine by rays is then drawn unrefined.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RaysUnavailable {
    /// The BVH of the scene's shadow casters is deeper than the GPU tracer's stack.
    #[error(
        "scene `{scene}`: the BVH of its shadow casters is {depth} levels deep, but the GPU \
         ray tracer walks at most {max}"
    )]
    TreeTooDeep {
        /// Name of the scene.
        scene: String,
        /// Depth of the built tree, the root counting 1.
        depth: u32,
        /// The deepest tree the tracer walks.
        max: u32,
    },
    /// One of the ray tracer's buffers is larger than the device binds.
    #[error(
        "scene `{scene}`: the GPU ray tracer's {buffer} take {bytes} bytes, but this device binds \
         at most {limit} bytes in one storage buffer"
    )]
    BufferTooLarge {
        /// Name of the scene.
        scene: String,
        /// Which buffer: nodes, triangles, alpha tests, alpha textures or alpha texels.
        buffer: &'static str,
        /// Its size.
        bytes: u64,
        /// The most bytes the device binds in one storage buffer.
        limit: u64,
    },
    /// The list of pixels to trace, room for every pixel of the image, is larger than
    /// the device binds.
    #[error(
        "an image of {width}×{height} pixels needs a list of {bytes} bytes for the pixels its \
         rays refine, but this device binds at most {limit} bytes in one storage buffer"
    )]
    ImageTooLarge {
        /// The image's width in pixels.
        width: u32,
        /// The image's height in pixels.
        height: u32,
        /// The list's size.
        bytes: u64,
        /// The most bytes the device binds in one storage buffer.
        limit: u64,
    },
}

/// The most bytes a device binds in one storage buffer.
pub(crate) fn storage_limit(gpu: &Gpu) -> u64 {
    gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size)
}

/// Refuses an image whose list of pixels to trace is larger than `limit` bytes.
pub(crate) fn check_image(width: u32, height: u32, limit: u64) -> Result<(), RaysUnavailable> {
    let bytes = RefineLists::list_bytes(width, height);
    if bytes > limit {
        return Err(RaysUnavailable::ImageTooLarge { width, height, bytes, limit });
    }
    Ok(())
}

/// Refuses a tree deeper than the shader's stack, or a buffer larger than `limit`
/// bytes (what the device binds in one storage buffer).
fn check_limits(bvh: &CasterBvh, scene: &str, limit: u64) -> Result<(), RaysUnavailable> {
    if bvh.depth > bvh::MAX_DEPTH {
        return Err(RaysUnavailable::TreeTooDeep {
            scene: scene.to_owned(),
            depth: bvh.depth,
            max: bvh::MAX_DEPTH,
        });
    }
    for (buffer, bytes) in bvh.buffer_sizes() {
        if bytes > limit {
            return Err(RaysUnavailable::BufferTooLarge { scene: scene.to_owned(), buffer, bytes, limit });
        }
    }
    Ok(())
}

/// A scene's casters on the GPU, bound for tracing, with the CPU copy of its tree
/// that a refit updates; and, once a frame has asked for ray queries, the adapter's
/// acceleration structures over the same triangles.
pub(crate) struct GpuBvh {
    /// The shader tracer's group ([`Traversal::Shader`]).
    group: wgpu::BindGroup,
    /// Triangles in the tree: every casting instance's (0 when none casts).
    pub triangles: usize,
    /// The tree's nodes and triangles as uploaded (its alpha tests and textures,
    /// which no move changes, are dropped after the upload).
    tree: CasterBvh,
    /// Nodes, triangles, alpha tests, alpha textures, alpha texels: bindings 2–6.
    buffers: Vec<wgpu::Buffer>,
    /// The light's samples and half-plane masks ([`light_mask_words`]): binding 7.
    light_masks: wgpu::TextureView,
    /// The acceleration structures and the ray-query tracer's group, built on first
    /// use; or why this device's structures cannot take the scene.
    accel: OnceLock<Result<QueryTracer, RayQueriesUnavailable>>,
    /// The scene's name, for the errors of a later build.
    scene: String,
}

/// The casters' acceleration structures, and the ray-query tracer's group that binds
/// them beside the alpha buffers.
struct QueryTracer {
    accel: CasterAccel,
    group: wgpu::BindGroup,
}

/// The light's samples and its half-plane masks (`gnomon_math::light_masks`) as
/// penumbra_beam.wgsl reads them, one `Rgba32Uint` texel to four words: row 0 the
/// samples two to a texel, as f32 bits (the rest of the row zero), then a row per
/// angle bin of the table, a mask to each offset bin. A texture, not a storage
/// buffer: the trace pass already binds WebGPU's default eight of those. The same
/// for every scene and light, made once.
fn light_mask_words() -> &'static [u32] {
    use gnomon_math::light_masks::{ANGLE_BINS, MASK_WORDS, OFFSET_BINS, SAMPLES, half_plane_table, samples};
    const { assert!(SAMPLES / 2 <= OFFSET_BINS && MASK_WORDS == 4) };
    static WORDS: OnceLock<Vec<u32>> = OnceLock::new();
    WORDS.get_or_init(|| {
        let mut words: Vec<u32> =
            samples().into_iter().flat_map(|p| [p.x.to_bits(), p.y.to_bits()]).collect();
        words.resize(OFFSET_BINS * MASK_WORDS, 0);
        words.extend(half_plane_table().into_iter().flatten());
        debug_assert_eq!(words.len(), (ANGLE_BINS + 1) * OFFSET_BINS * MASK_WORDS);
        words
    })
}

/// The texture of [`light_mask_words`].
fn light_mask_texture(device: &wgpu::Device, queue: &wgpu::Queue) -> wgpu::Texture {
    use gnomon_math::light_masks::{ANGLE_BINS, OFFSET_BINS};
    device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some("light masks"),
            size: wgpu::Extent3d {
                width: OFFSET_BINS as u32,
                height: ANGLE_BINS as u32 + 1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Uint,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(light_mask_words()),
    )
}

/// Which of [`GpuBvh`]'s buffers holds what.
const NODE_BUFFER: usize = 0;
const TRIANGLE_BUFFER: usize = 1;
/// The alpha tests, textures and texels: bindings 4–6 for either traversal.
const ALPHA_BUFFERS: std::ops::Range<usize> = 2..5;

impl GpuBvh {
    /// The casters' triangles in world space, [`bvh::TriangleGpu`] each, kept
    /// current by every refit: what the touched layer draws ([`touched`]).
    pub(crate) fn triangle_buffer(&self) -> &wgpu::Buffer {
        &self.buffers[TRIANGLE_BUFFER]
    }

    /// Builds the casters' BVH of `scene` and uploads it. The scene must be valid.
    /// Refuses a tree deeper than the shader's stack, or a buffer larger than the
    /// device binds.
    pub fn upload(
        gpu: &Gpu,
        scene: &gnomon_scene::Scene,
        layout: &wgpu::BindGroupLayout,
    ) -> Result<Self, RenderError> {
        let mut bvh = CasterBvh::build(scene);
        check_limits(&bvh, &scene.name, storage_limit(gpu))?;
        // wgpu refuses a binding smaller than one element: an unused buffer holds one
        // zeroed element of the largest kind.
        let contents = |bytes: &[u8]| if bytes.is_empty() { vec![0u8; 64] } else { bytes.to_vec() };
        // A refit rewrites the nodes and triangles in place; the acceleration
        // structures read their vertices from the triangle buffer.
        let mut usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        if gpu.ray_queries {
            usage |= wgpu::BufferUsages::BLAS_INPUT;
        }
        let device = &gpu.device;
        gpu.checked("uploading the shadow casters' BVH", || {
            let buffers: Vec<wgpu::Buffer> = [
                bytemuck::cast_slice(&bvh.nodes),
                bytemuck::cast_slice(&bvh.triangles),
                bytemuck::cast_slice(&bvh.alpha),
                bytemuck::cast_slice(&bvh.textures),
                bytemuck::cast_slice(&bvh.texels),
            ]
            .iter()
            .zip(bvh.buffer_sizes())
            .map(|(bytes, (name, _))| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(name),
                    contents: &contents(bytes),
                    usage,
                })
            })
            .collect();
            let masks =
                light_mask_texture(device, &gpu.queue).create_view(&wgpu::TextureViewDescriptor::default());
            let entries: Vec<wgpu::BindGroupEntry> = buffers
                .iter()
                .zip(FIRST_BINDING..)
                .map(|(buffer, binding)| wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                })
                .chain(std::iter::once(wgpu::BindGroupEntry {
                    binding: traversal::LIGHT_MASKS_BINDING,
                    resource: wgpu::BindingResource::TextureView(&masks),
                }))
                .collect();
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shadow rays"),
                layout,
                entries: &entries,
            });
            (bvh.alpha, bvh.textures, bvh.texels) = Default::default();
            Self {
                group,
                triangles: bvh.casters,
                tree: bvh,
                buffers,
                light_masks: masks,
                accel: OnceLock::new(),
                scene: scene.name.clone(),
            }
        })
    }

    /// Builds the acceleration structures once, for the ray-query tracer: `layout` is
    /// its group's ([`TracerLayouts::get`]), and the device must have ray queries.
    /// Ok(Err) says why its structures cannot take the scene (the same answer every
    /// time); Err is a failure of the device.
    pub fn build_accel(
        &self,
        gpu: &Gpu,
        layout: &wgpu::BindGroupLayout,
    ) -> Result<Result<(), RayQueriesUnavailable>, RenderError> {
        if self.accel.get().is_none() {
            let built = match CasterAccel::check_limits(gpu, &self.tree, &self.scene) {
                Ok(()) => {
                    let accel = CasterAccel::build(gpu, &self.tree, &self.buffers[TRIANGLE_BUFFER])?;
                    let entries: Vec<wgpu::BindGroupEntry> = std::iter::once(wgpu::BindGroupEntry {
                        binding: FIRST_BINDING,
                        resource: accel.binding(),
                    })
                    .chain(self.alpha_buffers().map(|(binding, buffer)| wgpu::BindGroupEntry {
                        binding,
                        resource: buffer.as_entire_binding(),
                    }))
                    .collect();
                    let group = gpu.checked("binding the casters' acceleration structures", || {
                        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some("shadow rays, ray queries"),
                            layout,
                            entries: &entries,
                        })
                    })?;
                    Ok(QueryTracer { accel, group })
                }
                Err(why) => Err(why),
            };
            // Another thread may have built them meanwhile: either is the same.
            let _ = self.accel.set(built);
        }
        Ok(self.accel.get().expect("set above").as_ref().map(|_| ()).map_err(Clone::clone))
    }

    /// The alpha buffers at their bindings (4–6).
    fn alpha_buffers(&self) -> impl Iterator<Item = (u32, &wgpu::Buffer)> {
        (FIRST_BINDING + ALPHA_BUFFERS.start as u32..).zip(&self.buffers[ALPHA_BUFFERS])
    }

    /// The tracer's group for `traversal`: for ray queries, once
    /// [`GpuBvh::build_accel`] has built the structures.
    pub(crate) fn group(&self, traversal: Traversal) -> &wgpu::BindGroup {
        match traversal {
            Traversal::Shader => &self.group,
            Traversal::RayQuery => &self.query_tracer().group,
        }
    }

    fn query_tracer(&self) -> &QueryTracer {
        self.accel
            .get()
            .and_then(|built| built.as_ref().ok())
            .expect("the acceleration structures, built when the frame was planned")
    }

    /// The tracer's resources for `traversal` at their bindings (2–6), for a group
    /// that holds them beside others.
    pub(crate) fn bindings(&self, traversal: Traversal) -> Vec<(u32, crate::pool::Binding)> {
        use crate::pool::Binding;
        match traversal {
            Traversal::Shader => (FIRST_BINDING..)
                .zip(self.buffers.iter().map(|b| Binding::Buffer(b.clone())))
                .chain(std::iter::once((
                    traversal::LIGHT_MASKS_BINDING,
                    Binding::View(self.light_masks.clone()),
                )))
                .collect(),
            Traversal::RayQuery => {
                std::iter::once((FIRST_BINDING, Binding::Tlas(self.query_tracer().accel.tlas().clone())))
                    .chain(
                        self.alpha_buffers()
                            .map(|(binding, buffer)| (binding, Binding::Buffer(buffer.clone()))),
                    )
                    .collect()
            }
        }
    }

    /// How many instances the scene the tree was built from had.
    pub fn instance_count(&self) -> usize {
        self.tree.instance_count()
    }

    /// Moves the triangles of the `moved` instances to where `scene` now places them
    /// and refits the tree's boxes ([`CasterBvh::refit`]), uploading what changed:
    /// the node buffer and the changed runs of triangles. Acceleration structures, if
    /// built, are built again over the moved triangles. `scene` must be the one the
    /// tree was built from, with new transforms only, and `moved` valid indices.
    pub fn refit(
        &mut self,
        gpu: &Gpu,
        scene: &gnomon_scene::Scene,
        moved: &[usize],
    ) -> Result<(), RenderError> {
        let changed = self.tree.refit(scene, moved);
        gpu.checked("refitting the shadow casters' BVH", || {
            write_runs(&gpu.queue, &self.buffers[NODE_BUFFER], &self.tree.nodes, &changed.nodes);
            write_runs(&gpu.queue, &self.buffers[TRIANGLE_BUFFER], &self.tree.triangles, &changed.triangles);
        })?;
        match self.accel.get() {
            Some(Ok(query)) if !changed.triangles.is_empty() => {
                query.accel.rebuild(gpu, &self.buffers[TRIANGLE_BUFFER])
            }
            Some(_) | None => Ok(()),
        }
    }
}

/// Uploads the `runs` of `elements` to where they lie in `buffer`.
fn write_runs<T: bytemuck::Pod>(
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    elements: &[T],
    runs: &[std::ops::Range<u32>],
) {
    let size = std::mem::size_of::<T>() as u64;
    for run in runs {
        let slice = &elements[run.start as usize..run.end as usize];
        queue.write_buffer(buffer, u64::from(run.start) * size, bytemuck::cast_slice(slice));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tree_too_deep_or_a_buffer_too_large_is_refused_naming_the_limit() {
        let mut bvh = CasterBvh::build(&gnomon_scene::builtin::spheres());
        assert!(check_limits(&bvh, "spheres", u64::MAX).is_ok());
        let triangles = bvh.buffer_sizes()[1].1;
        let e = check_limits(&bvh, "spheres", triangles - 1).unwrap_err().to_string();
        assert!(
            e.contains("spheres")
                && e.contains("triangles")
                && e.contains(&format!("at most {}", triangles - 1)),
            "{e}"
        );
        bvh.depth = bvh::MAX_DEPTH + 1;
        let e = check_limits(&bvh, "spheres", u64::MAX).unwrap_err().to_string();
        assert!(
            e.contains(&format!("{} levels deep", bvh::MAX_DEPTH + 1))
                && e.contains(&format!("at most {}", bvh::MAX_DEPTH)),
            "{e}"
        );
    }

    #[test]
    fn an_image_too_large_for_the_list_of_pixels_is_refused_naming_the_limit() {
        let bytes = RefineLists::list_bytes(1920, 1080);
        assert!(check_image(1920, 1080, bytes).is_ok());
        let e = check_image(1920, 1080, bytes - 1).unwrap_err().to_string();
        assert!(e.contains("1920×1080") && e.contains(&format!("at most {}", bytes - 1)), "{e}");
    }
}
