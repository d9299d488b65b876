//! The Rust↔WGSL interface, checked without a device: every shader variant Gnomon can
//! build (technique × light lookup × forward or mask path × role × refinement, the moment passes
//! per format, and every fixed pass) links and validates with naga, as wgpu would
//! compile it, and links again with each declaration named by its module, so that a
//! module that reads a name without importing it fails; every buffer struct's WGSL size
//! and field offsets equal its Rust twin's, and no struct a variant binds lacks one
//! (gpu_mirrors.rs).

use std::collections::{BTreeMap, BTreeSet};

use gnomon_scene::settings::Refine;
use wgpu::naga;

use super::{
    blit, depth_reduce, gpu_cull,
    gpu_mirrors::{GPU_ONLY, StructLayout, registered_names, struct_layouts, unregistered_bound_structs},
    light_list, lighting,
    lighting::{LightingKey, LightingRole, Lookup, MapLookup},
    map_preview, map_scroll, moments, receiver, screen_space, shadow,
};
use crate::{
    rays::{LightSize, Traversal},
    techniques::{TechniqueRef, TechniqueRegistry},
    uniforms::{FalloffGpu, LightKindGpu},
};

/// The lookups a technique's map can be read through, from its stated facts.
fn lookups(technique: TechniqueRef) -> Vec<Lookup> {
    let mut all = vec![Lookup::Own(MapLookup::Map), Lookup::Mask];
    if technique.cube_wgsl().is_some() {
        all.push(Lookup::Own(MapLookup::Cube));
    }
    if technique.maps().paraboloid {
        all.push(Lookup::Own(MapLookup::Paraboloid));
    }
    if technique.virtual_wgsl().is_some() {
        all.push(Lookup::Own(MapLookup::Virtual));
    }
    all
}

/// A host's fragment stage, as the receiver's documentation asks it to call
/// `shadow_visibility`.
const HOST_SHADER: &str = "
@fragment
fn host_main(@builtin(position) frag: vec4<f32>, @location(0) world: vec3<f32>, @location(1) normal: vec3<f32>) -> @location(0) vec4<f32> {
    let v = shadow_visibility(world, normalize(normal), frag);
    let l = shadow_light_direction(world);
    return vec4<f32>(shadow_light_radiance() * v * l.w * max(dot(normal, l.xyz), 0.0), 1.0);
}
";

