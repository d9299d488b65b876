//! The shadow receiver's WGSL: a light's lookup (its technique, its kind of map) and
//! the documented `shadow_visibility` entry of `receiver.wgsl`, with every resource
//! in one bind group at the index the host's shader chose.

use super::{
    BindingPlace, CAMERA_STRUCT_WGSL, LIGHT_WGSL, SHADING_WGSL, camera_binding_wgsl, compose_wgsl,
    light_binding_wgsl,
    lighting::{MapLookup, resolved_lookup_wgsl},
};
use crate::techniques::{TechniqueRef, shadow_bindings_wgsl};

/// The receiver's module for `technique` looked up through `lookup`, its group at
/// index `group`. A host's shader is appended to it.
pub(crate) fn receiver_wgsl(technique: TechniqueRef, lookup: MapLookup, group: u32) -> String {
    let mut parts: Vec<String> = [LIGHT_WGSL, CAMERA_STRUCT_WGSL, SHADING_WGSL].map(str::to_owned).to_vec();
    parts.extend(resolved_lookup_wgsl(technique, lookup));
    // The light and the camera at bindings 0 and 1, the shadow resources after them
    // (`Layouts::receiver`).
    parts.push(light_binding_wgsl(BindingPlace { group, binding: 0 }));
    parts.push(camera_binding_wgsl(BindingPlace { group, binding: 1 }));
    parts.push(shadow_bindings_wgsl(BindingPlace { group, binding: 2 }));
    parts.push(include_str!("receiver.wgsl").to_owned());
    let refs: Vec<&str> = parts.iter().map(String::as_str).collect();
    compose_wgsl(&refs)
}
