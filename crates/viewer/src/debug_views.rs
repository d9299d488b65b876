//! The viewer's measured debug views: the texel-density (Lloyd's m) heat-map of the
//! current view, and the error heat-map against the ray-traced reference, traced on
//! a worker thread with its progress reported (on the desktop), or against the same
//! view drawn by the GPU's `raytraced` (in a browser, which has no threads for it).

use std::sync::{
    Arc,
    atomic::{AtomicU64, Ordering},
    mpsc,
};

use gnomon_reference::{
    aliasing,
    aliasing::{AliasingImage, AliasingInput, LayerChoice},
    drawn::{DrawnSurfaces, DrawnTruth, measure_drawn},
    heatmap,
};
use gnomon_render::Frame;
use gnomon_scene::{Settings, settings::CascadeSelection};

/// Lloyd's m over `frame`, with the cascade selection of `settings`; over a virtual
/// map's levels, each pixel at the level its footprint picks (finer along shadow
/// edges: `shadow.virtual_map.edge_levels`).
pub fn measure_aliasing(frame: &Frame, settings: &Settings) -> AliasingImage {
    let (projections, choice, resolution) = match &frame.virtual_levels {
        Some(levels) => (
            &levels.projections,
            LayerChoice::Clipmap {
                clipmap: &levels.clipmap,
                footprint_per_depth: levels.footprint_per_depth,
            },
            levels.resolution,
        ),
        None => {
            let choice = match settings.shadow.cascades.cascade_selection {
                CascadeSelection::Projection => LayerChoice::Projection,
                CascadeSelection::Depth => LayerChoice::Splits(&frame.cascade_splits),
            };
            (&frame.cascades, choice, frame.shadow_resolution)
        }
    };
    let layers: Vec<glam::Mat4> = projections.iter().map(|p| p.clip_from_world()).collect();
    aliasing::measure(&AliasingInput {
        width: frame.width,
        height: frame.height,
        position: &frame.position,
        normal: &frame.normal,
        depth: &frame.depth,
        camera: &frame.camera,
        light: &frame.light,
        layers: &layers,
        choice,
        resolution,
    })
}

/// An RGBA8 picture with a one-line summary of what it shows.
#[derive(Clone, Debug)]
pub struct Picture {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    pub summary: String,
    /// The settings it was made with, to tell when it no longer matches the view.
    pub settings: Settings,
    /// Unique to this picture: a new one replaces the texture made from the old.
    pub id: u64,
}

impl Picture {
    fn new(width: u32, height: u32, rgba: Vec<u8>, summary: String, settings: Settings) -> Self {
        static NEXT: AtomicU64 = AtomicU64::new(0);
        let id = NEXT.fetch_add(1, Ordering::Relaxed);
        Self { width, height, rgba, summary, settings, id }
    }
}

/// The texel-density heat-map of `frame`.
pub fn texel_density(frame: &Frame, settings: &Settings) -> Picture {
    let m = measure_aliasing(frame, settings);
    Picture::new(
        frame.width,
        frame.height,
        aliasing::heatmap(&m),
        format!(
            "texel density m: mean {:.2}, max {:.1} pixels per texel (blue 1/16, green 1, red 16)",
            m.mean, m.max
        ),
        settings.clone(),
    )
}

/// A reference being traced for one view.
pub struct ErrorJob {
    rows_done: Arc<AtomicU64>,
    rows: u64,
    result: mpsc::Receiver<Picture>,
}

impl ErrorJob {
    /// The heat-map of `frame` against `traced`, the same view drawn by the GPU's
    /// `raytraced`: every light-facing pixel compared, as the browser's lab measures
    /// (`gnomon_reference::drawn`). Ready at once.
    // The desktop compares with the CPU reference, and tests this.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    pub fn against_raytraced(frame: &Frame, traced: Frame, settings: Settings) -> Self {
        let surfaces = DrawnSurfaces {
            width: frame.width,
            position: &frame.position,
            geometric_normal: &frame.geometric_normal,
        };
        let truth = DrawnTruth::from_traced(&frame.light, surfaces, traced.visibility);
        let measured = measure_drawn(&frame.visibility, &truth);
        let summary = format!(
            "error against `raytraced`, every light-facing pixel: {:.3} % wrong (red wrongly shadowed {:.3} %, \
             blue wrongly lit {:.3} %)",
            100.0 * measured.mismatch_rate,
            100.0 * measured.false_shadow_rate,
            100.0 * measured.false_lit_rate
        );
        let rgba = heatmap::drawn(&frame.visibility, &truth);
        let (sender, result) = mpsc::channel();
        // The receiver is alive: the send cannot fail.
        let _ = sender.send(Picture::new(frame.width, frame.height, rgba, summary, settings));
        let rows = frame.height as u64;
        Self { rows_done: Arc::new(AtomicU64::new(rows)), rows, result }
    }

    /// The fraction of rows traced.
    pub fn progress(&self) -> f32 {
        self.rows_done.load(Ordering::Relaxed) as f32 / self.rows.max(1) as f32
    }

    /// The heat-map, once it is ready; `Err` if the worker died.
    pub fn poll(&self) -> Option<Result<Picture, String>> {
        match self.result.try_recv() {
            Ok(picture) => Some(Ok(picture)),
            Err(mpsc::TryRecvError::Empty) => None,
            Err(mpsc::TryRecvError::Disconnected) => Some(Err("the reference worker stopped".into())),
        }
    }
}

