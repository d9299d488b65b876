//! Output files: PNG, OpenEXR and `.npy` encoders, and staging so that a failed run
//! leaves no partial file behind (everything is written to a temporary file beside
//! its destination and renamed only once every output has been encoded).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use glam::Vec3;
use gnomon_math::{LightProjection, ProjectionKind, linearize_perspective_depth};
use gnomon_render::ShadowMapImage;

/// Fails unless `path` has one of `extensions`, its directory exists and takes new
/// files, and `path` is absent or a regular file.
pub fn check_file(path: &Path, extensions: &[&str], flag: &str) -> anyhow::Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !ext.as_deref().is_some_and(|e| extensions.contains(&e)) {
        bail!(
            "{flag} {}: the file name must end in {}",
            path.display(),
            extensions.iter().map(|e| format!(".{e}")).collect::<Vec<_>>().join(" or ")
        );
    }
    let dir = parent_dir(path);
    if !dir.is_dir() {
        bail!(
            "{flag} {}: cannot write there, the directory {} does not exist",
            path.display(),
            dir.display()
        );
    }
    if path.is_dir() {
        bail!("{flag} {}: is a directory, expected a file name", path.display());
    }
    if let Some(kind) = not_a_regular_file(path) {
        bail!("{flag} {}: exists and is {kind}; outputs replace regular files only", path.display());
    }
    probe_writable(dir)
        .with_context(|| format!("{flag} {}: cannot write in {}", path.display(), dir.display()))
}

/// Creates and removes a file in `dir`, as staging will: a directory that exists but
/// takes no files (read-only, or a pseudo file system such as /proc) is found before
/// the work, not when the outputs are moved into place at its end.
fn probe_writable(dir: &Path) -> std::io::Result<()> {
    let probe = dir.join(format!(".gnomon-probe-{}", std::process::id()));
    std::fs::OpenOptions::new().write(true).create_new(true).open(&probe)?;
    std::fs::remove_file(&probe)
}

/// What is at `path` when it is neither absent nor a regular file (a device, a FIFO,
/// a directory, a socket): a rename over it would replace a device node with a file.
fn not_a_regular_file(path: &Path) -> Option<&'static str> {
    let metadata = std::fs::metadata(path).ok()?;
    (!metadata.is_file()).then(|| gnomon_scene::gltf_loader::sources::file_kind(&metadata))
}

/// Fails unless `dir` is a directory or could be created (its parent exists).
pub fn check_dir(dir: &Path, flag: &str) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("{flag} {}: exists and is not a directory", dir.display());
    }
    if !dir.exists() && !parent_dir(dir).is_dir() {
        bail!("{flag} {}: cannot create it, its parent directory does not exist", dir.display());
    }
    Ok(())
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Temporary files that exist right now (staged outputs, a cache file being
/// written): what an interrupted run must remove.
static LIVE_TEMPS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Removes every live temporary file and exits with 130 when the user presses Ctrl-C
/// or the process is sent SIGTERM: an interrupted run leaves no hidden file behind.
pub fn remove_temporaries_on_interrupt() {
    let installed = ctrlc::set_handler(|| {
        // Holding the lock until the exit keeps the main thread from staging another
        // file in between (it registers each before creating it).
        let live = LIVE_TEMPS.lock();
        for temp in live.iter().flat_map(|t| t.iter()) {
            let _ = std::fs::remove_file(temp);
        }
        eprintln!("\ngnomon: interrupted; its temporary files are removed");
        std::process::exit(130);
    });
    if let Err(e) = installed {
        eprintln!("gnomon: warning: cannot catch Ctrl-C ({e}); an interrupted run may leave temporary files");
    }
}

/// Marks `temp` as live (removed on an interrupt) until [`forget_temporary`].
pub fn track_temporary(temp: &Path) {
    if let Ok(mut live) = LIVE_TEMPS.lock() {
        live.push(temp.to_path_buf());
    }
}

/// `temp` was renamed into place or removed: an interrupt no longer touches it.
pub fn forget_temporary(temp: &Path) {
    if let Ok(mut live) = LIVE_TEMPS.lock() {
        live.retain(|t| t != temp);
    }
}

/// What a destination is called to compare it with others: its directory resolved
/// (links and `..` included) and its file name, so that `a.png` and `./d/../a.png` are
/// one file.
fn identity(path: &Path) -> PathBuf {
    let dir = parent_dir(path);
    let dir = dir.canonicalize().unwrap_or_else(|_| std::path::absolute(dir).unwrap_or(dir.to_path_buf()));
    dir.join(path.file_name().unwrap_or_default())
}

/// One output a command will write, named by the flag that asked for it.
pub struct Planned<'a> {
    /// The flag (or `--flag/name` for a file inside an output directory).
    pub flag: String,
    /// The file.
    pub path: &'a Path,
}

