//! The reference cache: a ray-traced reference is stored under a hash of everything it
//! depends on (scene geometry, camera, light, image size, samples), so `compare` runs
//! after the first reuse it. Location: `$GNOMON_CACHE_DIR`, else
//! `$XDG_CACHE_HOME/gnomon`, else `~/.cache/gnomon`. The cache holds at most
//! `$GNOMON_CACHE_MAX_MIB` MiB (2048 by default): storing a reference removes the
//! least recently used ones past that. `gnomon cache` lists and clears it.

use std::path::{Path, PathBuf};

use glam::Vec3;
use gnomon_reference::{ReferenceImage, ReferenceOptions};
use gnomon_scene::{Camera, Light, Scene, Texture};

const MAGIC: &[u8; 8] = b"GNOMREF1";
/// Part of every key: bump it whenever the tracer's results change, so that caches
/// written by an older tracer are not served. 2: hit points from the barycentrics and
/// the t error bound (false self-shadowing on large, distant triangles). 3: each
/// pixel says whether its surface faces the light. 4: camera rays through the f32
/// camera matrix inverted in f64 (the f32 inverse bent them by up to 1/25 px).
const TRACER_REVISION: u32 = 4;

pub fn cache_dir() -> Option<PathBuf> {
    if let Some(d) = std::env::var_os("GNOMON_CACHE_DIR") {
        return Some(PathBuf::from(d));
    }
    if let Some(d) = std::env::var_os("XDG_CACHE_HOME") {
        return Some(PathBuf::from(d).join("gnomon"));
    }
    std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache").join("gnomon"))
}

/// A stable key for a reference: xxh3 over everything that changes its answer: the
/// scene's geometry (positions, normals, texture coordinates, indices), its materials
/// and textures (alpha masks cut holes in casters), its instances and ground, and the
/// camera, light and options.
pub fn key(scene: &Scene, camera: &Camera, light: &Light, options: &ReferenceOptions) -> String {
    let mut h = xxhash_rust::xxh3::Xxh3::new();
    h.update(MAGIC);
    h.update(&TRACER_REVISION.to_le_bytes());
    let count = |h: &mut xxhash_rust::xxh3::Xxh3, n: usize| h.update(&(n as u64).to_le_bytes());
    for mesh in &scene.meshes {
        // Each array's length first, so that bytes moved from one to the next differ.
        count(&mut h, mesh.positions.len());
        mesh.positions.iter().for_each(|p| h.update(bytemuck::cast_slice(&p.to_array())));
        count(&mut h, mesh.normals.len());
        mesh.normals.iter().for_each(|n| h.update(bytemuck::cast_slice(&n.to_array())));
        count(&mut h, mesh.uvs.len());
        mesh.uvs.iter().for_each(|uv| h.update(bytemuck::cast_slice(&uv.to_array())));
        count(&mut h, mesh.indices.len());
        h.update(bytemuck::cast_slice(&mesh.indices));
    }
    for texture in &scene.textures {
        let Texture { name: _, width, height, rgba8, wrap_u, wrap_v, nearest } = texture;
        h.update(format!("{width}x{height} {wrap_u:?} {wrap_v:?} {nearest}").as_bytes());
        count(&mut h, rgba8.len());
        h.update(rgba8);
    }
    // Debug formatting of f32 round-trips exactly, so it is a faithful key; a
    // material's name is part of it, harmlessly.
    h.update(format!("{:?}", scene.materials).as_bytes());
    for inst in &scene.instances {
        h.update(bytemuck::cast_slice(&inst.world_from_object.to_cols_array()));
        count(&mut h, inst.mesh);
        count(&mut h, inst.material);
        h.update(&[u8::from(inst.casts_shadow)]);
    }
    h.update(format!("{camera:?}{light:?}{options:?} ground {}", scene.has_ground).as_bytes());
    format!("{:016x}", h.digest())
}

pub fn path_for(key: &str) -> Option<PathBuf> {
    cache_dir().map(|d| d.join(format!("reference-{key}.bin")))
}

/// The cache's size limit when `$GNOMON_CACHE_MAX_MIB` does not set one: a 4K
/// reference takes 265 MB, so this keeps the last seven or so.
const DEFAULT_MAX_MIB: u64 = 2048;

