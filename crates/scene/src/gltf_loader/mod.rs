//! Loading glTF 2.0 (`.gltf` with embedded or external buffers and images, and `.glb`)
//! into a [`Scene`]: every mesh primitive, the node hierarchy with its transforms,
//! base-colour factors and textures with their samplers and texcoord sets, alpha
//! modes, the double-sided flag, and cameras and `KHR_lights_punctual` lights.
//!
//! Every malformed input gives a [`LoadError`] naming the file and the problem; the
//! loader never panics on bad data (a panic inside the `gltf` crate is caught and
//! reported as an error too).

use std::path::{Path, PathBuf};

use crate::Scene;

mod assemble;
mod images;
mod lights;
mod node_extras;
mod primitives;
pub mod sources;
mod structure;
mod values;

pub use sources::UriScope;

/// How a model is loaded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Where the buffer and image files it names may be: by default in its folder.
    pub uri_scope: UriScope,
}

/// A glTF file that could not be loaded.
#[derive(Debug, thiserror::Error)]
#[error("{}: {problem}", path.display())]
pub struct LoadError {
    /// The file that failed: the `.gltf` or `.glb` that was asked for.
    pub path: PathBuf,
    /// What is wrong with it, in words, for the error message.
    pub problem: String,
}

/// Lights and views a file may carry besides geometry.
#[derive(Clone, Debug, Default)]
pub struct FileExtras {
    /// Whether the file had a camera (else the scene's camera was fitted to its bounds).
    pub has_camera: bool,
    /// Whether the file had a directional light (else a default sun was placed).
    pub has_sun: bool,
    /// Whether the file had a spot light (else a default spot was placed).
    pub has_spot: bool,
    /// Whether the file had a point light (else a default point light was placed).
    pub has_point: bool,
    /// Lights the file has that Gnomon cannot use (a directional or spot light with
    /// a degenerate transform).
    pub ignored_lights: usize,
    /// What was loaded but not as the file says, in words, for the user to see:
    /// skipped points and lines, singular node transforms, ignored extensions.
    pub warnings: Vec<String>,
}

/// Loads `path` into a scene, with the default [`LoadOptions`] (the files it names
/// must lie in its folder). The camera and the lights come from the file when it has
/// them; otherwise the camera is fitted to the bounds and a default sun (45° up) and
/// spot light are placed.
pub fn load(path: &Path) -> Result<(Scene, FileExtras), LoadError> {
    load_with(path, &LoadOptions::default())
}

/// Loads `path` into a scene as [`load`] does, with `options`.
pub fn load_with(path: &Path, options: &LoadOptions) -> Result<(Scene, FileExtras), LoadError> {
    load_charged(path, options, &mut sources::Budget::default())
}

/// Loads `path` as [`load_with`] does, charging what it holds to `budget`: the one
/// budget every model of a scene file shares, so that twelve models of a few
/// kilobytes cannot each take the whole frame's memory.
pub fn load_charged(
    path: &Path,
    options: &LoadOptions,
    budget: &mut sources::Budget,
) -> Result<(Scene, FileExtras), LoadError> {
    let bytes = read_model(path).map_err(|problem| LoadError { path: path.to_path_buf(), problem })?;
    load_bytes(&bytes, path, options, budget)
}

/// Loads a model given as bytes (a `.glb`, or a `.gltf` whose data are `data:`
/// URIs), as [`load`] does a file: a file dropped on a web page, say. `name` names
/// it in errors. It may name no file ([`UriScope::EmbeddedOnly`]): it has no folder.
pub fn load_from_bytes(bytes: &[u8], name: &str) -> Result<(Scene, FileExtras), LoadError> {
    let path = Path::new(name);
    let limit = crate::limits::MAX_MODEL_BYTES;
    if bytes.len() as u64 > limit {
        return Err(LoadError {
            path: path.to_path_buf(),
            problem: format!(
                "the file is {}; a model may be at most {}",
                sources::size(bytes.len() as u64),
                sources::size(limit)
            ),
        });
    }
    load_bytes(
        bytes,
        path,
        &LoadOptions { uri_scope: UriScope::EmbeddedOnly },
        &mut sources::Budget::default(),
    )
}

