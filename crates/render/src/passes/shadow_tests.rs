//! Structural guards on the shadow pass's cost, checked without a device: the shape of
//! its pipelines, and what each geometry vertex stage reads, by reflection of the
//! composed WGSL (naga, as wgpu compiles it). Timings belong in `gnomon bench`; these
//! tests hold the cause of a slow shadow pass instead (issue 20: a storage-buffer read
//! of the instance matrix in every vertex made Sponza's shadow pass 1.6–1.8× the
//! depth-only baseline on lavapipe).

use std::collections::BTreeSet;

use gnomon_scene::settings::{BiasSettings, CullMode, Refine, Technique};

use crate::techniques::TechniqueRegistry;
use wgpu::naga;

use super::*;
use crate::{
    gpu_types::INSTANCE_SLOT,
    passes::{
        lighting::{self, LightingKey, LightingRole, Lookup, MapLookup},
        screen_space,
    },
};

const TARGETS: [DepthTarget; 3] = [DepthTarget::Projected, DepthTarget::CubeFace, DepthTarget::Paraboloid];
const COVERAGES: [Coverage; 2] = [Coverage::Opaque, Coverage::Masked];

/// Every shadow pipeline key over targets, coverage, culls, sides and depth ranges.
fn all_keys() -> Vec<ShadowPipelineKey> {
    let mut keys = Vec::new();
    for cull in [CullMode::Auto, CullMode::Back, CullMode::Front, CullMode::None] {
        let bias = BiasSettings { cull, ..BiasSettings::default() };
        for target in TARGETS {
            for coverage in COVERAGES {
                for sides in [Sides::Double, Sides::Closed, Sides::Open] {
                    for range in [DepthRange::Clipped, DepthRange::Clamped] {
                        keys.push(ShadowPipelineKey::new(&bias, sides, coverage, range, target));
                    }
                }
            }
        }
    }
    keys
}

/// A composed WGSL module, parsed and validated as wgpu would.
struct Reflected {
    module: naga::Module,
    info: naga::valid::ModuleInfo,
}

impl Reflected {
    fn new(source: &str) -> Self {
        let module =
            naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
        Self { module, info }
    }

    fn entry(&self, name: &str) -> usize {
        self.module
            .entry_points
            .iter()
            .position(|e| e.name == name)
            .unwrap_or_else(|| panic!("no entry point {name}"))
    }

    /// The names of the globals an entry point (with everything it calls) uses.
    fn globals_used(&self, entry: &str) -> BTreeSet<String> {
        let info = self.info.get_entry_point(self.entry(entry));
        self.module
            .global_variables
            .iter()
            .filter(|(handle, _)| !info[*handle].is_empty())
            .map(|(_, global)| global.name.clone().unwrap_or_default())
            .collect()
    }

    /// The storage-buffer globals an entry point uses.
    fn storage_used(&self, entry: &str) -> BTreeSet<String> {
        let info = self.info.get_entry_point(self.entry(entry));
        self.module
            .global_variables
            .iter()
            .filter(|(handle, global)| {
                matches!(global.space, naga::AddressSpace::Storage { .. }) && !info[*handle].is_empty()
            })
            .map(|(_, global)| global.name.clone().unwrap_or_default())
            .collect()
    }

    /// The input locations of an entry point, its structs' members included.
    fn input_locations(&self, entry: &str) -> BTreeSet<u32> {
        let function = &self.module.entry_points[self.entry(entry)].function;
        let mut locations = BTreeSet::new();
        for argument in &function.arguments {
            match (&argument.binding, &self.module.types[argument.ty].inner) {
                (Some(naga::Binding::Location { location, .. }), _) => {
                    locations.insert(*location);
                }
                (None, naga::TypeInner::Struct { members, .. }) => {
                    locations.extend(members.iter().filter_map(|m| match m.binding {
                        Some(naga::Binding::Location { location, .. }) => Some(location),
                        _ => None,
                    }));
                }
                (Some(naga::Binding::BuiltIn(_)), _) | (None, _) => {}
            }
        }
        locations
    }

    fn vertex_entries(&self) -> Vec<String> {
        self.module
            .entry_points
            .iter()
            .filter(|e| e.stage == naga::ShaderStage::Vertex)
            .map(|e| e.name.clone())
            .collect()
    }
}