/// The CPU reference, traced on a thread: the desktop's (a browser has no threads).
#[cfg(not(target_arch = "wasm32"))]
mod cpu {
    use gnomon_reference::{
        ReferenceOptions, TracedScene, metrics, metrics::RasterView, reference_visibility,
    };
    use gnomon_scene::{Scene, memory};

    use super::*;

    impl ErrorJob {
        /// Starts tracing the reference for the view of `frame` (rendered with `settings`),
        /// or says why it would pass the memory budget (with room for the window's size).
        pub fn start(scene: &Scene, frame: Frame, settings: Settings) -> Result<Self, String> {
            let options = ReferenceOptions {
                width: frame.width,
                height: frame.height,
                samples: settings.reference.samples,
            };
            let window = memory::Window { width: frame.width, height: frame.height };
            let budget = memory::frame_budget_beside(Some(window))?;
            gnomon_reference::check_memory(scene, &options, &budget)
                .map_err(|e| format!("the error view's reference: {e}"))?;
            let rows_done = Arc::new(AtomicU64::new(0));
            let (sender, result) = mpsc::channel();
            let rows = frame.height as u64;
            let scene = scene.clone();
            let counter = rows_done.clone();
            std::thread::spawn(move || {
                let traced = TracedScene::build(&scene);
                let reference =
                    reference_visibility(&traced, &frame.camera, &frame.light, &options, &|done| {
                        counter.store(done, Ordering::Relaxed)
                    });
                let raster = RasterView {
                    visibility: &frame.visibility,
                    object_id: &frame.object_id,
                    depth: &frame.depth,
                };
                let classes = metrics::classify(raster, &reference);
                let measured = metrics::measure(raster, &reference, &classes);
                // An area light's reference is fractional: compare the penumbrae.
                let (rgba, summary) = if reference.samples > 1 {
                    (
                        heatmap::soft(&frame.visibility, &reference, &classes),
                        format!(
                            "error against a {}-sample reference: MAE {:.4} over all compared pixels, {:.4} over the {} penumbra pixels, p99 {:.3} (|V − R|, black 0 to red 1)",
                            reference.samples,
                            measured.mae,
                            measured.penumbra.error.mae,
                            measured.penumbra.error.pixels,
                            measured.p99
                        ),
                    )
                } else {
                    (
                        heatmap::hard(&frame.visibility, &reference, &classes),
                        format!(
                            "error against the exact reference: {:.3} % wrong (red wrongly shadowed {:.3} %, \
                             blue wrongly lit {:.3} %)",
                            100.0 * measured.mismatch_rate,
                            100.0 * measured.false_shadow_rate,
                            100.0 * measured.false_lit_rate
                        ),
                    )
                };
                let _ = sender.send(Picture::new(frame.width, frame.height, rgba, summary, settings));
            });
            Ok(Self { rows_done, rows, result })
        }
    }
}

#[cfg(test)]
mod tests {
    use gnomon_render::{Gpu, OutputRequest, Renderer};
    use gnomon_scene::builtin;

    use super::*;

