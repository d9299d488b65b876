//! Where a glTF file's bytes come from, each source checked before it is read: the
//! GLB's binary chunk, data URIs, and files the model names. A model is untrusted
//! input: a few kilobytes of JSON may name an 8 GB file, a device, a FIFO, or a path
//! outside its folder (`../../etc/passwd`), and declare buffers, accessors and images
//! far larger than the file. So:
//!
//! - a URI resolves inside the model's folder (after symbolic links), unless the
//!   caller allows more ([`UriScope::Anywhere`]); data URIs and the GLB chunk are
//!   always fine;
//! - a file must be a regular file, and is read up to the length the model declares;
//! - every size is charged to one [`Budget`] before anything of that size is
//!   allocated: buffers, decoded images and the accessors the loader expands.

use std::{
    io::Read,
    path::{Path, PathBuf},
};

/// Where the files a model names may be.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UriScope {
    /// In the model's folder or below it: what an embedding that loads models from
    /// others should allow.
    #[default]
    ModelFolder,
    /// Anywhere the process may read.
    Anywhere,
    /// No file at all: only the GLB's binary chunk and `data:` URIs. For a model
    /// given as bytes, which has no folder (a file dropped on a web page).
    EmbeddedOnly,
}

/// The bytes a model (or every model of a scene file, sharing one) may make the
/// loader hold: its buffers, its decoded images, the meshes it makes and their placed
/// copies, together: the frame's budget ([`crate::memory::frame_budget`]), so that
/// what loads is what the frame can then hold.
#[derive(Debug)]
pub struct Budget {
    left: u64,
    limit: u64,
    source: String,
}

impl Default for Budget {
    fn default() -> Self {
        let budget = crate::memory::frame_budget().unwrap_or(crate::memory::FrameBudget {
            bytes: crate::memory::DEFAULT_FRAME_BUDGET,
            source: "the default".into(),
        });
        Budget { left: budget.bytes, limit: budget.bytes, source: budget.source }
    }
}

impl Budget {
    /// Charges `bytes` for `what` (`buffer 2 (`body`)`), or says why it cannot.
    pub fn take(&mut self, bytes: u64, what: &str) -> Result<(), String> {
        if bytes > self.left {
            return Err(format!(
                "{what} takes {} but a scene may take at most {} in all ({}: buffers, decoded images, \
                 meshes and their placed copies; {} left)",
                size(bytes),
                size(self.limit),
                self.source,
                size(self.left)
            ));
        }
        self.left -= bytes;
        Ok(())
    }
}

/// `bytes` in words: `8.0 GiB`, `294.0 KiB`.
pub use crate::memory::size;

/// The file a URI names, resolved against the model's folder `base` and checked:
/// inside the folder unless `scope` allows more, and a regular file.
pub fn resolve(base: &Path, uri: &str, scope: UriScope, what: &str) -> Result<PathBuf, String> {
    let decoded = percent_encoding::percent_decode_str(uri)
        .decode_utf8()
        .map_err(|_| format!("{what}: its URI `{uri}` is not UTF-8 once decoded"))?;
    if decoded.contains("://") || decoded.starts_with("file:") {
        return Err(format!(
            "{what}: its URI `{uri}` names a scheme; only relative paths and data URIs are read"
        ));
    }
    let folder_check = match scope {
        UriScope::EmbeddedOnly => {
            return Err(format!(
                "{what}: it names the file `{uri}`, but this model was given as bytes, with no folder to \
                 read it from; embed its data (a .glb, or data: URIs)"
            ));
        }
        UriScope::ModelFolder => true,
        UriScope::Anywhere => false,
    };
    let path = base.join(decoded.as_ref());
    if folder_check {
        inside_folder(base, &path, uri, what)?;
    }
    let metadata = std::fs::metadata(&path).map_err(|e| {
        let base_shown = if base.as_os_str().is_empty() { Path::new(".") } else { base };
        match e.kind() {
            std::io::ErrorKind::NotFound => {
                format!("{what}: its file `{uri}` is missing (looked in {})", base_shown.display())
            }
            _ => format!("{what}: cannot read its file `{uri}`: {e}"),
        }
    })?;
    if !metadata.is_file() {
        return Err(format!("{what}: `{uri}` is {}, not a regular file", file_kind(&metadata)));
    }
    Ok(path)
}

