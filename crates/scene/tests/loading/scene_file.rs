//! Scene files: models placed by their transforms, lights, named views, and settings
//! merged with the command line.

use crate::common;

use glam::Vec3;
use gnomon_scene::{DirectionalLight, PointLight, Settings, scene_file, settings::Technique};

use common::{glb, hierarchy_json, temp_dir, triangle_bytes};

fn write_scene(dir: &std::path::Path, text: &str) -> std::path::PathBuf {
    std::fs::write(dir.join("tri.glb"), glb(&hierarchy_json(None), &triangle_bytes())).unwrap();
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

const SCENE: &str = r#"
ground = true

[[model]]
file = "tri.glb"

[[model]]
file = "tri.glb"
translation = [10.0, 0.0, 0.0]
scale = 2.0

[sun]
elevation = 30.0
azimuth = 90.0
angular_diameter = 0.5

[[view]]
name = "front"
eye = [0.0, 3.0, 9.0]
target = [0.0, 1.0, 0.0]

[[view]]
name = "top"
eye = [5.0, 20.0, 0.1]
target = [5.0, 0.0, 0.0]
fov = 30.0

[settings.shadow.filter]
technique = "pcf"
pcf_kernel = 5
"#;

#[test]
fn models_lights_views_and_settings_come_from_the_file() {
    let temp = temp_dir("scene-file");
    let dir = temp.path();
    let path = write_scene(dir, SCENE);
    let loaded = scene_file::load(&path, None).unwrap();
    let scene = &loaded.scene;
    // Two models of one instance each, and the ground.
    assert_eq!(scene.instances.len(), 3);
    assert_eq!(loaded.view_names, ["front", "top"]);
    // The first view is the default.
    assert_eq!(scene.camera.eye, Vec3::new(0.0, 3.0, 9.0));
    // The second model is scaled by 2 about its origin, then moved 10 along x: its
    // child's origin (0, 2, −2) in the model becomes (10, 4, −4).
    let second = scene.instances[1].world_from_object.transform_point3(Vec3::ZERO);
    assert!(second.abs_diff_eq(Vec3::new(10.0, 4.0, -4.0), 1e-4), "{second}");
    assert!(
        ((-scene.light::<DirectionalLight>().unwrap().direction.y).asin().to_degrees() - 30.0).abs() < 1e-3
    );
    assert_eq!(scene.light::<DirectionalLight>().unwrap().angular_diameter_degrees, 0.5);
    let top = scene_file::load(&path, Some("top")).unwrap().scene.camera;
    assert_eq!((top.eye, top.fov_y_degrees), (Vec3::new(5.0, 20.0, 0.1), 30.0));

    // File settings apply; a command-line value that differs from its default wins.
    let table = loaded.settings.unwrap();
    let merged = scene_file::merge_settings(&table, &Settings::default()).unwrap();
    assert_eq!((merged.shadow.filter.technique, merged.shadow.filter.pcf_kernel), (Technique::PCF, 5.0));
    let mut cli = Settings::default();
    cli.shadow.filter.pcf_kernel = 7.0;
    cli.shadow.map.resolution = 1024;
    let merged = scene_file::merge_settings(&table, &cli).unwrap();
    assert_eq!(merged.shadow.filter.technique, Technique::PCF, "kept from the file");
    assert_eq!(merged.shadow.filter.pcf_kernel, 7.0, "the command line wins");
    assert_eq!(merged.shadow.map.resolution, 1024);
}

#[test]
fn bad_scene_files_name_the_file_and_the_problem() {
    let temp = temp_dir("scene-file-bad");
    let dir = temp.path();
    let check = |text: &str, expected: &str| {
        let path = write_scene(dir, text);
        let e = scene_file::load(&path, None).err().expect(expected).to_string();
        assert!(e.contains("scene.toml") && e.contains(expected), "{e}");
    };
    check("[[model]]\nfile = \"missing.glb\"\n", "missing.glb");
    check("[[model]]\nfile = \"tri.glb\"\nsclae = 2.0\n", "unknown field `sclae`");
    check("ground = true\n", "lists no models");
    // A malformed technique name is refused here; whether a well-formed one is
    // registered is the renderer's to say (`gnomon-render`'s custom_technique test).
    check("[[model]]\nfile = \"tri.glb\"\n[settings.shadow.filter]\ntechnique = \"No pe\"\n", "[settings]");
    check(
        "[[model]]\nfile = \"tri.glb\"\n[[light]]\ntype = \"sun\"\nelevation = 40.0\nazimuth = 0.0\n[light.shadow]\nmap.resolutoin = 512\n",
        "unknown field `resolutoin`",
    );
    let path = write_scene(dir, SCENE);
    let e = scene_file::load(&path, Some("side")).err().unwrap().to_string();
    assert!(e.contains("no view `side`") && e.contains("front, top"), "{e}");
}

const LIGHTS: &str = r#"
[[model]]
file = "tri.glb"

[point]
position = [0.0, 3.0, 0.0]
range = 12.0
radius = 0.1

[[light]]
name = "key"
type = "sun"
elevation = 40.0
azimuth = 10.0

[[light]]
name = "lamp"
type = "point"
position = [1.0, 2.0, 0.0]
range = 8.0
color = [1.0, 0.5, 0.25]
falloff = "inverse-square"
[light.shadow]
filter.technique = "pcss"
map.resolution = 512

[[light]]
type = "spot"
position = [0.0, 5.0, 5.0]
target = [0.0, 0.0, 0.0]
outer_angle = 30.0
range = 20.0
"#;

#[test]
fn point_lights_and_the_light_list_come_from_the_file() {
    use gnomon_scene::{Light, settings::LightKind};
    let temp = temp_dir("scene-file-lights");
    let dir = temp.path();
    let scene = scene_file::load(&write_scene(dir, LIGHTS), None).unwrap().scene;
    let point = *scene.light::<PointLight>().unwrap();
    assert_eq!((point.position, point.range, point.radius), (Vec3::new(0.0, 3.0, 0.0), 12.0, 0.1));
    let names: Vec<&str> = scene.listed_lights().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["key", "lamp", "light 2"]);
    let listed: Vec<_> = scene.listed_lights().collect();
    let Light::Point(lamp) = listed[1].light else { panic!("{:?}", listed[1]) };
    assert_eq!((lamp.range, lamp.color), (8.0, Vec3::new(1.0, 0.5, 0.25)));
    // `falloff` is glTF's, windowed at the range; a light without it keeps Gnomon's constant.
    assert_eq!(lamp.falloff, gnomon_scene::Falloff::InverseSquare { window: Some(8.0) });
    assert_eq!(point.falloff, gnomon_scene::Falloff::Constant);

    // --light all resolves every light with its own shadow settings over the render's.
    let mut s = Settings::default();
    s.light.kind = LightKind::All;
    s.shadow.bias.normal_offset = 1.25;
    let lights = s.resolve_lights(&scene).unwrap();
    assert_eq!(lights.len(), 3);
    assert_eq!(lights[0].shadow, s.shadow, "no table: the render's settings");
    assert_eq!(
        (lights[1].shadow.filter.technique.clone(), lights[1].shadow.map.resolution),
        (Technique::PCSS, 512)
    );
    assert_eq!(lights[1].shadow.bias.normal_offset, 1.25, "the rest stays the render's");
    s.light.light_index = 2;
    assert!(matches!(s.resolve_light(&scene).unwrap(), Light::Spot(_)));
    s.light.light_index = 3;
    let e = s.resolve_light(&scene).unwrap_err().to_string();
    assert!(e.contains("`light.light_index`") && e.contains("below 3"), "{e}");
}

