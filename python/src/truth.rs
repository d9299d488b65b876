//! The ray-traced truth: `gnomon.reference` traces the reference through the pixel
//! centres on the CPU, and `gnomon.compare` measures a frame against it as
//! `gnomon compare` does: through the pixel centres, and at the surfaces the frame
//! drew (every light-facing pixel). Both trace on other threads while Python waits,
//! answering Ctrl-C.

use std::{sync::Arc, time::Duration};

use gnomon_reference::{
    ReferenceImage, ReferenceOptions, TracedScene,
    cross_check::{ShadowSegments, shadow_segments},
    drawn::{DrawnOptions, DrawnSurfaces, drawn_truth, measure_drawn},
    metrics::{self, RasterView},
    reference_visibility,
};
use gnomon_scene::{Camera, Light};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn};
use pyo3::{prelude::*, types::PyDict};

use crate::{SettingsError, render::PyFrame, scene::PyScene, settings::PySettings, to_python};

/// The reference for one view: its visibility, and the traced scene and light, for
/// comparisons that trace from a frame's own surfaces.
#[pyclass(module = "gnomon", name = "Reference", frozen)]
pub struct PyReference {
    image: Arc<ReferenceImage>,
    traced: Arc<TracedScene>,
    camera: Camera,
    light: Light,
    /// Shadow rays per pixel under an area light.
    #[pyo3(get)]
    samples: u32,
    /// How far above a surface the second ray starts that finds the ambiguous pixels.
    lift: f32,
}

#[pymethods]
impl PyReference {
    /// H×W float32: the fraction of the light visible at each pixel's surface, NaN
    /// where the camera's ray misses.
    #[getter]
    fn visibility<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (h, w) = (self.image.height as usize, self.image.width as usize);
        Ok(PyArray1::from_vec(py, self.image.visibility.clone()).reshape([h, w])?.into_any())
    }

    #[getter]
    fn width(&self) -> u32 {
        self.image.width
    }

    /// N×3×3 float32: the world-space triangles that cast shadows, each as its three
    /// vertices, as the reference traces them: for tracing the same scene with
    /// another tracer. Raises ValueError where an alpha test cuts any of them.
    fn caster_triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let casters = self.traced.caster_triangles();
        if casters.alpha_tested > 0 {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "{} of the scene's {} casting triangles are alpha-tested: another tracer would need their alpha test",
                casters.alpha_tested,
                casters.vertices.len()
            )));
        }
        let n = casters.vertices.len();
        let flat: Vec<f32> =
            casters.vertices.iter().flat_map(|t| t.iter().flat_map(|v| v.to_array())).collect();
        Ok(PyArray1::from_vec(py, flat).reshape([n, 3, 3])?.into_any())
    }

    /// The shadow rays the truth traces from the surfaces `frame` drew, under a light
    /// of size 0: one per light-facing pixel whose light lies above its surface, as a
    /// dict of arrays: `pixel` (M uint32, row-major), `origin` and `direction` (M×3
    /// float32, the origin already moved off the surface), `length` (M float32,
    /// infinite under a sun) and `occluded` (M bool, the reference's answer). Raises
    /// ValueError under a light with an area.
    fn shadow_segments<'py>(&self, py: Python<'py>, frame: &PyFrame) -> PyResult<Bound<'py, PyDict>> {
        same_view(frame, self)?;
        let (traced, light) = (self.traced.clone(), self.light);
        let (position, normal) = (frame.kept.position.clone(), frame.kept.geometric_normal.clone());
        let width = frame.width_px();
        let segments = interruptible(py, move || {
            let surfaces = DrawnSurfaces { width, position: &position, geometric_normal: &normal };
            shadow_segments(&traced, &light, surfaces)
        })?
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        let ShadowSegments { pixel, origin, direction, length, occluded } = segments;
        let m = pixel.len();
        let xyz = |v: &[glam::Vec3]| -> Vec<f32> { v.iter().flat_map(|p| p.to_array()).collect() };
        let dict = PyDict::new(py);
        dict.set_item("pixel", PyArray1::from_vec(py, pixel))?;
        dict.set_item("origin", PyArray1::from_vec(py, xyz(&origin)).reshape([m, 3])?)?;
        dict.set_item("direction", PyArray1::from_vec(py, xyz(&direction)).reshape([m, 3])?)?;
        dict.set_item("length", PyArray1::from_vec(py, length))?;
        dict.set_item("occluded", PyArray1::from_vec(py, occluded))?;
        Ok(dict)
    }

    #[getter]
    fn height(&self) -> u32 {
        self.image.height
    }
}

/// Runs `work` on a thread of its own while Python waits without the GIL, looking
/// for Ctrl-C ten times a second: an interrupt raises `KeyboardInterrupt` at once
/// (the work runs out on its thread and is dropped).
fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send + 'static,
) -> PyResult<T> {
    let (sender, mut answer) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        // The receiver is gone only if Python gave up waiting.
        let _ = sender.send(work());
    });
    loop {
        // The receiver is not Sync: it goes into the GIL-free wait and comes back.
        let (back, received) = py.detach(move || {
            let received = answer.recv_timeout(Duration::from_millis(100));
            (answer, received)
        });
        answer = back;
        match received {
            Ok(value) => return Ok(value),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => py.check_signals()?,
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(pyo3::exceptions::PyRuntimeError::new_err("the tracing thread stopped"));
            }
        }
    }
}

