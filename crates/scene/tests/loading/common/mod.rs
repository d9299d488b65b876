//! Writers for small glTF files built in the tests.
#![allow(dead_code)]

/// A fresh directory under the system's temporary folder, removed with everything
/// in it when the guard is dropped, so test runs leave nothing behind.
pub fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("gnomon-gltf-{name}-"))
        .tempdir()
        .expect("create a temporary directory")
}

/// One triangle (positions only), 36 bytes.
pub fn triangle_bytes() -> Vec<u8> {
    [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]
        .iter()
        .flatten()
        .flat_map(|f| f.to_le_bytes())
        .collect()
}

/// A parent node (translated, rotated and scaled) with a child (translated) holding
/// the triangle, and a MASK material. `buffer_uri` is the buffer's URI, or None for GLB.
pub fn hierarchy_json(buffer_uri: Option<&str>) -> String {
    let uri = buffer_uri.map(|u| format!(r#""uri": "{u}","#)).unwrap_or_default();
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [
    {{"name": "parent", "translation": [0, 2, 0], "rotation": [0, 0.7071068, 0, 0.7071068], "scale": [2, 2, 2], "children": [1]}},
    {{"name": "child", "translation": [1, 0, 0], "mesh": 0}}
  ],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "material": 0}}]}}],
  "materials": [{{"name": "leaf", "pbrMetallicRoughness": {{"baseColorFactor": [0.2, 0.6, 0.1, 0.9]}},
                 "alphaMode": "MASK", "alphaCutoff": 0.4, "doubleSided": true}}],
  "buffers": [{{{uri} "byteLength": 36}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                  "min": [0, 0, -1], "max": [1, 0, 0]}}]
}}"#
    )
}

pub fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut json = json.as_bytes().to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// CRC-32 (ISO 3309, as PNG uses): for the hand-made PNG header below.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

/// A PNG whose header declares `side`² pixels, with no pixel data behind it (an
/// empty IDAT chunk, then IEND).
pub fn png_declaring(side: u32) -> Vec<u8> {
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(side.to_be_bytes());
    ihdr.extend(side.to_be_bytes());
    ihdr.extend([8, 6, 0, 0, 0]); // 8-bit RGBA, deflate, adaptive filter, no interlace
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    for chunk in [&ihdr[..], b"IDAT", b"IEND"] {
        png.extend((chunk.len() as u32 - 4).to_be_bytes());
        png.extend(chunk);
        png.extend(crc32(chunk).to_be_bytes());
    }
    png
}