#[test]
fn bad_light_entries_name_the_light_and_the_field() {
    let temp = temp_dir("scene-file-bad-lights");
    let dir = temp.path();
    let check = |light: &str, expected: &str| {
        let text = format!("[[model]]\nfile = \"tri.glb\"\n[[light]]\nname = \"lamp\"\n{light}");
        let path = write_scene(dir, &text);
        let e = scene_file::load(&path, None).err().expect(expected).to_string();
        assert!(e.contains("scene.toml") && e.contains("`lamp`") && e.contains(expected), "{e}");
    };
    check("type = \"point\"\nposition = [0.0, 1.0, 0.0]\n", "needs `range`");
    check("type = \"point\"\nposition = [0.0, 1.0, 0.0]\nrange = -1.0\n", "a distance in (0, 1e7]");
    check("type = \"area\"\n", "sun, spot or point");
    // A falloff of no known name is a parse error at its line, listing the valid ones.
    let path = write_scene(
        dir,
        "[[model]]\nfile = \"tri.glb\"\n[[light]]\ntype = \"point\"\nposition = [0.0, 1.0, 0.0]\nrange = 5.0\nfalloff = \"quadratic\"\n",
    );
    let e = scene_file::load(&path, None).err().unwrap().to_string();
    assert!(
        e.contains("scene.toml") && e.contains("line 7") && e.contains("`constant` or `inverse-square`"),
        "{e}"
    );
    // The [point] table is checked the same way.
    let path =
        write_scene(dir, "[[model]]\nfile = \"tri.glb\"\n[point]\nposition = [0.0, 1.0, 0.0]\nrange = 0.0\n");
    let e = scene_file::load(&path, None).err().unwrap().to_string();
    assert!(e.contains("[point]") && e.contains("a distance in (0, 1e7]"), "{e}");
    check(
        "type = \"spot\"\nposition = [0.0, 1.0, 0.0]\ntarget = [0.0, 1.0, 0.0]\nouter_angle = 30.0\nrange = 5.0\n",
        "a spot must aim",
    );
    check(
        "type = \"point\"\nposition = [0.0, 1.0, 0.0]\nrange = 5.0\n[light.shadow]\nmap.resolution = 3\n",
        "`shadow.map.resolution`",
    );
}

