//! Issue 75: round three's hostile files. Data a file holds once but Gnomon would
//! hold many times (textures of one image, primitives of one accessor, instances of
//! one mesh, sparse accessors) is charged per use, before it is allocated; triangles
//! of zero area are dropped; the values the glTF specification forbids are refused
//! with their JSON path; and the features Gnomon does not draw are warned of.

use crate::common::temp_dir;

use gnomon_scene::gltf_loader;

/// `json` written as `model.gltf` in a fresh folder, loaded: the scene's textures,
/// materials' textures, the camera's far plane and the warnings, or the error.
fn load(json: &str) -> Result<(gnomon_scene::Scene, Vec<String>), String> {
    let temp = temp_dir("round3");
    let path = temp.path().join("model.gltf");
    std::fs::write(&path, json).unwrap();
    gltf_loader::load(&path).map(|(s, e)| (s, e.warnings)).map_err(|e| e.to_string())
}

/// A data URI of `bytes`.
fn data_uri(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::from("data:application/octet-stream;base64,");
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * i)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

fn floats(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A file whose POSITION accessor has `count` elements, all zero but for the three
/// of one triangle (a sparse substitution: 48 bytes of data), drawn by
/// `primitives` primitives of one mesh and placed by `nodes` nodes.
fn sparse_model(count: usize, primitives: usize, nodes: usize) -> String {
    let mut data: Vec<u8> = [0u32, 1, 2].iter().flat_map(|i| i.to_le_bytes()).collect();
    data.extend(floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0]));
    let primitive = r#"{"attributes": {"POSITION": 0}}"#;
    let node_list: Vec<String> =
        (0..nodes).map(|i| format!(r#"{{"mesh": 0, "translation": [{i}, 0, 0]}}"#)).collect();
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scenes": [{{"nodes": {roots:?}}}],
  "nodes": [{nodes}], "meshes": [{{"primitives": [{prims}]}}],
  "buffers": [{{"uri": "{uri}", "byteLength": 48}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 12}}, {{"buffer": 0, "byteOffset": 12, "byteLength": 36}}],
  "accessors": [{{"componentType": 5126, "count": {count}, "type": "VEC3", "min": [0, 0, -1], "max": [1, 0, 0],
    "sparse": {{"count": 3, "indices": {{"bufferView": 0, "componentType": 5125}}, "values": {{"bufferView": 1}}}}}}]}}"#,
        roots = (0..nodes).collect::<Vec<_>>(),
        nodes = node_list.join(", "),
        prims = vec![primitive; primitives].join(", "),
        uri = data_uri(&data),
    )
}

#[test]
fn a_sparse_accessor_is_charged_for_every_vertex_it_becomes() {
    // 976 bytes in the audit, 30 M vertices: 3.2 GB and still running after 120 s.
    let e = load(&sparse_model(30_000_000, 1, 1)).unwrap_err();
    assert!(e.contains("30000000") && e.contains("at most"), "{e}");
}

#[test]
fn primitives_sharing_one_accessor_are_each_charged() {
    // One 999 999-vertex accessor fits; fifty primitives of it do not.
    assert!(load(&sparse_model(999_999, 1, 1)).is_ok());
    let e = load(&sparse_model(999_999, 50, 1)).unwrap_err();
    assert!(e.contains("primitive") && e.contains("999999 vertices"), "{e}");
}

#[test]
fn zero_area_triangles_are_dropped_with_a_warning_not_built_into_trees() {
    // 333 332 of the 333 333 triangles have all three corners at the origin.
    let started = std::time::Instant::now();
    let (scene, warnings) = load(&sparse_model(999_999, 1, 100)).unwrap();
    assert_eq!(scene.meshes[0].indices.len(), 3, "one triangle left");
    assert_eq!(scene.meshes[0].positions.len(), 3, "and only its vertices");
    assert!(warnings.iter().any(|w| w.contains("333332 triangle(s) of zero area dropped")), "{warnings:?}");
    assert!(started.elapsed().as_secs() < 10, "{:?}", started.elapsed());
}

