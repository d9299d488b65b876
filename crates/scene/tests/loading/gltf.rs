//! The glTF loader: hierarchy transforms, materials and both containers on files
//! built here, and a clear error for every broken file in `tests/data/broken`.

use crate::common;

use std::path::Path;

use common::{glb, hierarchy_json, temp_dir, triangle_bytes};

use glam::{Mat4, Quat, Vec3};
use gnomon_scene::{AlphaMode, DirectionalLight, Falloff, PointLight, gltf_loader};

fn check_hierarchy(path: &Path) {
    let (scene, extras) = gltf_loader::load(path).unwrap();
    assert_eq!(scene.instances.len(), 1);
    // World = parent (T·R·S) × child (T), applied to the triangle's vertices.
    let parent = Mat4::from_scale_rotation_translation(
        Vec3::splat(2.0),
        Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        Vec3::new(0.0, 2.0, 0.0),
    );
    let expected = parent * Mat4::from_translation(Vec3::X);
    let inst = &scene.instances[0];
    assert!(inst.world_from_object.abs_diff_eq(expected, 1e-5), "{:?}", inst.world_from_object);
    // The child's origin lands at parent × (1, 0, 0): rotated 90° about y to (0, 0, −1),
    // scaled by 2 and lifted by 2.
    let origin = inst.world_from_object.transform_point3(Vec3::ZERO);
    assert!(origin.abs_diff_eq(Vec3::new(0.0, 2.0, -2.0), 1e-5), "{origin}");
    let m = &scene.materials[inst.material];
    assert_eq!(m.alpha_mode, AlphaMode::Mask { cutoff: 0.4 });
    assert!(
        m.double_sided
            && (m.alpha - 0.9).abs() < 1e-6
            && (m.base_color - Vec3::new(0.2, 0.6, 0.1)).length() < 1e-6
    );
    // No normals in the file: they are computed, facing up (+y after the transforms
    // act on the object, +y in object space for this triangle).
    let mesh = &scene.meshes[inst.mesh];
    assert!(mesh.normals.iter().all(|n| n.abs_diff_eq(Vec3::Y, 1e-5)), "{:?}", mesh.normals);
    // No camera or lights in the file: fitted and defaulted.
    assert!(!extras.has_camera && !extras.has_sun);
    assert!(scene.camera.eye.distance(scene.camera.target) > 0.0);
}

#[test]
fn hierarchy_transforms_and_materials_from_gltf_with_an_external_buffer() {
    let temp = temp_dir("external");
    let dir = temp.path();
    std::fs::write(dir.join("tri.bin"), triangle_bytes()).unwrap();
    std::fs::write(dir.join("tri.gltf"), hierarchy_json(Some("tri.bin"))).unwrap();
    check_hierarchy(&dir.join("tri.gltf"));
}

#[test]
fn hierarchy_transforms_and_materials_from_glb() {
    let temp = temp_dir("glb");
    let dir = temp.path();
    std::fs::write(dir.join("tri.glb"), glb(&hierarchy_json(None), &triangle_bytes())).unwrap();
    check_hierarchy(&dir.join("tri.glb"));
}