/// The ray-traced reference for `scene` seen with `settings` (its camera, light,
/// size and ground plane), with `samples` shadow rays per pixel under an area light
/// (default: the settings' `reference_samples`).
#[pyfunction]
#[pyo3(signature = (scene, settings, samples = None))]
pub fn reference(
    py: Python<'_>,
    scene: &PyScene,
    settings: &PySettings,
    samples: Option<u32>,
) -> PyResult<PyReference> {
    let settings = settings.settings.clone();
    let drawn = crate::render::drawn(&scene.scene, settings.scene.ground);
    let camera = settings.resolve_camera(&drawn).map_err(|e| SettingsError::new_err(e.to_string()))?;
    let light = settings.resolve_light(&drawn).map_err(|e| SettingsError::new_err(e.to_string()))?;
    let samples = samples.unwrap_or(settings.reference.samples);
    if samples == 0 {
        return Err(SettingsError::new_err("samples = 0 is invalid: give at least 1"));
    }
    let options = ReferenceOptions { width: settings.image.width, height: settings.image.height, samples };
    let budget = gnomon_scene::memory::frame_budget().map_err(SettingsError::new_err)?;
    gnomon_reference::check_memory(&drawn, &options, &budget).map_err(|e| {
        pyo3::exceptions::PyMemoryError::new_err(format!("the reference of scene `{}`: {e}", drawn.name))
    })?;
    let lift = 1e-5 * drawn.bounds().extent().length();
    let (image, traced) = interruptible(py, move || {
        let traced = TracedScene::build(&drawn);
        let image = reference_visibility(&traced, &camera, &light, &options, &|_| {});
        (image, traced)
    })?;
    Ok(PyReference {
        samples: image.samples,
        image: Arc::new(image),
        traced: Arc::new(traced),
        camera,
        light,
        lift,
    })
}

/// `frame` against `truth`, as `gnomon compare` measures it: a dict of its
/// `metrics.json` row (`mismatch_rate`, `false_shadow_rate`, `false_lit_rate`,
/// `mae`, `penumbra`, `edge`…), with `drawn` holding the metrics at the surfaces the
/// frame drew, every light-facing pixel counted. The frame's `visibility` is read
/// as it is now: change it, and the comparison sees the change.
#[pyfunction]
pub fn compare<'py>(py: Python<'py>, frame: &PyFrame, truth: &PyReference) -> PyResult<Bound<'py, PyDict>> {
    let (w, h) = (frame.width_px(), frame.height_px());
    if (w, h) != (truth.image.width, truth.image.height) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "the frame is {w}×{h} and the reference {}×{}: render and trace with the same settings",
            truth.image.width, truth.image.height
        )));
    }
    same_view(frame, truth)?;
    let visibility = read_f32(frame.visibility_array().bind(py))?;
    let depth = read_f32(frame.depth_array().bind(py))?;
    if visibility.len() != (w * h) as usize || depth.len() != (w * h) as usize {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "the frame's visibility or depth changed its size",
        ));
    }
    let kept = &frame.kept;
    let raster = RasterView { visibility: &visibility, object_id: &kept.object_id, depth: &depth };
    let classes = metrics::classify(raster, &truth.image);
    let measured = metrics::measure(raster, &truth.image, &classes);
    let traced = truth.traced.clone();
    let light = truth.light;
    let (position, normal) = (kept.position.clone(), kept.geometric_normal.clone());
    let options = DrawnOptions { samples: truth.samples, lift: truth.lift };
    let drawn = interruptible(py, move || {
        let surfaces = DrawnSurfaces { width: w, position: &position, geometric_normal: &normal };
        let truth = drawn_truth(&traced, &light, surfaces, &options, &|_| {});
        measure_drawn(&visibility, &truth)
    })?;
    let row: Bound<'py, PyDict> = to_python(py, &measured)?.cast_into()?;
    row.set_item("technique", frame.technique_name())?;
    row.set_item("drawn", to_python(py, &drawn)?)?;
    Ok(row)
}

/// Refuses a frame drawn from another view or light than the reference traced.
fn same_view(frame: &PyFrame, truth: &PyReference) -> PyResult<()> {
    if frame.kept.camera != truth.camera || frame.kept.light != truth.light {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "the frame and the reference see different views or lights: trace the reference with the frame's scene and settings",
        ));
    }
    Ok(())
}

fn read_f32(array: &Bound<'_, PyAny>) -> PyResult<Vec<f32>> {
    let readonly: PyReadonlyArrayDyn<'_, f32> = array.extract()?;
    Ok(readonly.as_array().iter().copied().collect())
}
