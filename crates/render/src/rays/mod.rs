//! Shadow rays on the GPU, on any adapter (no ray-tracing hardware needed): the
//! scene's casters in a BVH built on the CPU and flattened into storage buffers
//! (`bvh.rs`), walked by a WGSL shader (`trace.wgsl`) that gives the CPU reference's
//! answers. [`ShadowRays`] answers batches of rays, for a host or a test; the
//! renderer binds the same buffers where it refines a shadow.

mod bvh;
mod query;

pub use query::{ShadowRay, ShadowRays};

use gnomon_scene::{Light, settings::Refine};
use wgpu::util::DeviceExt;

use crate::{Gpu, RenderError, passes::lighting::MapLookup};
use bvh::CasterBvh;

/// The bind group slot the tracer's buffers take in every pipeline that traces.
pub(crate) const GROUP: u32 = 3;

/// `trace.wgsl` with the constants it shares with [`bvh`].
pub(crate) fn trace_wgsl() -> String {
    format!(
        "const TRACE_STACK_SIZE: u32 = {}u;\nconst NO_ALPHA: u32 = {}u;\nconst NO_TEXTURE: u32 = {}u;\n{}",
        bvh::MAX_DEPTH,
        bvh::NO_ALPHA,
        bvh::NO_TEXTURE,
        include_str!("trace.wgsl")
    )
}

/// The WGSL of `refined_visibility`, which the shadow-mask pass calls with each
/// pixel's map answer: the answer itself when `refine` is off, otherwise the
/// classification and the ray (refine.wgsl), with the footprint test of the light's
/// kind of map.
pub(crate) fn refine_wgsl(refine: Refine, lookup: MapLookup) -> Vec<String> {
    let every_pixel = match refine {
        Refine::Off => return vec![include_str!("refine_off.wgsl").to_owned()],
        Refine::Rays => false,
        Refine::EveryPixel => true,
    };
    let footprint = match lookup {
        MapLookup::Map => include_str!("refine_map.wgsl"),
        MapLookup::Cube | MapLookup::Paraboloid => include_str!("refine_omni.wgsl"),
    };
    vec![
        format!("const REFINE_EVERY_PIXEL: bool = {every_pixel};\n"),
        trace_wgsl(),
        include_str!("refine.wgsl").to_owned(),
        footprint.to_owned(),
    ]
}

/// The refinement a light gets: `refine` for a hard light, none for a light with an
/// area, whose soft shadow one ray to its centre would harden.
pub(crate) fn light_refine(refine: Refine, light: &Light) -> Refine {
    let hard = match light {
        Light::Directional(sun) => sun.angular_diameter_degrees == 0.0,
        Light::Spot(spot) => spot.radius == 0.0,
        Light::Point(point) => point.radius == 0.0,
    };
    if hard { refine } else { Refine::Off }
}

/// The layout of the tracer's group: bindings 2–6, read-only storage (0 and 1 stay
/// free for the material texture that passes sharing `scene_common.wgsl` declare).
pub(crate) fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = (2..7)
        .map(|binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("shadow rays"),
        entries: &entries,
    })
}

/// Refuses a tree deeper than the shader's stack, or a buffer larger than `limit`
/// bytes (what the device binds in one storage buffer).
fn check_limits(bvh: &CasterBvh, scene: &str, limit: u64) -> Result<(), RenderError> {
    if bvh.depth > bvh::MAX_DEPTH {
        return Err(RenderError::RayTreeTooDeep {
            scene: scene.to_owned(),
            depth: bvh.depth,
            max: bvh::MAX_DEPTH,
        });
    }
    for (buffer, bytes) in bvh.buffer_sizes() {
        if bytes > limit {
            return Err(RenderError::RayBufferTooLarge { scene: scene.to_owned(), buffer, bytes, limit });
        }
    }
    Ok(())
}

/// A scene's casters on the GPU, bound for tracing.
pub(crate) struct GpuBvh {
    pub group: wgpu::BindGroup,
    /// Triangles in the tree: every casting instance's (0 when none casts).
    pub triangles: usize,
    _buffers: Vec<wgpu::Buffer>,
}

impl GpuBvh {
    /// Builds the casters' BVH of `scene` and uploads it. The scene must be valid.
    /// Refuses a tree deeper than the shader's stack, or a buffer larger than the
    /// device binds.
    pub fn upload(
        gpu: &Gpu,
        scene: &gnomon_scene::Scene,
        layout: &wgpu::BindGroupLayout,
    ) -> Result<Self, RenderError> {
        let bvh = CasterBvh::build(scene);
        let limit = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
        check_limits(&bvh, &scene.name, limit)?;
        // wgpu refuses a binding smaller than one element: an unused buffer holds one
        // zeroed element of the largest kind.
        let contents = |bytes: &[u8]| if bytes.is_empty() { vec![0u8; 64] } else { bytes.to_vec() };
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
                    usage: wgpu::BufferUsages::STORAGE,
                })
            })
            .collect();
            let entries: Vec<wgpu::BindGroupEntry> = buffers
                .iter()
                .zip(2..)
                .map(|(buffer, binding)| wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                })
                .collect();
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shadow rays"),
                layout,
                entries: &entries,
            });
            Self { group, triangles: bvh.casters, _buffers: buffers }
        })
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
}
