//! The glTF inputs the hardening audit found mishandled, each built here by hand:
//! strips and fans, points and lines, an index accessor past its buffer, a singular
//! node matrix, an image that declares more pixels than any texture may hold, and
//! extensions Gnomon ignores or cannot read.

use crate::common;

use common::{glb, png_declaring, temp_dir};
use gnomon_scene::gltf_loader;

/// A unit quad's four corners (48 bytes) then the indices 0, 1, 2, 3 as u16 (8 bytes).
fn quad_bytes() -> Vec<u8> {
    let corners = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, -1.0]];
    let mut bytes: Vec<u8> = corners.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
    bytes.extend([0u16, 1, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    bytes
}

/// What varies between the files of these tests.
struct Quad<'a> {
    /// Each primitive's mode (4 triangles, 5 strip, 6 fan, 0 points, 1 lines).
    modes: &'a [u32],
    /// The index accessor's count (4 fits its 8 bytes).
    index_count: u32,
    /// The node's `matrix`, if it has one.
    matrix: Option<&'a str>,
    /// Extra top-level JSON members (`"extensionsUsed": [...]`), each followed by a comma.
    extra: &'a str,
    /// More nodes drawing the mesh untransformed, beside the first.
    copies: usize,
}

impl Default for Quad<'_> {
    fn default() -> Self {
        Quad { modes: &[5], index_count: 4, matrix: None, extra: "", copies: 0 }
    }
}

fn quad_json(q: &Quad, bin_length: usize, image: &str) -> String {
    let primitives: Vec<String> = q
        .modes
        .iter()
        .map(|m| format!(r#"{{"attributes": {{"POSITION": 0}}, "indices": 1, "mode": {m}}}"#))
        .collect();
    let matrix = q.matrix.map(|m| format!(r#", "matrix": {m}"#)).unwrap_or_default();
    format!(
        r#"{{
  "asset": {{"version": "2.0"}}, {extra}
  "scene": 0,
  "scenes": [{{"nodes": [{roots}]}}],
  "nodes": [{{"mesh": 0{matrix}}}{copies}],
  "meshes": [{{"primitives": [{primitives}]}}],
  "buffers": [{{"byteLength": {bin_length}}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 8}}{image_view}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, -1], "max": [1, 0, 0]}},
                {{"bufferView": 1, "componentType": 5123, "count": {count}, "type": "SCALAR"}}]{images}
}}"#,
        extra = q.extra,
        roots = (0..=q.copies).map(|i| i.to_string()).collect::<Vec<_>>().join(", "),
        copies = r#", {"mesh": 0}"#.repeat(q.copies),
        primitives = primitives.join(", "),
        count = q.index_count,
        image_view = if image.is_empty() {
            String::new()
        } else {
            format!(r#", {{"buffer": 0, "byteOffset": 56, "byteLength": {}}}"#, bin_length - 56)
        },
        images = image,
    )
}

fn load(name: &str, q: &Quad) -> Result<(gnomon_scene::Scene, gltf_loader::FileExtras), String> {
    let temp = temp_dir(name);
    let path = temp.path().join(format!("{name}.glb"));
    let bin = quad_bytes();
    std::fs::write(&path, glb(&quad_json(q, bin.len(), ""), &bin)).unwrap();
    gltf_loader::load(&path).map_err(|e| e.to_string())
}

#[test]
fn strips_and_fans_are_drawn_as_triangles() {
    for mode in [5, 6] {
        let (scene, extras) = load("strip", &Quad { modes: &[mode], ..Default::default() }).unwrap();
        assert_eq!(scene.triangle_count(), 2, "mode {mode}");
        assert!(extras.warnings.is_empty(), "{:?}", extras.warnings);
    }
}

#[test]
fn points_and_lines_are_skipped_with_a_count_and_alone_are_refused_by_mode() {
    let (scene, extras) = load("mixed", &Quad { modes: &[5, 1, 1, 0], ..Default::default() }).unwrap();
    assert_eq!(scene.triangle_count(), 2, "the strip alone");
    assert!(
        extras.warnings.iter().any(|w| w.contains("1 point and 2 line primitive(s) skipped")),
        "{:?}",
        extras.warnings
    );
    let e = load("points", &Quad { modes: &[0], ..Default::default() }).unwrap_err();
    assert!(e.contains("no triangles to draw") && e.contains("1 point primitive(s)"), "{e}");
}

#[test]
fn an_index_accessor_past_its_buffer_is_an_error_that_names_it() {
    let e = load("overrun", &Quad { modes: &[4], index_count: 600, ..Default::default() }).unwrap_err();
    assert!(e.contains("accessor 1"), "{e}");
}

#[test]
fn a_singular_node_matrix_warns_and_a_scene_of_nothing_else_is_refused() {
    // Scale 0: singular, and still affine (a last row of zeros is refused as projective).
    let zero = "[0,0,0,0, 0,0,0,0, 0,0,0,0, 0,0,0,1]";
    let (_, extras) =
        load("singular", &Quad { matrix: Some(zero), copies: 1, ..Default::default() }).unwrap();
    assert!(extras.warnings.iter().any(|w| w.contains("singular transform")), "{:?}", extras.warnings);
    // Alone, the flattened mesh would draw an empty sky.
    let e = load("flattened", &Quad { matrix: Some(zero), ..Default::default() }).unwrap_err();
    assert!(e.contains("zero area"), "{e}");
}

#[test]
fn ignored_extensions_warn_and_unreadable_required_ones_fail() {
    let used = r#""extensionsUsed": ["KHR_texture_transform"],"#;
    let (_, extras) = load("used", &Quad { extra: used, ..Default::default() }).unwrap();
    assert!(extras.warnings.iter().any(|w| w.contains("KHR_texture_transform")), "{:?}", extras.warnings);
    let required =
        r#""extensionsUsed": ["KHR_mesh_quantization"], "extensionsRequired": ["KHR_mesh_quantization"],"#;
    let e = load("required", &Quad { extra: required, ..Default::default() }).unwrap_err();
    assert!(e.contains("KHR_mesh_quantization"), "{e}");
}

#[test]
fn an_image_declaring_more_pixels_than_a_texture_holds_is_refused_before_decoding() {
    let temp = temp_dir("huge-image");
    let path = temp.path().join("huge.glb");
    let mut bin = quad_bytes();
    bin.extend(png_declaring(20_000));
    let images = r#", "images": [{"bufferView": 2, "mimeType": "image/png"}]"#;
    std::fs::write(&path, glb(&quad_json(&Quad::default(), bin.len(), images), &bin)).unwrap();
    let e = gltf_loader::load(&path).unwrap_err().to_string();
    assert!(e.contains("image 0") && e.contains("20000×20000") && e.contains("16384"), "{e}");
}
