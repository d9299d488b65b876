//! `gnomon.Renderer` and `gnomon.Frame`. A renderer holds a GPU device (lavapipe where
//! there is no GPU) and the last scene's upload, kept across calls; a frame hands its
//! images to numpy without copying them, and keeps what a comparison needs.

use glam::Vec3;
use gnomon_render::{Frame, Gpu, GpuScene, OutputRequest, RenderError, Renderer};
use gnomon_scene::{Camera, Light, Scene};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::{prelude::*, types::PyDict};

use crate::{GpuError, scene::PyScene, settings::PySettings};

/// The scene as drawn (with the ground plane the settings ask for) and its upload.
struct Upload {
    /// The scene object's id and whether the ground was added.
    key: (u64, bool),
    uploaded: GpuScene,
}

/// A renderer on the GPU, kept across calls: its pipelines, pools and the last
/// scene's upload persist.
#[pyclass(module = "gnomon", name = "Renderer")]
pub struct PyRenderer {
    gpu: Gpu,
    renderer: Renderer,
    upload: Option<Upload>,
}

/// A frame over the memory budget is a `MemoryError` (refused before anything was
/// allocated), a bad `GNOMON_MEMORY_MIB` a `SettingsError`; every other renderer
/// error a `GpuError`.
fn gpu_error(e: RenderError) -> PyErr {
    let message = e.to_string();
    if matches!(e, RenderError::OverBudget { .. }) {
        pyo3::exceptions::PyMemoryError::new_err(message)
    } else if matches!(e, RenderError::MemoryBudget(_)) {
        crate::SettingsError::new_err(message)
    } else {
        GpuError::new_err(message)
    }
}

/// `scene` as a render draws it: with a ground plane under it where asked.
pub fn drawn(scene: &Scene, ground: bool) -> Scene {
    let mut drawn = scene.clone();
    if ground {
        drawn.add_ground_plane();
    }
    drawn
}

#[pymethods]
impl PyRenderer {
    /// Opens the GPU (the first adapter Vulkan offers; lavapipe where there is no
    /// GPU) and builds the renderer. Raises `GpuError` when there is none.
    #[new]
    fn new(py: Python<'_>) -> PyResult<Self> {
        py.detach(|| {
            let gpu = Gpu::new_headless()?;
            let renderer = Renderer::new(&gpu)?;
            Ok(Self { gpu, renderer, upload: None })
        })
        .map_err(gpu_error)
    }

    /// Renders `scene` with `settings` and returns the `Frame`. The scene's upload is
    /// kept while the next call gives the same scene.
    fn render(&mut self, py: Python<'_>, scene: &PyScene, settings: &PySettings) -> PyResult<PyFrame> {
        let settings = settings.settings.clone();
        let ground = settings.scene.ground;
        let drawn_scene = drawn(&scene.scene, ground);
        let key = (scene.id, ground);
        let Self { renderer, upload, .. } = self;
        let frame = py
            .detach(|| -> Result<Frame, RenderError> {
                let uploaded = match upload.take() {
                    Some(kept) if kept.key == key => kept.uploaded,
                    _ => renderer.upload(&drawn_scene)?,
                };
                let frame =
                    renderer.render_uploaded(&uploaded, &drawn_scene, &settings, &OutputRequest::default());
                *upload = Some(Upload { key, uploaded });
                frame
            })
            .map_err(gpu_error)?;
        PyFrame::new(py, frame, gnomon_scene::flags::technique_name(&settings))
    }

    /// The adapter: `name`, `backend`, `device_type`, `driver`.
    #[getter]
    fn adapter<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let info = &self.gpu.info;
        let dict = PyDict::new(py);
        dict.set_item("name", &info.adapter)?;
        dict.set_item("backend", &info.backend)?;
        dict.set_item("device_type", &info.device_type)?;
        dict.set_item("driver", &info.driver)?;
        Ok(dict)
    }

    fn __repr__(&self) -> String {
        format!("gnomon.Renderer({:?})", self.gpu.info.adapter)
    }
}

/// A rendered frame: its images as numpy arrays (rows from the top), its pass times
/// and its draw counts.
#[pyclass(module = "gnomon", name = "Frame", frozen)]
pub struct PyFrame {
    /// H×W×4 uint8, sRGB.
    #[pyo3(get)]
    color: Py<PyAny>,
    /// H×W float32: 1 lit, 0 shadowed, NaN background.
    #[pyo3(get)]
    visibility: Py<PyAny>,
    /// H×W float32: view-space depth (distance along the camera's axis), NaN
    /// background.
    #[pyo3(get)]
    depth: Py<PyAny>,
    /// H×W×3 float32: world-space position, NaN background.
    #[pyo3(get)]
    position: Py<PyAny>,
    /// H×W×3 float32: world-space shading normal, NaN background.
    #[pyo3(get)]
    normal: Py<PyAny>,
    /// H×W uint32: the instance drawn at each pixel (its index + 1), 0 background.
    #[pyo3(get)]
    object_id: Py<PyAny>,
    /// Each pass's GPU milliseconds (None where the pass did not run or the adapter
    /// has no timestamps): `shadow_ms`, `filter_ms`, `prepass_ms`, `mask_ms`,
    /// `trace_ms`, `lighting_ms`, `frame_ms`.
    #[pyo3(get)]
    times: Py<PyDict>,
    /// Draw calls, state changes, instances and triangles.
    #[pyo3(get)]
    stats: Py<PyDict>,
    /// One dict a light ([`LightReport`]): how its shadow was refined by rays, how
    /// many pixels were traced, and the frames its penumbra history holds.
    #[pyo3(get)]
    lights: Py<PyAny>,
    /// The shadow technique it was drawn with.
    #[pyo3(get)]
    technique: String,
    #[pyo3(get)]
    width: u32,
    #[pyo3(get)]
    height: u32,
    /// What a comparison needs that the arrays do not hold.
    pub kept: Kept,
}