/// Every composed shader, named.
fn every_variant() -> Vec<(String, String)> {
    let mut out = Vec::new();
    let registry = TechniqueRegistry::builtin();
    for technique in registry.iter() {
        for lookup in lookups(technique) {
            for role in [
                LightingRole::First,
                LightingRole::Added { visibility: true },
                LightingRole::Added { visibility: false },
            ] {
                let key = LightingKey {
                    technique,
                    lookup,
                    role,
                    refine: Refine::Off,
                    size: LightSize::Hard,
                    traversal: Traversal::Shader,
                };
                out.push((format!("lighting {key:?}"), lighting::lighting_wgsl(key)));
            }
            // The forward path's lighting pass that traces rays where the map is unsure.
            if let Lookup::Own(_) = lookup {
                for refine in [Refine::Rays, Refine::EveryPixel] {
                    for traversal in [Traversal::Shader, Traversal::RayQuery] {
                        for size in [LightSize::Hard, LightSize::Area] {
                            let role = LightingRole::First;
                            let key = LightingKey { technique, lookup, role, refine, size, traversal };
                            out.push((format!("lighting {key:?}"), lighting::lighting_wgsl(key)));
                        }
                    }
                }
            }
            if let Lookup::Own(map) = lookup {
                for refine in [Refine::Off, Refine::Rays, Refine::EveryPixel] {
                    for size in [LightSize::Hard, LightSize::Area] {
                        let key = screen_space::MaskKey { technique, lookup: map, refine, size };
                        out.push((format!("mask {key:?}"), screen_space::mask_wgsl(key)));
                    }
                }
                // The receiver with a host's fragment shader calling it, in the group
                // a host might pick.
                let source = receiver::receiver_wgsl(technique, map, 3) + HOST_SHADER;
                out.push((format!("receiver {technique:?} {map:?}"), source));
            }
        }
        if technique.filterable_map(&Default::default()).is_some() {
            for format in [wgpu::TextureFormat::Rgba16Float, wgpu::TextureFormat::Rgba32Float] {
                out.push((
                    format!("moments encode {technique:?} {format:?}"),
                    moments::encode_wgsl(technique, format),
                ));
            }
        }
    }
    for format in [wgpu::TextureFormat::Rgba16Float, wgpu::TextureFormat::Rgba32Float] {
        out.push((format!("moments filter {format:?}"), moments::filter_wgsl(format)));
    }
    out.push(("shadow".into(), shadow::shadow_wgsl()));
    out.push(("prepass".into(), screen_space::prepass_wgsl()));
    out.push(("light list".into(), light_list::light_list_wgsl()));
    out.push(("depth reduce".into(), depth_reduce::reduce_wgsl()));
    out.push(("sample bounds".into(), depth_reduce::bounds_wgsl()));
    out.push(("map preview".into(), map_preview::preview_wgsl()));
    out.push(("map scroll".into(), map_scroll::scroll_wgsl()));
    out.push(("blit".into(), blit::blit_wgsl()));
    out.push(("gpu cull".into(), gpu_cull::gpu_cull_wgsl()));
    out.push(("depth baseline".into(), super::depth_baseline::baseline_wgsl()));
    out.push(("page requests".into(), crate::virtual_map::page_requests_wgsl()));
    out.push(("edge page requests".into(), crate::virtual_map::edges::edge_requests_wgsl()));
    out.push(("page clear".into(), crate::virtual_map::draw::page_clear_wgsl()));
    out.push(("surface from depth".into(), crate::virtual_map::surface_from_depth_wgsl()));
    out.push(("virtual lookup probe".into(), crate::virtual_map::lookup_probe_wgsl()));
    out.push(("depth pyramid".into(), crate::rays::pyramid::depth_pyramid_wgsl()));
    out.push(("touched layer, list".into(), crate::rays::touched::touched_list_wgsl()));
    out.push(("touched layer, draw".into(), crate::rays::touched::touched_draw_wgsl()));
    for traversal in [Traversal::Shader, Traversal::RayQuery] {
        for size in [LightSize::Hard, LightSize::Area] {
            let source = crate::rays::trace_pass_wgsl(traversal, size);
            out.push((format!("ray trace {traversal:?} {size:?}"), source));
        }
        out.push((format!("ray query {traversal:?}"), crate::rays::query::query_wgsl(traversal)));
    }
    out
}

fn parse(name: &str, source: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    module
}

/// Compares a WGSL struct with its Rust mirror.
fn check_layout(variant: &str, module: &naga::Module, layout: &StructLayout) -> bool {
    let Some(ty) = module.types.iter().find(|(_, t)| t.name.as_deref() == Some(layout.wgsl_name)) else {
        return false;
    };
    let naga::TypeInner::Struct { members, span } = &ty.1.inner else {
        panic!("{variant}: `{}` is not a struct", layout.wgsl_name)
    };
    let wgsl: Vec<(&str, usize)> =
        members.iter().map(|m| (m.name.as_deref().unwrap_or("?"), m.offset as usize)).collect();
    assert_eq!(
        wgsl, layout.fields,
        "{variant}: `{}`'s fields (name, offset) differ from Rust's",
        layout.wgsl_name
    );
    assert_eq!(*span as usize, layout.size, "{variant}: `{}`'s size differs from Rust's", layout.wgsl_name);
    true
}

