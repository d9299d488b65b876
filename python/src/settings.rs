//! `gnomon.Settings`: the command line's settings, made from keyword arguments named
//! as its flags (`shadow_res=2048` is `--shadow-res 2048`). They are parsed and
//! checked by the very definition the command line uses (`gnomon_scene::flags`), so
//! the names, the defaults, the checks and the error text are the command line's.

use gnomon_render::techniques::TechniqueRegistry;
use gnomon_scene::{
    Settings,
    flags::{Flag, settings_from_flags},
    settings::in_flags,
};
use pyo3::{
    prelude::*,
    types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple},
};

use crate::{SettingsError, to_python};

/// Settings for a render: the defaults, with the keyword arguments over them.
#[pyclass(module = "gnomon", name = "Settings", frozen)]
pub struct PySettings {
    pub settings: Settings,
    /// The flags given, in order, for `repr` and `replace`.
    flags: Vec<(String, String)>,
}

#[pymethods]
impl PySettings {
    /// `Settings(technique="pcss", shadow_res=2048, width=640, height=360, ...)`:
    /// every keyword is a flag of `gnomon render --help`, dashes as underscores.
    /// Values are strings as typed on the command line, numbers, `True`/`False` for
    /// a switch, or a sequence of numbers for a vector (`camera_eye=(0, 2, 5)`).
    /// A value the command line refuses raises `SettingsError` (a `ValueError`) with
    /// its message, naming the flag.
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn new(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut flags = Vec::new();
        if let Some(kwargs) = kwargs {
            for (key, value) in kwargs.iter() {
                let name: String = key.extract()?;
                if let Some(words) = words(&name, &value)? {
                    flags.push((name, words));
                }
            }
        }
        Self::from_flags(flags)
    }

    /// These settings with `kwargs` changed (or added): a new `Settings`.
    #[pyo3(signature = (**kwargs))]
    fn replace(&self, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut flags = self.flags.clone();
        if let Some(kwargs) = kwargs {
            for (key, value) in kwargs.iter() {
                let name: String = key.extract()?;
                flags.retain(|(n, _)| *n != name);
                if let Some(words) = words(&name, &value)? {
                    flags.push((name, words));
                }
            }
        }
        Self::from_flags(flags)
    }

    /// Every setting, as the nested tables of a scene file's `[settings]`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.settings)
    }

    /// Every settings flag: `name` (as a keyword: underscores), `flag`, `heading`,
    /// `help`, `choices`, `switch` and `default`.
    #[staticmethod]
    fn flags<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let described = to_python(py, &gnomon_scene::flags::describe())?;
        for entry in described.try_iter()? {
            let entry = entry?;
            let flag: String = entry.get_item("name")?.extract()?;
            entry.set_item("flag", format!("--{flag}"))?;
            entry.set_item("name", flag.replace('-', "_"))?;
        }
        Ok(described)
    }

    /// The shadow technique's name.
    #[getter]
    fn technique(&self) -> String {
        gnomon_scene::flags::technique_name(&self.settings)
    }

    /// Image width in pixels.
    #[getter]
    fn width(&self) -> u32 {
        self.settings.image.width
    }

    /// Image height in pixels.
    #[getter]
    fn height(&self) -> u32 {
        self.settings.image.height
    }

    fn __repr__(&self) -> String {
        let given: Vec<String> = self.flags.iter().map(|(n, v)| format!("{n}={v:?}")).collect();
        format!("gnomon.Settings({})", given.join(", "))
    }
}

impl PySettings {
    fn from_flags(flags: Vec<(String, String)>) -> PyResult<Self> {
        let as_flags: Vec<Flag> = flags
            .iter()
            .map(|(name, value)| Flag { name: name.replace('_', "-"), value: value.clone() })
            .collect();
        let settings = settings_from_flags(&as_flags).map_err(|e| SettingsError::new_err(e.to_string()))?;
        TechniqueRegistry::builtin()
            .check(&settings.shadow)
            .map_err(|e| SettingsError::new_err(in_flags(&e.to_string())))?;
        Ok(Self { settings, flags })
    }
}

/// A keyword's value as it would be typed after its flag; `None` leaves it unset.
fn words(name: &str, value: &Bound<'_, PyAny>) -> PyResult<Option<String>> {
    if value.is_none() {
        return Ok(None);
    }
    // bool before int: Python's True is an int too.
    if value.is_instance_of::<PyBool>() {
        return Ok(Some(value.extract::<bool>()?.to_string()));
    }
    if value.is_instance_of::<PyString>()
        || value.is_instance_of::<PyInt>()
        || value.is_instance_of::<PyFloat>()
    {
        return Ok(Some(value.str()?.to_string()));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let parts: PyResult<Vec<String>> = value
            .try_iter()?
            .map(|item| {
                let item = item?;
                if item.is_instance_of::<PyInt>() || item.is_instance_of::<PyFloat>() {
                    Ok(item.str()?.to_string())
                } else {
                    Err(SettingsError::new_err(format!(
                        "{name}: a sequence must hold numbers, such as (0, 2, 5)"
                    )))
                }
            })
            .collect();
        return Ok(Some(parts?.join(",")));
    }
    // numpy's scalars (np.float32, np.int64) are numbers without being int or float.
    if value.extract::<f64>().is_ok() {
        return Ok(Some(value.str()?.to_string()));
    }
    Err(SettingsError::new_err(format!(
        "{name}: give a string, a number, True or False, or a sequence of numbers; got {}",
        value.get_type().name()?
    )))
}

/// Every technique the renderer knows, by name.
#[pyfunction]
pub fn techniques() -> Vec<String> {
    TechniqueRegistry::builtin().iter().map(|t| t.technique().to_string()).collect()
}
