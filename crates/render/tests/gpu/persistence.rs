//! Persistence (issue 21): the renderer keeps its GPU resources across frames. After a
//! warm-up frame, the same frame again creates no texture, view, buffer, query set or
//! bind group, for every technique, every light kind (sun, spot, point through a cube
//! and through paraboloids, all of `lamps` at once), on the forward and mask paths and
//! through every entry point (read back, live, timed, drawn into a host's target,
//! shadows for a host's shader); and a changed setting creates only what depends on it.

use crate::support;

use gnomon_render::{
    Creations, HostTarget, OutputRequest, Renderer,
    techniques::{TechniqueRef, TechniqueRegistry},
    timing::ClockChoice,
    wgpu,
};
use gnomon_scene::{
    Scene, Settings, builtin,
    settings::{LightKind, OmniMap, Partition, RayUse, Refine, ShadowPath, Technique},
};

/// Frames checked after the warm-up.
const STEADY_FRAMES: usize = 10;

fn small(technique: Technique, light: LightKind) -> Settings {
    let mut s = Settings::default();
    s.image.width = 48;
    s.image.height = 32;
    s.shadow.map.resolution = 256;
    s.shadow.filter.technique = technique;
    s.light.kind = light;
    s
}

/// Renders `settings` once to warm up, then [`STEADY_FRAMES`] times through each
/// entry point (read back, live, timed, into a host's target, and shadows for a
/// host's shader where the settings allow it), and returns what the steady frames
/// created.
fn created_in_steady_state(renderer: &mut Renderer, scene: &Scene, settings: &Settings) -> Creations {
    let uploaded = renderer.upload(scene).unwrap();
    let request = OutputRequest { shadow_map: true, ..Default::default() };
    let gpu = renderer.gpu().clone();
    let host_texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host target"),
        size: wgpu::Extent3d {
            width: settings.image.width,
            height: settings.image.height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Bgra8UnormSrgb,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let host_view = host_texture.create_view(&Default::default());
    let target = HostTarget::new(&host_texture, &host_view);
    // A host's shader reads maps: not on the mask path, nor from a technique that is rays.
    let technique = renderer.techniques().get(&settings.shadow.filter.technique).unwrap();
    let receives =
        settings.screen.shadow_path != ShadowPath::Mask && technique.rays() == RayUse::AsSettingsSay;
    let frame_through = |renderer: &mut Renderer, entry: Entry| {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        match entry {
            Entry::ReadBack => drop(renderer.render_uploaded(&uploaded, scene, settings, &request).unwrap()),
            Entry::Live => drop(renderer.render_live(&uploaded, scene, settings).unwrap()),
            Entry::Timed => {
                drop(renderer.time_passes(&uploaded, scene, settings, ClockChoice::Auto).unwrap())
            }
            Entry::Into => {
                renderer.render_into(&mut encoder, &target, &uploaded, scene, settings).unwrap();
            }
            Entry::Shadows => {
                drop(renderer.record_shadows(&mut encoder, &uploaded, scene, settings).unwrap())
            }
        }
        gpu.queue.submit([encoder.finish()]);
    };
    // The viewer's entry points alternate: warm each up (each holds its own
    // readbacks), then alternate them. A light whose penumbrae are beamed writes one
    // of its history's two textures and reads the other, in turn (penumbra_history.rs),
    // so each entry point is warmed up on both.
    let alternating = [Entry::ReadBack, Entry::Live, Entry::Timed];
    for entry in alternating.iter().chain(&alternating) {
        frame_through(renderer, *entry);
    }
    let mut created = Creations::default();
    let mut count = |renderer: &Renderer, before: Creations| {
        let after = renderer.creations();
        created.textures += after.textures - before.textures;
        created.views += after.views - before.views;
        created.buffers += after.buffers - before.buffers;
        created.bind_groups += after.bind_groups - before.bind_groups;
        created.query_sets += after.query_sets - before.query_sets;
    };
    let before = renderer.creations();
    for frame in 0..STEADY_FRAMES {
        frame_through(renderer, alternating[frame % alternating.len()]);
    }
    count(renderer, before);
    // A host's frames take one entry point each time: what only another entry point
    // uses may have been dropped meanwhile, so each gets its own warm-up frames.
    let embedded: &[Entry] = if receives { &[Entry::Into, Entry::Shadows] } else { &[Entry::Into] };
    for &entry in embedded {
        // Two warm-up frames: both of a beamed light's history textures.
        frame_through(renderer, entry);
        frame_through(renderer, entry);
        let before = renderer.creations();
        for _ in 0..STEADY_FRAMES / 2 {
            frame_through(renderer, entry);
        }
        count(renderer, before);
    }
    created
}

/// A renderer entry point.
#[derive(Clone, Copy)]
enum Entry {
    ReadBack,
    Live,
    Timed,
    Into,
    Shadows,
}

/// Every light kind a technique can shadow, with its settings adjusted.
fn light_cases(technique: TechniqueRef) -> Vec<(&'static str, Settings)> {
    let small = |light| small(technique.technique(), light);
    let mut cases = vec![("sun", small(LightKind::Sun)), ("spot", small(LightKind::Spot))];
    let mut cascades = small(LightKind::Sun);
    cascades.shadow.partition = Partition::Cascades;
    cascades.shadow.cascades.count = 3;
    cases.push(("sun, 3 cascades", cascades));
    let mut mask = small(LightKind::Sun);
    mask.screen.shadow_path = ShadowPath::Mask;
    cases.push(("sun, mask path", mask));
    if technique.cube_wgsl().is_some() {
        cases.push(("point, cube", small(LightKind::Point)));
    }
    if technique.maps().paraboloid {
        let mut paraboloid = small(LightKind::Point);
        paraboloid.shadow.map.omni = OmniMap::Paraboloid;
        cases.push(("point, paraboloids", paraboloid));
    }
    cases
}

#[test]
fn a_steady_frame_creates_nothing_for_every_technique_and_light_kind() {
    let gpu = crate::support::gpu();
    let scene = builtin::spheres();
    let mut failures = Vec::new();
    let (mut checked, mut total) = (0, 0);
    for technique in TechniqueRegistry::builtin().iter() {
        for (name, settings) in light_cases(technique) {
            // A fresh renderer per case, so that each case warms up alone.
            let mut renderer = Renderer::new(gpu).unwrap();
            let created = created_in_steady_state(&mut renderer, &scene, &settings);
            checked += 1;
            total += created.total();
            if created.total() != 0 {
                failures.push(format!("{technique:?}, {name}: {created:?}"));
            }
        }
    }
    support::figures::figure(
        &format!(
            "persistence: resources created by {STEADY_FRAMES} steady frames per entry point group \
             (read back/live/timed alternating; into a host's target; shadows for a host's shader), \
             over {checked} cases"
        ),
        total,
        0,
    );
    assert!(failures.is_empty(), "steady frames created resources:\n{}", failures.join("\n"));
}

#[test]
fn every_light_of_lamps_at_once_creates_nothing_in_steady_state() {
    let gpu = crate::support::gpu();
    let scene = builtin::lamps();
    // Auto: the light list on the mask path for Gnomon's frames; per-light maps for a
    // host's shader.
    for path in [ShadowPath::Forward, ShadowPath::Mask, ShadowPath::Auto] {
        let mut settings = small(Technique::PCF, LightKind::All);
        settings.screen.shadow_path = path;
        let mut renderer = Renderer::new(gpu).unwrap();
        let created = created_in_steady_state(&mut renderer, &scene, &settings);
        assert_eq!(created.total(), 0, "{path:?}: {created:?}");
    }
}

/// Refinement by rays lists its pixels and traces them in pooled buffers and groups:
/// steady frames create none of them either, for a sun, for every lamp at once, and
/// for a sun with a disk (whose penumbra filter copies the mask into a pooled texture).
#[test]
fn refined_frames_create_nothing_in_steady_state() {
    let gpu = crate::support::gpu();
    let cases = [
        (builtin::spheres(), LightKind::Sun, None),
        (builtin::lamps(), LightKind::All, None),
        (builtin::spheres(), LightKind::Sun, Some(2.0)),
    ];
    for (scene, light, sun_disk) in cases {
        for refine in [Refine::Rays, Refine::EveryPixel] {
            let mut settings = small(Technique::PCF, light);
            settings.light.sun_angular_diameter = sun_disk;
            settings.screen.refine = refine;
            settings.screen.shadow_path = ShadowPath::Mask;
            let mut renderer = Renderer::new(gpu).unwrap();
            let created = created_in_steady_state(&mut renderer, &scene, &settings);
            assert_eq!(created.total(), 0, "{} {refine:?}: {created:?}", scene.name);
        }
    }
}

/// The pool keys resources by their description: a changed setting makes what
/// depends on it (a larger map: a texture, its views and the groups that bind it),
/// and nothing else; going back finds the first resources again.
#[test]
fn a_changed_setting_creates_only_what_depends_on_it() {
    let gpu = crate::support::gpu();
    let scene = builtin::spheres();
    let mut renderer = Renderer::new(gpu).unwrap();
    let uploaded = renderer.upload(&scene).unwrap();
    let mut small_map = small(Technique::PCF, LightKind::Sun);
    // The pool's keying: a kept map (`map_cache.rs`) is its own texture, made again
    // whenever its size changes, so it would not be found again.
    small_map.shadow.map.cache = gnomon_scene::settings::MapCache::Off;
    let mut large_map = small_map.clone();
    large_map.shadow.map.resolution = 512;
    renderer.render_live(&uploaded, &scene, &small_map).unwrap();
    renderer.render_live(&uploaded, &scene, &small_map).unwrap();
    let warm = renderer.creations();
    renderer.render_live(&uploaded, &scene, &large_map).unwrap();
    let changed = renderer.creations();
    // The map and the touched layer beside it that rays read (`rays/touched.rs`).
    assert_eq!(
        changed.textures - warm.textures,
        2,
        "a new shadow map and touched layer: {warm:?} → {changed:?}"
    );
    assert_eq!(changed.buffers, warm.buffers, "no buffer depends on the map's size");
    assert!(changed.bind_groups > warm.bind_groups, "the groups binding the map are new");
    renderer.render_live(&uploaded, &scene, &small_map).unwrap();
    assert_eq!(renderer.creations(), changed, "the first map was kept");
}
