//! Output files: PNG, OpenEXR and `.npy` encoders, and staging so that a failed run
//! leaves no partial file behind (everything is written to a temporary file beside
//! its destination and renamed only once every output has been encoded).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use glam::Vec3;
use gnomon_math::{LightProjection, ProjectionKind, linearize_perspective_depth};
use gnomon_render::ShadowMapImage;

/// Fails unless `path` has one of `extensions`, its directory exists and takes new
/// files, and `path` is absent, a regular file or a link (which is replaced).
pub fn check_file(path: &Path, extensions: &[&str], flag: &str) -> anyhow::Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !ext.as_deref().is_some_and(|e| extensions.contains(&e)) {
        bail!(
            "{flag} {}: the file name must end in {}",
            path.display(),
            extensions.iter().map(|e| format!(".{e}")).collect::<Vec<_>>().join(" or ")
        );
    }
    check_destination(path, flag)?;
    let dir = parent_dir(path);
    if !dir.is_dir() {
        bail!(
            "{flag} {}: cannot write there, the directory {} does not exist",
            path.display(),
            dir.display()
        );
    }
    probe_writable(dir)
        .with_context(|| format!("{flag} {}: cannot write in {}", path.display(), dir.display()))
}

/// Creates and removes a file in `dir`, as staging will: a directory that exists but
/// takes no files (read-only, or a pseudo file system such as /proc) is found before
/// the work, not when the outputs are moved into place at its end.
fn probe_writable(dir: &Path) -> std::io::Result<()> {
    // Dropping the temporary file removes it.
    tempfile::Builder::new().prefix(".gnomon-probe-").tempfile_in(dir).map(drop)
}

/// The longest file name most file systems take (ext4, XFS, APFS, NTFS: 255 bytes).
const NAME_MAX_BYTES: usize = 255;
/// A staging file's name around its destination's: `.NAME.` + random + this suffix.
const STAGING_SUFFIX: &str = ".gnomon-tmp";
/// How many random characters a staging name holds: 62⁸ names, so one cannot be
/// guessed and planted in a shared folder before the run creates it.
const STAGING_RANDOM: usize = 8;

/// The staging file's prefix for a destination named `name`.
fn staging_prefix(name: &str) -> String {
    format!(".{name}.")
}

/// A new, empty file beside `path` to encode it into: created exclusively (`O_EXCL`,
/// so a link or file planted at its name is never opened) under a name no one can
/// predict, and registered for removal on an interrupt from the moment it exists
/// (until [`forget_temporary`]).
pub fn create_staging(path: &Path) -> std::io::Result<(std::fs::File, PathBuf)> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let prefix = staging_prefix(&name);
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(STAGING_SUFFIX).rand_bytes(STAGING_RANDOM);
    #[cfg(unix)]
    {
        // An output is as readable as any file the user makes (the umask applies);
        // tempfile's default, 0600, would hide images from the user's group.
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    // Holding the lock while the file is made keeps an interrupt from missing it.
    let mut live = LIVE_TEMPS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let (file, temp) = builder.tempfile_in(parent_dir(path))?.keep().map_err(|e| e.error)?;
    live.push(temp.clone());
    Ok((file, temp))
}

/// The checks on one output file that need no folder to exist yet (so they serve the
/// files inside an `--aov-out` folder too): no trailing `/`, a name short enough for
/// its staging name, and nothing but a regular file or a link already there.
pub fn check_destination(path: &Path, flag: &str) -> anyhow::Result<()> {
    if path.as_os_str().as_encoded_bytes().ends_with(b"/") {
        bail!("{flag} {}: ends in `/`, which names a folder; give a file name", path.display());
    }
    let name = path.file_name().map(|n| n.len()).unwrap_or_default();
    let staged = staging_prefix("").len() + name + STAGING_RANDOM + STAGING_SUFFIX.len();
    if staged > NAME_MAX_BYTES {
        bail!(
            "{flag} {}: its file name is {name} bytes; at most {} fit, since it is first written under \
             a staging name {} bytes longer (file names take at most {NAME_MAX_BYTES} bytes)",
            path.display(),
            NAME_MAX_BYTES - (staged - name),
            staged - name
        );
    }
    if path.is_dir() {
        bail!("{flag} {}: is a directory, expected a file name", path.display());
    }
    if let Some(kind) = not_a_regular_file(path) {
        bail!("{flag} {}: exists and is {kind}; outputs replace regular files only", path.display());
    }
    Ok(())
}

