//! `gnomon.Scene`: a built-in scene or a glTF model, with its camera and lights as
//! attributes. A scene is immutable from Python; a renderer keeps its upload for as
//! long as it is given the same scene.

use std::sync::{
    Arc,
    atomic::{AtomicU64, Ordering},
};

use gnomon_scene::{Scene, builtin, gltf_loader};
use pyo3::{prelude::*, types::PyDict};

use crate::SceneError;

/// A scene: what is drawn and traced, the default camera and the lights.
#[pyclass(module = "gnomon", name = "Scene", frozen)]
pub struct PyScene {
    pub scene: Arc<Scene>,
    /// Unique to this scene object: a renderer reuses its upload while it is the same.
    pub id: u64,
    /// The model's warnings, for a loaded one.
    warnings: Vec<String>,
}

impl PyScene {
    fn new(scene: Scene, warnings: Vec<String>) -> Self {
        static NEXT: AtomicU64 = AtomicU64::new(1);
        Self { scene: Arc::new(scene), id: NEXT.fetch_add(1, Ordering::Relaxed), warnings }
    }
}

#[pymethods]
impl PyScene {
    /// The built-in scene `name` (see `gnomon.builtin_scenes()`).
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<Self> {
        let scene = builtin::build(name).map_err(|e| match e {
            builtin::BuiltinError::Unknown(_) => SceneError::new_err(format!(
                "unknown scene `{name}`: give one of the built-in scenes {}",
                builtin::names().join(", ")
            )),
            other => SceneError::new_err(other.to_string()),
        })?;
        Ok(Self::new(scene, Vec::new()))
    }

    /// The glTF model at `path` (`.gltf` or `.glb`). As on the command line, a model
    /// may read only files beside or below it; a file it cannot load raises
    /// `SceneError` naming it.
    #[staticmethod]
    fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        let loaded = py.detach(|| gltf_loader::load_with(&path, &gltf_loader::LoadOptions::default()));
        let (scene, extras) = loaded.map_err(|e| SceneError::new_err(e.to_string()))?;
        Ok(Self::new(scene, extras.warnings))
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> &str {
        &self.scene.name
    }

    /// The default view: `eye`, `target`, `up`, `fov_y_degrees`, `near`, `far`.
    #[getter]
    fn camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = &self.scene.camera;
        let dict = PyDict::new(py);
        dict.set_item("eye", c.eye.to_array())?;
        dict.set_item("target", c.target.to_array())?;
        dict.set_item("up", c.up.to_array())?;
        dict.set_item("fov_y_degrees", c.fov_y_degrees)?;
        dict.set_item("near", c.near)?;
        dict.set_item("far", c.far)?;
        Ok(dict)
    }

    /// Every light: `name`, `kind` (`sun`, `spot`, `point`…) and `listed` (named by
    /// the scene, rather than its kind's default).
    #[getter]
    fn lights<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.scene
            .lights
            .iter()
            .map(|l| {
                let dict = PyDict::new(py);
                dict.set_item("name", &l.name)?;
                dict.set_item("kind", l.light.type_name())?;
                dict.set_item("listed", l.role == gnomon_scene::scene_lights::LightRole::Listed)?;
                Ok(dict)
            })
            .collect()
    }

    /// Triangles over every instance.
    #[getter]
    fn triangles(&self) -> usize {
        self.scene.instances.iter().map(|i| self.scene.meshes[i.mesh].indices.len() / 3).sum()
    }

    /// The loader's warnings, for a model.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "gnomon.Scene({:?}, {} lights, {} triangles)",
            self.scene.name,
            self.scene.lights.len(),
            self.triangles()
        )
    }
}

/// The built-in scenes' names.
#[pyfunction]
pub fn builtin_scenes() -> Vec<String> {
    builtin::names().into_iter().map(String::from).collect()
}