#[test]
fn a_light_may_have_contact_shadows_and_the_file_a_shadow_path() {
    let temp = temp_dir("contact-shadows");
    let dir = temp.path();
    let text = r#"
ground = true
[[model]]
file = "tri.glb"
[[light]]
type = "sun"
elevation = 40.0
azimuth = 30.0
[light.shadow.contact]
contact_shadows = true
contact_length = 0.5
[[light]]
type = "point"
position = [0.0, 2.0, 0.0]
range = 10.0
[settings.screen]
shadow_path = "mask"
"#;
    let loaded = scene_file::load(&write_scene(dir, text), None).unwrap();
    let mut s: Settings = loaded.settings.clone().unwrap().try_into().unwrap();
    assert_eq!(s.screen.shadow_path, gnomon_scene::settings::ShadowPath::Mask);
    s.light.kind = gnomon_scene::settings::LightKind::All;
    let lights = s.resolve_lights(&loaded.scene).unwrap();
    assert!(lights[0].shadow.contact.contact_shadows && lights[0].shadow.contact.contact_length == 0.5);
    assert!(!lights[1].shadow.contact.contact_shadows);
    // A contact parameter out of range is named with its light.
    let bad = text.replace("contact_length = 0.5", "contact_length = -1.0");
    let mut scene = scene_file::load(&write_scene(dir, &bad), None).map(|l| l.scene);
    let e = match scene.as_mut() {
        Ok(scene) => s.resolve_lights(scene).unwrap_err().to_string(),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("`shadow.contact.contact_length`"), "{e}");
}

/// Every scene-file value the hardening audit found silently accepted is refused, and
/// the error points at the line and column the user wrote.
#[test]
fn nonsense_light_and_view_values_are_refused_at_their_line_and_column() {
    let temp = temp_dir("scene-file-audit");
    let dir = temp.path();
    let cases: &[(&str, &str, &str)] = &[
        (
            "[spot]\nposition = [2.0, 6.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\nouter_angle = 40.0\ninner_angle = -50\nrange = 30.0\n",
            ":7:15:",
            "`inner_angle` = -50",
        ),
        ("[sun]\nelevation = 40\nazimuth = 10\ncolor = [nan, -1, 1e38]\n", ":6:9:", "`color`"),
        ("[[view]]\nname = \"a\"\neye = [0, 3, 9]\ntarget = [0, 1, 0]\nfov = 0\n", ":7:7:", "`fov` = 0"),
        ("[[view]]\nname = \"a\"\neye = [0, 3, 9]\ntarget = [0, 1, 0]\nnear = -1\n", ":7:8:", "`near` = -1"),
        ("[sun]\nelevation = nan\nazimuth = 10\n", ":4:13:", "`elevation` = NaN"),
        ("[sun]\nelevation = -30\nazimuth = 10\n", ":4:13:", "in (0, 90] degrees"),
        ("[sun]\nelevation = 0\nazimuth = 10\n", ":4:13:", "in (0, 90] degrees"),
        ("[sun]\nelevation = 30\nazimuth = inf\n", ":5:11:", "`azimuth` = inf"),
        ("[sun]\nelevation = 30\nazimuth = 10\nangular_diameter = 1e30\n", ":6:20:", "`angular_diameter`"),
        (
            "[[light]]\ntype = \"point\"\nposition = [0, 2, 0]\nrange = 5\nintensity = nan\n",
            ":7:13:",
            "`intensity` = NaN",
        ),
    ];
    for (table, at, expected) in cases {
        let text = format!("[[model]]\nfile = \"tri.glb\"\n{table}");
        let e = scene_file::load(&write_scene(dir, &text), None).err().map(|e| e.to_string());
        let e = e.unwrap_or_else(|| panic!("accepted:\n{text}"));
        assert!(e.contains(at) && e.contains(expected), "expected {at} and {expected} in: {e}");
    }
}

