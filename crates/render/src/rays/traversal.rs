//! The two ways a shadow ray finds its casters, and what differs between them: the
//! WGSL that defines `ray_first_hit` (trace_bvh.wgsl or trace_query.wgsl, each
//! beside trace_common.wgsl) and the tracer's bind group layout. Everything else (the
//! rays' origins, the light's samples, the classification, the list, the filter) is
//! the same code for both.

use gnomon_scene::settings::Tracer;

use super::bvh;
use crate::Gpu;

/// How shadow rays traverse the casters: the choice `Tracer` asks for, resolved on a
/// device.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Traversal {
    /// Gnomon's own BVH, built on the CPU (`bvh.rs`) and walked by a WGSL shader
    /// (`trace_bvh.wgsl`): any adapter.
    Shader,
    /// The adapter's acceleration structures (`accel.rs`), through ray queries
    /// (`trace_query.wgsl`).
    RayQuery,
}

impl Traversal {
    /// What `tracer` resolves to on `gpu`: ray queries where asked by name and the
    /// device has them, or by `auto` on a GPU that has them; the shader otherwise,
    /// with why it was not ray queries where they were asked for by name. (On
    /// lavapipe, which runs ray queries in software, the shader's BVH traced
    /// Florence's unsure pixels 5–6× faster: docs/rays-tracers.md.)
    pub(crate) fn resolve(tracer: Tracer, gpu: &Gpu) -> (Self, Option<RayQueriesUnavailable>) {
        match tracer {
            Tracer::Shader => (Traversal::Shader, None),
            Tracer::Auto if gpu.ray_queries && gpu.device_type != wgpu::DeviceType::Cpu => {
                (Traversal::RayQuery, None)
            }
            Tracer::Auto => (Traversal::Shader, None),
            Tracer::RayQuery if gpu.ray_queries => (Traversal::RayQuery, None),
            Tracer::RayQuery => (
                Traversal::Shader,
                Some(RayQueriesUnavailable::NotOnDevice { adapter: gpu.info.adapter.clone() }),
            ),
        }
    }

    /// The setting that asks for exactly this traversal.
    pub fn tracer(self) -> Tracer {
        match self {
            Traversal::Shader => Tracer::Shader,
            Traversal::RayQuery => Tracer::RayQuery,
        }
    }
}

/// Why a frame that asked for ray queries traced with the shader instead.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RayQueriesUnavailable {
    /// The device was opened without `EXPERIMENTAL_RAY_QUERY`: the adapter has none,
    /// or the host did not ask for them.
    #[error("the device on `{adapter}` has no ray queries (wgpu's EXPERIMENTAL_RAY_QUERY)")]
    NotOnDevice {
        /// The adapter's name.
        adapter: String,
    },
    /// The scene's casters hold more triangles than the device puts in one
    /// bottom-level acceleration structure.
    #[error(
        "scene `{scene}`: its shadow casters have {triangles} triangles, but this device's \
         acceleration structures take at most {limit}"
    )]
    TooManyTriangles {
        /// Name of the scene.
        scene: String,
        /// The casters' triangles.
        triangles: u64,
        /// The device's `max_blas_primitive_count`.
        limit: u64,
    },
}

/// The tracer's generated WGSL for `traversal`: the constants it shares with [`bvh`],
/// its bindings' group (`TRACE_GROUP`, bindings 2–6), and `ray_first_hit` bound to
/// the walk (`trace_bvh.wgsl` or `trace_query.wgsl`, loaded by that import with
/// `trace_common.wgsl`).
pub(crate) fn trace_wgsl(group: u32, traversal: Traversal) -> String {
    let first_hit = match traversal {
        Traversal::Shader => "bvh_ray_first_hit",
        Traversal::RayQuery => "query_ray_first_hit",
    };
    format!(
        "const TRACE_GROUP: u32 = {group}u;\nconst TRACE_STACK_SIZE: u32 = {}u;\nconst NO_ALPHA: u32 = {}u;\nconst NO_TEXTURE: u32 = {}u;\n{}",
        bvh::MAX_DEPTH,
        bvh::NO_ALPHA,
        bvh::NO_TEXTURE,
        crate::passes::wgsl_interfaces::RAY_FIRST_HIT.bind(first_hit),
    )
}

/// The first binding of the tracer's resources in whichever group holds them (0 and
/// 1 stay free for the material texture that passes sharing `scene_common.wgsl`
/// declare).
pub(crate) const FIRST_BINDING: u32 = 2;

/// The binding of the light's samples and half-plane masks (`light_masks` in
/// penumbra_beam.wgsl, a texture), after the shader tracer's five buffers.
pub(crate) const LIGHT_MASKS_BINDING: u32 = FIRST_BINDING + 5;

/// The entries of the tracer's bindings, seen by `stages`: for the shader, five
/// read-only buffers at 2–6 (nodes, triangles, alpha tests, alpha textures, alpha
/// texels); for ray queries, the top-level structure at 2 and the three alpha
/// buffers at 4–6.
pub(crate) fn entries(stages: wgpu::ShaderStages, traversal: Traversal) -> Vec<wgpu::BindGroupLayoutEntry> {
    let entry = |binding, ty| wgpu::BindGroupLayoutEntry { binding, visibility: stages, ty, count: None };
    let buffer = wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only: true },
        has_dynamic_offset: false,
        min_binding_size: None,
    };
    let alpha = (FIRST_BINDING + 2..FIRST_BINDING + 5).map(|binding| entry(binding, buffer));
    match traversal {
        Traversal::Shader => (FIRST_BINDING..FIRST_BINDING + 2)
            .map(|binding| entry(binding, buffer))
            .chain(alpha)
            .chain(std::iter::once(entry(
                LIGHT_MASKS_BINDING,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Uint,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
            )))
            .collect(),
        Traversal::RayQuery => std::iter::once(entry(
            FIRST_BINDING,
            wgpu::BindingType::AccelerationStructure { vertex_return: false },
        ))
        .chain(alpha)
        .collect(),
    }
}

/// A bind group layout for each traversal the device can run: the ray queries' only
/// where it has them (the layout itself needs the feature).
pub(crate) struct TracerLayouts {
    shader: wgpu::BindGroupLayout,
    ray_query: Option<wgpu::BindGroupLayout>,
}

impl TracerLayouts {
    /// The layouts of `label`, made by `make` for each traversal `device` runs.
    pub fn new(device: &wgpu::Device, make: impl Fn(Traversal) -> wgpu::BindGroupLayout) -> Self {
        let ray_queries = device.features().contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY);
        Self { shader: make(Traversal::Shader), ray_query: ray_queries.then(|| make(Traversal::RayQuery)) }
    }

    /// The layout for `traversal`, which the device must run ([`Traversal::resolve`]
    /// only gives one it does).
    pub fn get(&self, traversal: Traversal) -> &wgpu::BindGroupLayout {
        match traversal {
            Traversal::Shader => &self.shader,
            Traversal::RayQuery => {
                self.ray_query.as_ref().expect("ray queries are resolved only on a device that has them")
            }
        }
    }
}