/// Loads the model `bytes`, read from (or named) `path`.
fn load_bytes(
    bytes: &[u8],
    path: &Path,
    options: &LoadOptions,
    budget: &mut sources::Budget,
) -> Result<(Scene, FileExtras), LoadError> {
    let fail = |problem: String| LoadError { path: path.to_path_buf(), problem };
    glb_header_fits(bytes).map_err(fail)?;
    // A first look without validation, for the problems validation would misname.
    if let Ok(raw) = gltf::Gltf::from_slice_without_validation(bytes) {
        if raw.extensions_used().any(|e| e == "KHR_draco_mesh_compression") {
            return Err(fail(
                "uses KHR_draco_mesh_compression, which Gnomon does not support; re-export the file without \
                 Draco compression"
                    .into(),
            ));
        }
        let base = path.parent().unwrap_or(Path::new("."));
        // The JSON itself, not the crate's wrappers: on an unvalidated file those
        // unwrap indices that may be out of range (found by fuzzing).
        let json = raw.document.as_json();
        indices_the_crate_trusts(json).map_err(fail)?;
        // Every file the model names, checked before anything is read: missing,
        // outside the model's folder, or not a regular file.
        let buffers = json
            .buffers
            .iter()
            .enumerate()
            .filter_map(|(i, b)| b.uri.as_deref().map(|u| (format!("buffer {i}"), u)));
        let images = json
            .images
            .iter()
            .enumerate()
            .filter_map(|(i, m)| m.uri.as_deref().map(|u| (format!("image {i}"), u)));
        for (what, uri) in buffers.chain(images) {
            if !uri.starts_with("data:") {
                sources::resolve(base, uri, options.uri_scope, &what).map_err(fail)?;
            }
        }
        check_version(json).map_err(fail)?;
        structure::check(json).map_err(fail)?;
        values::check(json).map_err(fail)?;
    }
    // The gltf crate validates the JSON and the buffer and accessor ranges; guard
    // against a panic on data it does not check all the same.
    let base = path.parent().unwrap_or(Path::new("."));
    let imported = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(bytes).map_err(|e| describe(&e))?;
        let buffers = sources::buffers(&document, base, blob, options.uri_scope, budget)?;
        Ok::<_, String>((document, buffers))
    }))
    .map_err(|_| fail("the glTF importer failed on malformed data".into()))?;
    let (document, buffers) = match imported {
        Ok(i) => i,
        Err(problem) => {
            // Validation insists on min/max for positions, which files with NaN or
            // infinite positions often lack; say what is really wrong when we can.
            // Only then: any other fault may make the unvalidated read panic.
            let only_bounds_missing = gltf::Gltf::from_slice(bytes).err().is_some_and(|e| {
                matches!(&e, gltf::Error::Validation(errors)
                    if errors.iter().all(|(path, _)| path.as_str().ends_with(".min") || path.as_str().ends_with(".max")))
            });
            if only_bounds_missing && let Some(problem) = non_finite_positions(path, bytes, options.uri_scope)
            {
                return Err(fail(problem));
            }
            return Err(fail(problem));
        }
    };
    accessors_fit(&document, budget).map_err(fail)?;
    values::sparse_indices(&document, &buffers).map_err(fail)?;
    let mut extension_warnings = extensions(&document).map_err(fail)?;
    extension_warnings.extend(values::unsupported(document.as_json()));
    let images = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        images::import(&document, base, &buffers, options.uri_scope, budget)
    }))
    .map_err(|_| fail("the glTF image reader failed on malformed data".into()))?
    .map_err(fail)?;
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        assemble::build(path, &document, &buffers, &images, budget)
    }))
    .map(|built| {
        built.map(|(scene, mut extras)| {
            extras.warnings.extend(extension_warnings);
            (scene, extras)
        })
    })
    .map_err(|_| fail("the glTF reader failed on malformed data".into()))?
    .map_err(fail)
}