/// What `Frame.lights` says of one light: the fields of `gnomon_render::LightStats`
/// that tell how its shadow was answered (`gnomon render --verbose` prints them).
#[derive(serde::Serialize)]
struct LightReport<'a> {
    name: &'a str,
    /// "sun", "spot" or "point".
    kind: &'a str,
    technique: &'a str,
    /// The refinement it got: `auto` resolved ("rays", "every-pixel"), or "off".
    refine: gnomon_scene::settings::Refine,
    /// Shadow rays a refined pixel asks for: 1 under a hard light, a penumbra
    /// beam's samples under a light with an area.
    rays_per_pixel: u32,
    /// Pixels refined this frame, on the mask path.
    traced_pixels: Option<u32>,
    /// Pixels whose rays decide, this frame or before.
    unsure_pixels: Option<u32>,
    /// Frames its penumbra history holds, this one counted.
    penumbra_frames: Option<u32>,
}

impl<'a> LightReport<'a> {
    fn of(light: &'a gnomon_render::LightStats) -> Self {
        Self {
            name: &light.name,
            kind: light.kind,
            technique: light.technique.name(),
            refine: light.refine,
            rays_per_pixel: light.rays_per_pixel,
            traced_pixels: light.traced_pixels,
            unsure_pixels: light.unsure_pixels,
            penumbra_frames: light.penumbra_frames,
        }
    }
}

/// The frame's surfaces and view, for a comparison with the reference.
pub struct Kept {
    pub geometric_normal: Vec<Vec3>,
    pub position: Vec<Vec3>,
    pub object_id: Vec<u32>,
    pub camera: Camera,
    pub light: Light,
}

impl PyFrame {
    pub fn width_px(&self) -> u32 {
        self.width
    }

    pub fn height_px(&self) -> u32 {
        self.height
    }

    pub fn visibility_array(&self) -> &Py<PyAny> {
        &self.visibility
    }

    pub fn depth_array(&self) -> &Py<PyAny> {
        &self.depth
    }

    pub fn technique_name(&self) -> &str {
        &self.technique
    }

    fn new(py: Python<'_>, frame: Frame, technique: String) -> PyResult<Self> {
        let (h, w) = (frame.height as usize, frame.width as usize);
        let xyz = |v: &[Vec3]| -> Vec<f32> { v.iter().flat_map(|p| p.to_array()).collect() };
        let times = PyDict::new(py);
        let t = frame.timings.as_ref();
        times.set_item("shadow_ms", t.map(|t| t.shadow_ms))?;
        times.set_item("filter_ms", t.and_then(|t| t.filter_ms))?;
        times.set_item("prepass_ms", t.and_then(|t| t.prepass_ms))?;
        times.set_item("mask_ms", t.and_then(|t| t.mask_ms))?;
        times.set_item("trace_ms", t.and_then(|t| t.trace_ms))?;
        times.set_item("lighting_ms", t.map(|t| t.lighting_ms))?;
        times.set_item("frame_ms", t.map(|t| t.frame_ms))?;
        let s = frame.stats;
        let stats = PyDict::new(py);
        stats.set_item("shadow_draws", s.shadow_draws)?;
        stats.set_item("shadow_commands", s.shadow_commands)?;
        stats.set_item("lighting_draws", s.lighting_draws)?;
        stats.set_item("prepass_draws", s.prepass_draws)?;
        stats.set_item("pipeline_changes", s.pipeline_changes)?;
        stats.set_item("bind_group_changes", s.bind_group_changes)?;
        stats.set_item("shadow_instances", s.shadow_instances)?;
        stats.set_item("shadow_triangles", s.shadow_triangles)?;
        stats.set_item("lighting_instances", s.lighting_instances)?;
        let reports: Vec<LightReport> = frame.lights.iter().map(LightReport::of).collect();
        let lights = crate::to_python(py, &reports)?.unbind();
        let position_xyz = xyz(&frame.position);
        let normal = xyz(&frame.normal);
        let Frame { color, visibility, depth, object_id, position, geometric_normal, camera, light, .. } =
            frame;
        Ok(Self {
            // The Vecs become the arrays' memory: no copy.
            color: PyArray1::from_vec(py, color).reshape([h, w, 4])?.into_any().unbind(),
            visibility: PyArray1::from_vec(py, visibility).reshape([h, w])?.into_any().unbind(),
            depth: PyArray1::from_vec(py, depth).reshape([h, w])?.into_any().unbind(),
            position: PyArray1::from_vec(py, position_xyz).reshape([h, w, 3])?.into_any().unbind(),
            normal: PyArray1::from_vec(py, normal).reshape([h, w, 3])?.into_any().unbind(),
            object_id: PyArray1::from_vec(py, object_id.clone()).reshape([h, w])?.into_any().unbind(),
            times: times.unbind(),
            stats: stats.unbind(),
            lights,
            technique,
            width: w as u32,
            height: h as u32,
            kept: Kept { geometric_normal, position, object_id, camera, light },
        })
    }
}