#[test]
fn every_shader_variant_validates_and_every_uniform_matches_its_rust_type() {
    let variants = every_variant();
    // Every technique reaches the lighting pass on the forward and mask paths.
    let techniques = TechniqueRegistry::builtin().iter().count();
    assert!(variants.len() > 3 * 2 * techniques, "{} variants", variants.len());
    let layouts = struct_layouts();
    let registered = registered_names();
    let mut found: BTreeMap<&str, usize> = registered.iter().map(|&name| (name, 0)).collect();
    let mut unregistered: BTreeMap<String, String> = BTreeMap::new();
    for (name, source) in &variants {
        let module = parse(name, source);
        for layout in &layouts {
            if check_layout(name, &module, layout) {
                *found.get_mut(layout.wgsl_name).expect("listed") += 1;
            }
        }
        for (gpu_only, _) in GPU_ONLY {
            if module.types.iter().any(|(_, t)| t.name.as_deref() == Some(gpu_only)) {
                *found.get_mut(gpu_only).expect("listed") += 1;
            }
        }
        for stray in unregistered_bound_structs(&module, &registered) {
            unregistered.entry(stray).or_insert_with(|| name.clone());
        }
    }
    assert!(
        unregistered.is_empty(),
        "bound with no Rust twin in gpu_mirrors.rs (`struct_layouts`, or `GPU_ONLY` with why), each with a variant that binds it: {unregistered:#?}"
    );
    for (name, count) in found {
        assert!(count > 0, "no shader declares `{name}`: its registration in gpu_mirrors.rs checks nothing");
    }
}

/// The completeness check finds a bound struct nobody registered, held directly,
/// in an array and inside another struct, and passes it once registered.
#[test]
fn a_bound_struct_without_a_rust_twin_is_found() {
    let source = "struct Stray { a: u32 }\nstruct Inner { b: f32 }\nstruct Outer { inner: Inner }\n\
        @group(0) @binding(0) var<uniform> stray: Stray;\n\
        @group(0) @binding(1) var<storage, read> outers: array<Outer>;\n\
        var<private> unbound: Stray;\n\
        @compute @workgroup_size(1) fn main() { unbound = stray; _ = outers[0].inner.b; }";
    let module = parse("stray", source);
    let found: Vec<String> = unregistered_bound_structs(&module, &registered_names()).into_iter().collect();
    assert_eq!(found, ["Inner", "Outer", "Stray"]);
    let known = BTreeSet::from(["Stray", "Inner", "Outer"]);
    assert!(unregistered_bound_structs(&module, &known).is_empty());
}

#[test]
fn generated_constants_are_what_rust_says() {
    let source = format!(
        "{}\nfn f() -> u32 {{ return MAX_CASCADES + LIGHT_POINT; }}",
        super::generated::wgsl_constants()
    );
    let module = parse("constants", &source);
    let value = |name: &str| {
        let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).expect(name);
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref other => panic!("{name} = {other:?}"),
        }
    };
    assert_eq!(value("MAX_CASCADES") as usize, crate::uniforms::MAX_CASCADES);
    for kind in LightKindGpu::all() {
        assert_eq!(value(&kind.wgsl_name()), kind.id);
    }
    for falloff in FalloffGpu::ALL {
        assert_eq!(value(falloff.wgsl_name()), falloff as u32);
    }
    // Array sizes come from the settings' limits, declared once there.
    assert_eq!(value("POISSON_DISK_SIZE"), *gnomon_scene::settings::POISSON_TAPS.end());
}

/// A layout check that would pass whatever the offsets were proves nothing: a Rust
/// struct with a field moved must fail it.
#[test]
#[should_panic(expected = "differ from Rust's")]
fn a_moved_field_fails_the_layout_check() {
    let mut layout = struct_layouts().into_iter().find(|l| l.wgsl_name == "Light").unwrap();
    layout.fields.swap(2, 3);
    let module = parse("shadow", &shadow::shadow_wgsl());
    check_layout("shadow", &module, &layout);
}

/// Every WGSL file of the crate beside `dir`'s, recursively, as (path, source).
fn wgsl_files(dir: &std::path::Path) -> Vec<(std::path::PathBuf, String)> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).expect("the crate's sources") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            files.extend(wgsl_files(&path));
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            let source = std::fs::read_to_string(&path).expect("a WGSL file");
            files.push((path, source));
        }
    }
    files
}

