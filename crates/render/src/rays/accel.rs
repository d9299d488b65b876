//! The casters as the adapter's own acceleration structures, for the ray-query
//! tracer (`trace_query.wgsl`, wgpu's `EXPERIMENTAL_RAY_QUERY`): one bottom-level
//! structure over the very triangles the shader tracer walks, read from its triangle
//! buffer (`bvh.rs`'s `TriangleGpu`, whose three vertices lie 16 bytes apart), and a
//! top-level structure holding it once, untransformed: the triangles are in world
//! space already.
//!
//! The bottom level has two geometries. The opaque triangles are flagged so, and the
//! adapter's traversal commits a hit on them by itself; the cut-out ones are not, and
//! come back to the shader as candidates for their alpha test. They are listed in
//! the order of their alpha tests (`bvh.rs` numbers the tests in leaf order as it
//! meets them), so a candidate's primitive index is its test's index.
//!
//! When instances move, the shader tracer's refit rewrites the moved triangles in the
//! same buffer, and both levels are built again from it: wgpu 30 implements no
//! update of a built structure (its `PreferUpdate` rebuilds), so this is the
//! driver's build, on the GPU, of what the CPU refitted. Frames in which nothing
//! moves build nothing.

use super::{
    RayQueriesUnavailable,
    bvh::{CasterBvh, NO_ALPHA},
};
use crate::{Gpu, RenderError};
use wgpu::util::DeviceExt;

/// Bytes from one vertex to the next in the triangle buffer: a `TriangleGpu` is three
/// `vec3<f32>`, each padded to 16 bytes.
const VERTEX_STRIDE: u64 = 16;

/// The top-level structure's one instance: the identity, as 3 × 4 rows.
const IDENTITY: [f32; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// One geometry of the bottom level: its size and the indices of its vertices in the
/// triangle buffer.
struct Geometry {
    size: wgpu::BlasTriangleGeometrySizeDescriptor,
    indices: wgpu::Buffer,
}

/// The casters' acceleration structures, and the buffers their builds read.
pub(crate) struct CasterAccel {
    blas: wgpu::Blas,
    tlas: wgpu::Tlas,
    geometries: Vec<Geometry>,
}

impl CasterAccel {
    /// The limits a device sets on the structures that `tree` needs, checked: a scene
    /// over them is refused naming the limit, and traced by the shader instead.
    pub fn check_limits(gpu: &Gpu, tree: &CasterBvh, scene: &str) -> Result<(), RayQueriesUnavailable> {
        let triangles = tree.triangles.len() as u64;
        let limit = u64::from(gpu.limits.max_blas_primitive_count);
        if triangles > limit {
            return Err(RayQueriesUnavailable::TooManyTriangles {
                scene: scene.to_owned(),
                triangles,
                limit,
            });
        }
        Ok(())
    }

    /// Builds the structures over `tree`'s triangles, which `triangles` holds on the
    /// GPU (created with `BLAS_INPUT`). The device must have ray queries
    /// ([`Gpu::ray_queries`]) and `tree` fit its limits ([`CasterAccel::check_limits`]).
    pub fn build(gpu: &Gpu, tree: &CasterBvh, triangles: &wgpu::Buffer) -> Result<Self, RenderError> {
        let device = &gpu.device;
        let accel = gpu.checked("building the casters' acceleration structures", || {
            let geometries = geometries(device, tree);
            let sizes = geometries.iter().map(|g| g.size.clone()).collect();
            let blas = device.create_blas(
                &wgpu::CreateBlasDescriptor {
                    label: Some("shadow casters, bottom level"),
                    flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
                    update_mode: wgpu::AccelerationStructureUpdateMode::Build,
                },
                wgpu::BlasGeometrySizeDescriptors::Triangles { descriptors: sizes },
            );
            let mut tlas = device.create_tlas(&wgpu::CreateTlasDescriptor {
                label: Some("shadow casters, top level"),
                max_instances: 1,
                flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
                update_mode: wgpu::AccelerationStructureUpdateMode::Build,
            });
            tlas[0] = Some(wgpu::TlasInstance::new(&blas, IDENTITY, 0, 0xff));
            let accel = Self { blas, tlas, geometries };
            accel.record_build(gpu, triangles);
            accel
        })?;
        Ok(accel)
    }

    /// Builds both levels again around `triangles` as a refit left them.
    pub fn rebuild(&self, gpu: &Gpu, triangles: &wgpu::Buffer) -> Result<(), RenderError> {
        gpu.checked("rebuilding the casters' acceleration structures", || self.record_build(gpu, triangles))
    }

    /// Builds both levels from `triangles`, and submits.
    fn record_build(&self, gpu: &Gpu, triangles: &wgpu::Buffer) {
        let geometry = self
            .geometries
            .iter()
            .map(|g| wgpu::BlasTriangleGeometry {
                size: &g.size,
                vertex_buffer: triangles,
                first_vertex: 0,
                vertex_stride: VERTEX_STRIDE,
                index_buffer: Some(&g.indices),
                first_index: Some(0),
                transform_buffer: None,
                transform_buffer_offset: None,
            })
            .collect();
        let entry = wgpu::BlasBuildEntry {
            blas: &self.blas,
            geometry: wgpu::BlasGeometries::TriangleGeometries(geometry),
        };
        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("building the casters' acceleration structures"),
        });
        encoder.build_acceleration_structures(std::iter::once(&entry), std::iter::once(&self.tlas));
        gpu.queue.submit([encoder.finish()]);
    }

    /// The top level, to bind.
    pub fn binding(&self) -> wgpu::BindingResource<'_> {
        self.tlas.as_binding()
    }

    /// The top level itself, for a bind group that holds it beside others.
    pub fn tlas(&self) -> &wgpu::Tlas {
        &self.tlas
    }
}

/// The opaque triangles and the cut-out ones of `tree`, each as the indices of their
/// vertices in the triangle buffer (triangle `k`'s are `3k`, `3k + 1`, `3k + 2`);
/// the cut-out ones in the order of their alpha tests. A kind with no triangle has no
/// geometry; a tree always holds one triangle (`CasterBvh::build`), so there is one.
fn geometries(device: &wgpu::Device, tree: &CasterBvh) -> Vec<Geometry> {
    let mut opaque: Vec<u32> = Vec::new();
    let mut cut_out: Vec<u32> = Vec::new();
    for (k, triangle) in tree.triangles.iter().enumerate() {
        let vertices = [0, 1, 2].map(|v| 3 * k as u32 + v);
        if triangle.alpha == NO_ALPHA {
            opaque.extend(vertices);
        } else {
            // Its alpha test's index is its primitive index in this geometry.
            debug_assert_eq!(triangle.alpha as usize, cut_out.len() / 3);
            cut_out.extend(vertices);
        }
    }
    let vertex_count = 3 * tree.triangles.len() as u32;
    [
        (opaque, wgpu::AccelerationStructureGeometryFlags::OPAQUE),
        (cut_out, wgpu::AccelerationStructureGeometryFlags::empty()),
    ]
    .into_iter()
    .filter(|(indices, _)| !indices.is_empty())
    .map(|(indices, flags)| Geometry {
        size: wgpu::BlasTriangleGeometrySizeDescriptor {
            vertex_format: wgpu::VertexFormat::Float32x3,
            vertex_count,
            index_format: Some(wgpu::IndexFormat::Uint32),
            index_count: Some(indices.len() as u32),
            flags,
        },
        indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadow casters, triangle indices"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::BLAS_INPUT,
        }),
    })
    .collect()
}
