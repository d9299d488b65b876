//! `gnomon._gnomon`: the extension module behind `import gnomon`. It follows the
//! library, not the command line: a `Scene` (built in or loaded),
//! `Settings` made from the command line's own flags (same names,
//! defaults, checks and words), a `Renderer` kept across calls so that
//! its GPU resources persist, whose frames hand their images to numpy without a copy,
//! and the ray-traced reference with `gnomon compare`'s metrics (`truth`). The GIL
//! is released while the GPU or the tracer works; a long trace answers Ctrl-C.

mod render;
mod scene;
mod settings;
mod truth;

use pyo3::prelude::*;

pyo3::create_exception!(
    gnomon,
    SettingsError,
    pyo3::exceptions::PyValueError,
    "A setting the command line would refuse too; the message is the command line's."
);
pyo3::create_exception!(
    gnomon,
    SceneError,
    pyo3::exceptions::PyValueError,
    "A scene that cannot be built or loaded; the message names it."
);
pyo3::create_exception!(
    gnomon,
    GpuError,
    pyo3::exceptions::PyRuntimeError,
    "No GPU adapter, or the GPU refused the work; the message says why."
);

#[pymodule]
fn _gnomon(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SettingsError", py.get_type::<SettingsError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("GpuError", py.get_type::<GpuError>())?;
    m.add_class::<scene::PyScene>()?;
    m.add_class::<settings::PySettings>()?;
    m.add_class::<render::PyRenderer>()?;
    m.add_class::<render::PyFrame>()?;
    m.add_class::<truth::PyReference>()?;
    m.add_function(wrap_pyfunction!(truth::reference, m)?)?;
    m.add_function(wrap_pyfunction!(truth::compare, m)?)?;
    m.add_function(wrap_pyfunction!(scene::builtin_scenes, m)?)?;
    m.add_function(wrap_pyfunction!(settings::techniques, m)?)?;
    Ok(())
}

/// A serde value as the Python object `json.loads` makes of it: dicts, lists,
/// numbers, strings, None.
fn to_python<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let json =
        serde_json::to_string(value).map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (json,))
}