/// A light kind's WGSL lives in one module: `light_kinds.wgsl` names every kind, and
/// no other shader reads an emitter's kind, so a new kind is one more branch there
/// and nothing elsewhere can silently treat it as another.
#[test]
fn only_light_kinds_wgsl_reads_a_lights_kind() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let files = wgsl_files(&root);
    assert!(files.len() > 40, "found only {} WGSL files under {}", files.len(), root.display());
    let home = root.join("passes/light_kinds.wgsl");
    for (path, source) in &files {
        let code: String =
            source.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n");
        if *path == home {
            for kind in LightKindGpu::all() {
                assert!(
                    code.contains(&kind.wgsl_name()),
                    "light_kinds.wgsl never names {}",
                    kind.wgsl_name()
                );
            }
            continue;
        }
        for kind in LightKindGpu::all() {
            assert!(!code.contains(&kind.wgsl_name()), "{} names {}", path.display(), kind.wgsl_name());
        }
        for reader in ["emitter.kind", "e.kind"] {
            assert!(!code.contains(reader), "{} reads {reader}", path.display());
        }
    }
}

/// Every module imports each name it uses from another module, and the shaders do
/// not link by accident: linked with every declaration named by its module's path,
/// each shader still parses, so no module reads a name it did not import
/// (`link::Naming::ByModule`; `link::tests` shows the check failing). Every module
/// is in some shader, so the check reaches them all.
#[test]
fn every_module_imports_what_it_uses() {
    use wesl::Mangler as _;
    super::link::TEST_NAMING.with(|naming| naming.set(super::link::Naming::ByModule));
    let mut unlinked: BTreeMap<String, &str> = BTreeMap::new();
    for module in super::link::MODULES {
        let first = super::link::declared_names(module.source).expect("the module parses");
        let first = first.first().unwrap_or_else(|| panic!("{} declares nothing", module.path));
        unlinked
            .insert(wesl::EscapeMangler.mangle(&super::link::module_path(module.path), first), module.path);
    }
    for (name, source) in every_variant() {
        // The host's stage calls the receiver's functions by their written names.
        let source = source.strip_suffix(HOST_SHADER).unwrap_or(&source);
        naga::front::wgsl::parse_str(source)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
        let found = words(source);
        unlinked.retain(|mangled, _| !found.contains(mangled.as_str()));
    }
    assert!(unlinked.is_empty(), "modules in no shader, whose imports this test never saw: {unlinked:?}");
}

/// The identifiers of WGSL `code` (comments removed), by word.
fn words(code: &str) -> BTreeSet<&str> {
    code.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).collect()
}

/// No module imports a name it does not use, so a module's imports list what it
/// depends on.
#[test]
fn every_import_is_used() {
    let mut imports = 0;
    for module in super::link::MODULES {
        let code: String =
            module.source.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n");
        let (import_lines, body): (Vec<&str>, Vec<&str>) =
            code.lines().partition(|l| l.starts_with("import "));
        let body = body.join("\n");
        let used = words(&body);
        for line in import_lines {
            let names = line.trim_end_matches(';').rsplit("::").next().unwrap_or("");
            for name in names.trim_matches(|c| c == '{' || c == '}').split(',').map(str::trim) {
                imports += 1;
                assert!(used.contains(name), "{} imports `{name}` and never uses it", module.path);
            }
        }
    }
    assert!(imports > 100, "found only {imports} imports");
}

/// The modules' imports, as (module, the modules it imports from).
fn module_imports() -> BTreeMap<&'static str, BTreeSet<String>> {
    let mut graph = BTreeMap::new();
    for module in super::link::MODULES {
        let from: BTreeSet<String> = module
            .source
            .lines()
            .filter_map(|l| l.strip_prefix("import package::"))
            .filter_map(|l| l.rsplit_once("::").map(|(path, _)| path.to_owned()))
            .collect();
        graph.insert(module.path, from);
    }
    graph
}