/// Refuses `path` unless it lies in the model's folder `base`, links resolved. The
/// answer is the same whether or not the file exists, so a model cannot probe which
/// paths outside its folder exist: the deepest part of the path that exists is
/// resolved and must lie inside, and what follows it is checked by its names alone
/// (no `..`).
fn inside_folder(base: &Path, path: &Path, uri: &str, what: &str) -> Result<(), String> {
    let folder = std::fs::canonicalize(if base.as_os_str().is_empty() { Path::new(".") } else { base })
        .map_err(|e| format!("{what}: cannot resolve the model's folder {}: {e}", base.display()))?;
    // `file_name` is never `..`, so the names popped here cannot climb; a path whose
    // last part is `..` (`missing/..`) is resolved or refused as a whole.
    let mut existing = path;
    let resolved = loop {
        match std::fs::canonicalize(existing) {
            Ok(resolved) => break Some(resolved),
            Err(_) => match (existing.parent(), existing.file_name()) {
                (Some(parent), Some(_)) => {
                    existing = if parent.as_os_str().is_empty() { Path::new(".") } else { parent }
                }
                _ => break None,
            },
        }
    };
    if resolved.is_some_and(|r| r.starts_with(&folder)) {
        return Ok(());
    }
    Err(format!(
        "{what}: `{uri}` lies outside the model's folder ({}); a model may only name files beside \
         or below it (a caller may allow more: `UriScope::Anywhere`)",
        folder.display()
    ))
}

/// What kind of file system entry `metadata` describes, for a message.
pub fn file_kind(metadata: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = metadata.file_type();
        if kind.is_fifo() {
            return "a FIFO";
        }
        if kind.is_char_device() {
            return "a character device";
        }
        if kind.is_block_device() {
            return "a block device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if metadata.is_dir() { "a directory" } else { "not a regular file" }
}

/// The first `length` bytes of the regular file at `path` (checked by [`resolve`]),
/// which must hold at least that many.
pub fn read_prefix(path: &Path, length: u64, what: &str, uri: &str) -> Result<Vec<u8>, String> {
    let (file, metadata) = crate::files::open_regular(path, crate::files::Links::Follow)
        .map_err(|e| format!("{what}: cannot read its file `{uri}`: {e}"))?;
    let on_disk = metadata.len();
    if on_disk < length {
        return Err(format!(
            "{what}: its file `{uri}` holds {} but the model declares {}",
            size(on_disk),
            size(length)
        ));
    }
    let mut bytes = Vec::with_capacity(length as usize);
    file.take(length)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("{what}: cannot read its file `{uri}`: {e}"))?;
    Ok(bytes)
}

/// The bytes of a data URI (`data:[<type>][;base64],<data>`).
pub fn data_uri(uri: &str, what: &str) -> Result<Vec<u8>, String> {
    let (header, payload) = uri
        .strip_prefix("data:")
        .and_then(|rest| rest.split_once(','))
        .ok_or_else(|| format!("{what}: its data URI has no `,` after its header"))?;
    if !header.ends_with(";base64") {
        return Ok(percent_encoding::percent_decode_str(payload).collect());
    }
    base64::decode(payload.trim())
        .map_err(|e| format!("{what}: its data URI is not valid base64: {}", base64_error(&e)))
}

fn base64_error(e: &base64::DecodeError) -> String {
    match e {
        base64::DecodeError::InvalidByte(offset, byte) => {
            format!("byte {byte} (`{}`) at offset {offset} of its data", char::from(*byte).escape_default())
        }
        base64::DecodeError::InvalidLength => "its length is not that of base64 data".into(),
        base64::DecodeError::InvalidLastSymbol(offset, byte) => {
            format!("its last symbol {byte} at offset {offset} has bits past the data's end")
        }
    }
}

/// Reads every buffer of `document`, each checked and charged to `budget` first: the
/// GLB's binary chunk `blob`, a data URI, or a file beside the model.
pub fn buffers(
    document: &gltf::Document,
    base: &Path,
    mut blob: Option<Vec<u8>>,
    scope: UriScope,
    budget: &mut Budget,
) -> Result<Vec<gltf::buffer::Data>, String> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let what = format!("buffer {}{}", buffer.index(), named(buffer.name()));
        let length = buffer.length() as u64;
        budget.take(length, &what)?;
        let mut bytes = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .take()
                .ok_or_else(|| format!("{what} is the GLB's binary chunk, which the file lacks"))?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => data_uri(uri, &what)?,
            gltf::buffer::Source::Uri(uri) => {
                read_prefix(&resolve(base, uri, scope, &what)?, length, &what, uri)?
            }
        };
        if (bytes.len() as u64) < length {
            return Err(format!("{what} holds {} but declares {}", size(bytes.len() as u64), size(length)));
        }
        // The glTF crate pads each buffer to a multiple of four, as its reader expects.
        bytes.truncate(length as usize);
        while bytes.len() % 4 != 0 {
            bytes.push(0);
        }
        buffers.push(gltf::buffer::Data(bytes));
    }
    Ok(buffers)
}

