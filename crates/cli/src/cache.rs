//! The reference cache: a ray-traced reference is stored under a hash of everything it
//! depends on (scene geometry, camera, light, image size, samples), so `compare` runs
//! after the first reuse it. Location: `$GNOMON_CACHE_DIR`, else
//! `$XDG_CACHE_HOME/gnomon`, else `~/.cache/gnomon`.

use std::path::{Path, PathBuf};

use glam::Vec3;
use gnomon_reference::{ReferenceImage, ReferenceOptions};
use gnomon_scene::{Camera, Light, Scene};

const MAGIC: &[u8; 8] = b"GNOMREF1";
/// Part of every key: bump it whenever the tracer's results change, so that caches
/// written by an older tracer are not served. 2: hit points from the barycentrics and
/// the t error bound (false self-shadowing on large, distant triangles). 3: each
/// pixel says whether its surface faces the light.
const TRACER_REVISION: u32 = 3;

pub fn cache_dir() -> Option<PathBuf> {
    if let Some(d) = std::env::var_os("GNOMON_CACHE_DIR") {
        return Some(PathBuf::from(d));
    }
    if let Some(d) = std::env::var_os("XDG_CACHE_HOME") {
        return Some(PathBuf::from(d).join("gnomon"));
    }
    std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache").join("gnomon"))
}

/// A stable key for a reference: xxh3 over the scene's geometry and every parameter.
pub fn key(scene: &Scene, camera: &Camera, light: &Light, options: &ReferenceOptions) -> String {
    let mut h = xxhash_rust::xxh3::Xxh3::new();
    h.update(MAGIC);
    h.update(&TRACER_REVISION.to_le_bytes());
    for mesh in &scene.meshes {
        h.update(bytemuck::cast_slice(&mesh.positions.iter().map(|p| p.to_array()).collect::<Vec<_>>()));
        h.update(bytemuck::cast_slice(&mesh.indices));
    }
    for inst in &scene.instances {
        h.update(bytemuck::cast_slice(&inst.world_from_object.to_cols_array()));
        h.update(&[inst.mesh as u8, (inst.mesh >> 8) as u8, inst.casts_shadow as u8]);
    }
    // Debug formatting of f32 round-trips exactly, so it is a faithful key.
    h.update(format!("{camera:?}{light:?}{options:?}").as_bytes());
    format!("{:016x}", h.digest())
}

pub fn path_for(key: &str) -> Option<PathBuf> {
    cache_dir().map(|d| d.join(format!("reference-{key}.bin")))
}

/// Loads a cached reference of the expected size, or `None` (missing, unreadable or stale).
pub fn load(path: &Path, options: &ReferenceOptions) -> Option<ReferenceImage> {
    let bytes = std::fs::read(path).ok()?;
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
    let temp = path.with_extension(format!("tmp-{}", std::process::id()));
    std::fs::write(&temp, bytes)?;
    std::fs::rename(&temp, path)
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
}
