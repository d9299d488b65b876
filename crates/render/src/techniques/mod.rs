//! The shadow techniques. Each family is a module with its WGSL beside it, and each
//! technique is one line of [`BUILTIN`]. A technique states every fact about itself
//! through [`ShadowTechnique`]: its name and summary, its WGSL and parameters, the
//! maps it can read and how far its filter reaches. The passes, the layout and the
//! settings' checks ask a [`TechniqueRegistry`] and know nothing else about it: a host
//! registers a technique of its own with [`TechniqueRegistry::with`].
//!
//! A technique's WGSL implements the technique contract
//! (`passes::wgsl_interfaces::TECHNIQUE_CONTRACT`) under its module's name:
//! `fn pcf_box_sample_shadow(q: ShadowQuery) -> f32` (the lookup, see `common.wgsl`),
//! returning the lit fraction in [0, 1], and the shader's generated module binds
//! `sample_shadow` to it (a host's technique may define `sample_shadow` itself). It
//! may read the shadow bindings of `bindings.wgsl`, the `light` uniform
//! (`passes/light_binding.wgsl`), whose `technique` block carries the typed values of
//! [`ShadowTechnique::params`] ([`TechniqueParams`]), and the helpers of
//! `common.wgsl`. A built-in technique's `.wgsl` is a WESL module that imports each
//! of these (`import package::techniques::bindings::shadow_map;`); a host's WGSL is
//! linked into the shader's `package::variant`, which imports them for it
//! (`passes::link`). A filterable technique also defines
//! `fn <module>_encode_moments(d: f32, layer: u32) -> vec4<f32>`, which the moment pass
//! applies to every texel's linear depth d ∈ [0, 1].
//!
//! The contract itself is `contract.rs` ([`ShadowTechnique`] and the facts it
//! states), which every technique's module imports and nothing of which imports a
//! technique; the built-in list is `registry.rs`'s [`BUILTIN`].

mod contract;
pub(crate) mod convolution;
pub(crate) mod esm;
pub(crate) mod msm;
mod params;
mod pcf;
mod pcss;
mod raytraced;
mod registry;
pub(crate) mod variance;

pub use contract::{FilterableMap, MapPrecision, MapSupport, ShadowTechnique, Tunables, VirtualReach};
pub use params::{GpuParams, NoParams, PARAMS_BYTES, ParamsBlockGpu, TechniqueParams};
pub use registry::{BUILTIN, RegistryError, TechniqueRef, TechniqueRegistry};

use crate::passes::binding_place::BindingPlace;
use crate::passes::wgsl_interfaces::TECHNIQUE_CONTRACT;

/// A technique's WGSL `sources` (its lookup's, or its cube lookup's), after the
/// generated line that types `light.technique` as its parameter struct.
pub(crate) fn technique_wgsl(technique: &dyn ShadowTechnique, sources: &[&str]) -> Vec<String> {
    let mut parts = vec![technique.params_struct().wgsl_alias()];
    parts.extend(sources.iter().map(|s| (*s).to_owned()));
    for interface in TECHNIQUE_CONTRACT {
        // Two implementations of one contract function leave the binding out, and
        // naga then refuses the shader by the interface's name: the registry's test
        // `every_technique_defines_its_entry_points` names the culprits first.
        if let Ok(Some(implementation)) = interface.implementation_in(sources)
            && implementation != interface.name
        {
            parts.push(interface.bind(&implementation));
        }
    }
    parts
}

/// The helpers every cube lookup shares, which a technique's cube WGSL imports.
pub(crate) const CUBE_WGSL: &str = include_str!("cube.wgsl");

/// The query and helpers every virtual-map lookup shares, which a technique's
/// virtual WGSL imports.
pub(crate) const VIRTUAL_QUERY_WGSL: &str = include_str!("virtual_query.wgsl");

/// Taps in the shared Poisson disk: the most any technique may ask for, the end of
/// the settings' `POISSON_TAPS` (which `Settings::validate` holds every render to).
pub const POISSON_DISK_SIZE: usize = *gnomon_scene::settings::POISSON_TAPS.end() as usize;

/// Where Gnomon's lighting, mask and moment passes bind the shadow resources a
/// technique may read: group 2, from binding 0 (`Layouts::shadow`).
pub(crate) const OWN_SHADOW_BINDINGS: BindingPlace = BindingPlace { group: 2, binding: 0 };

/// The shadow resources a technique may read (`bindings.wgsl`, declared once), the
/// first (`shadow_map`) at `place` and the other six after it.
pub(crate) fn shadow_bindings_wgsl(place: BindingPlace) -> String {
    place.declare("SHADOW")
}

/// The WGSL every technique is composed with, before its own: the shadow bindings,
/// the generated kernels, the lookup contract and its helpers.
pub(crate) fn shared_wgsl() -> Vec<String> {
    let mut parts = vec![shadow_bindings_wgsl(OWN_SHADOW_BINDINGS)];
    parts.extend(helper_wgsl());
    parts
}

/// [`shared_wgsl`] without the bindings: the generated kernels, the lookup contract
/// and its helpers.
pub(crate) fn helper_wgsl() -> Vec<String> {
    vec![
        poisson_disk_wgsl().to_owned(),
        include_str!("common.wgsl").to_owned(),
        include_str!("filterable.wgsl").to_owned(),
    ]
}

/// The shared Poisson disk as generated WGSL, made once: building it is quadratic
/// in its taps, and every shader with a technique is composed with it.
fn poisson_disk_wgsl() -> &'static str {
    static DISK: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    DISK.get_or_init(|| {
        let disk: Vec<String> = gnomon_math::kernels::poisson_disk(POISSON_DISK_SIZE)
            .iter()
            .map(|p| format!("vec2<f32>({:.6}, {:.6})", p.x, p.y))
            .collect();
        format!(
            "// Generated by gnomon_math::kernels::poisson_disk: a progressive Poisson disk in\n\
             // the unit disk; any prefix is well spread.\n\
             var<private> POISSON_DISK: array<vec2<f32>, {POISSON_DISK_SIZE}> = array<vec2<f32>, {POISSON_DISK_SIZE}>(\n    {}\n);\n",
            disk.join(",\n    ")
        )
    })
}