/// Refuses, before any work, two outputs that would write the same file: the second
/// would silently replace the first.
pub fn refuse_shared_destinations(outputs: &[Planned]) -> anyhow::Result<()> {
    for (i, a) in outputs.iter().enumerate() {
        if let Some(b) = outputs[..i].iter().find(|b| identity(b.path) == identity(a.path)) {
            bail!(
                "{} {} and {} {} are the same file: give each output its own path",
                b.flag,
                b.path.display(),
                a.flag,
                a.path.display()
            );
        }
    }
    Ok(())
}

/// Encoded files waiting to be moved into place: all of them, or none.
#[derive(Default)]
pub struct Staged {
    files: Vec<(PathBuf, PathBuf)>,
}

impl Drop for Staged {
    fn drop(&mut self) {
        for (temp, _) in &self.files {
            let _ = std::fs::remove_file(temp);
            forget_temporary(temp);
        }
    }
}

impl Staged {
    fn temp_for(&mut self, path: &Path) -> anyhow::Result<PathBuf> {
        if let Some(kind) = not_a_regular_file(path) {
            bail!("cannot write {}: it is {kind}; outputs replace regular files only", path.display());
        }
        if let Some((_, earlier)) = self.files.iter().find(|(_, dest)| identity(dest) == identity(path)) {
            bail!(
                "two outputs would write {} (and {}): give each its own path",
                path.display(),
                earlier.display()
            );
        }
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let temp = parent_dir(path).join(format!(".{name}.gnomon-{}.tmp", std::process::id()));
        track_temporary(&temp);
        self.files.push((temp.clone(), path.to_path_buf()));
        Ok(temp)
    }

    fn write_with(
        &mut self,
        path: &Path,
        write: impl FnOnce(&Path) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        let temp = self.temp_for(path)?;
        write(&temp).with_context(|| format!("cannot write {}", path.display()))
    }

    fn png(
        &mut self,
        path: &Path,
        width: u32,
        height: u32,
        bytes: &[u8],
        color: image::ExtendedColorType,
    ) -> anyhow::Result<()> {
        self.write_with(path, |temp| {
            image::save_buffer_with_format(temp, bytes, width, height, color, image::ImageFormat::Png)?;
            Ok(())
        })
    }

    pub fn png_rgba(&mut self, path: &Path, width: u32, height: u32, rgba: &[u8]) -> anyhow::Result<()> {
        self.png(path, width, height, rgba, image::ExtendedColorType::Rgba8)
    }

    pub fn png_gray16(&mut self, path: &Path, width: u32, height: u32, gray: &[u16]) -> anyhow::Result<()> {
        // `image` takes 16-bit samples in native byte order and writes PNG's big-endian.
        self.png(path, width, height, bytemuck::cast_slice(gray), image::ExtendedColorType::L16)
    }