/// A model of `triangles` distinct triangles (real data: 48 bytes each), placed by
/// `nodes` nodes.
fn real_model(triangles: usize, nodes: usize) -> String {
    let positions: Vec<f32> = (0..triangles)
        .flat_map(|i| {
            let x = i as f32;
            [x, 0.0, 0.0, x + 1.0, 0.0, 0.0, x, 0.0, -1.0]
        })
        .collect();
    let bytes = floats(&positions);
    let node_list: Vec<String> =
        (0..nodes).map(|i| format!(r#"{{"mesh": 0, "translation": [0, {i}, 0]}}"#)).collect();
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scenes": [{{"nodes": {roots:?}}}],
  "nodes": [{nodes}], "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
  "buffers": [{{"uri": "{uri}", "byteLength": {n}}}], "bufferViews": [{{"buffer": 0, "byteLength": {n}}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": {count}, "type": "VEC3",
    "min": [0, 0, -1], "max": [{max}, 0, 0]}}]}}"#,
        roots = (0..nodes).collect::<Vec<_>>(),
        nodes = node_list.join(", "),
        uri = data_uri(&bytes),
        n = bytes.len(),
        count = 3 * triangles,
        max = triangles,
    )
}

#[test]
fn every_instance_of_a_mesh_is_charged_for_its_placed_triangles() {
    assert!(load(&real_model(10_000, 10)).is_ok());
    // 10 000 triangles placed 1 000 times: 10 M triangles in the casters' BVHs.
    let e = load(&real_model(10_000, 1_000)).unwrap_err();
    assert!(e.contains("1000 instances' 10000000 placed triangles"), "{e}");
}

/// A file of one triangle whose materials sample `copies` textures of one 64² PNG,
/// with `samplers` distinct samplers among them.
fn textured(copies: usize, samplers: usize) -> String {
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(64, 64, image::Rgba([200, 100, 50, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let mut data = floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0]);
    data.extend(floats(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0]));
    let wraps = [10497, 33648, 33071];
    let sampler_list: Vec<String> =
        (0..samplers).map(|i| format!(r#"{{"wrapS": {}}}"#, wraps[i % 3])).collect();
    let textures: Vec<String> =
        (0..copies).map(|i| format!(r#"{{"source": 0, "sampler": {}}}"#, i % samplers)).collect();
    let materials: Vec<String> = (0..copies)
        .map(|i| format!(r#"{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": {i}}}}}}}"#))
        .collect();
    let primitives: Vec<String> = (0..copies)
        .map(|i| format!(r#"{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "material": {i}}}"#))
        .collect();
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{primitives}]}}], "materials": [{materials}], "textures": [{textures}],
  "samplers": [{samplers}], "images": [{{"uri": "data:image/png;base64,{png}"}}],
  "buffers": [{{"uri": "{uri}", "byteLength": 60}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 24}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, -1], "max": [1, 0, 0]}},
                {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}}]}}"#,
        primitives = primitives.join(", "),
        materials = materials.join(", "),
        textures = textures.join(", "),
        samplers = sampler_list.join(", "),
        png = data_uri(&png).trim_start_matches("data:application/octet-stream;base64,"),
        uri = data_uri(&data),
    )
}

#[test]
fn textures_of_one_image_and_sampler_hold_its_pixels_once() {
    let (scene, _) = load(&textured(16, 1)).unwrap();
    assert_eq!(scene.textures.len(), 1, "16 glTF textures of one image and sampler");
    assert!(scene.materials[..16].iter().all(|m| m.base_color_texture == Some(0)));
    let (scene, _) = load(&textured(16, 3)).unwrap();
    assert_eq!(scene.textures.len(), 3, "one per distinct sampler");
    let samplers: Vec<_> = scene.materials[..3].iter().map(|m| m.base_color_texture).collect();
    assert_eq!(samplers, [Some(0), Some(1), Some(2)]);
}

