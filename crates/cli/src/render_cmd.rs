//! `gnomon render`: one scene, one light, one technique, to an image and optional
//! float outputs.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use gnomon_render::{Frame, Gpu, LayerCache, OutputRequest, Renderer};
use gnomon_scene::{
    Scene, Settings,
    settings::{CullMode, value_name},
};

use crate::output::{self, Staged};

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: crate::lab::SceneArgs,
    /// Output image (PNG, sRGB).
    #[arg(long, short, default_value = "gnomon.png", help_heading = "Outputs")]
    pub out: PathBuf,
    /// Also write the light's depth map as a 16-bit grayscale PNG: depth stretched to
    /// the covered range (near = black), linearized first for perspective (spot) maps;
    /// texels with no caster are white.
    #[arg(long, value_name = "FILE.png", help_heading = "Outputs")]
    pub shadow_map_out: Option<PathBuf>,
    /// Also write the per-pixel shadow factor as 32-bit float: `.exr` (one channel `Y`)
    /// or `.npy` (float32, shape (height, width), top row first). 1 is lit, 0 is
    /// shadowed (also outside a spot light's cone and on surfaces turned away from
    /// the light); background pixels are NaN.
    #[arg(long, value_name = "FILE.exr|FILE.npy", help_heading = "Outputs")]
    pub visibility_out: Option<PathBuf>,
    /// Also write per-pixel float images to this directory (created if missing):
    /// position.exr (world XYZ), normal.exr (the shading normal, world XYZ),
    /// geometric_normal.exr (the triangle's plane, facing the camera: what shadow rays
    /// leave along), depth.exr (view depth, Y), object_id.exr (instance index + 1, Y;
    /// 0 is background) and visibility.exr. Background pixels are NaN in the first
    /// four. `gnomon reference --surfaces` traces the truth from such a folder.
    #[arg(long, value_name = "DIR", help_heading = "Outputs")]
    pub aov_out: Option<PathBuf>,
    /// The format of `--aov-out`'s images: OpenEXR, or NumPy `.npy` (float32; position
    /// and normals height × width × 3, the others height × width).
    #[arg(long, value_enum, default_value = "exr", help_heading = "Outputs")]
    pub aov_format: AovFormat,
    /// Print the adapter, driver and backend used, and timings.
    #[arg(long, short)]
    pub verbose: bool,
    #[command(flatten)]
    pub settings: Settings,
}

impl RenderArgs {
    /// The arguments of a bare `gnomon` invocation: every default.
    pub fn default_from_cli() -> Self {
        use clap::FromArgMatches;
        let command = <Self as Args>::augment_args(clap::Command::new("render"));
        let matches = command.get_matches_from(["render"]);
        Self::from_arg_matches(&matches).expect("defaults always parse")
    }
}

/// The images `--aov-out` writes into its directory, by name (the format's
/// extension follows).
const AOV_NAMES: [&str; 6] = ["position", "normal", "geometric_normal", "depth", "object_id", "visibility"];

/// The file format of `--aov-out`'s images.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AovFormat {
    /// OpenEXR: position and normal in channels R, G, B; the others in Y.
    Exr,
    /// NumPy `.npy`, little-endian float32 (what Python's `gnomon.Frame` holds).
    Npy,
}

impl AovFormat {
    fn extension(self) -> &'static str {
        match self {
            AovFormat::Exr => "exr",
            AovFormat::Npy => "npy",
        }
    }
}

/// The files `--aov-out` writes, in the order of [`AOV_NAMES`].
fn aov_files(dir: &std::path::Path, format: AovFormat) -> [PathBuf; 6] {
    AOV_NAMES.map(|name| dir.join(format!("{name}.{}", format.extension())))
}

pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    let started = std::time::Instant::now();
    args.settings.validate()?;
    let (scene, settings) = crate::lab::load(&args.scene, &args.settings)?;
    let settings = &settings;
    check_outputs(args)?;

    let gpu = Gpu::new_headless()?;
    if args.verbose {
        eprintln!("gnomon: {}", gpu.info);
        let b = scene.bounds();
        let camera = settings.resolve_camera(&scene)?;
        eprintln!(
            "gnomon: scene bounds {:.3} to {:.3}; camera at {:.3} looking at {:.3}",
            b.min, b.max, camera.eye, camera.target
        );
        eprintln!("gnomon: {}", open_casters_line(&scene, settings.shadow.bias.cull));
    }
    let mut renderer = Renderer::new(&gpu)?;
    renderer.check_limits(settings)?;
    let request = OutputRequest { shadow_map: args.shadow_map_out.is_some(), ..Default::default() };
    let render_started = std::time::Instant::now();
    let frame = renderer.render(&scene, settings, &request)?;
    warn_fallbacks(&frame.lights);
    if args.verbose {
        report_frame(&gpu, &scene, &frame, render_started.elapsed());
    }
    let written = stage_outputs(args, &frame)?.commit()?;
    for path in &written {
        println!("{}", path.display());
    }
    if args.verbose {
        eprintln!("gnomon: done in {:.1} ms", started.elapsed().as_secs_f64() * 1e3);
    }
    Ok(())
}

/// Every output location checked before any work, so that a typo costs nothing, and
/// no two outputs aimed at one file.
fn check_outputs(args: &RenderArgs) -> anyhow::Result<()> {
    // Check every output location before any work, so that a typo costs nothing.
    output::check_file(&args.out, &["png"], "--out")?;
    if let Some(p) = &args.shadow_map_out {
        output::check_file(p, &["png"], "--shadow-map-out")?;
    }
    if let Some(p) = &args.visibility_out {
        output::check_file(p, &["exr", "npy"], "--visibility-out")?;
    }
    if let Some(dir) = &args.aov_out {
        output::check_dir(dir, "--aov-out")?;
    }
    let aov_files: Vec<PathBuf> = args.aov_out.iter().flat_map(|d| aov_files(d, args.aov_format)).collect();
    for path in &aov_files {
        output::check_destination(path, "--aov-out")?;
    }
    let planned: Vec<output::Planned> =
        [("--out", Some(&args.out)), ("--shadow-map-out", args.shadow_map_out.as_ref())]
            .into_iter()
            .chain([("--visibility-out", args.visibility_out.as_ref())])
            .filter_map(|(flag, path)| path.map(|path| output::Planned { flag: flag.into(), path }))
            .chain(aov_files.iter().map(|path| output::Planned { flag: "--aov-out".into(), path }))
            .collect();
    output::refuse_shared_destinations(&planned)?;

    Ok(())
}

/// `--verbose`'s lines on a rendered frame: its scene and size, its draws, its moment
/// map, its GPU times, and each light's map, draws and rays.
fn report_frame(gpu: &Gpu, scene: &Scene, frame: &Frame, render_time: std::time::Duration) {
    let shadows = match frame.lights.as_slice() {
        [one] => format!("technique {}, shadow map {}²", one.technique.name(), one.resolution),
        many => format!("{} shadowed lights", many.len()),
    };
    eprintln!(
        "gnomon: scene `{}` ({} triangles, {} instances), {}×{}, {shadows}, rendered in {:.1} ms",
        scene.name,
        scene.triangle_count(),
        scene.instances.len(),
        frame.width,
        frame.height,
        render_time.as_secs_f64() * 1e3
    );
    let st = frame.stats;
    let prepass = if frame.shadow_mask {
        format!(", {} in the prepass (shadows resolved in a screen-space mask)", st.prepass_draws)
    } else {
        String::new()
    };
    eprintln!(
        "gnomon: draws: {} in the shadow pass ({} draw commands), {} in the lighting pass{prepass}; {} pipeline and {} bind group changes",
        st.shadow_draws, st.shadow_commands, st.lighting_draws, st.pipeline_changes, st.bind_group_changes
    );
    if let Some(format) = frame.moment_format {
        let why = match format {
            gnomon_render::wgpu::TextureFormat::Rgba16Float
                if !gpu.device.features().contains(gnomon_render::wgpu::Features::FLOAT32_FILTERABLE) =>
            {
                " (this adapter cannot filter 32-bit floats)"
            }
            _ => "",
        };
        eprintln!("gnomon: moment map {format:?}{why}");
    }
    if let Some(t) = frame.timings {
        let filter = t.filter_ms.map(|f| format!(", derived maps {f:.2} ms")).unwrap_or_default();
        let prepass = t.prepass_ms.map(|p| format!(", prepass {p:.2} ms")).unwrap_or_default();
        let mask = t.mask_ms.map(|m| format!(", shadow mask {m:.2} ms")).unwrap_or_default();
        let trace = t.trace_ms.map(|m| format!(", ray trace {m:.2} ms")).unwrap_or_default();
        eprintln!(
            "gnomon: GPU time: frame {:.2} ms: shadow pass {:.2} ms{filter}{prepass}{mask}{trace}, lighting pass {:.2} ms",
            t.frame_ms, t.shadow_ms, t.lighting_ms
        );
    }
    for (i, light) in frame.lights.iter().enumerate() {
        eprintln!("gnomon: {}", light_line(i, light));
        if let Some(pages) = &light.pages {
            eprintln!("gnomon: {}", pages_line(i, pages));
        }
        if light.traced_pixels.is_some() {
            eprintln!("gnomon: {}", traced_line(i, light, frame.pixel_count()));
        } else if light.refine != gnomon_scene::settings::Refine::Off {
            // The forward path counts nothing (rays/refine_forward.wgsl says why).
            eprintln!("gnomon: light {i}: refined by rays in the lighting pass (forward path: not counted)");
        }
    }
}