/// The model file's bytes: a regular file (not a directory, FIFO or device, each of
/// which is named as what it is), no larger than a model may be.
fn read_model(path: &Path) -> Result<Vec<u8>, String> {
    use crate::files::{Links, ReadError, read_regular};
    let bytes = read_regular(path, Links::Follow, crate::limits::MAX_MODEL_BYTES, "a model").map_err(
        |e| match e {
            ReadError::Missing => "cannot read: no such file".to_string(),
            ReadError::NotRegular(kind) => format!("cannot read: it is {kind}, not a regular file"),
            other => other.to_string(),
        },
    )?;
    if bytes.is_empty() {
        // A pseudo file (`/proc/self/pagemap`) states no length and is read as such.
        return Err("the file is empty (it states a length of 0 bytes)".into());
    }
    Ok(bytes)
}

/// glTF 2.x only: `asset.version` is "2.0" (a `minVersion` above it is refused too).
fn check_version(json: &gltf::json::Root) -> Result<(), String> {
    let major = |v: &str| v.split('.').next().and_then(|m| m.parse::<u32>().ok());
    let version = &json.asset.version;
    if major(version) != Some(2) {
        return Err(format!("`asset.version` is \"{version}\"; Gnomon reads glTF 2.x"));
    }
    if let Some(min) = &json.asset.min_version
        && (major(min) != Some(2) || min.as_str() > "2.0")
    {
        return Err(format!("`asset.minVersion` is \"{min}\"; Gnomon reads glTF 2.0"));
    }
    Ok(())
}

/// Checks every accessor against what reading it would take, before anything is read:
/// its byte stride against its element (the gltf crate asserts on a stride smaller
/// than an element, and the spec asks for a multiple of 4 from 4 to 252), and its
/// element count against the budget, which a sparse accessor with no buffer view
/// leaves to its count alone (999,999,999 asked for 12 GB).
fn accessors_fit(document: &gltf::Document, budget: &mut sources::Budget) -> Result<(), String> {
    for accessor in document.accessors() {
        let what = format!("accessor {}{}", accessor.index(), sources::named(accessor.name()));
        let element = accessor.size() as u64;
        if let Some(view) = accessor.view()
            && let Some(stride) = view.stride()
            && ((stride as u64) < element || stride % 4 != 0 || !(4..=252).contains(&stride))
        {
            return Err(format!(
                "{what}: its buffer view {} has a byte stride of {stride}, for elements of {element} bytes; a stride is \
                 a multiple of 4 from 4 to 252, at least an element's size",
                view.index()
            ));
        }
        // What the reader expands it to: at most 16 bytes an element of any type
        // Gnomon reads (positions and normals as 3 × f32, UVs 2 × f32, indices u32),
        // and the element itself as stored.
        let expanded = (accessor.count() as u64).saturating_mul(element.max(16));
        budget.take(expanded, &format!("{what}, {} elements,", accessor.count()))?;
    }
    primitives_fit(document, budget)
}

/// Charges every triangle primitive's mesh as Gnomon will hold it, once per
/// primitive that reads it (300 primitives sharing one POSITION accessor make 300
/// meshes): its vertices and triangles ([`crate::memory`]'s costs). A sparse
/// accessor's count is charged whole, whatever few bytes it is stored in.
fn primitives_fit(document: &gltf::Document, budget: &mut sources::Budget) -> Result<(), String> {
    use crate::memory::{BYTES_PER_TRIANGLE, BYTES_PER_VERTEX};
    for mesh in document.meshes() {
        for (k, prim) in mesh.primitives().enumerate() {
            let Some(positions) = prim.get(&gltf::Semantic::Positions) else { continue };
            let vertices = positions.count() as u64;
            let triangles = prim.indices().map_or(vertices, |i| i.count() as u64) / 3;
            let bytes = vertices
                .saturating_mul(BYTES_PER_VERTEX)
                .saturating_add(triangles.saturating_mul(BYTES_PER_TRIANGLE));
            let what = format!(
                "mesh {} primitive {k}, {vertices} vertices and {triangles} triangles,",
                mesh.index()
            );
            budget.take(bytes, &what)?;
        }
    }
    Ok(())
}