/// The cache's size limit in bytes: `$GNOMON_CACHE_MAX_MIB`, else [`DEFAULT_MAX_MIB`].
fn max_bytes() -> anyhow::Result<u64> {
    let mib = match std::env::var("GNOMON_CACHE_MAX_MIB") {
        Ok(text) => text.trim().parse::<u64>().ok().filter(|&m| m <= 1 << 30).ok_or_else(|| {
            anyhow::anyhow!(
                "GNOMON_CACHE_MAX_MIB = `{text}` is invalid: a whole number of MiB, 0 to {}",
                1u64 << 30
            )
        })?,
        Err(_) => DEFAULT_MAX_MIB,
    };
    Ok(mib << 20)
}

/// One cached reference: its file, size and when it was last used.
pub struct Entry {
    pub path: PathBuf,
    pub bytes: u64,
    pub last_used: std::time::SystemTime,
}

/// Every cached reference in `dir`, least recently used first.
pub fn entries(dir: &Path) -> Vec<Entry> {
    let Ok(read) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut found: Vec<Entry> = read
        .filter_map(|e| e.ok())
        .filter(|e| {
            e.file_name().to_str().is_some_and(|n| n.starts_with("reference-") && n.ends_with(".bin"))
        })
        .filter_map(|e| {
            let meta = e.metadata().ok()?;
            Some(Entry { path: e.path(), bytes: meta.len(), last_used: meta.modified().ok()? })
        })
        .collect();
    found.sort_by_key(|e| e.last_used);
    found
}

/// Removes the least recently used references of `dir` until it holds at most
/// `max_bytes`, keeping `keep` (the one just stored) whatever its size.
fn trim(dir: &Path, max_bytes: u64, keep: &Path) {
    let all = entries(dir);
    let mut total: u64 = all.iter().map(|e| e.bytes).sum();
    for e in all.iter().filter(|e| e.path != keep) {
        if total <= max_bytes {
            break;
        }
        if std::fs::remove_file(&e.path).is_ok() {
            total -= e.bytes;
        }
    }
}

/// The size of a cached reference of `options`' image: its header and, per pixel,
/// visibility, error, id, triangle and depth (4 bytes each), position (12) and the
/// faces-light flag (1).
fn entry_bytes(options: &ReferenceOptions) -> u64 {
    let pixels = u64::from(options.width) * u64::from(options.height);
    (MAGIC.len() + 3 * 4 + 8) as u64 + pixels * (5 * 4 + 12 + 1)
}

/// Loads a cached reference of the expected size, or `None` (missing, unreadable or stale).
/// Only a regular file the user owns, of exactly the size the image needs, is read: a
/// link, a FIFO or a file someone else put in the cache is a miss.
/// A hit marks the file as used, for the least-recently-used trim.
pub fn load(path: &Path, options: &ReferenceOptions) -> Option<ReferenceImage> {
    use gnomon_scene::files::{Links, open_regular};
    let (file, metadata) = open_regular(path, Links::Refuse).ok()?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        // SAFETY: geteuid has no preconditions and cannot fail.
        if metadata.uid() != unsafe { libc::geteuid() } {
            return None;
        }
    }
    let expected = entry_bytes(options);
    if metadata.len() != expected {
        return None;
    }
    let mut bytes = Vec::with_capacity(expected as usize);
    std::io::Read::read_to_end(&mut std::io::Read::take(&file, expected), &mut bytes).ok()?;
    let _ = file.set_modified(std::time::SystemTime::now());
    let mut r = Reader { bytes: &bytes, at: 0 };
    if r.take(8)? != MAGIC {
        return None;
    }
    let (width, height, samples) = (r.u32()?, r.u32()?, r.u32()?);
    let rays = r.u64()?;
    if (width, height) != (options.width, options.height) {
        return None;
    }
    let n = (width * height) as usize;
    let image = ReferenceImage {
        width,
        height,
        samples,
        visibility: r.f32s(n)?,
        faces_light: r.take(n)?.iter().map(|&b| b != 0).collect(),
        std_error: r.f32s(n)?,
        object_id: r.u32s(n)?,
        triangle: r.u32s(n)?,
        depth: r.f32s(n)?,
        position: r.f32s(3 * n)?.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect(),
        rays,
    };
    (r.at == bytes.len()).then_some(image)
}

