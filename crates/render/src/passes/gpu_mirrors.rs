//! Every Rust↔WGSL mirror, registered by type (a test module): the structs Rust
//! lays out for a shader's buffers (`struct_layouts`), whose WGSL twins
//! interface_tests.rs checks field by field in every variant, and the check that no
//! struct a variant binds as a uniform or storage buffer, or holds in one, goes
//! unregistered (`unregistered_bound_structs`): a new buffer's struct needs its Rust
//! twin listed here, or its name in `GPU_ONLY` with why Rust never touches it.

use std::collections::BTreeSet;

use wgpu::naga;

use super::{depth_reduce, gpu_cull, light_list, map_preview, map_scroll, moments};
use crate::{
    rays, techniques,
    uniforms::{
        BiasGpu, CameraGpu, CascadeChoiceGpu, CascadeGpu, ContactGpu, EmitterGpu, LightGpu, MapGpu, PcfGpu,
        PcssGpu, RaysGpu,
    },
};

/// A GPU struct's fields as Rust lays them out, for the layout test to compare with
/// the WGSL struct of the same name.
pub(super) struct StructLayout {
    pub wgsl_name: &'static str,
    pub size: usize,
    pub fields: Vec<(&'static str, usize)>,
}

/// `StructLayout` of a `repr(C)` struct, listing its WGSL twin's fields by name.
macro_rules! struct_layout {
    ($ty:ty as $wgsl:literal { $($field:ident $(= $rust:ident)?),* $(,)? }) => {
        StructLayout {
            wgsl_name: $wgsl,
            size: std::mem::size_of::<$ty>(),
            fields: vec![$((stringify!($field), struct_layout!(@offset $ty, $field $(, $rust)?))),*],
        }
    };
    // A WGSL field named as in Rust, or `wgsl = rust` where a `vec3<u32>` stands for
    // three Rust words from its first.
    (@offset $ty:ty, $field:ident) => { std::mem::offset_of!($ty, $field) };
    (@offset $ty:ty, $field:ident, $rust:ident) => { std::mem::offset_of!($ty, $rust) };
}

/// Every struct shared with WGSL: each a uniform or storage buffer's, or a field's
/// of one, that Rust writes or reads.
pub(super) fn struct_layouts() -> Vec<StructLayout> {
    vec![
        struct_layout!(LightGpu as "Light" {
            clip_from_world, light_from_world, emitter, ambient, _pad0, map, cascade_choice, bias, pcf, pcss,
            contact, rays, technique, cascade_clip_from_world, cascades,
        }),
        struct_layout!(EmitterGpu as "Emitter" {
            radiance, kind, direction, range, position, cos_inner, cos_outer, falloff, falloff_window, size,
        }),
        struct_layout!(MapGpu as "ShadowMap" {
            layer_count, moment_layers, resolution, near, far, texel_ortho, texel_per_distance, _pad0,
        }),
        struct_layout!(CascadeChoiceGpu as "CascadeChoice" { by_projection, blend, _pad0, _pad1 }),
        struct_layout!(BiasGpu as "Bias" { normal_offset, depth, slope, receiver_plane }),
        struct_layout!(PcfGpu as "Pcf" { kernel_width, kernel_in_world, poisson_taps, _pad0 }),
        struct_layout!(PcssGpu as "Pcss" { blocker_taps, max_penumbra_texels, max_search_texels, _pad1 }),
        struct_layout!(ContactGpu as "Contact" { steps, length, thickness, bias, distance, _pad0, _pad1, _pad2 }),
        struct_layout!(RaysGpu as "Rays" { penumbra_rays, history, frame, penumbra_frames }),
        struct_layout!(techniques::NoParams as "NoParams" { _pad0, _pad1 }),
        struct_layout!(techniques::variance::VarianceParams as "VarianceParams" {
            positive_exponent, negative_exponent, min_variance, bleeding_reduction, variant, _pad0, _pad1, _pad2,
        }),
        struct_layout!(techniques::esm::EsmParams as "EsmParams" { exponent, _pad0, _pad1, _pad2, _pad3 }),
        struct_layout!(techniques::msm::MsmParams as "MsmParams" { moment_bias, hausdorff, quantised, _pad0, _pad1 }),
        struct_layout!(techniques::convolution::ConvolutionParams as "ConvolutionParams" {
            terms, attenuation, scale, offset, _pad0,
        }),
        struct_layout!(light_list::LightListGpu as "LightList" {
            ambient, shown, tiles_x, _pad0, _pad1, _pad2,
        }),
        struct_layout!(crate::gpu_types::InstanceGpu as "Instance" {
            world_from_object, base_color, specular, shininess, object_id, alpha_cutoff, textured, seen_faces, _pad1,
            _pad2,
        }),
        struct_layout!(CascadeGpu as "Cascade" {
            texel_world, warp_step, split_start, split_end, warped, _pad0, _pad1, _pad2,
        }),
        struct_layout!(CameraGpu as "Camera" {
            clip_from_world, view_from_world, world_from_view, eye, debug_view, scale_x, scale_y, near,
            far, width, height, inv_width, inv_height,
        }),
        struct_layout!(depth_reduce::BoundsParams as "BoundsParams" {
            world_from_clip, light_from_world, splits, near, far, cascade_count, blend,
        }),
        struct_layout!(depth_reduce::Planes as "Planes" { near, far, _pad0, _pad1 }),
        struct_layout!(crate::virtual_map::MapSpaceGpu as "MapSpace" {
            light_from_world, near, far, tan_half_fov, kind,
        }),
        struct_layout!(crate::virtual_map::PageRequestParams as "PageRequestParams" {
            map, origins, finest_texel, footprint_per_depth, reach_texels, levels, pages_per_side,
            page_texels, width, height, edge_levels, area_light_size, area_cap_texels, cone_light_size,
            cone_level_cap_texels, cone_reach_cap_texels, _pad0, _pad1,
        }),
        struct_layout!(crate::virtual_map::VirtualMapGpu as "VirtualMap" {
            map, origins, finest_texel, levels, pages_per_side, page_texels,
            pool_pages_per_side, footprint_per_depth, pool_rows_per_layer, edge_levels,
        }),
        struct_layout!(crate::virtual_map::SurfaceParams as "SurfaceParams" {
            world_from_clip, view_z_from_world, width, height, _pad0, _pad1,
        }),
        struct_layout!(map_preview::PreviewParams as "Preview" { tile, layer_count, resolution, _pad, layers }),
        struct_layout!(map_preview::PreviewLayer as "PreviewLayer" { perspective, near, far, _pad }),
        struct_layout!(crate::gpu_scene::shadow_items::ItemGpu as "ShadowItem" {
            min, bucket, max, has_cone, axis, sin_half_angle, index_count, first_index, base_vertex,
            first_instance,
        }),
        struct_layout!(gpu_cull::CullViewGpu as "CullView" { planes, centre, item_count, near, _pad0, _pad1 }),
        struct_layout!(gpu_cull::BucketGpu as "CullBucket" { first_slot, culled }),
        struct_layout!(crate::gpu_scene::DrawArgs as "DrawArgs" {
            index_count, instance_count, first_index, base_vertex, first_instance,
        }),
        struct_layout!(moments::FilterParamsGpu as "FilterParams" {
            direction, radius, log_c, sigma, _pad0, _pad1, _pad2,
        }),
        struct_layout!(rays::bvh::NodeGpu as "BvhNode" { min, count, max, first }),
        struct_layout!(rays::bvh::TriangleGpu as "BvhTriangle" { v0, alpha, v1, closed, v2, _pad2 }),
        struct_layout!(rays::bvh::AlphaGpu as "AlphaTest" { uv0, uv1, uv2, texture, base_alpha, cutoff, _pad }),
        struct_layout!(rays::bvh::AlphaTextureGpu as "AlphaTexture" {
            first_word, width, height, wrap_u, wrap_v, nearest, _pad0, _pad1,
        }),
        struct_layout!(rays::query::RayGpu as "QueryRay" { origin, length, direction, _pad }),
        struct_layout!(map_scroll::ScrollParams as "Scroll" { offset, size }),
        struct_layout!(crate::virtual_map::VirtualProbe as "Probe" { world, level }),
        struct_layout!(rays::PyramidParams as "PyramidParams" { cube, range, near, _pad }),
        struct_layout!(rays::touched::TouchedDrawGpu as "TouchedDraw" {
            vertex_count, instance_count, first_vertex, first_instance,
        }),
        struct_layout!(rays::refine::UnsurePixelGpu as "UnsurePixel" { pixel, layer, mean, beams }),
        struct_layout!(rays::refine::RefineCountersGpu as "RefineCounters" {
            groups_x, groups_y, groups_z, count, fill_groups_x, fill_groups_y, fill_groups_z, fill_count,
            kept_count, _pad0, _pad1, _pad2,
        }),
        struct_layout!(rays::refine::RefineCountersGpu as "ListedPixels" {
            groups = groups_x, count, fill_groups = fill_groups_x, fill_count, kept_count,
        }),
    ]
}

/// Structs a shader binds that Rust never writes or reads: buffers the GPU fills and
/// reads itself, each with why, so that none lacks a twin by oversight.
pub(super) const GPU_ONLY: &[(&str, &str)] = &[];

/// The named structs of `module` that a uniform or storage global holds, directly, as
/// an array's element, or as a field of one, that neither `struct_layouts` nor
/// `GPU_ONLY` names.
pub(super) fn unregistered_bound_structs(
    module: &naga::Module,
    registered: &BTreeSet<&str>,
) -> BTreeSet<String> {
    let mut bound = BTreeSet::new();
    let mut pending: Vec<naga::Handle<naga::Type>> = module
        .global_variables
        .iter()
        .filter(|(_, g)| matches!(g.space, naga::AddressSpace::Uniform | naga::AddressSpace::Storage { .. }))
        .map(|(_, g)| g.ty)
        .collect();
    let mut seen = BTreeSet::new();
    while let Some(ty) = pending.pop() {
        if !seen.insert(ty) {
            continue;
        }
        let t = &module.types[ty];
        match &t.inner {
            naga::TypeInner::Struct { members, .. } => {
                if let Some(name) = &t.name {
                    bound.insert(name.clone());
                }
                pending.extend(members.iter().map(|m| m.ty));
            }
            naga::TypeInner::Array { base, .. } | naga::TypeInner::BindingArray { base, .. } => {
                pending.push(*base)
            }
            naga::TypeInner::Atomic(_)
            | naga::TypeInner::Scalar(_)
            | naga::TypeInner::Vector { .. }
            | naga::TypeInner::Matrix { .. }
            | naga::TypeInner::Pointer { .. }
            | naga::TypeInner::ValuePointer { .. }
            | naga::TypeInner::Image { .. }
            | naga::TypeInner::Sampler { .. }
            | naga::TypeInner::AccelerationStructure { .. }
            | naga::TypeInner::RayQuery { .. }
            | naga::TypeInner::CooperativeMatrix { .. } => {}
        }
    }
    bound.into_iter().filter(|name| !registered.contains(name.as_str())).collect()
}

/// The names `struct_layouts` and `GPU_ONLY` register.
pub(super) fn registered_names() -> BTreeSet<&'static str> {
    struct_layouts().iter().map(|l| l.wgsl_name).chain(GPU_ONLY.iter().map(|(name, _)| *name)).collect()
}