/// A model given as bytes loads as the same file does; one that names a file of its
/// own is refused, naming the file, since bytes have no folder.
#[test]
fn a_model_given_as_bytes_loads_as_its_file_does_and_names_no_file() {
    let temp = temp_dir("bytes");
    let path = temp.path().join("tri.glb");
    let bytes = glb(&hierarchy_json(None), &triangle_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let (from_file, _) = gltf_loader::load(&path).unwrap();
    let (from_bytes, _) = gltf_loader::load_from_bytes(&bytes, "dropped.glb").unwrap();
    assert_eq!(from_bytes.instances.len(), from_file.instances.len());
    assert_eq!(from_bytes.instances[0].world_from_object, from_file.instances[0].world_from_object);
    assert_eq!(from_bytes.meshes[0].positions, from_file.meshes[0].positions);
    let external = hierarchy_json(Some("tri.bin"));
    let e = gltf_loader::load_from_bytes(external.as_bytes(), "dropped.gltf").unwrap_err().to_string();
    assert!(e.starts_with("dropped.gltf: buffer 0") && e.contains("`tri.bin`"), "{e}");
}

fn broken(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/broken").join(name);
    let err = gltf_loader::load(&path).expect_err(name).to_string();
    assert!(err.contains(name), "the error names the file: {err}");
    err
}

#[test]
fn every_broken_file_gives_a_clear_error() {
    let e = broken("IndexOutOfRange.gltf");
    assert!(e.contains("index 255 is out of range for its 24 vertices"), "{e}");
    let e = broken("MissingBin.gltf");
    assert!(e.contains("buffer 0: its file `BoxTextured0.bin` is missing"), "{e}");
    let e = broken("RecursiveNodes.gltf");
    assert!(e.contains("cycle"), "{e}");
    let e = broken("BoxWithInfinites.glb");
    assert!(e.contains("non-finite vertex position"), "{e}");
    let e = broken("badArray.gltf");
    assert!(e.contains("invalid type") && e.contains("expected a sequence"), "{e}");
    let e = broken("badNumber.gltf");
    assert!(e.contains("invalid type") && e.contains("expected f32"), "{e}");
    let e = broken("sceneWrongType.gltf");
    assert!(e.contains("invalid type"), "{e}");
    let e = broken("bunny_draco.glb");
    assert!(e.contains("KHR_draco_mesh_compression") && e.contains("not support"), "{e}");
    let missing = gltf_loader::load(Path::new("no/such/file.glb")).unwrap_err().to_string();
    assert!(missing.contains("no/such/file.glb") && missing.contains("cannot read"), "{missing}");
}

#[test]
fn truncated_and_garbage_files_do_not_panic() {
    let temp = temp_dir("garbage");
    let dir = temp.path();
    let good = glb(&hierarchy_json(None), &triangle_bytes());
    for cut in [0, 4, 12, 20, 40, good.len() / 2, good.len() - 3] {
        let path = dir.join(format!("cut{cut}.glb"));
        std::fs::write(&path, &good[..cut]).unwrap();
        let e = gltf_loader::load(&path).expect_err("truncated").to_string();
        assert!(e.contains(&format!("cut{cut}.glb")), "{e}");
    }
    // A GLB header that declares fewer bytes than the header itself (found by
    // fuzzing: the gltf crate's subtraction overflows on it).
    let mut short = good.clone();
    short[8..12].copy_from_slice(&0u32.to_le_bytes());
    let path = dir.join("short.glb");
    std::fs::write(&path, &short).unwrap();
    let e = gltf_loader::load(&path).expect_err("a length below the header's").to_string();
    assert!(e.contains("short.glb") && e.contains("declares a length of 0 bytes"), "{e}");
    let path = dir.join("noise.gltf");
    std::fs::write(&path, (0..4096u32).map(|i| (i.wrapping_mul(2654435761) >> 24) as u8).collect::<Vec<_>>())
        .unwrap();
    assert!(gltf_loader::load(&path).is_err());
}

#[test]
fn every_punctual_light_joins_the_light_list() {
    use gnomon_scene::Light;
    let temp = temp_dir("lights");
    let dir = temp.path();
    let json = hierarchy_json(None).replacen(
        r#""asset": {"version": "2.0"},"#,
        r#""asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {"KHR_lights_punctual": {"lights": [
    {"type": "point", "name": "bulb", "color": [1, 0.5, 0.5], "range": 6, "intensity": 40},
    {"type": "spot", "spot": {"outerConeAngle": 0.5}, "intensity": 250},
    {"type": "point"}
  ]}},"#,
        1,
    );
    // Three light nodes beside the hierarchy.
    let json = json
        .replacen(r#""scenes": [{"nodes": [0]}],"#, r#""scenes": [{"nodes": [0, 2, 3, 4]}],"#, 1)
        .replacen(
            r#"{"name": "child", "translation": [1, 0, 0], "mesh": 0}"#,
            r#"{"name": "child", "translation": [1, 0, 0], "mesh": 0},
    {"translation": [0, 3, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
    {"translation": [0, 5, 0], "extensions": {"KHR_lights_punctual": {"light": 1}}},
    {"translation": [2, 1, 0], "extensions": {"KHR_lights_punctual": {"light": 2}}}"#,
            1,
        );
    std::fs::write(dir.join("lights.glb"), glb(&json, &triangle_bytes())).unwrap();
    let (scene, extras) = gltf_loader::load(&dir.join("lights.glb")).unwrap();
    assert!(extras.has_point && extras.has_spot && !extras.has_sun);
    let listed: Vec<_> = scene.listed_lights().collect();
    assert_eq!(listed.len(), 3);
    assert_eq!(listed[0].name, "bulb");
    let Light::Point(bulb) = listed[0].light else { panic!("{:?}", listed[0]) };
    assert_eq!((bulb.position, bulb.range), (Vec3::new(0.0, 3.0, 0.0), 6.0));
    assert_eq!(*scene.light::<PointLight>().unwrap(), bulb, "the first point light is the default");
    // A light without a range reaches past the scene.
    let Light::Point(unranged) = listed[2].light else { panic!() };
    assert!(unranged.range.is_finite() && unranged.range > 2.0);
    // The extension's units and falloff: candela, the inverse square windowed at the
    // range, and no window without one (the range Gnomon gives it is only the map's).
    assert_eq!(bulb.intensity, 40.0);
    assert_eq!(bulb.falloff, Falloff::InverseSquare { window: Some(6.0) });
    assert_eq!((unranged.intensity, unranged.falloff), (1.0, Falloff::InverseSquare { window: None }));
    let Light::Spot(spot) = listed[1].light else { panic!() };
    assert_eq!((spot.intensity, spot.falloff), (250.0, Falloff::InverseSquare { window: None }));
}

/// A directional light's intensity is illuminance in lux, which Gnomon shades one to
/// one (a sun of intensity 1 is 1 lux): it is kept, not replaced by 1.
#[test]
fn a_suns_lux_are_its_intensity() {
    use gnomon_scene::Light;
    let temp = temp_dir("sun-lux");
    let dir = temp.path();
    let json = hierarchy_json(None)
        .replacen(
            r#""asset": {"version": "2.0"},"#,
            r#""asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 3.5}]}},"#,
            1,
        )
        .replacen(r#""scenes": [{"nodes": [0]}],"#, r#""scenes": [{"nodes": [0, 2]}],"#, 1)
        .replacen(
            r#"{"name": "child", "translation": [1, 0, 0], "mesh": 0}"#,
            r#"{"name": "child", "translation": [1, 0, 0], "mesh": 0},
    {"rotation": [-0.5, 0, 0, 0.8660254], "extensions": {"KHR_lights_punctual": {"light": 0}}}"#,
            1,
        );
    std::fs::write(dir.join("sun.glb"), glb(&json, &triangle_bytes())).unwrap();
    let (scene, extras) = gltf_loader::load(&dir.join("sun.glb")).unwrap();
    assert!(extras.has_sun);
    let listed: Vec<_> = scene.listed_lights().collect();
    let Light::Directional(sun) = listed[0].light else { panic!("{:?}", listed[0]) };
    assert_eq!(sun.intensity, 3.5);
    assert_eq!(*scene.light::<DirectionalLight>().unwrap(), sun, "the file's sun is the default");
}