/// Every output encoded to a temporary file beside its destination, to be moved into
/// place together.
fn stage_outputs(args: &RenderArgs, frame: &Frame) -> anyhow::Result<Staged> {
    let mut staged = Staged::default();
    staged.png_rgba(&args.out, frame.width, frame.height, &frame.color)?;
    if let (Some(path), Some(map)) = (&args.shadow_map_out, &frame.shadow_map) {
        let linear = output::shadow_map_to_gray16(
            map,
            &frame.light_projection,
            matches!(frame.light.shadow_view(), gnomon_scene::lights::ShadowView::Omni { .. }),
        );
        staged.png_gray16(path, map.resolution, map.resolution, &linear)?;
    }
    if let Some(path) = &args.visibility_out {
        staged.float_image(path, frame.width, frame.height, &frame.visibility)?;
    }
    if let Some(dir) = &args.aov_out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--aov-out: cannot create directory {}", dir.display()))?;
        let (w, h) = (frame.width, frame.height);
        let [position, normal, geometric_normal, depth, object_id, visibility] =
            aov_files(dir, args.aov_format);
        staged.vec3_image(&position, w, h, &frame.position)?;
        staged.vec3_image(&normal, w, h, &frame.normal)?;
        staged.vec3_image(&geometric_normal, w, h, &frame.geometric_normal)?;
        staged.float_image(&depth, w, h, &frame.depth)?;
        let ids: Vec<f32> = frame.object_id.iter().map(|&i| i as f32).collect();
        staged.float_image(&object_id, w, h, &ids)?;
        staged.float_image(&visibility, w, h, &frame.visibility)?;
    }
    Ok(staged)
}

/// `--verbose`'s line on open meshes: how many single-sided casters `cull auto` found
/// open (drawn with both faces), whatever the cull mode in use.
pub(crate) fn open_casters_line(scene: &Scene, cull: CullMode) -> String {
    let open = scene.open_casters(&scene.closed_meshes());
    format!(
        "{} of {} single-sided caster meshes are open ({} of {} triangles); cull {}: {}",
        open.open_meshes,
        open.meshes,
        open.open_triangles,
        open.triangles,
        value_name(&cull),
        match cull {
            CullMode::Auto => "open meshes draw both faces, closed ones cull back faces",
            CullMode::Back => "every single-sided mesh culls back faces; open ones may leak",
            CullMode::Front => "every single-sided mesh culls front faces; open ones may leak",
            CullMode::None => "every mesh draws both faces",
        }
    )
}

/// Warns, once per reason, of lights drawn unrefined though `--refine` asked for rays
/// (the device cannot trace the scene or an image this large), of rays traced by the
/// shader though `--tracer` asked for ray queries, and of lights whose layers were
/// culled on the CPU though `--draw-submission gpu-culled` asked for the GPU (the same
/// maps, at the CPU's cost).
pub(crate) fn warn_fallbacks(lights: &[gnomon_render::LightStats]) {
    let mut said: Vec<String> = Vec::new();
    let refine = lights.iter().filter_map(|l| l.refine_fallback.as_ref());
    let tracer = lights.iter().filter_map(|l| l.tracer_fallback.as_ref());
    let culling = lights.iter().filter_map(|l| l.cull_fallback.as_ref());
    let warnings = refine
        .map(|why| format!("--refine: {why}; shadows drawn unrefined"))
        .chain(tracer.map(|why| format!("--tracer ray-query: {why}; rays traced by the shader's BVH")))
        .chain(culling.map(|why| format!("--draw-submission gpu-culled: {why}; layers culled on the CPU")));
    for warning in warnings {
        if !said.contains(&warning) {
            eprintln!("gnomon: warning: {warning}");
            said.push(warning);
        }
    }
}

