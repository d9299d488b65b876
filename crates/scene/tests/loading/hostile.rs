//! Issue 49: small hostile files. Each declares far more than it holds, names a file
//! it must not read, or breaks a rule of the glTF specification that the gltf crate
//! does not check; each is refused before anything of its declared size is
//! allocated, with a message that names the element at fault. (The peak memory of
//! each, loaded by the `gnomon` binary, is in docs/hardening.md.)

use crate::common::temp_dir;

use gnomon_scene::gltf_loader::{self, LoadOptions, UriScope};

/// A model of one mesh, its POSITION accessor `accessor` (by default a triangle's,
/// from the 36 bytes of `buffer`, a data URI), the `nodes`, `extra` top-level members
/// and `asset.version`.
struct Model<'a> {
    buffer: &'a str,
    nodes: &'a str,
    accessor: &'a str,
    extra: &'a str,
    version: &'a str,
}

impl Default for Model<'_> {
    fn default() -> Self {
        Model {
            buffer: r#"{"uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAAAAAAIC/", "byteLength": 36}"#,
            nodes: r#"[{"mesh": 0}]"#,
            accessor: r#"{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, -1], "max": [1, 0, 0]}"#,
            extra: "",
            version: "2.0",
        }
    }
}

impl Model<'_> {
    fn json(&self) -> String {
        format!(
            r#"{{"asset": {{"version": "{version}"}}, {extra}
  "scene": 0, "scenes": [{{"nodes": [0]}}],
  "nodes": {nodes},
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
  "buffers": [{buffer}],
  "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
  "accessors": [{accessor}]}}"#,
            version = self.version,
            extra = self.extra,
            nodes = self.nodes,
            buffer = self.buffer,
            accessor = self.accessor,
        )
    }

    /// Loads the model as `model.gltf` in a folder of its own (inside `dir`).
    fn load(&self, dir: &std::path::Path) -> Result<(), String> {
        let folder = dir.join("model");
        std::fs::create_dir_all(&folder).unwrap();
        let path = folder.join("model.gltf");
        std::fs::write(&path, self.json()).unwrap();
        gltf_loader::load(&path).map(|_| ()).map_err(|e| e.to_string())
    }
}

/// The budget in the words of a refusal: `at most 768.0 MiB`.
fn at_most() -> String {
    format!("at most {}", gnomon_scene::memory::size(gnomon_scene::memory::frame_budget().unwrap().bytes))
}

#[test]
fn the_triangle_itself_loads() {
    let temp = temp_dir("hostile-valid");
    Model::default().load(temp.path()).expect("the valid model");
}

#[test]
fn a_sparse_accessor_of_a_billion_elements_is_refused_before_it_is_allocated() {
    let temp = temp_dir("hostile-sparse");
    let sparse = r#"{"componentType": 5126, "count": 999999999, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1],
        "sparse": {"count": 1, "indices": {"bufferView": 0, "componentType": 5125}, "values": {"bufferView": 0}}}"#;
    let started = std::time::Instant::now();
    let e = Model { accessor: sparse, ..Default::default() }.load(temp.path()).unwrap_err();
    assert!(e.contains("accessor 0") && e.contains("999999999 elements") && e.contains("GiB"), "{e}");
    assert!(started.elapsed().as_secs() < 5, "refused at once, not after reading: {:?}", started.elapsed());
}