/// Stores `image` (to a temporary file, then renamed, so readers never see half a file).
pub fn store(path: &Path, image: &ReferenceImage) -> std::io::Result<()> {
    let mut bytes = Vec::new();
    bytes.extend_from_slice(MAGIC);
    for v in [image.width, image.height, image.samples] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.extend_from_slice(&image.rays.to_le_bytes());
    let floats = |b: &mut Vec<u8>, v: &[f32]| v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
    let ints = |b: &mut Vec<u8>, v: &[u32]| v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
    floats(&mut bytes, &image.visibility);
    bytes.extend(image.faces_light.iter().map(|&b| u8::from(b)));
    floats(&mut bytes, &image.std_error);
    ints(&mut bytes, &image.object_id);
    ints(&mut bytes, &image.triangle);
    floats(&mut bytes, &image.depth);
    floats(&mut bytes, &image.position.iter().flat_map(|p| p.to_array()).collect::<Vec<_>>());
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    // Created exclusively under a name no one can predict, then renamed over the
    // entry (which replaces a link there rather than following it).
    let (mut file, temp) = crate::output::create_staging(path)?;
    let written = std::io::Write::write_all(&mut file, &bytes).and_then(|()| std::fs::rename(&temp, path));
    if written.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    crate::output::forget_temporary(&temp);
    written?;
    if let Some(dir) = path.parent() {
        trim(dir, max_bytes().map_err(std::io::Error::other)?, path);
    }
    Ok(())
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        let s = self.bytes.get(self.at..self.at.checked_add(n)?)?;
        self.at += n;
        Some(s)
    }
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
    fn f32s(&mut self, n: usize) -> Option<Vec<f32>> {
        Some(
            self.take(4 * n)?
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap_or([0; 4])))
                .collect(),
        )
    }
    fn u32s(&mut self, n: usize) -> Option<Vec<u32>> {
        Some(
            self.take(4 * n)?
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes(c.try_into().unwrap_or([0; 4])))
                .collect(),
        )
    }
}

/// `gnomon cache`: what the reference cache holds, or clear it.
#[derive(clap::Args, Debug)]
pub struct CacheArgs {
    /// Remove every cached reference.
    #[arg(long)]
    pub clear: bool,
}