    fn finish(job: ErrorJob) -> Picture {
        let started = std::time::Instant::now();
        loop {
            if let Some(result) = job.poll() {
                assert!((job.progress() - 1.0).abs() < 1e-6, "progress ended at {}", job.progress());
                return result.unwrap();
            }
            assert!(started.elapsed().as_secs() < 300, "the reference took over 5 minutes");
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
    }

    /// Against the GPU's `raytraced` (the browser's error view), a good render is
    /// nearly all right and an inverted one nearly all wrong.
    #[test]
    fn the_error_view_against_raytraced_marks_where_the_shadows_are_wrong() {
        let gpu = Gpu::new_headless().unwrap();
        let mut renderer = Renderer::new(&gpu).unwrap();
        let scene = builtin::spheres();
        let mut settings = Settings::default();
        (settings.image.width, settings.image.height) = (128, 72);
        let mut traced = settings.clone();
        traced.shadow.filter.technique = gnomon_scene::settings::Technique::RAYTRACED;
        let request = OutputRequest::default();
        let frame = renderer.render(&scene, &settings, &request).unwrap();
        let truth = renderer.render(&scene, &traced, &request).unwrap();
        let surface = frame.object_id.iter().filter(|&&id| id != 0).count();
        let good = finish(ErrorJob::against_raytraced(&frame, truth.clone(), settings.clone()));
        assert!(good.summary.contains("% wrong"), "{}", good.summary);
        let mut inverted = frame;
        for v in inverted.visibility.iter_mut().filter(|v| !v.is_nan()) {
            *v = 1.0 - *v;
        }
        let bad = finish(ErrorJob::against_raytraced(&inverted, truth, settings));
        let (good, bad) = (wrong(&good), wrong(&bad));
        assert!(good * 200 < surface, "{good} of {surface} surface pixels marked wrong on a good render");
        assert!(
            bad * 10 > surface * 8,
            "only {bad} of {surface} surface pixels marked on an inverted render"
        );
    }

    /// The viewer's settings with only a light's size given (through its form, as a
    /// user sets them), in the frame its error view measures (`render_uploaded`, as
    /// the window's comparison draws it): the defaults beam the penumbrae to within
    /// issue 74's 0.01 of the truth, as on the command line, in Python and in the
    /// browser (docs/soft-shadows.md).
    #[test]
    fn the_viewers_error_view_finds_the_soft_defaults_within_a_hundredth() {
        let gpu = Gpu::new_headless().unwrap();
        let mut renderer = Renderer::new(&gpu).unwrap();
        let scene = builtin::spheres();
        let form = crate::settings_form::SettingsForm::new();
        let sized = form.set(&Settings::default(), "sun_angular_diameter", Some("5")).unwrap();
        // The truth's own noise, under 0.01 over a penumbra, needs more rays than the
        // default 256 (python/tests/test_soft_defaults.py says why).
        let mut settings = form.set(&sized, "samples", Some("1024")).unwrap();
        (settings.image.width, settings.image.height) = (320, 180);
        let uploaded = renderer.upload(&scene).unwrap();
        let frame =
            renderer.render_uploaded(&uploaded, &scene, &settings, &OutputRequest::default()).unwrap();
        let [light] = &frame.lights[..] else { panic!("one light: {:?}", frame.lights) };
        assert_eq!(light.refine, gnomon_scene::settings::Refine::Rays, "{light:?}");
        assert!(light.penumbra_frames.is_some_and(|f| f > 1), "a still view gathers frames: {light:?}");
        let picture = finish(ErrorJob::start(&scene, frame, settings).unwrap());
        // "…, 0.0038 over the 573 penumbra pixels, …": the figure the viewer shows.
        let mae: f64 = picture
            .summary
            .split(", ")
            .find(|part| part.ends_with("penumbra pixels"))
            .and_then(|part| part.split(' ').next()?.parse().ok())
            .unwrap_or_else(|| panic!("no penumbra MAE in: {}", picture.summary));
        println!(
            "figure: the viewer's error view, spheres 320×180, sun 5°, the defaults: {}",
            picture.summary
        );
        assert!(mae <= 0.01, "{}", picture.summary);
    }

    /// Pixels painted as wrongly shadowed or wrongly lit.
    fn wrong(picture: &Picture) -> usize {
        picture
            .rgba
            .chunks_exact(4)
            .filter(|p| p[..3] == heatmap::FALSE_SHADOW || p[..3] == heatmap::FALSE_LIT)
            .count()
    }

    /// The heat-map marks few pixels on a good render and most on a render whose
    /// shadows were turned inside out.
    #[test]
    fn the_error_view_marks_where_the_shadows_are_wrong() {
        let gpu = Gpu::new_headless().unwrap();
        let mut renderer = Renderer::new(&gpu).unwrap();
        let scene = builtin::spheres();
        let mut settings = Settings::default();
        (settings.image.width, settings.image.height) = (128, 72);
        let frame = renderer.render(&scene, &settings, &OutputRequest::default()).unwrap();
        let surface = frame.object_id.iter().filter(|&&id| id != 0).count();
        let good = finish(ErrorJob::start(&scene, frame.clone(), settings.clone()).unwrap());
        assert_eq!(good.rgba.len(), 128 * 72 * 4);
        assert!(good.summary.contains("% wrong"), "{}", good.summary);
        let mut inverted = frame;
        for v in inverted.visibility.iter_mut().filter(|v| !v.is_nan()) {
            *v = 1.0 - *v;
        }
        let bad = finish(ErrorJob::start(&scene, inverted, settings).unwrap());
        let (good, bad) = (wrong(&good), wrong(&bad));
        assert!(good * 50 < surface, "{good} of {surface} surface pixels marked wrong on a good render");
        assert!(
            bad * 10 > surface * 8,
            "only {bad} of {surface} surface pixels marked on an inverted render"
        );
    }
}