#[test]
fn a_buffer_larger_than_the_budget_or_its_file_is_refused_before_it_is_read() {
    let temp = temp_dir("hostile-buffer");
    let folder = temp.path().join("model");
    std::fs::create_dir_all(&folder).unwrap();
    // A sparse file of 8 GB: nothing is read from it.
    let huge = std::fs::File::create(folder.join("huge.bin")).unwrap();
    huge.set_len(8 << 30).unwrap();
    let e = Model { buffer: r#"{"uri": "huge.bin", "byteLength": 8589934592}"#, ..Default::default() }
        .load(temp.path())
        .unwrap_err();
    assert!(e.contains("buffer 0") && e.contains("8.0 GiB") && e.contains(&at_most()), "{e}");
    // A file shorter than the buffer it is said to hold.
    std::fs::write(folder.join("short.bin"), [0u8; 12]).unwrap();
    let e = Model { buffer: r#"{"uri": "short.bin", "byteLength": 36}"#, ..Default::default() }
        .load(temp.path())
        .unwrap_err();
    assert!(e.contains("buffer 0") && e.contains("short.bin") && e.contains("12 bytes"), "{e}");
}

#[test]
fn a_uri_outside_the_models_folder_is_not_read_unless_allowed() {
    let temp = temp_dir("hostile-uri");
    std::fs::write(temp.path().join("outside.bin"), crate::common::triangle_bytes()).unwrap();
    let model = Model { buffer: r#"{"uri": "../outside.bin", "byteLength": 36}"#, ..Default::default() };
    let e = model.load(temp.path()).unwrap_err();
    assert!(e.contains("buffer 0") && e.contains("outside the model's folder"), "{e}");
    let passwd = Model {
        buffer: r#"{"uri": "../../../../../../../../etc/passwd", "byteLength": 36}"#,
        ..Default::default()
    };
    let e = passwd.load(temp.path()).unwrap_err();
    assert!(e.contains("outside the model's folder") || e.contains("is missing"), "{e}");
    let path = temp.path().join("model/model.gltf");
    std::fs::write(&path, model.json()).unwrap();
    let anywhere = LoadOptions { uri_scope: UriScope::Anywhere };
    if let Err(e) = gltf_loader::load_with(&path, &anywhere) {
        panic!("allowed, it loads: {e}");
    }
}

#[test]
fn a_base64_error_names_its_buffer() {
    let temp = temp_dir("hostile-base64");
    let bad = Model {
        buffer: r#"{"uri": "data:application/octet-stream;base64,!AAAAAAA", "byteLength": 36}"#,
        ..Default::default()
    };
    let e = bad.load(temp.path()).unwrap_err();
    assert!(e.contains("buffer 0") && e.contains("base64"), "{e}");
}

#[test]
fn a_stride_shorter_than_its_element_is_refused_before_the_gltf_crate_reads_it() {
    let temp = temp_dir("hostile-stride");
    let json = Model::default()
        .json()
        .replace(r#"{"buffer": 0, "byteLength": 36}"#, r#"{"buffer": 0, "byteLength": 36, "byteStride": 4}"#);
    let folder = temp.path().join("model");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("model.gltf"), json).unwrap();
    let e = gltf_loader::load(&folder.join("model.gltf")).unwrap_err().to_string();
    assert!(e.contains("accessor 0") && e.contains("byte stride of 4"), "{e}");
}

#[test]
fn the_node_forest_is_a_forest_and_every_fault_has_its_name() {
    let temp = temp_dir("hostile-nodes");
    // A cycle no scene reaches.
    let e = Model { nodes: r#"[{"mesh": 0}, {"children": [2]}, {"children": [1]}]"#, ..Default::default() }
        .load(temp.path())
        .unwrap_err();
    assert!(e.contains("nodes 1 → 2 → 1 form a cycle") || e.contains("nodes 2 → 1 → 2 form a cycle"), "{e}");
    // Two parents.
    let e = Model { nodes: r#"[{"mesh": 0, "children": [2]}, {"children": [2]}, {}]"#, ..Default::default() }
        .load(temp.path())
        .unwrap_err();
    assert!(e.contains("node 2 has two parents, nodes 0 and 1"), "{e}");
    // A chain of 300, deep but no cycle.
    let chain: Vec<String> = (0..300)
        .map(|i| {
            if i < 299 {
                format!(r#"{{"mesh": 0, "children": [{}]}}"#, i + 1)
            } else {
                r#"{"mesh": 0}"#.into()
            }
        })
        .collect();
    let nodes = format!("[{}]", chain.join(", "));
    let e = Model { nodes: &nodes, ..Default::default() }.load(temp.path()).unwrap_err();
    assert!(e.contains("deeper than 256 levels") && !e.contains("cycle"), "{e}");
    // A zero quaternion.
    let e = Model { nodes: r#"[{"mesh": 0, "rotation": [0, 0, 0, 0]}]"#, ..Default::default() }
        .load(temp.path())
        .unwrap_err();
    assert!(e.contains("`nodes[0].rotation`") && e.contains("not a unit quaternion"), "{e}");
}

#[test]
fn a_version_other_than_two_and_lights_beyond_their_ranges_are_refused() {
    let temp = temp_dir("hostile-spec");
    let e = Model { version: "3.0", ..Default::default() }.load(temp.path()).unwrap_err();
    assert!(e.contains("`asset.version` is \"3.0\""), "{e}");
    let light = |spot: &str, intensity: &str| {
        format!(
            r#""extensionsUsed": ["KHR_lights_punctual"],
               "extensions": {{"KHR_lights_punctual": {{"lights": [{{"type": "spot", "intensity": {intensity}, "spot": {spot}}}]}}}},"#
        )
    };
    let wide = light(r#"{"outerConeAngle": 3.0}"#, "1");
    let e = Model { extra: &wide, ..Default::default() }.load(temp.path()).unwrap_err();
    assert!(e.contains("lights[0].spot.outerConeAngle` = 3 rad") && e.contains("(0, π/2]"), "{e}");
    let bright = light(r#"{"outerConeAngle": 0.5}"#, "1e39");
    let e = Model { extra: &bright, ..Default::default() }.load(temp.path()).unwrap_err();
    assert!(e.contains("lights[0].intensity`") && e.contains("is invalid"), "{e}");
}

#[test]
fn a_model_of_zero_area_triangles_draws_nothing_and_is_refused() {
    let temp = temp_dir("hostile-flat");
    // Three copies of the first vertex.
    let flat = Model {
        buffer: r#"{"uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA", "byteLength": 36}"#,
        accessor: r#"{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 0]}"#,
        ..Default::default()
    };
    let e = flat.load(temp.path()).unwrap_err();
    assert!(e.contains("zero area"), "{e}");
}

#[test]
fn images_that_each_fit_but_together_exceed_the_budget_are_refused_before_decoding() {
    let temp = temp_dir("hostile-images");
    let folder = temp.path().join("model");
    std::fs::create_dir_all(&folder).unwrap();
    // One small PNG declaring 8000² pixels (0.7 GiB decoded), named by twelve images.
    std::fs::write(folder.join("big.png"), crate::common::png_declaring(8000)).unwrap();
    let images: Vec<&str> = vec![r#"{"uri": "big.png"}"#; 12];
    let extra = format!(r#""images": [{}],"#, images.join(", "));
    let e = Model { extra: &extra, ..Default::default() }.load(temp.path()).unwrap_err();
    assert!(e.contains("image 1") && e.contains("8000×8000") && e.contains(&at_most()), "{e}");
}