pub fn run(args: &CacheArgs) -> anyhow::Result<()> {
    let dir = cache_dir()
        .ok_or_else(|| anyhow::anyhow!("no cache directory: set GNOMON_CACHE_DIR, XDG_CACHE_HOME or HOME"))?;
    let all = entries(&dir);
    let total: u64 = all.iter().map(|e| e.bytes).sum();
    if args.clear {
        let mut freed = 0;
        for e in &all {
            std::fs::remove_file(&e.path)
                .map_err(|err| anyhow::anyhow!("cannot remove {}: {err}", e.path.display()))?;
            freed += e.bytes;
        }
        println!(
            "removed {} references, {:.1} MiB, from {}",
            all.len(),
            freed as f64 / 1048576.0,
            dir.display()
        );
        return Ok(());
    }
    let now = std::time::SystemTime::now();
    for e in all.iter().rev() {
        let age = now.duration_since(e.last_used).unwrap_or_default().as_secs();
        println!(
            "{:>10.1} MiB  used {:>6} min ago  {}",
            e.bytes as f64 / 1048576.0,
            age / 60,
            e.path.display()
        );
    }
    println!(
        "{} references, {:.1} MiB of at most {} MiB (GNOMON_CACHE_MAX_MIB), in {}",
        all.len(),
        total as f64 / 1048576.0,
        max_bytes()? >> 20,
        dir.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn store_then_load_round_trips_and_rejects_other_sizes() {
        let image = ReferenceImage {
            width: 2,
            height: 1,
            samples: 64,
            visibility: vec![0.25, f32::NAN],
            faces_light: vec![true, false],
            std_error: vec![0.01, 0.0],
            object_id: vec![3, 0],
            triangle: vec![17, 0],
            depth: vec![4.5, f32::NAN],
            position: vec![Vec3::new(1.0, 2.0, 3.0), Vec3::NAN],
            rays: 130,
        };
        let dir = std::env::temp_dir().join(format!("gnomon-cache-{}", std::process::id()));
        let path = dir.join("r.bin");
        store(&path, &image).unwrap();
        let options = ReferenceOptions { width: 2, height: 1, samples: 64 };
        let back = load(&path, &options).unwrap();
        assert_eq!(back.visibility[0], 0.25);
        assert!(back.visibility[1].is_nan());
        assert_eq!(
            (back.object_id.clone(), back.triangle.clone(), back.rays),
            (vec![3, 0], vec![17, 0], 130)
        );
        assert_eq!(back.position[0], Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(back.faces_light, [true, false]);
        assert!(load(&path, &ReferenceOptions { width: 1, height: 2, samples: 64 }).is_none());
        std::fs::write(&path, b"GNOMREF1junk").unwrap();
        assert!(load(&path, &options).is_none(), "a truncated file is ignored");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn trimming_removes_the_least_recently_used_references_first_and_keeps_the_new_one() {
        let dir = tempfile::tempdir().unwrap();
        let day = std::time::Duration::from_secs(86_400);
        let now = std::time::SystemTime::now();
        for (name, days_ago) in [("a", 3), ("b", 1), ("c", 2), ("new", 5)] {
            let path = dir.path().join(format!("reference-{name}.bin"));
            std::fs::write(&path, vec![0u8; 1000]).unwrap();
            let file = std::fs::File::options().append(true).open(&path).unwrap();
            file.set_modified(now - day * days_ago).unwrap();
        }
        std::fs::write(dir.path().join("unrelated.txt"), vec![0u8; 5000]).unwrap();
        trim(dir.path(), 2500, &dir.path().join("reference-new.bin"));
        let left: Vec<String> = entries(dir.path())
            .iter()
            .map(|e| e.path.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(left, ["reference-new.bin", "reference-b.bin"], "a (3 days) and c (2 days) went first");
        assert!(dir.path().join("unrelated.txt").exists(), "only references are touched");
    }

    /// The audit's pair: one mesh, opaque and then cut away by an alpha mask, must not
    /// share a cached reference (the second would be served the first's shadow).
    #[test]
    fn the_key_changes_with_materials_and_textures() {
        let scene = gnomon_scene::builtin::build("spheres").unwrap();
        let light = scene.lights[0].light;
        let options = ReferenceOptions { width: 4, height: 4, samples: 1 };
        let base = key(&scene, &scene.camera, &light, &options);
        let mut masked = scene.clone();
        masked.materials[0].alpha = 0.0;
        masked.materials[0].alpha_mode = gnomon_scene::AlphaMode::Mask { cutoff: 0.5 };
        assert_ne!(key(&masked, &masked.camera, &light, &options), base, "alpha 0, MASK");
        let mut textured = scene.clone();
        textured.textures.push(Texture {
            name: "t".into(),
            width: 1,
            height: 1,
            rgba8: vec![255, 255, 255, 0],
            wrap_u: gnomon_scene::Wrap::Repeat,
            wrap_v: gnomon_scene::Wrap::Repeat,
            nearest: false,
        });
        assert_ne!(key(&textured, &textured.camera, &light, &options), base, "a texture");
        assert_eq!(key(&scene.clone(), &scene.camera, &light, &options), base, "and is stable");
    }

    fn tiny_image() -> ReferenceImage {
        ReferenceImage {
            width: 1,
            height: 1,
            samples: 4,
            visibility: vec![0.5],
            faces_light: vec![true],
            std_error: vec![0.0],
            object_id: vec![1],
            triangle: vec![2],
            depth: vec![3.0],
            position: vec![Vec3::ONE],
            rays: 4,
        }
    }

    /// A link planted at the temporary name an earlier Gnomon chose
    /// (`reference-KEY.tmp-PID`) is not written through.
    #[cfg(unix)]
    #[test]
    fn storing_does_not_follow_a_planted_link() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, "secret").unwrap();
        let path = dir.path().join("reference-k.bin");
        let planted = path.with_extension(format!("tmp-{}", std::process::id()));
        std::os::unix::fs::symlink(&victim, &planted).unwrap();
        store(&path, &tiny_image()).unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "secret", "the victim is untouched");
        assert!(std::fs::symlink_metadata(&path).unwrap().file_type().is_file());
        let options = ReferenceOptions { width: 1, height: 1, samples: 4 };
        assert_eq!(load(&path, &options).unwrap().visibility, [0.5]);
    }

    /// Only a regular file is served: a link (to a reference someone else wrote) and a
    /// FIFO (which would block the read forever) are cache misses.
    #[cfg(unix)]
    #[test]
    fn only_regular_files_are_served() {
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("elsewhere.bin");
        store(&real, &tiny_image()).unwrap();
        let options = ReferenceOptions { width: 1, height: 1, samples: 4 };
        assert!(load(&real, &options).is_some());
        let link = dir.path().join("reference-link.bin");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        assert!(load(&link, &options).is_none(), "a link is not served");
        let fifo = dir.path().join("reference-fifo.bin");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(made.success());
        assert!(load(&fifo, &options).is_none(), "a FIFO is a miss, at once");
    }
}