/// What is at `path` when it is neither absent, nor a regular file, nor a link (a
/// device, a FIFO, a directory, a socket): a rename over it would replace a device
/// node with a file. A link is replaced by the output, never written through, so a
/// link is fine whatever it points at.
fn not_a_regular_file(path: &Path) -> Option<&'static str> {
    let metadata = std::fs::symlink_metadata(path).ok()?;
    let fine = metadata.is_file() || metadata.file_type().is_symlink();
    (!fine).then(|| gnomon_scene::gltf_loader::sources::file_kind(&metadata))
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
    fn temp_for(&mut self, path: &Path) -> anyhow::Result<std::fs::File> {
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
        let (file, temp) =
            create_staging(path).with_context(|| format!("cannot write {}", path.display()))?;
        self.files.push((temp, path.to_path_buf()));
        Ok(file)
    }

    /// Encodes one output into its staging file, through the open handle: the file
    /// is never opened again by name, so nothing swapped in at that name is written.
    fn write_with(
        &mut self,
        path: &Path,
        write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        let file = self.temp_for(path)?;
        let mut writer = std::io::BufWriter::new(file);
        write(&mut writer)
            .and_then(|()| Ok(std::io::Write::flush(&mut writer)?))
            .with_context(|| format!("cannot write {}", path.display()))
    }

    fn png(
        &mut self,
        path: &Path,
        width: u32,
        height: u32,
        bytes: &[u8],
        color: image::ExtendedColorType,
    ) -> anyhow::Result<()> {
        self.write_with(path, |out| {
            image::write_buffer_with_format(out, bytes, width, height, color, image::ImageFormat::Png)?;
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
        self.write_with(path, |out| {
            if npy {
                write_npy(out, &[height as usize, width as usize], values)
            } else {
                write_exr_y(out, width, height, values)
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
        self.write_with(path, |out| write_npy(out, &[height as usize, width as usize, 3], &flat))
    }

    pub fn exr_rgb(&mut self, path: &Path, width: u32, height: u32, values: &[Vec3]) -> anyhow::Result<()> {
        self.write_with(path, |out| {
            use exr::prelude::*;
            let w = width as usize;
            let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
                let v = values[p.y() * w + p.x()];
                (v.x, v.y, v.z)
            });
            Image::from_channels((w, height as usize), channels).write().to_buffered(out)?;
            Ok(())
        })
    }

    pub fn text(&mut self, path: &Path, text: &str) -> anyhow::Result<()> {
        self.write_with(path, |out| Ok(std::io::Write::write_all(out, text.as_bytes())?))
    }

    /// Moves every staged file into place and returns the destinations. All or
    /// nothing: a file already at a destination is set aside first and put back if
    /// any later move fails, so a failed commit leaves every earlier file as it was.
    pub fn commit(mut self) -> anyhow::Result<Vec<PathBuf>> {
        let files = std::mem::take(&mut self.files);
        let mut moved: Vec<(&Path, Option<PathBuf>)> = Vec::new();
        let mut failure = None;
        for (temp, dest) in &files {
            // `symlink_metadata`: a link at the destination (even a dangling one) is
            // set aside and replaced like a file; `rename` never follows it.
            let backup = std::fs::symlink_metadata(dest).is_ok().then(|| temp.with_extension("old"));
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
fn write_exr_y(out: &mut impl WriteSeek, width: u32, height: u32, values: &[f32]) -> anyhow::Result<()> {
    use exr::prelude::*;
    let w = width as usize;
    let channels = SpecificChannels::build()
        .with_channel("Y")
        .with_pixel_fn(|p: Vec2<usize>| (values[p.y() * w + p.x()],));
    Image::from_channels((w, height as usize), channels).write().to_buffered(out)?;
    Ok(())
}

/// A NumPy `.npy` file (format version 1.0): little-endian float32, C order, of
/// `shape` (height, width, and channels where there are several).
fn write_npy(out: &mut impl std::io::Write, shape: &[usize], values: &[f32]) -> anyhow::Result<()> {
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
    out.write_all(&bytes)?;
    Ok(())
}

/// What the OpenEXR encoder writes into: it seeks back to fill in its offset tables.
pub trait WriteSeek: std::io::Write + std::io::Seek {}
impl<T: std::io::Write + std::io::Seek> WriteSeek for T {}

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
        write_npy(
            &mut std::fs::File::create(&path).unwrap(),
            &[2, 3],
            &[0.0, 0.5, 1.0, f32::NAN, 0.25, 0.75],
        )
        .unwrap();
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

    /// A special file (here a FIFO named like a PNG; a device node is refused the same
    /// way) is not replaced by the output: refused before anything is written, by the
    /// flag and in staging. A link to a device is replaced, never written through.
    #[cfg(unix)]
    #[test]
    fn a_special_file_is_not_an_output() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("x.png");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let e = check_file(&fifo, &["png"], "--out").unwrap_err().to_string();
        assert!(e.contains("--out") && e.contains("a FIFO"), "{e}");
        let mut staged = Staged::default();
        let e = staged.text(&fifo, "text").unwrap_err().to_string();
        assert!(e.contains("a FIFO"), "{e}");
        let link = dir.path().join("null.txt");
        std::os::unix::fs::symlink("/dev/null", &link).unwrap();
        let mut staged = Staged::default();
        staged.text(&link, "text").unwrap();
        staged.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&link).unwrap(), "text", "the link became the output");
    }

    #[test]
    fn names_that_cannot_be_staged_are_refused_before_the_work() {
        let e = check_file(Path::new("x.png/"), &["png"], "--out").unwrap_err().to_string();
        assert!(e.contains("ends in `/`"), "{e}");
        let long = format!("{}.png", "a".repeat(240));
        let e = check_file(Path::new(&long), &["png"], "--out").unwrap_err().to_string();
        assert!(e.contains("244 bytes") && e.contains("at most 234"), "{e}");
        assert!(check_file(Path::new(&format!("{}.png", "a".repeat(230))), &["png"], "--out").is_ok());
    }

    /// A link planted where the staging file would go, under the name an earlier
    /// Gnomon chose (`.NAME.gnomon-PID.tmp`), is neither followed nor left behind as
    /// the output: the victim it points at keeps its bytes.
    #[cfg(unix)]
    #[test]
    fn a_link_planted_at_a_staging_name_is_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, "secret").unwrap();
        let planted = dir.path().join(format!(".out.txt.gnomon-{}.tmp", std::process::id()));
        std::os::unix::fs::symlink(&victim, &planted).unwrap();
        let out = dir.path().join("out.txt");
        let mut staged = Staged::default();
        staged.text(&out, "output").unwrap();
        staged.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "secret", "the victim is untouched");
        let kind = std::fs::symlink_metadata(&out).unwrap().file_type();
        assert!(kind.is_file(), "the output is a regular file, not a link: {kind:?}");
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "output");
    }

    /// A link at the destination itself is replaced by the output, not written through.
    #[cfg(unix)]
    #[test]
    fn a_link_at_the_destination_is_replaced_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, "secret").unwrap();
        let out = dir.path().join("out.txt");
        std::os::unix::fs::symlink(&victim, &out).unwrap();
        check_file(&out, &["txt"], "--out").unwrap();
        let mut staged = Staged::default();
        staged.text(&out, "output").unwrap();
        staged.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "secret");
        assert!(std::fs::symlink_metadata(&out).unwrap().file_type().is_file());
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "output");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(left.len(), 2, "no staging or backup file is left: {left:?}");
    }
}