/// ` (`name`)`, or nothing for an unnamed element.
pub fn named(name: Option<&str>) -> String {
    name.map(|n| format!(" (`{n}`)")).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uri_outside_the_models_folder_is_refused_unless_allowed() {
        let dir = tempfile::tempdir().unwrap();
        let model = dir.path().join("model");
        std::fs::create_dir(&model).unwrap();
        std::fs::write(dir.path().join("secret.bin"), b"1234").unwrap();
        std::fs::write(model.join("mine.bin"), b"5678").unwrap();
        let e = resolve(&model, "../secret.bin", UriScope::ModelFolder, "buffer 0").unwrap_err();
        assert!(e.contains("outside the model's folder"), "{e}");
        assert!(resolve(&model, "../secret.bin", UriScope::Anywhere, "buffer 0").is_ok());
        assert!(resolve(&model, "mine.bin", UriScope::ModelFolder, "buffer 0").is_ok());
        let absolute = dir.path().join("secret.bin");
        let e = resolve(&model, absolute.to_str().unwrap(), UriScope::ModelFolder, "buffer 0").unwrap_err();
        assert!(e.contains("outside the model's folder"), "{e}");
        let e = resolve(&model, "file:///etc/passwd", UriScope::Anywhere, "buffer 0").unwrap_err();
        assert!(e.contains("scheme"), "{e}");
        // A model given as bytes names no file at all, even one beside it.
        let e = resolve(&model, "mine.bin", UriScope::EmbeddedOnly, "buffer 0").unwrap_err();
        assert!(e.contains("given as bytes") && e.contains("`mine.bin`"), "{e}");
        // A missing file outside gets the same answer as an existing one: a model
        // cannot probe which paths exist.
        let missing = resolve(&model, "../no-such.bin", UriScope::ModelFolder, "buffer 0").unwrap_err();
        let existing = resolve(&model, "../secret.bin", UriScope::ModelFolder, "buffer 0").unwrap_err();
        assert_eq!(missing.replace("no-such", "secret"), existing);
        let e = resolve(&model, "sub/../gone.bin", UriScope::ModelFolder, "buffer 0").unwrap_err();
        assert!(e.contains("outside"), "a path through a missing folder is judged as outside: {e}");
        let e = resolve(&model, "gone.bin", UriScope::ModelFolder, "buffer 0").unwrap_err();
        assert!(e.contains("is missing"), "a missing file inside is reported as missing: {e}");
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(dir.path().join("secret.bin"), model.join("link.bin")).unwrap();
            let e = resolve(&model, "link.bin", UriScope::ModelFolder, "buffer 0").unwrap_err();
            assert!(e.contains("outside the model's folder"), "a link out of the folder: {e}");
        }
    }

    #[test]
    fn a_directory_or_a_device_is_named_for_what_it_is() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let e = resolve(dir.path(), "sub", UriScope::ModelFolder, "image 1").unwrap_err();
        assert!(e.contains("is a directory"), "{e}");
        #[cfg(unix)]
        {
            let e = resolve(Path::new("/dev"), "null", UriScope::Anywhere, "image 1").unwrap_err();
            assert!(e.contains("a character device"), "{e}");
        }
        let e = resolve(dir.path(), "gone.png", UriScope::ModelFolder, "image 1").unwrap_err();
        assert!(e.contains("is missing"), "{e}");
    }

    #[test]
    fn a_file_shorter_than_declared_and_a_bad_data_uri_name_their_buffer() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("short.bin");
        std::fs::write(&path, b"12").unwrap();
        let e = read_prefix(&path, 8, "buffer 3", "short.bin").unwrap_err();
        assert!(e.contains("buffer 3") && e.contains("2 bytes") && e.contains("8 bytes"), "{e}");
        assert_eq!(read_prefix(&path, 1, "buffer 3", "short.bin").unwrap(), b"1");
        let e = data_uri("data:application/octet-stream;base64,!AAA", "buffer 0").unwrap_err();
        assert!(e.contains("buffer 0") && e.contains("base64") && e.contains("offset 0"), "{e}");
        assert_eq!(data_uri("data:application/octet-stream;base64,AQID", "buffer 0").unwrap(), [1, 2, 3]);
    }

    #[test]
    fn the_budget_refuses_what_it_cannot_hold_and_says_how_much() {
        let mut budget = Budget::default();
        budget.take(budget.limit / 2, "buffer 0").unwrap();
        let e = budget.take(budget.limit, "image 4").unwrap_err();
        let at_most = format!("at most {}", size(budget.limit));
        assert!(e.contains("image 4") && e.contains(&at_most) && e.contains("left"), "{e}");
    }
}