/// The triangle of [`textured`] with `material` as its one material and `extra`
/// top-level members.
fn with(material: &str, extra: &str) -> String {
    let data = floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0]);
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scenes": [{{"nodes": [0]}}], {extra}
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "material": 0}}]}}], "materials": [{material}],
  "buffers": [{{"uri": "{uri}", "byteLength": 36}}], "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, -1], "max": [1, 0, 0]}}]}}"#,
        uri = data_uri(&data),
    )
}

const NODE: &str = r#""nodes": [{"mesh": 0}],"#;

#[test]
fn values_the_specification_forbids_are_refused_with_their_path() {
    let cases = [
        (r#"{"pbrMetallicRoughness": {"baseColorFactor": [1e30, 1, 1, 1]}}"#, NODE, "baseColorFactor"),
        (r#"{"pbrMetallicRoughness": {"baseColorFactor": [-1, 1, 1, 1]}}"#, NODE, "baseColorFactor"),
        (r#"{"alphaMode": "MASK", "alphaCutoff": -1}"#, NODE, "alphaCutoff"),
        (
            "{}",
            r#""nodes": [{"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1], "scale": [2,2,2]}],"#,
            "both a `matrix`",
        ),
        ("{}", r#""nodes": [{"mesh": 0, "matrix": [1,0,0,0.5, 0,1,0,0, 0,0,1,0, 0,0,0,1]}],"#, "projective"),
    ];
    for (material, extra, expected) in cases {
        let e = load(&with(material, extra)).unwrap_err();
        assert!(e.contains(expected) && e.contains("glTF 2.0"), "{material} {extra}: {e}");
    }
    assert!(load(&with(r#"{"alphaMode": "MASK", "alphaCutoff": 0.3}"#, NODE)).is_ok());
}

#[test]
fn sparse_indices_past_the_count_or_out_of_order_are_refused() {
    for (indices, expected) in
        [([0u32, 1, 5], "past"), ([0, 2, 1], "strictly increase"), ([0, 1, 1], "strictly increase")]
    {
        let json = sparse_model(3, 1, 1);
        let mut data: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        data.extend(floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0]));
        let before = json.split(r#""uri": ""#).nth(1).unwrap().split('"').next().unwrap();
        let e = load(&json.replace(before, &data_uri(&data))).unwrap_err();
        assert!(e.contains("sparse.indices") && e.contains(expected), "{indices:?}: {e}");
    }
}

#[test]
fn a_normalized_float_accessor_is_refused() {
    let json = with("{}", NODE).replace(r#""type": "VEC3","#, r#""type": "VEC3", "normalized": true,"#);
    let e = load(&json).unwrap_err();
    assert!(e.contains("normalized") && e.contains("F32"), "{e}");
}

#[test]
fn min_and_max_that_do_not_bound_the_positions_are_warned_of() {
    let lies =
        |json: &str| load(json).unwrap().1.iter().any(|w| w.contains("min/max of POSITION accessor(s) 0"));
    assert!(!lies(&with("{}", NODE)), "exact bounds");
    // A bound off by a rounding of its decimal is no lie.
    assert!(!lies(&with("{}", NODE).replace(r#""max": [1, 0, 0]"#, r#""max": [0.9999999, 0, 0]"#)));
    for (from, to) in
        [(r#""max": [1, 0, 0]"#, r#""max": [0.5, 0, 0]"#), (r#""min": [0, 0, -1]"#, r#""min": [0, 0, 0]"#)]
    {
        let json = with("{}", NODE).replace(from, to);
        assert!(lies(&json), "{to}");
        assert!(load(&json).unwrap().0.instances.len() == 1, "still drawn, from its data");
    }
    // An accessor shared by fifty primitives is named once.
    let shared = sparse_model(3, 50, 1).replace(r#""max": [1, 0, 0]"#, r#""max": [0, 0, 0]"#);
    let warnings = load(&shared).unwrap().1;
    let named: Vec<&String> = warnings.iter().filter(|w| w.contains("min/max")).collect();
    assert!(named.len() == 1 && named[0].contains("accessor(s) 0 do not"), "{named:?}");
}

#[test]
fn skins_morph_targets_and_orthographic_cameras_are_warned_of() {
    let extra = r#""nodes": [{"mesh": 0}, {"camera": 0}], "cameras": [{"type": "orthographic",
        "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}],"#;
    let (_, warnings) = load(&with("{}", extra)).unwrap();
    assert!(warnings.iter().any(|w| w.contains("orthographic camera")), "{warnings:?}");
}

#[test]
fn a_camera_without_zfar_is_infinite_and_sees_the_whole_model() {
    // The audit's case: znear 1e-4 and the model 12 m away, once drawn as nothing.
    let extra = r#""nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 12]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.0001}}],"#;
    let json = with("{}", extra).replace(r#""scenes": [{"nodes": [0]}]"#, r#""scenes": [{"nodes": [0, 1]}]"#);
    let (scene, _) = load(&json).unwrap();
    let farthest = scene.bounds().corners().iter().map(|c| c.distance(scene.camera.eye)).fold(0.0, f32::max);
    assert!(
        scene.camera.far > farthest && scene.camera.far.is_finite(),
        "far {} for {farthest}",
        scene.camera.far
    );
}

#[test]
fn a_glb_with_two_binary_chunks_or_a_wrong_length_is_refused() {
    let json = crate::common::hierarchy_json(None);
    let good = crate::common::glb(&json, &crate::common::triangle_bytes());
    let temp = temp_dir("round3-glb");
    let path = temp.path().join("m.glb");
    let try_load = |bytes: &[u8]| {
        std::fs::write(&path, bytes).unwrap();
        gltf_loader::load(&path).map(|_| ()).map_err(|e| e.to_string())
    };
    try_load(&good).unwrap();
    let mut short = good.clone();
    short.truncate(good.len() - 4);
    let e = try_load(&short).unwrap_err();
    assert!(e.contains("declares a length"), "{e}");
    let mut two = good.clone();
    let bin = good[good.len() - 44..].to_vec();
    two.extend(&bin);
    let total = two.len() as u32;
    two[8..12].copy_from_slice(&total.to_le_bytes());
    let e = try_load(&two).unwrap_err();
    assert!(e.contains("two binary (BIN) chunks"), "{e}");
}

#[cfg(target_os = "linux")]
#[test]
fn a_pseudo_file_of_no_stated_length_is_read_as_empty() {
    let temp = temp_dir("round3-proc");
    let link = temp.path().join("pagemap.glb");
    std::os::unix::fs::symlink("/proc/self/pagemap", &link).unwrap();
    let e = gltf_loader::load(&link).unwrap_err().to_string();
    assert!(e.contains("empty"), "{e}");
}

#[test]
fn the_models_of_a_scene_file_share_one_budget() {
    // Each model alone fits (2.1 M vertices, 0.3 GiB as held); twelve together do not.
    let temp = temp_dir("round3-models");
    std::fs::write(temp.path().join("big.gltf"), sparse_model(2_100_000, 1, 1)).unwrap();
    let one = temp.path().join("one.toml");
    std::fs::write(&one, "[[model]]\nfile = \"big.gltf\"\n").unwrap();
    assert!(gnomon_scene::scene_file::load(&one, None).is_ok());
    let twelve = temp.path().join("twelve.toml");
    let models: String =
        (0..12).map(|i| format!("[[model]]\nfile = \"big.gltf\"\ntranslation = [{i}, 0, 0]\n")).collect();
    std::fs::write(&twelve, models).unwrap();
    let e = gnomon_scene::scene_file::load(&twelve, None).err().unwrap().to_string();
    assert!(
        e.contains("a scene may take at most") && !e.contains(":1:"),
        "refused past the first model: {e}"
    );
}