    /// One float channel, by the path's extension: `.exr` (channel `Y`) or `.npy`.
    pub fn float_image(
        &mut self,
        path: &Path,
        width: u32,
        height: u32,
        values: &[f32],
    ) -> anyhow::Result<()> {
        let npy = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("npy"));
        self.write_with(path, |temp| {
            if npy {
                write_npy(temp, &[height as usize, width as usize], values)
            } else {
                write_exr_y(temp, width, height, values)
            }
        })
    }

    /// Three float channels, by the path's extension: `.exr` (channels `R`, `G`, `B`)
    /// or `.npy` (shape height × width × 3).
    pub fn vec3_image(
        &mut self,
        path: &Path,
        width: u32,
        height: u32,
        values: &[Vec3],
    ) -> anyhow::Result<()> {
        let npy = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("npy"));
        if !npy {
            return self.exr_rgb(path, width, height, values);
        }
        let flat: Vec<f32> = values.iter().flat_map(|v| v.to_array()).collect();
        self.write_with(path, |temp| write_npy(temp, &[height as usize, width as usize, 3], &flat))
    }

    pub fn exr_rgb(&mut self, path: &Path, width: u32, height: u32, values: &[Vec3]) -> anyhow::Result<()> {
        self.write_with(path, |temp| {
            let w = width as usize;
            exr::prelude::write_rgb_file(temp, w, height as usize, |x, y| {
                let v = values[y * w + x];
                (v.x, v.y, v.z)
            })?;
            Ok(())
        })
    }

    pub fn text(&mut self, path: &Path, text: &str) -> anyhow::Result<()> {
        self.write_with(path, |temp| Ok(std::fs::write(temp, text)?))
    }

    /// Moves every staged file into place and returns the destinations. All or
    /// nothing: a file already at a destination is set aside first and put back if
    /// any later move fails, so a failed commit leaves every earlier file as it was.
    pub fn commit(mut self) -> anyhow::Result<Vec<PathBuf>> {
        let files = std::mem::take(&mut self.files);
        let mut moved: Vec<(&Path, Option<PathBuf>)> = Vec::new();
        let mut failure = None;
        for (temp, dest) in &files {
            let backup = dest.exists().then(|| temp.with_extension("old"));
            let result = match &backup {
                Some(b) => std::fs::rename(dest, b).and_then(|()| {
                    std::fs::rename(temp, dest).inspect_err(|_| {
                        let _ = std::fs::rename(b, dest);
                    })
                }),
                None => std::fs::rename(temp, dest),
            };
            if let Err(e) = result {
                failure = Some(anyhow::Error::new(e).context(format!("cannot write {}", dest.display())));
                break;
            }
            moved.push((dest, backup));
        }
        for (temp, _) in &files {
            let _ = std::fs::remove_file(temp);
            forget_temporary(temp);
        }
        if let Some(e) = failure {
            for (dest, backup) in moved.into_iter().rev() {
                let _ = match backup {
                    Some(b) => std::fs::rename(b, dest),
                    None => std::fs::remove_file(dest),
                };
            }
            return Err(e);
        }
        for (_, backup) in &moved {
            if let Some(b) = backup {
                let _ = std::fs::remove_file(b);
            }
        }
        Ok(files.into_iter().map(|(_, dest)| dest).collect())
    }
}

/// A single-channel float32 OpenEXR file with channel `Y`.
fn write_exr_y(path: &Path, width: u32, height: u32, values: &[f32]) -> anyhow::Result<()> {
    use exr::prelude::*;
    let w = width as usize;
    let channels = SpecificChannels::build()
        .with_channel("Y")
        .with_pixel_fn(|p: Vec2<usize>| (values[p.y() * w + p.x()],));
    Image::from_channels((w, height as usize), channels).write().to_file(path)?;
    Ok(())
}

/// A NumPy `.npy` file (format version 1.0): little-endian float32, C order, of
/// `shape` (height, width, and channels where there are several).
fn write_npy(path: &Path, shape: &[usize], values: &[f32]) -> anyhow::Result<()> {
    let dims: Vec<String> = shape.iter().map(usize::to_string).collect();
    let mut header = format!(
        "{{'descr': '<f4', 'fortran_order': False, 'shape': ({}), }}",
        dims.join(", ") + if shape.len() == 1 { "," } else { "" }
    );
    // Magic (6) + version (2) + header length (2) + header + '\n' must be a multiple of 64.
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat(unpadded.next_multiple_of(64) - unpadded));
    header.push('\n');
    let mut bytes = Vec::with_capacity(10 + header.len() + 4 * values.len());
    bytes.extend_from_slice(b"\x93NUMPY\x01\x00");
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, bytes)?;
    Ok(())
}

