//! GPU-driven submission (`DrawSubmission::GpuCulled`, `passes/gpu_cull.wgsl`): a
//! compute pass culls every shadow item for each layer and the layer draws what it
//! kept with one multi-draw per pipeline whose count the GPU wrote. Its maps are
//! identical, texel for texel, to the CPU fallback's (the same setting on a device
//! forced to lack indirect counts) and to the unculled maps drawn one by one, for
//! every light kind, map layout and cull mode; and they follow a moved caster, kept
//! map or not.

use crate::support;

use glam::{Mat4, Vec3};
use gnomon_render::{Frame, Gpu, GpuCullUnavailable, GpuScene, OutputRequest, Renderer};
use gnomon_scene::{
    Motion, Scene, Settings, builtin,
    settings::{
        CasterCulling, CullMode, DrawSubmission, LightKind, MapCache, OmniMap, Partition, Refine, WarpKind,
    },
};
use support::figures::skipped;

/// The device as it is, or `None` (with a note) where it cannot cull on the GPU.
fn culling_gpu() -> Option<&'static Gpu> {
    let gpu = support::gpu();
    if !gpu.indirect_count {
        skipped("GPU culling", "the device cannot take a draw count from a buffer");
        return None;
    }
    Some(gpu)
}

/// The same device, told it lacks indirect counts: the CPU fallback.
fn fallback_gpu(gpu: &Gpu) -> Gpu {
    Gpu { indirect_count: false, ..gpu.clone() }
}

fn with_map(renderer: &mut Renderer, uploaded: &GpuScene, scene: &Scene, s: &Settings) -> Frame {
    let request = OutputRequest { shadow_map: true, ..Default::default() };
    renderer.render_uploaded(uploaded, scene, s, &request).expect("render")
}

/// The reported light's map of `scene` drawn on `gpu` with `settings`.
fn map(gpu: &Gpu, scene: &Scene, settings: &Settings) -> (Frame, Vec<f32>) {
    let mut renderer = Renderer::new(gpu).expect("renderer");
    let uploaded = renderer.upload(scene).expect("upload");
    let mut frame = with_map(&mut renderer, &uploaded, scene, settings);
    let depth = frame.shadow_map.take().expect("map").depth;
    (frame, depth)
}

/// The map with nothing culled below whole instances, drawn one by one, from scratch.
fn unculled(gpu: &Gpu, scene: &Scene, settings: &Settings) -> Vec<f32> {
    let mut s = settings.clone();
    s.shadow.map.caster_culling = CasterCulling::Instances;
    s.shadow.map.draw_submission = DrawSubmission::Direct;
    s.shadow.map.cache = MapCache::Off;
    map(gpu, scene, &s).1
}

fn differing(a: &[f32], b: &[f32]) -> usize {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).filter(|(x, y)| x.to_bits() != y.to_bits()).count()
}

fn settings(light: LightKind, cull: CullMode) -> Settings {
    let mut s = support::settings(160, 90, 512);
    s.screen.refine = Refine::Off;
    s.shadow.map.cache = MapCache::Off;
    s.shadow.map.draw_submission = DrawSubmission::GpuCulled;
    s.light.kind = light;
    s.shadow.bias.cull = cull;
    s
}

#[test]
fn gpu_culled_maps_equal_the_cpu_fallback_and_the_unculled_maps() {
    let Some(gpu) = culling_gpu() else { return };
    let fallback = fallback_gpu(gpu);
    let cascades = |cull| {
        let mut s = settings(LightKind::Sun, cull);
        s.shadow.partition = Partition::Cascades;
        s
    };
    let mut paraboloid = settings(LightKind::Point, CullMode::Auto);
    paraboloid.shadow.map.omni = OmniMap::Paraboloid;
    let mut warped = settings(LightKind::Sun, CullMode::Auto);
    warped.shadow.map.warp = WarpKind::Lispsm;
    let cases = [
        ("sun cascades, cull auto", cascades(CullMode::Auto)),
        ("sun cascades, cull back", cascades(CullMode::Back)),
        ("sun cascades, cull front", cascades(CullMode::Front)),
        ("sun cascades, cull none", cascades(CullMode::None)),
        ("sun, lispsm", warped),
        ("spot", settings(LightKind::Spot, CullMode::Auto)),
        ("point, cube", settings(LightKind::Point, CullMode::Auto)),
        ("point, paraboloids", paraboloid),
    ];
    let scene = builtin::spheres();
    for (name, s) in &cases {
        let (on_gpu, gpu_map) = map(gpu, &scene, s);
        let (on_cpu, cpu_map) = map(&fallback, &scene, s);
        let whole = unculled(gpu, &scene, s);
        assert_eq!(differing(&gpu_map, &cpu_map), 0, "{name}: GPU-culled against the CPU fallback");
        assert_eq!(differing(&gpu_map, &whole), 0, "{name}: GPU-culled against the unculled map");
        // The GPU culler's commands: one per bucket of items and layer, whatever the
        // CPU would have drawn. `spheres` casts with two kinds of mesh, closed (the
        // spheres, the box) and open (the ground), each its own pipeline.
        const BUCKETS: u32 = 2;
        let layers = on_gpu.lights[0].layer_commands.len() as u32;
        println!("{name}: {} commands, {} draws", on_gpu.stats.shadow_commands, on_gpu.stats.shadow_draws);
        assert_eq!(on_gpu.stats.shadow_commands, BUCKETS * layers, "{name}: {:?}", on_gpu.stats);
        assert_eq!(on_gpu.stats.shadow_triangles, on_cpu.stats.shadow_triangles, "{name}");
        // The fallback says why, and the GPU-culled frame has nothing to say.
        assert_eq!(on_gpu.lights[0].cull_fallback, None, "{name}");
        assert_eq!(on_cpu.lights[0].cull_fallback, Some(GpuCullUnavailable::NoIndirectCount), "{name}");
        let mut indirect = s.clone();
        indirect.shadow.map.draw_submission = DrawSubmission::Indirect;
        assert_eq!(
            map(&fallback, &scene, &indirect).0.lights[0].cull_fallback,
            None,
            "{name}: not asked for"
        );
    }
}