/// `--verbose`'s line on a light refined by rays: the pixels that traced a ray, as a
/// share of the screen.
pub(crate) fn traced_line(index: usize, light: &gnomon_render::LightStats, pixels: usize) -> String {
    let traced = light.traced_pixels.unwrap_or(0);
    let rays = light.traced_rays().unwrap_or(0);
    let per_pixel = match light.rays_per_pixel {
        1 => String::new(),
        n => format!(", {n} per pixel over the light's area"),
    };
    let tracer = match light.traversal {
        Some(gnomon_render::rays::Traversal::RayQuery) => "ray queries",
        Some(gnomon_render::rays::Traversal::Shader) | None => "the shader's BVH",
    };
    format!(
        "light {index}: refined by rays at {traced} pixels, {:.2} % of the screen ({rays} rays{per_pixel}), traced by {tracer}",
        100.0 * f64::from(traced) / pixels.max(1) as f64
    )
}

/// One light's line of `--verbose`: what it is, what its map holds, the draws into
/// each layer and its GPU time.
fn light_line(index: usize, light: &gnomon_render::LightStats) -> String {
    let layers = light.layer_draws.len();
    let map = if layers > 1 {
        format!("{layers} × {}²", light.resolution)
    } else {
        format!("{}²", light.resolution)
    };
    let per_layer: Vec<String> = light.layer_draws.iter().map(u32::to_string).collect();
    let commands: Vec<String> = light.layer_commands.iter().map(u32::to_string).collect();
    let triangles: Vec<String> = light.layer_triangles.iter().map(u64::to_string).collect();
    let ms = |label: &str, t: Option<f64>| t.map(|t| format!(", {label} {t:.2} ms")).unwrap_or_default();
    let count = |state: LayerCache| light.layer_cache.iter().filter(|&&s| s == state).count();
    let cache = match (count(LayerCache::Kept), count(LayerCache::Drawn)) {
        (0, 0) => String::new(),
        (kept, drawn) => format!(" (cache: {kept} layers kept, {drawn} drawn)"),
    };
    format!(
        "light {index} `{}` ({}, {}, map {map}): {} shadow draws [{}] in [{}] commands, of {} triangles [{}]{cache}{}{}{}{}{}",
        light.name,
        light.kind,
        light.technique.name(),
        light.shadow_draws(),
        per_layer.join(" "),
        commands.join(" "),
        light.layer_triangles.iter().sum::<u64>(),
        triangles.join(" "),
        ms("shadow", light.shadow_ms),
        ms("derived maps", light.filter_ms),
        ms("mask", light.mask_ms),
        ms("trace", light.trace_ms),
        ms("lighting", light.lighting_ms),
    )
}

/// `--verbose`'s line on a virtual map's pages: drawn (and in how many runs of
/// neighbours), kept and refused (whose pixels fell back to a coarser page), those
/// along shadow edges, and the pool.
pub(crate) fn pages_line(index: usize, pages: &gnomon_render::PageStats) -> String {
    let texels = u64::from(pages.drawn) * u64::from(pages.page_size).pow(2);
    let fallback = match pages.refused {
        0 => String::new(),
        n => format!("; {n} refused, the pool full: their pixels read a coarser page"),
    };
    let edges = match pages.edge_levels {
        0 => String::new(),
        levels => format!(" and {} along shadow edges (up to {levels} levels finer)", pages.edges),
    };
    format!(
        "light {index}: virtual map: {} pages requested{edges}, {} drawn ({:.2} M texels, in {} runs), {} kept{fallback}; {} of {} tiles resident",
        pages.requested,
        pages.drawn,
        texels as f64 / 1e6,
        pages.runs,
        pages.kept,
        pages.resident,
        pages.capacity,
    )
}
