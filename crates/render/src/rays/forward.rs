//! Refinement by rays on the forward path: the lighting pass looks each fragment's
//! shadow up in the map and, where the map is unsure of it, traces the fragment's
//! rays then and there (`refine_forward.wgsl`), over the casters' BVH bound in its
//! group 1 beside the camera. The classification and the rays are the mask path's;
//! what differs is where they run (see the WGSL for what that costs).

use crate::passes::wgsl_interfaces::REFINE_FORWARD;
use gnomon_scene::settings::Refine;

use super::{
    GpuBvh, TracerLayouts, Traversal,
    refine::{LightSize, classify_wgsl, surface_rays_wgsl},
    traversal,
};
use crate::{
    passes::lighting::MapLookup,
    pool::{Binding, Pool},
};

/// The lighting pass's group that holds the tracer's buffers, beside the camera
/// (binding 0): the material takes group 3, where the compute passes keep them.
const GROUP: u32 = 1;

/// The WGSL of `refine_forward`, which the lighting pass calls with each fragment's
/// map answer: the answer itself when `refine` is off (and on the mask path, whose
/// mask holds the rays' answers already); otherwise the classification, the tracer
/// (`traversal`'s) and the fragment's rays.
pub(crate) fn forward_refine_wgsl(
    refine: Refine,
    lookup: MapLookup,
    size: LightSize,
    traversal: Traversal,
) -> Vec<String> {
    let Some(mut parts) = classify_wgsl(refine, lookup, size) else {
        return vec![
            include_str!("refine_forward_off.wgsl").to_owned(),
            REFINE_FORWARD.bind("unrefined_refine_forward"),
        ];
    };
    parts.extend(surface_rays_wgsl(GROUP, traversal));
    parts.push(include_str!("refine_forward.wgsl").to_owned());
    parts.push(REFINE_FORWARD.bind("traced_refine_forward"));
    parts
}

/// Group 1 of a lighting pass that traces: the camera (0) and the tracer's
/// resources (2–6), for each traversal the device runs.
pub(crate) fn forward_layouts(device: &wgpu::Device) -> TracerLayouts {
    let fragment = wgpu::ShaderStages::FRAGMENT;
    let camera = wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::VERTEX | fragment,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    TracerLayouts::new(device, |t| {
        let entries = [vec![camera], traversal::entries(fragment, t)].concat();
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("camera, tracing shadow rays"),
            entries: &entries,
        })
    })
}

/// Group 1 of the lighting pass that traces by `traversal`: `camera` and `bvh`'s
/// resources.
pub(crate) fn forward_group(
    pool: &mut Pool,
    layouts: &TracerLayouts,
    camera: &wgpu::Buffer,
    bvh: &GpuBvh,
    traversal: Traversal,
) -> wgpu::BindGroup {
    let mut bindings = vec![(0, Binding::Buffer(camera.clone()))];
    bindings.extend(bvh.bindings(traversal));
    pool.bind_group_numbered("camera, tracing shadow rays", layouts.get(traversal), bindings)
}