#[test]
fn a_moved_caster_moves_in_the_gpu_culled_map_kept_or_not() {
    let Some(gpu) = culling_gpu() else { return };
    let mut cascades = settings(LightKind::Sun, CullMode::Auto);
    cascades.shadow.partition = Partition::Cascades;
    let cases = [("spot", settings(LightKind::Spot, CullMode::Auto)), ("sun cascades", cascades)];
    for ((name, base), cache) in cases.iter().flat_map(|c| [(c, MapCache::Off), (c, MapCache::StillCasters)])
    {
        let mut s = base.clone();
        s.shadow.map.cache = cache;
        let mut scene = builtin::spheres();
        let named = |scene: &Scene, name: &str| scene.instances.iter().position(|i| i.name == name).unwrap();
        let ball = named(&scene, "sphere 1,1");
        let crate_box = named(&scene, "box");
        scene.instances[ball].motion = Motion::Dynamic;
        // The ball starts far outside every layer: its items must follow it in, or
        // the culler would keep skipping it where it was.
        let away = Vec3::new(60.0, 0.0, 60.0);
        scene.instances[ball].world_from_object =
            Mat4::from_translation(away) * scene.instances[ball].world_from_object;
        let mut renderer = Renderer::new(gpu).unwrap();
        let mut uploaded = renderer.upload(&scene).unwrap();
        let first = with_map(&mut renderer, &uploaded, &scene, &s);
        let first_map = &first.shadow_map.as_ref().unwrap().depth;
        assert_eq!(differing(first_map, &unculled(gpu, &scene, &s)), 0, "{name}, {cache:?}: first frame");
        for (moved, by) in [(ball, -away), (crate_box, Vec3::new(1.0, 0.0, 1.0))] {
            let placed = &mut scene.instances[moved].world_from_object;
            *placed = Mat4::from_translation(by) * *placed;
            renderer.move_instances(&mut uploaded, &scene, &[moved]).unwrap();
            let frame = with_map(&mut renderer, &uploaded, &scene, &s);
            let after = &frame.shadow_map.as_ref().unwrap().depth;
            let what = &scene.instances[moved].name;
            assert!(differing(after, first_map) > 0, "{name}, {cache:?}: moving {what} changes the map");
            let wrong = differing(after, &unculled(gpu, &scene, &s));
            assert_eq!(wrong, 0, "{name}, {cache:?}: after {what} moved");
        }
    }
}

/// `spheres` with an alpha-masked checkerboard quad hung over it: a bucket of its own,
/// whose pipeline samples the quad's texture.
fn with_cutout(mut scene: Scene) -> Scene {
    use gnomon_scene::{AlphaMode, Material, Texture, Wrap, geometry};
    let cells = 8u32;
    let rgba8 = (0..cells * cells)
        .flat_map(|k| [200, 180, 60, if (k % cells + k / cells).is_multiple_of(2) { 255 } else { 0 }]);
    scene.textures.push(Texture {
        name: "checker".into(),
        width: cells,
        height: cells,
        rgba8: rgba8.collect(),
        wrap_u: Wrap::ClampToEdge,
        wrap_v: Wrap::ClampToEdge,
        nearest: true,
    });
    let mut cutout = Material::new("cut-out", Vec3::ONE);
    cutout.base_color_texture = Some(scene.textures.len() - 1);
    cutout.alpha_mode = AlphaMode::Mask { cutoff: 0.5 };
    cutout.double_sided = true;
    scene.materials.push(cutout);
    let material = scene.materials.len() - 1;
    support::add(
        &mut scene,
        "checker",
        geometry::plane(2.0, 2.0),
        Mat4::from_translation(Vec3::new(0.3, 1.4, -0.2)),
    );
    scene.instances.last_mut().expect("added").material = material;
    scene
}

#[test]
fn an_alpha_masked_caster_is_culled_on_the_gpu_with_its_texture() {
    let Some(gpu) = culling_gpu() else { return };
    let scene = with_cutout(builtin::spheres());
    let mut cascades = settings(LightKind::Sun, CullMode::Auto);
    cascades.shadow.partition = Partition::Cascades;
    for (name, s) in [("sun cascades", cascades), ("spot", settings(LightKind::Spot, CullMode::Auto))] {
        let (frame, culled) = map(gpu, &scene, &s);
        let whole = unculled(gpu, &scene, &s);
        assert_eq!(differing(&culled, &whole), 0, "{name}: GPU-culled against the unculled map");
        // The closed meshes, the ground, and the cut-out: three buckets a layer.
        let layers = frame.lights[0].layer_commands.len() as u32;
        assert_eq!(frame.stats.shadow_commands, 3 * layers, "{name}: {:?}", frame.stats);
    }
}