/// Visibility as RGBA8 gray (V = 1 white), with background (NaN) dark blue-grey.
pub fn visibility_rgba(visibility: &[f32]) -> Vec<u8> {
    visibility
        .iter()
        .flat_map(|&v| {
            if v.is_nan() {
                let [r, g, b] = gnomon_reference::heatmap::BACKGROUND;
                [r, g, b, 255]
            } else {
                let g = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
                [g, g, g, 255]
            }
        })
        .collect()
}

/// The shadow map as 16-bit gray: depth linearized for perspective maps (a point
/// light's cube, `stores_distance`, holds linear distance already), then stretched
/// over the range the casters cover. Empty texels (depth 1) are white.
pub fn shadow_map_to_gray16(
    map: &ShadowMapImage,
    projection: &LightProjection,
    stores_distance: bool,
) -> Vec<u16> {
    let linear = |d: f32| match projection.kind {
        _ if stores_distance => d,
        ProjectionKind::Perspective { .. } => {
            let z = linearize_perspective_depth(d, projection.near, projection.far);
            (z - projection.near) / (projection.far - projection.near)
        }
        // Warped depth is monotonic along each ray, which is all a picture needs.
        ProjectionKind::Orthographic { .. } | ProjectionKind::Warped { .. } => d,
    };
    // The first layer: the nearest cascade, or a cube's +x face.
    let depth = map.layer(0);
    let covered = depth.iter().copied().filter(|&d| d < 1.0).map(linear);
    let (lo, hi) = covered.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), d| (lo.min(d), hi.max(d)));
    let span = if hi > lo { hi - lo } else { 1.0 };
    depth
        .iter()
        .map(|&d| {
            if d >= 1.0 {
                u16::MAX
            } else {
                (((linear(d) - lo) / span).clamp(0.0, 1.0) * 65535.0).round() as u16
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_header_is_aligned_and_data_follows() {
        let dir = std::env::temp_dir().join(format!("gnomon-npy-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("v.npy");
        write_npy(&path, &[2, 3], &[0.0, 0.5, 1.0, f32::NAN, 0.25, 0.75]).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
        assert!(header.contains("'shape': (2, 3)") && header.contains("'<f4'"), "{header}");
        let data = &bytes[10 + header_len..];
        assert_eq!(data.len(), 24);
        assert_eq!(f32::from_le_bytes(data[4..8].try_into().unwrap()), 0.5);
        assert!(f32::from_le_bytes(data[12..16].try_into().unwrap()).is_nan());
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn file_checks_name_the_flag_and_the_problem() {
        let e = check_file(Path::new("out.jpg"), &["png"], "--out").unwrap_err().to_string();
        assert!(e.contains("--out") && e.contains(".png"), "{e}");
        let e = check_file(Path::new("/no/such/dir/out.png"), &["png"], "--out").unwrap_err().to_string();
        assert!(e.contains("does not exist"), "{e}");
        assert!(check_file(Path::new("out.png"), &["png"], "--out").is_ok());
    }

    /// A device node (here a link to /dev/null named like a PNG) is not replaced by
    /// the output: refused before anything is written, by the flag and in staging.
    #[cfg(unix)]
    #[test]
    fn a_device_is_not_an_output() {
        let dir = tempfile::tempdir().unwrap();
        let device = dir.path().join("x.png");
        std::os::unix::fs::symlink("/dev/null", &device).unwrap();
        let e = check_file(&device, &["png"], "--out").unwrap_err().to_string();
        assert!(e.contains("--out") && e.contains("a character device"), "{e}");
        let mut staged = Staged::default();
        let e = staged.text(&device, "text").unwrap_err().to_string();
        assert!(e.contains("a character device"), "{e}");
        assert!(std::fs::symlink_metadata(&device).unwrap().file_type().is_symlink(), "left as it was");
    }
}