/// No module imports, through others, one that imports it: each can be read after
/// the ones it imports. (`light.wgsl`'s structs sit apart from the uniform's
/// functions in `light_binding.wgsl` for this.)
#[test]
fn the_modules_import_one_another_without_a_circle() {
    let graph = module_imports();
    // Depth-first, with the path walked so far: a module met again on it closes a circle.
    fn walk<'a>(
        module: &'a str,
        graph: &'a BTreeMap<&'static str, BTreeSet<String>>,
        path: &mut Vec<&'a str>,
        done: &mut BTreeSet<&'a str>,
    ) {
        if let Some(at) = path.iter().position(|m| *m == module) {
            panic!("an import circle: {}", path[at..].join(" → ") + " → " + module);
        }
        if !done.insert(module) {
            return;
        }
        path.push(module);
        for next in graph.get(module).into_iter().flatten() {
            walk(next, graph, path, done);
        }
        path.pop();
    }
    let mut done = BTreeSet::new();
    for module in graph.keys() {
        walk(module, &graph, &mut Vec::new(), &mut done);
    }
    assert!(done.len() >= graph.len(), "walked {} of {} modules", done.len(), graph.len());
}

/// What one entry point reads, by the kind of resource WebGPU limits per stage.
fn resources_read(module: &naga::Module, entry: &naga::valid::FunctionInfo) -> BTreeMap<&'static str, u32> {
    use naga::{AddressSpace, ImageClass, TypeInner};
    let mut counts = BTreeMap::new();
    for (handle, var) in module.global_variables.iter() {
        if entry[handle].is_empty() || var.binding.is_none() {
            continue;
        }
        let kind = match (var.space, &module.types[var.ty].inner) {
            (AddressSpace::Storage { .. }, _) => "storage buffers",
            (AddressSpace::Uniform, _) => "uniform buffers",
            (_, TypeInner::Image { class: ImageClass::Storage { .. }, .. }) => "storage textures",
            (_, TypeInner::Image { .. }) => "sampled textures",
            (_, TypeInner::Sampler { .. }) => "samplers",
            (space, ty) => panic!("a binding in {space:?} of {ty:?}, which this check does not count"),
        };
        *counts.entry(kind).or_default() += 1;
    }
    counts
}

/// Every shader a browser can run fits WebGPU's default limits (wgpu's
/// `Limits::default()`, the specification's): the bind groups it reads, and per
/// stage its storage and uniform buffers, storage and sampled textures and
/// samplers. Ray queries are not in WebGPU; those variants are left out.
#[test]
fn every_shader_fits_webgpus_default_limits() {
    let limits = wgpu::Limits::default();
    let per_stage = BTreeMap::from([
        ("storage buffers", limits.max_storage_buffers_per_shader_stage),
        ("uniform buffers", limits.max_uniform_buffers_per_shader_stage),
        ("storage textures", limits.max_storage_textures_per_shader_stage),
        ("sampled textures", limits.max_sampled_textures_per_shader_stage),
        ("samplers", limits.max_samplers_per_shader_stage),
    ]);
    let mut checked = 0;
    for (name, source) in every_variant().iter().filter(|(name, _)| !name.contains("RayQuery")) {
        let module = parse(name, source);
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .expect("validated by parse");
        let groups =
            module.global_variables.iter().filter_map(|(_, v)| v.binding.as_ref()).map(|b| b.group + 1).max();
        assert!(groups.unwrap_or(0) <= limits.max_bind_groups, "{name} reads {groups:?} bind groups");
        for (index, entry) in module.entry_points.iter().enumerate() {
            for (kind, count) in resources_read(&module, info.get_entry_point(index)) {
                assert!(
                    count <= per_stage[kind],
                    "{name}, {}: {count} {kind}, over {}",
                    entry.name,
                    per_stage[kind]
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 300, "checked only {checked} entry points");
}