/// Checks the indices that the gltf crate uses unchecked: its validation looks up
/// each POSITION accessor before checking that it exists, and an image in a buffer
/// view is read with an unwrapped MIME type. Both panicked on fuzzed files.
fn indices_the_crate_trusts(json: &gltf::json::Root) -> Result<(), String> {
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (k, primitive) in mesh.primitives.iter().enumerate() {
            let accessors = primitive.attributes.values().chain(primitive.indices.as_ref());
            if let Some(bad) = accessors.map(|a| a.value()).find(|&a| a >= json.accessors.len()) {
                return Err(format!(
                    "mesh {m} primitive {k} names accessor {bad}, but the file has {} accessors",
                    json.accessors.len()
                ));
            }
        }
    }
    for (i, image) in json.images.iter().enumerate() {
        if let Some(view) = image.buffer_view {
            if view.value() >= json.buffer_views.len() {
                return Err(format!(
                    "image {i} names buffer view {}, but the file has {} buffer views",
                    view.value(),
                    json.buffer_views.len()
                ));
            }
            if image.mime_type.is_none() {
                return Err(format!(
                    "image {i} is in a buffer view but has no `mimeType` (glTF requires one)"
                ));
            }
        } else if image.uri.is_none() {
            return Err(format!("image {i} has neither a `uri` nor a `bufferView`"));
        }
    }
    Ok(())
}

/// Whether every POSITION accessor is what the reader reads: vec3 of f32, at least
/// one. (On an unvalidated file the reader's debug assertions would fire.)
fn positions_readable(json: &gltf::json::Root) -> bool {
    use gltf::json::accessor::{ComponentType, GenericComponentType, Type};
    use gltf::json::validation::Checked::Valid;
    json.meshes.iter().flat_map(|m| &m.primitives).all(|p| {
        p.attributes.iter().all(|(semantic, a)| {
            let accessor = &json.accessors[a.value()];
            *semantic != Valid(gltf::Semantic::Positions)
                || (accessor.count.0 > 0
                    && accessor.type_ == Valid(Type::Vec3)
                    && matches!(accessor.component_type, Valid(GenericComponentType(ComponentType::F32))))
        })
    })
}

/// Refuses a binary glTF whose header declares a length shorter than the 12-byte
/// header itself: the gltf crate (1.4.1, `Glb::from_slice`) subtracts the header's
/// size from that length unchecked, which overflows (found by fuzzing).
fn glb_header_fits(bytes: &[u8]) -> Result<(), String> {
    const HEADER_BYTES: u32 = 12;
    let Some(header) = bytes.strip_prefix(b"glTF") else { return Ok(()) };
    let Some(length) = header.get(4..8) else {
        return Err(format!(
            "is a binary glTF (GLB) of {} bytes, shorter than the {HEADER_BYTES}-byte GLB header",
            bytes.len()
        ));
    };
    let length = u32::from_le_bytes([length[0], length[1], length[2], length[3]]);
    if length < HEADER_BYTES {
        return Err(format!(
            "is a binary glTF (GLB) whose header declares a length of {length} bytes, less than the \
             {HEADER_BYTES}-byte header itself"
        ));
    }
    if u64::from(length) != bytes.len() as u64 {
        return Err(format!(
            "is a binary glTF (GLB) whose header declares a length of {length} bytes, but the file holds {}: \
             the two must agree (glTF 2.0, §4.4.2)",
            bytes.len()
        ));
    }
    glb_chunks(&bytes[HEADER_BYTES as usize..])
}