/// A setting out of range in a file's `[settings]` is blamed on the file, at its line,
/// by its key, even when a flag would override it: the file must stand alone. A bad
/// value after the merge that a flag gave is the flag's.
#[test]
fn a_bad_file_setting_is_blamed_on_the_file_not_on_a_flag() {
    let temp = temp_dir("scene-file-blame");
    let dir = temp.path();
    let text = "[[model]]\nfile = \"tri.glb\"\n\n[settings.shadow.map]\nresolution = 3\n";
    let e = scene_file::load(&write_scene(dir, text), None).err().expect("resolution 3").to_string();
    assert!(e.contains("scene.toml:5:14:") && e.contains("`settings.shadow.map.resolution` = 3"), "{e}");
    let good = text.replace("= 3", "= 512");
    let loaded = scene_file::load(&write_scene(dir, &good), None).unwrap();
    let mut flags = Settings::default();
    flags.shadow.map.resolution = 100;
    let merged = scene_file::merge_settings(loaded.settings.as_ref().unwrap(), &flags).unwrap();
    let e = merged.validate().unwrap_err();
    assert!(loaded.blame(&e, &flags).is_none(), "the flag set it: the flag is to blame");
}

#[test]
fn a_model_or_a_gltf_node_may_be_marked_as_moving() {
    use gnomon_scene::Motion;
    let temp = temp_dir("scene-file-motion");
    let dir = temp.path();
    // A glTF whose parent node says it moves: its child, the mesh, moves with it.
    let moving_json = hierarchy_json(None).replacen(
        r#""name": "parent","#,
        r#""name": "parent", "extras": {"motion": "dynamic", "note": "another tool's"},"#,
        1,
    );
    std::fs::write(dir.join("moving.glb"), glb(&moving_json, &triangle_bytes())).unwrap();
    let text = r#"
[[model]]
file = "tri.glb"

[[model]]
file = "tri.glb"
motion = "dynamic"

[[model]]
file = "moving.glb"
"#;
    let path = write_scene(dir, text);
    let scene = scene_file::load(&path, None).unwrap().scene;
    let motions: Vec<Motion> = scene.instances.iter().map(|i| i.motion).collect();
    assert_eq!(motions, [Motion::Static, Motion::Dynamic, Motion::Dynamic]);

    // Anything else is refused, naming the node, or the entry and its value.
    let bad_json = hierarchy_json(None).replacen(
        r#""name": "child","#,
        r#""name": "child", "extras": {"motion": "fast"},"#,
        1,
    );
    std::fs::write(dir.join("bad.glb"), glb(&bad_json, &triangle_bytes())).unwrap();
    let message = gnomon_scene::gltf_loader::load(&dir.join("bad.glb")).unwrap_err().to_string();
    assert!(message.contains("node 1") && message.contains("motion"), "{message}");
    let path = write_scene(dir, "[[model]]\nfile = \"tri.glb\"\nmotion = \"fast\"\n");
    let Err(error) = scene_file::load(&path, None) else { panic!("motion = \"fast\" was taken") };
    let message = error.to_string();
    assert!(message.contains("fast") && message.contains("dynamic"), "{message}");
}

/// Issue 49: two views of one name (`--view` would pick the first, silently), a file
/// too large to be a scene file, a directory, and a long malformed line, which toml
/// quotes in its error, cut short.
#[test]
fn duplicate_views_oversized_files_and_directories_are_refused_by_name() {
    let temp = temp_dir("scene-file-hostile");
    let dir = temp.path();
    let view = "[[view]]\nname = \"top\"\neye = [0.0, 9.0, 0.0]\ntarget = [0.0, 0.0, 0.1]\n";
    let path = write_scene(dir, &format!("[[model]]\nfile = \"tri.glb\"\n{view}{view}"));
    let e = scene_file::load(&path, None).err().unwrap().to_string();
    assert!(e.contains("[[view]] 2 has the name `top` of [[view]] 1"), "{e}");
    let big = dir.join("big.toml");
    std::fs::write(&big, vec![b'#'; 2 << 20]).unwrap();
    let e = scene_file::load(&big, None).err().unwrap().to_string();
    assert!(e.contains("2.0 MiB") && e.contains("at most 1.0 MiB"), "{e}");
    let e = scene_file::load(dir, None).err().unwrap().to_string();
    assert!(e.contains("is a directory"), "{e}");
    let long = dir.join("long.toml");
    std::fs::write(&long, format!("builtin = \"spheres\"\nx = [{}", "1,".repeat(200_000))).unwrap();
    let e = scene_file::load(&long, None).err().unwrap().to_string();
    assert!(
        e.len() < 2_000 && e.contains("more characters"),
        "{} bytes: {}",
        e.len(),
        &e[..e.len().min(400)]
    );
}