#[test]
fn opaque_casters_into_a_projected_map_take_the_depth_only_path() {
    let reflected = Reflected::new(&shadow_wgsl());
    let opaque: Vec<_> = all_keys()
        .into_iter()
        .filter(|k| k.target == DepthTarget::Projected && k.coverage == Coverage::Opaque)
        .collect();
    // 4 cull modes × 3 kinds of sides × 2 depth ranges.
    assert_eq!(opaque.len(), 24);
    for key in opaque {
        let shape = ShadowPipelineShape::of(&key);
        assert_eq!(shape.fragment_entry, None, "{key:?}: no fragment stage");
        assert_eq!(shape.stream, VertexStream::PositionsOnly, "{key:?}: the 12-byte position stream");
        let [Some(vertices), Some(instances)] = shape.stream.buffers() else { panic!("two vertex buffers") };
        assert_eq!((vertices.array_stride, vertices.step_mode), (12, wgpu::VertexStepMode::Vertex));
        assert_eq!(instances.step_mode, wgpu::VertexStepMode::Instance);
        assert_eq!(INSTANCE_SLOT, 1);
        // The only global it reads is the light's projection: no instance storage.
        assert_eq!(
            reflected.globals_used(shape.vertex_entry),
            BTreeSet::from(["light".to_string()]),
            "{key:?}: {} reads more than the light uniform",
            shape.vertex_entry
        );
    }
}

#[test]
fn no_geometry_vertex_stage_reads_a_storage_buffer() {
    let mut modules = vec![("shadow", Reflected::new(&shadow_wgsl()))];
    modules.push(("prepass", Reflected::new(&screen_space::prepass_wgsl())));
    let registry = TechniqueRegistry::builtin();
    for technique in [Technique::HARD, Technique::PCSS, Technique::VSM] {
        let technique = registry.get(&technique).expect("built in");
        for lookup in [Lookup::Own(MapLookup::Map), Lookup::Mask] {
            let key = LightingKey {
                technique,
                lookup,
                role: LightingRole::First,
                refine: Refine::Off,
                size: crate::rays::LightSize::Hard,
                traversal: crate::rays::Traversal::Shader,
            };
            modules.push(("lighting", Reflected::new(&lighting::lighting_wgsl(key))));
        }
    }
    let mut checked = 0;
    for (name, reflected) in &modules {
        for entry in reflected.vertex_entries() {
            assert_eq!(
                reflected.storage_used(&entry),
                BTreeSet::new(),
                "{name}'s {entry} reads a storage buffer per vertex; take per-instance data as \
                 instance-step attributes (InstanceTransform)"
            );
            checked += 1;
        }
    }
    // vs_shadow, vs_shadow_masked, vs_shadow_distance, vs_shadow_paraboloid, and
    // vs_surface in the prepass and six lighting modules.
    assert_eq!(checked, 4 + 1 + 6);
}

#[test]
fn every_shadow_pipeline_declares_exactly_the_inputs_its_vertex_stage_reads() {
    let reflected = Reflected::new(&shadow_wgsl());
    for key in all_keys() {
        let shape = ShadowPipelineShape::of(&key);
        let declared: BTreeSet<u32> = shape
            .stream
            .buffers()
            .iter()
            .flatten()
            .flat_map(|b| b.attributes.iter().map(|a| a.shader_location))
            .collect();
        let read = reflected.input_locations(shape.vertex_entry);
        // Reading fewer is fine for wgpu, but the stream is chosen to be the smallest.
        assert_eq!(
            read, declared,
            "{key:?}: {} reads {read:?}, the pipeline declares {declared:?}",
            shape.vertex_entry
        );
        if let Some(fragment) = shape.fragment_entry {
            reflected.entry(fragment);
        }
    }
}

#[test]
fn the_instance_transform_is_the_start_of_each_instance_entry() {
    use crate::gpu_types::InstanceGpu;
    assert_eq!(std::mem::offset_of!(InstanceGpu, world_from_object), 0);
    let layout = InstanceGpu::transform_layout();
    assert_eq!(layout.array_stride as usize, std::mem::size_of::<InstanceGpu>());
    let offsets: Vec<u64> = layout.attributes.iter().map(|a| a.offset).collect();
    let locations: Vec<u32> = layout.attributes.iter().map(|a| a.shader_location).collect();
    assert_eq!((offsets, locations), (vec![0, 16, 32, 48], vec![3, 4, 5, 6]));
}

#[test]
fn distance_maps_bias_in_the_shader_and_projected_maps_in_the_rasterizer() {
    for key in all_keys() {
        let shape = ShadowPipelineShape::of(&key);
        match key.target {
            DepthTarget::Projected => {
                assert_eq!((shape.bias.constant, shape.bias.slope_scale), (key.depth_bias, key.slope_bias()));
                assert_eq!(shape.front_face, wgpu::FrontFace::Ccw);
            }
            DepthTarget::CubeFace | DepthTarget::Paraboloid => {
                assert_eq!(shape.bias, wgpu::DepthBiasState::default());
                assert_eq!(shape.front_face, wgpu::FrontFace::Cw);
                assert!(shape.fragment_entry.is_some(), "{key:?} writes its distance");
            }
        }
        assert_eq!(shape.bias.clamp, 0.0, "wgpu 30 does not enable depthBiasClamp");
        assert_eq!(shape.unclipped_depth, key.depth_range == DepthRange::Clamped);
        assert_eq!(
            shape.fragment_entry.is_some(),
            key.coverage == Coverage::Masked || key.target != DepthTarget::Projected
        );
    }
}
