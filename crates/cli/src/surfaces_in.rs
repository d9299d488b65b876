//! Reading a frame's drawn surfaces back in, for `gnomon reference --surfaces`: the
//! `position.npy` and `geometric_normal.npy` of an `--aov-out` folder (`gnomon render
//! --aov-format npy`), or any renderer's frame written in the same form (the browser
//! lab's, in its test). Each file is untrusted input: read as a regular file no
//! longer than its header's shape needs, its shape checked against its length before
//! anything is allocated, and every fault named with the file and what is valid.

use std::path::{Path, PathBuf};

use glam::Vec3;
use gnomon_scene::{
    files::{Links, read_regular},
    settings::MAX_IMAGE_SIDE,
};

/// The surfaces of a frame, row-major from the top: NaN where it shows none.
pub struct ReadSurfaces {
    pub width: u32,
    pub height: u32,
    pub position: Vec<Vec3>,
    pub geometric_normal: Vec<Vec3>,
}

/// Why a folder's surfaces were refused: the file and its fault.
#[derive(Debug, thiserror::Error)]
#[error("--surfaces: {}: {fault}", file.display())]
pub struct SurfacesError {
    file: PathBuf,
    fault: String,
}

/// The longest `.npy` header taken: NumPy pads its own to 64 bytes, or 128 for long
/// shapes.
const MAX_HEADER: usize = 4096;
/// What a geometric normal's length may be off unit by, for float32 rounding and a
/// renderer's own encoding of it (Gnomon's octahedral one is good to 10⁻⁴).
const UNIT_TOLERANCE: f32 = 0.01;

/// `dir`'s `position.npy` and `geometric_normal.npy`, checked against each other: the
/// same shape, a surface in both or in neither at each pixel, the normals unit.
pub fn read_surfaces(dir: &Path) -> Result<ReadSurfaces, SurfacesError> {
    let position_file = dir.join("position.npy");
    let normal_file = dir.join("geometric_normal.npy");
    let (position_shape, position) = read_vec3_npy(&position_file)?;
    let (normal_shape, geometric_normal) = read_vec3_npy(&normal_file)?;
    let fault = |file: &Path, fault: String| SurfacesError { file: file.to_owned(), fault };
    if position_shape != normal_shape {
        return Err(fault(
            &normal_file,
            format!(
                "{}×{} pixels, but position.npy beside it is {}×{}: both must come from one frame",
                normal_shape[1], normal_shape[0], position_shape[1], position_shape[0]
            ),
        ));
    }
    for (i, (p, n)) in position.iter().zip(&geometric_normal).enumerate() {
        let (x, y) = (i % position_shape[1], i / position_shape[1]);
        if p.is_finite() != n.is_finite() {
            let (which, file) =
                if p.is_finite() { ("a position", &normal_file) } else { ("a normal", &position_file) };
            return Err(fault(
                file,
                format!(
                    "pixel ({x}, {y}) is NaN (or infinite) here but has {which} in the other file: a pixel shows a surface in both or in neither"
                ),
            ));
        }
        if n.is_finite() && (n.length() - 1.0).abs() > UNIT_TOLERANCE {
            return Err(fault(
                &normal_file,
                format!(
                    "pixel ({x}, {y})'s normal has length {:.4}: each must be of unit length",
                    n.length()
                ),
            ));
        }
    }
    Ok(ReadSurfaces {
        width: position_shape[1] as u32,
        height: position_shape[0] as u32,
        position,
        geometric_normal,
    })
}

/// A little-endian float32 `.npy` of shape height × width × 3 (C order), each side
/// at most `MAX_IMAGE_SIDE`: its shape and its values as vectors.
fn read_vec3_npy(file: &Path) -> Result<([usize; 2], Vec<Vec3>), SurfacesError> {
    let fault = |fault: String| SurfacesError { file: file.to_owned(), fault };
    let side = MAX_IMAGE_SIDE as u64;
    let limit = (MAX_HEADER as u64) + side * side * 12;
    let bytes =
        read_regular(file, Links::Follow, limit, "a surfaces image").map_err(|e| fault(e.to_string()))?;
    let (shape, data) = parse_npy_f32(&bytes).map_err(fault)?;
    let [height, width, 3] = shape[..] else {
        return Err(fault(format!("shape {shape:?}: it must be height × width × 3 (world XYZ per pixel)")));
    };
    if !(1..=MAX_IMAGE_SIDE as usize).contains(&height) || !(1..=MAX_IMAGE_SIDE as usize).contains(&width) {
        return Err(fault(format!("{width}×{height} pixels: each side must be 1 to {MAX_IMAGE_SIDE}")));
    }
    let values: Vec<Vec3> = data
        .chunks_exact(12)
        .map(|c| {
            let f = |k: usize| f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
            Vec3::new(f(0), f(4), f(8))
        })
        .collect();
    Ok(([height, width], values))
}