/// Walks a GLB's chunks after its header: each fits in the file, and there is at
/// most one binary chunk (glTF 2.0, §4.4.3.3); a second would be silently ignored.
fn glb_chunks(mut rest: &[u8]) -> Result<(), String> {
    const BIN: u32 = 0x004E_4942;
    let mut binary_chunks = 0;
    while rest.len() >= 8 {
        let word = |at: usize| u32::from_le_bytes([rest[at], rest[at + 1], rest[at + 2], rest[at + 3]]);
        let (length, kind) = (word(0) as usize, word(4));
        let Some(after) = rest.get(8..).and_then(|r| r.get(length..)) else {
            return Err(format!(
                "is a binary glTF (GLB) with a chunk of {length} bytes that runs past the file's end"
            ));
        };
        binary_chunks += usize::from(kind == BIN);
        if binary_chunks > 1 {
            return Err(
                "is a binary glTF (GLB) with two binary (BIN) chunks; it may have one (glTF 2.0, §4.4.3.3)"
                    .into(),
            );
        }
        rest = after;
    }
    Ok(())
}

/// The glTF extensions Gnomon reads; every other one is ignored (used) or refused
/// (required).
const SUPPORTED_EXTENSIONS: &[&str] = &["KHR_lights_punctual"];

/// Warnings for the extensions `document` uses that Gnomon ignores, or an error for
/// one it requires that Gnomon cannot read (Draco is refused earlier, by name).
fn extensions(document: &gltf::Document) -> Result<Vec<String>, String> {
    let unsupported = |name: &&str| !SUPPORTED_EXTENSIONS.contains(name);
    let required: Vec<&str> = document.extensions_required().filter(unsupported).collect();
    if !required.is_empty() {
        return Err(format!(
            "requires the glTF extension(s) {}, which Gnomon cannot read (it reads {})",
            required.join(", "),
            SUPPORTED_EXTENSIONS.join(", ")
        ));
    }
    let ignored: Vec<&str> = document.extensions_used().filter(unsupported).collect();
    Ok(if ignored.is_empty() {
        Vec::new()
    } else {
        vec![format!("ignores the glTF extension(s) {}: drawn as if they were absent", ignored.join(", "))]
    })
}

/// Reads the positions of an unvalidated file and reports the first NaN or infinity.
fn non_finite_positions(path: &Path, bytes: &[u8], scope: UriScope) -> Option<String> {
    std::panic::catch_unwind(|| {
        let raw = gltf::Gltf::from_slice_without_validation(bytes).ok()?;
        // The reader unwraps the accessors' and views' indices: read only a file whose
        // indices are in range (the crate would panic, caught but printed).
        let json = raw.document.as_json();
        let views_in_range = json.buffer_views.iter().all(|v| v.buffer.value() < json.buffers.len());
        let accessors_in_range = json
            .accessors
            .iter()
            .all(|a| a.sparse.is_none() && a.buffer_view.is_none_or(|v| v.value() < json.buffer_views.len()));
        let positions_in_range = json
            .meshes
            .iter()
            .flat_map(|m| &m.primitives)
            .all(|p| p.attributes.values().all(|a| a.value() < json.accessors.len()));
        if !(views_in_range && accessors_in_range && positions_in_range && positions_readable(json)) {
            return None;
        }
        // Strides and sizes as the validated path checks them: the reader asserts on a
        // stride shorter than its element (found by fuzzing, the hour-long run).
        let mut budget = sources::Budget::default();
        accessors_fit(&raw.document, &mut budget).ok()?;
        let base = path.parent().unwrap_or(Path::new("."));
        let buffers = sources::buffers(&raw.document, base, raw.blob.clone(), scope, &mut budget).ok()?;
        for mesh in raw.document.meshes() {
            for (k, prim) in mesh.primitives().enumerate() {
                let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
                if let Some(p) = reader.read_positions()?.find(|p| !p.iter().all(|c| c.is_finite())) {
                    return Some(format!(
                        "mesh {} primitive {k} has a non-finite vertex position {p:?} (NaN or infinite)",
                        mesh.index()
                    ));
                }
            }
        }
        None
    })
    .ok()
    .flatten()
}

fn describe(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Validation(errors) => {
            let list: Vec<String> =
                errors.iter().take(5).map(|(path, err)| format!("{path}: {err}")).collect();
            format!("invalid glTF: {}", list.join("; "))
        }
        gltf::Error::Io(io) => format!("cannot read a file it refers to: {io}"),
        other => other.to_string(),
    }
}