/// The shape and the data bytes of a `.npy` (versions 1 to 3) of little-endian
/// float32 in C order, the data exactly as long as the shape says.
fn parse_npy_f32(bytes: &[u8]) -> Result<(Vec<usize>, &[u8]), String> {
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err("not a NumPy .npy file (no \\x93NUMPY magic)".into());
    }
    let (header_len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => {
            (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12)
        }
        v => return Err(format!(".npy format version {v}: versions 1 to 3 are read")),
    };
    if header_len > MAX_HEADER || start + header_len > bytes.len() {
        return Err(format!("a header of {header_len} bytes, past the file's end or over {MAX_HEADER}"));
    }
    let header =
        std::str::from_utf8(&bytes[start..start + header_len]).map_err(|_| "a header that is not text")?;
    let descr = header_value(header, "descr").ok_or("a header with no 'descr'")?;
    if descr.trim() != "'<f4'" {
        return Err(format!("elements {}: they must be little-endian float32 ('<f4')", descr.trim()));
    }
    if header_value(header, "fortran_order").is_none_or(|v| v.trim() != "False") {
        return Err("not in C order ('fortran_order' must be False)".into());
    }
    let shape_text = header_value(header, "shape").ok_or("a header with no 'shape'")?;
    let shape =
        parse_shape(shape_text).ok_or_else(|| format!("a shape it cannot read: {}", shape_text.trim()))?;
    let count = shape.iter().try_fold(1usize, |n, &d| n.checked_mul(d)).ok_or("a shape too large to hold")?;
    let data = &bytes[start + header_len..];
    if Some(data.len()) != count.checked_mul(4) {
        return Err(format!(
            "shape {shape:?} needs {count} floats, but the file holds {} bytes of data",
            data.len()
        ));
    }
    Ok((shape, data))
}

/// The text after `'key':` in a `.npy` header dictionary, up to the next key (a tuple
/// for `shape` kept whole).
fn header_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let at = header.find(&format!("'{key}':"))? + key.len() + 3;
    let rest = &header[at..];
    let end = if rest.trim_start().starts_with('(') {
        rest.find(')')? + 1
    } else {
        rest.find(',').unwrap_or(rest.len())
    };
    Some(&rest[..end])
}

/// `(h, w, 3)` as its dimensions.
fn parse_shape(text: &str) -> Option<Vec<usize>> {
    let inner = text.trim().strip_prefix('(')?.strip_suffix(')')?;
    inner.split(',').map(str::trim).filter(|d| !d.is_empty()).map(|d| d.parse().ok()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn npy(shape: &str, descr: &str, values: &[f32]) -> Vec<u8> {
        let header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}\n");
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
        bytes.extend_from_slice(header.as_bytes());
        bytes.extend(values.iter().flat_map(|v| v.to_le_bytes()));
        bytes
    }

    fn folder(position: &[u8], normal: &[u8]) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("position.npy"), position).unwrap();
        std::fs::write(dir.path().join("geometric_normal.npy"), normal).unwrap();
        dir
    }

    fn refusal(position: &[u8], normal: &[u8]) -> String {
        let dir = folder(position, normal);
        match read_surfaces(dir.path()) {
            Ok(_) => panic!("read"),
            Err(e) => e.to_string(),
        }
    }

    const UP: [f32; 6] = [0.0, 1.0, 0.0, 0.0, 1.0, 0.0];
    const POINTS: [f32; 6] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];

    #[test]
    fn a_frame_of_two_pixels_reads_back() {
        let dir = folder(&npy("(1, 2, 3)", "<f4", &POINTS), &npy("(1, 2, 3)", "<f4", &UP));
        let s = read_surfaces(dir.path()).unwrap();
        assert_eq!((s.width, s.height), (2, 1));
        assert_eq!(s.position, vec![Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0)]);
        assert_eq!(s.geometric_normal, vec![Vec3::Y; 2]);
    }

    /// Each fault is refused with the file and what is valid.
    #[test]
    fn each_fault_is_named() {
        let good = npy("(1, 2, 3)", "<f4", &UP);
        let cases = [
            (npy("(1, 2, 3)", "<f8", &POINTS), "little-endian float32"),
            (npy("(2, 3)", "<f4", &POINTS), "height × width × 3"),
            (npy("(1, 3, 3)", "<f4", &POINTS), "needs 9 floats"),
            (npy("(0, 2, 3)", "<f4", &[]), "each side must be 1 to"),
            (npy("(99999999999, 99999999999, 3)", "<f4", &POINTS), "too large"),
            (b"P6 not npy".to_vec(), "no \\x93NUMPY"),
            (npy("(2, 1, 3)", "<f4", &POINTS), "both must come from one frame"),
        ];
        for (position, expected) in cases {
            let e = refusal(&position, &good);
            assert!(e.contains("position.npy") || e.contains("geometric_normal.npy"), "{e}");
            assert!(e.contains(expected), "{expected}: {e}");
        }
        let half = npy("(1, 2, 3)", "<f4", &[1.0, 2.0, 3.0, f32::NAN, f32::NAN, f32::NAN]);
        assert!(refusal(&half, &good).contains("in both or in neither"));
        let long = npy("(1, 2, 3)", "<f4", &[0.0, 2.0, 0.0, 0.0, 1.0, 0.0]);
        assert!(refusal(&npy("(1, 2, 3)", "<f4", &POINTS), &long).contains("unit length"));
        let dir = tempfile::tempdir().unwrap();
        let e = read_surfaces(dir.path()).err().unwrap().to_string();
        assert!(e.contains("position.npy") && e.contains("no such file"), "{e}");
    }
}
