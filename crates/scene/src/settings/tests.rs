//! Settings tests: flags, defaults and TOML agree; invalid values name their
//! setting and range; lights resolve with their own shadow settings.

use super::*;
use crate::{DirectionalLight, PointLight};
use clap::{CommandFactory, FromArgMatches, Parser};

#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    settings: Settings,
}

#[test]
fn flag_defaults_equal_struct_defaults() {
    let parsed = Cli::try_parse_from(["gnomon"]).unwrap().settings;
    assert_eq!(parsed, Settings::default());
    parsed.validate().unwrap();
}

#[test]
fn flags_and_toml_agree() {
    let parsed = Cli::try_parse_from([
        "gnomon",
        "--technique",
        "pcf",
        "--pcf-kernel",
        "5",
        "--shadow-res",
        "1024",
        "--slope-bias",
        "2.5",
        "--cull",
        "front",
        "--light",
        "spot",
        "--camera-eye",
        "1,2,3",
        "--kernel-unit",
        "world",
        "--receiver-plane-bias",
        "false",
        "--blur-radius",
        "4",
        "--mipmaps",
        "--moment-format",
        "rgba16float",
        "--csm-terms",
        "12",
        "--shadow-path",
        "mask",
        "--penumbra-rays",
        "32",
        "--tracer",
        "shader",
        "--contact-shadows",
        "--contact-length",
        "0.5",
        "--contact-steps",
        "24",
        "--caster-culling",
        "instances",
        "--map-cache",
        "off",
    ])
    .unwrap()
    .settings;
    let text = r#"
        [camera]
        eye = [1.0, 2.0, 3.0]
        [light]
        kind = "spot"
        [shadow.filter]
        technique = "pcf"
        pcf_kernel = 5
        kernel_unit = "world"
        receiver_plane_bias = false
        [shadow.filter.moments]
        blur_radius = 4
        mipmaps = true
        moment_format = "rgba16float"
        csm_terms = 12
        [shadow.bias]
        slope_bias = 2.5
        cull = "front"
        [shadow.map]
        resolution = 1024
        caster_culling = "instances"
        cache = "off"
        [shadow.contact]
        contact_shadows = true
        contact_length = 0.5
        contact_steps = 24
        [screen]
        shadow_path = "mask"
        penumbra_rays = 32
        tracer = "shader"
    "#;
    let from_file: Settings = toml::from_str(text).unwrap();
    assert_eq!(parsed, from_file);
    // And a round trip through TOML keeps everything.
    let again: Settings = toml::from_str(&toml::to_string(&parsed).unwrap()).unwrap();
    assert_eq!(again, parsed);
}

#[test]
fn invalid_values_name_the_setting_and_the_range() {
    let mut s = Settings::default();
    s.shadow.map.resolution = 100;
    let e = s.validate().unwrap_err();
    assert_eq!(e.setting, "shadow.map.resolution");
    assert!(e.to_string().contains("256 to 8192"), "{e}");
    let mut s = Settings::default();
    s.shadow.filter.pcf_kernel = 40.0;
    assert_eq!(s.validate().unwrap_err().setting, "shadow.filter.pcf_kernel");
    let mut s = Settings::default();
    s.camera.fov_y_degrees = Some(180.0);
    assert_eq!(s.validate().unwrap_err().setting, "camera.fov_y_degrees");
    for rays in [0, MAX_PENUMBRA_RAYS + 1] {
        let mut s = Settings::default();
        s.screen.penumbra_rays = rays;
        let e = s.validate().unwrap_err();
        assert_eq!(e.setting, "screen.penumbra_rays");
        assert!(e.to_string().contains(&format!("1 to {MAX_PENUMBRA_RAYS}")), "{e}");
    }
    assert!(parse_vec3("1,2").is_err() && parse_vec3("1,x,3").is_err() && parse_vec3("1,inf,2").is_err());
    assert_eq!(parse_vec3(" 1, 2.5,-3").unwrap(), Vec3::new(1.0, 2.5, -3.0));
}

#[test]
fn warps_take_a_single_map_and_texel_kernels() {
    let mut s = Settings::default();
    s.shadow.map.warp = WarpKind::Lispsm;
    s.validate().unwrap();
    s.shadow.partition = Partition::Cascades;
    let e = s.validate().unwrap_err();
    assert_eq!(e.setting, "shadow.map.warp");
    assert!(e.to_string().contains("`shadow.map.warp` none"), "{e}");
    // Which techniques read a warped map is the renderer's registry's to say.
    let mut s = Settings::default();
    s.shadow.map.warp = WarpKind::Tsm;
    s.shadow.filter.technique = Technique::PCF_POISSON;
    s.validate().unwrap();
    s.shadow.filter.kernel_unit = KernelUnit::World;
    assert!(s.validate().unwrap_err().to_string().contains("`shadow.filter.kernel_unit` world"));
}

#[test]
fn sdsm_bounds_need_sdsm_and_tight_cascades() {
    let mut s = Settings::default();
    s.shadow.partition = Partition::Cascades;
    s.shadow.cascades.sdsm_bounds = true;
    let e = s.validate().unwrap_err();
    assert!(
        e.setting == "shadow.cascades.sdsm_bounds"
            && e.to_string().contains("only with `shadow.cascades.sdsm`"),
        "{e}"
    );
    s.shadow.cascades.sdsm = true;
    s.shadow.cascades.cascade_fit = CascadeFit::Stable;
    assert!(s.validate().unwrap_err().to_string().contains("`shadow.cascades.cascade_fit` tight"));
    s.shadow.cascades.cascade_fit = CascadeFit::Tight;
    s.validate().unwrap();
}

#[test]
fn errors_speak_in_settings_not_flags() {
    let mut cases = Vec::new();
    let mut s = Settings::default();
    s.shadow.map.resolution = 100;
    cases.push(s);
    let mut s = Settings::default();
    s.shadow.partition = Partition::Cascades;
    s.shadow.cascades.sdsm_bounds = true;
    cases.push(s);
    let mut s = Settings::default();
    s.shadow.map.warp = WarpKind::Lispsm;
    s.shadow.partition = Partition::Cascades;
    cases.push(s);
    for s in cases {
        let e = s.validate().unwrap_err().to_string();
        assert!(e.starts_with('`') && !e.contains("--"), "{e}");
    }
}

#[test]
fn technique_names_are_checked_where_they_are_parsed() {
    for name in ["pcf2x2", "msm-hausdorff", "my-technique-2"] {
        let flag = Cli::try_parse_from(["gnomon", "--technique", name]).unwrap().settings;
        assert_eq!(flag.shadow.filter.technique.name(), name);
        let file: Settings = toml::from_str(&format!("[shadow.filter]\ntechnique = \"{name}\"")).unwrap();
        assert_eq!(file.shadow.filter.technique, flag.shadow.filter.technique, "flags and files agree");
        let written = toml::to_string(&file).unwrap();
        assert!(written.contains(&format!("technique = \"{name}\"")), "{written}");
    }
    for bad in ["", "PCF", "pcf 2", "-pcf", "ab/c", &"x".repeat(Technique::MAX_NAME_LENGTH + 1)] {
        let e = bad.parse::<Technique>().unwrap_err();
        assert_eq!(e.setting, "shadow.filter.technique", "{bad:?}");
        assert!(Cli::try_parse_from(["gnomon", "--technique", bad]).is_err(), "{bad:?}");
        assert!(toml::from_str::<Settings>(&format!("[shadow.filter]\ntechnique = \"{bad}\"")).is_err());
    }
}

#[test]
fn offered_techniques_become_the_flags_choices() {
    let choices = [("hard".to_owned(), "one tap".to_owned()), ("mine".to_owned(), "a host's".to_owned())];
    let command = offer_techniques(Cli::command(), &choices);
    let technique = command.get_arguments().find(|a| a.get_id() == "technique").unwrap();
    let names: Vec<String> =
        technique.get_possible_values().iter().map(|v| v.get_name().to_owned()).collect();
    assert_eq!(names, ["hard", "mine"]);
    let matches = command.clone().try_get_matches_from(["gnomon", "--technique", "mine"]).unwrap();
    let parsed = Cli::from_arg_matches(&matches).unwrap().settings;
    assert_eq!(parsed.shadow.filter.technique, Technique::named("mine"));
    assert!(command.try_get_matches_from(["gnomon", "--technique", "pcss"]).is_err(), "not offered");
}

#[test]
fn sun_overrides_keep_the_other_angle() {
    let scene = crate::builtin::spheres();
    let mut s = Settings::default();
    s.light.sun_elevation = Some(30.0);
    let Light::Directional(sun) = s.resolve_light(&scene).unwrap() else { panic!() };
    assert!(((-sun.direction.y).asin().to_degrees() - 30.0).abs() < 1e-3);
    let before = scene.light::<DirectionalLight>().unwrap().direction;
    let (a0, a1) = (before.x.atan2(before.z), sun.direction.x.atan2(sun.direction.z));
    assert!((a0 - a1).abs() < 1e-4, "azimuth unchanged");
}

#[test]
fn point_light_flags_override_the_scenes_and_are_checked() {
    let scene = crate::builtin::spheres();
    let parsed = Cli::try_parse_from([
        "gnomon",
        "--light",
        "point",
        "--point-position",
        "1,2,3",
        "--point-range",
        "7",
        "--point-radius",
        "0.2",
    ])
    .unwrap()
    .settings;
    parsed.validate().unwrap();
    let Light::Point(p) = parsed.resolve_light(&scene).unwrap() else { panic!("a point light") };
    assert_eq!((p.position, p.range, p.radius), (Vec3::new(1.0, 2.0, 3.0), 7.0, 0.2));
    assert_eq!(p.color, scene.light::<PointLight>().unwrap().color, "what no flag names stays the scene's");
    let lights = parsed.resolve_lights(&scene).unwrap();
    assert_eq!((lights.len(), lights[0].name.as_str()), (1, "point"));

    let mut bad = parsed.clone();
    bad.light.point_range = Some(0.0);
    assert_eq!(bad.validate().unwrap_err().setting, "light.point_range");
    bad.light.point_range = None;
    bad.light.point_radius = Some(-1.0);
    assert_eq!(bad.validate().unwrap_err().setting, "light.point_radius");
}

#[test]
fn light_all_takes_each_lights_own_shadow_settings() {
    let scene = crate::builtin::lamps();
    let mut s = Settings::default();
    s.light.kind = LightKind::All;
    s.shadow.bias.slope_bias = 2.5;
    let lights = s.resolve_lights(&scene).unwrap();
    assert_eq!(lights.len(), 8);
    assert_eq!(lights[0].shadow.partition, Partition::Cascades);
    assert_eq!(lights[2].shadow.filter.technique, Technique::PCSS);
    assert!(
        lights.iter().all(|l| l.shadow.bias.slope_bias == 2.5),
        "the render's, where a light says nothing"
    );
    // A light whose own table is invalid over these settings is named.
    let mut broken = scene.clone();
    broken.listed_lights_mut().nth(3).unwrap().shadow = Some(ShadowOverrides {
        map: MapSettingsPatch { resolution: Some(100), ..Default::default() },
        ..Default::default()
    });
    let e = s.resolve_lights(&broken).unwrap_err();
    assert!(e.to_string().contains("spot 2") && e.to_string().contains("`shadow.map.resolution`"), "{e}");
    // No list: a clear error naming where lists come from.
    let e = s.resolve_lights(&crate::builtin::spheres()).unwrap_err();
    assert!(e.valid.contains("[[light]]") && e.valid.contains("lamps"), "{e}");
}

#[test]
fn refining_by_rays_chooses_the_mask_path_and_forward_keeps_its_own() {
    let scene = crate::builtin::spheres();
    let mut s = Settings::default();
    let lights = s.resolve_lights(&scene).unwrap();
    for refine in [Refine::Rays, Refine::EveryPixel] {
        s.screen.refine = refine;
        s.screen.shadow_path = ShadowPath::Auto;
        assert!(s.uses_shadow_mask(&lights).unwrap(), "{refine:?}: auto takes the mask");
        // The forward path traces in its lighting pass.
        s.screen.shadow_path = ShadowPath::Forward;
        assert!(!s.uses_shadow_mask(&lights).unwrap(), "{refine:?}: forward stays forward");
    }
}

#[test]
fn several_lights_take_the_mask_path_for_their_light_list_under_auto_only() {
    let scene = crate::builtin::build("lamps:4").unwrap();
    let mut s = Settings::default();
    s.light.kind = LightKind::All;
    s.screen.refine = Refine::Off;
    assert_eq!(s.screen.lighting, Lighting::LightList, "the light list by default");
    let lights = s.resolve_lights(&scene).unwrap();
    assert!(s.uses_shadow_mask(&lights).unwrap(), "four lights: the mask, for the list");
    assert!(!s.uses_shadow_mask(&lights[..1]).unwrap(), "one light, no rays: forward");
    s.screen.lighting = Lighting::PerLight;
    assert!(!s.uses_shadow_mask(&lights).unwrap(), "per-light passes need no mask");
    s.screen.lighting = Lighting::LightList;
    s.screen.shadow_path = ShadowPath::Forward;
    assert!(!s.uses_shadow_mask(&lights).unwrap(), "forward by name stays forward");
}

#[test]
fn refining_by_default_takes_the_mask_path_for_hard_and_area_lights() {
    let scene = crate::builtin::spheres();
    let mut s = Settings::default();
    assert_eq!(s.screen.refine, Refine::Auto);
    let lights = s.resolve_lights(&scene).unwrap();
    assert!(lights.iter().all(|l| l.light.is_hard()), "the default sun is a point source");
    assert!(s.uses_shadow_mask(&lights).unwrap(), "auto refinement takes the mask for a hard sun");
    // Forward asked for by name: auto refinement yields, with no error.
    s.screen.shadow_path = ShadowPath::Forward;
    assert!(!s.uses_shadow_mask(&lights).unwrap(), "auto refinement gives way to --shadow-path forward");
    // A sun with a disk: its penumbrae are beamed on the mask path by default.
    s.screen.shadow_path = ShadowPath::Auto;
    s.light.sun_angular_diameter = Some(1.0);
    let soft = s.resolve_lights(&scene).unwrap();
    assert!(!soft[0].light.is_hard());
    assert!(s.uses_shadow_mask(&soft).unwrap(), "auto refinement takes the mask for an area light");
    s.screen.refine = Refine::Off;
    assert!(!s.uses_shadow_mask(&soft).unwrap(), "nothing refined and one light: forward");
    s.screen.refine = Refine::Rays;
    assert!(s.uses_shadow_mask(&soft).unwrap(), "rays by name take the mask as before");
}

#[test]
fn a_light_whose_technique_is_rays_is_traced_whatever_refine_says() {
    let scene = crate::builtin::spheres();
    let mut s = Settings::default();
    s.screen.refine = Refine::Off;
    s.light.sun_angular_diameter = Some(1.0);
    let mut lights = s.resolve_lights(&scene).unwrap();
    assert_eq!(lights[0].rays, RayUse::AsSettingsSay, "resolved lights leave rays to the settings");
    assert_eq!(s.light_refine(&lights[0]), Refine::Off);
    assert!(!s.uses_shadow_mask(&lights).unwrap());
    lights[0].rays = RayUse::EveryPixel;
    for refine in [Refine::Off, Refine::Auto, Refine::Rays] {
        s.screen.refine = refine;
        assert_eq!(s.light_refine(&lights[0]), Refine::EveryPixel, "{refine:?}");
        assert!(
            s.uses_shadow_mask(&lights).unwrap(),
            "{refine:?}: auto takes the mask, even for an area light"
        );
    }
    s.screen.shadow_path = ShadowPath::Forward;
    assert!(!s.uses_shadow_mask(&lights).unwrap(), "forward traces it in its lighting pass");
    // Its penumbra rays and the traced view are used though `screen.refine` is off.
    s.screen.refine = Refine::Off;
    s.screen.penumbra_rays = 32;
    s.image.debug_view = DebugView::Traced;
    assert!(s.unused(&lights).is_empty(), "{:?}", s.unused(&lights));
    lights[0].rays = RayUse::AsSettingsSay;
    let unused: Vec<&str> = s.unused(&lights).iter().map(|u| u.setting).collect();
    assert_eq!(unused, ["image.debug_view", "screen.penumbra_rays"]);
}

#[test]
fn contact_shadows_choose_the_mask_path_and_are_checked() {
    let scene = crate::builtin::lamps();
    let mut s = Settings {
        screen: ScreenSpaceSettings { refine: Refine::Off, ..Default::default() },
        ..Default::default()
    };
    let lights = s.resolve_lights(&scene).unwrap();
    assert!(!s.uses_shadow_mask(&lights).unwrap(), "auto without contact shadows or rays is forward");
    s.screen.shadow_path = ShadowPath::Mask;
    assert!(s.uses_shadow_mask(&lights).unwrap());
    // One light with contact shadows is enough for auto to take the mask...
    s.screen.shadow_path = ShadowPath::Auto;
    s.light.kind = LightKind::All;
    let mut lit = scene.clone();
    lit.listed_lights_mut().nth(5).unwrap().shadow = Some(ShadowOverrides {
        contact: ContactSettingsPatch { contact_shadows: Some(true), ..Default::default() },
        ..Default::default()
    });
    let lights = s.resolve_lights(&lit).unwrap();
    assert!(lights[5].shadow.contact.contact_shadows && !lights[4].shadow.contact.contact_shadows);
    assert!(s.uses_shadow_mask(&lights).unwrap());
    // ...and forward refuses it, naming the light.
    s.screen.shadow_path = ShadowPath::Forward;
    let e = s.uses_shadow_mask(&lights).unwrap_err();
    assert!(
        e.setting == "shadow.contact.contact_shadows"
            && e.to_string().contains(&lit.listed_lights().nth(5).unwrap().name),
        "{e}"
    );
    // Each parameter's range is checked, naming the flag.
    for (setting, set) in [
        (
            "shadow.contact.contact_length",
            (|c: &mut ContactSettings| c.contact_length = 0.0) as fn(&mut ContactSettings),
        ),
        ("shadow.contact.contact_steps", |c| c.contact_steps = 0),
        ("shadow.contact.contact_steps", |c| c.contact_steps = 65),
        ("shadow.contact.contact_thickness", |c| c.contact_thickness = f32::NAN),
        ("shadow.contact.contact_bias", |c| c.contact_bias = -0.1),
        ("shadow.contact.contact_distance", |c| c.contact_distance = 0.0),
    ] {
        let mut s = Settings::default();
        set(&mut s.shadow.contact);
        assert_eq!(s.validate().unwrap_err().setting, setting);
    }
}

/// Settings named by the library become the flags of the command line; other
/// quoted names stay as they are.
#[test]
fn settings_in_messages_become_flags() {
    let library = "`shadow.contact.contact_shadows` = on for light `lamp` is invalid: only with \
                   `screen.shadow_path` auto or mask; `shadow.map.resolution` too; model `box.width`";
    assert_eq!(
        in_flags(library),
        "--contact-shadows = on for light `lamp` is invalid: only with --shadow-path auto or mask; \
         --shadow-res too; model `box.width`"
    );
}

#[test]
fn shadow_overrides_are_typed_and_lay_only_what_they_name() {
    let written = "partition = \"cascades\"\n[filter]\ntechnique = \"pcss\"\n[map]\nresolution = 512\n";
    let parsed: ShadowOverrides = toml::from_str(written).unwrap();
    assert_eq!((parsed.filter.technique.clone(), parsed.map.resolution), (Some(Technique::PCSS), Some(512)));
    assert_eq!(parsed.bias.slope_bias, None, "what it does not name is left alone");
    let again: ShadowOverrides = toml::from_str(&toml::to_string(&parsed).unwrap()).unwrap();
    assert_eq!(again, parsed, "written and read back");
    assert!(toml::from_str::<ShadowOverrides>("[map]\nresolutoin = 512").is_err(), "a misspelt key");

    let base = ShadowSettings {
        bias: BiasSettings { slope_bias: 2.5, ..BiasSettings::default() },
        ..Default::default()
    };
    let laid = base.with_overrides(&parsed).unwrap();
    assert_eq!((laid.partition, laid.map.resolution), (Partition::Cascades, 512));
    assert_eq!((laid.filter.technique, laid.bias.slope_bias), (Technique::PCSS, 2.5));
    let bad = ShadowOverrides {
        map: MapSettingsPatch { resolution: Some(3), ..Default::default() },
        ..Default::default()
    };
    assert_eq!(base.with_overrides(&bad).unwrap_err().setting, "shadow.map.resolution");
}

/// Every setting an error can name is written as a string in the checks; a string that
/// named no setting (a typo, a renamed field) would reach the user as a path nothing
/// answers to, and `in_flags` could not turn it into a flag. Each must be a group of
/// [`Settings`] and a field that is a flag's id.
#[test]
fn every_setting_path_the_checks_name_is_a_setting() {
    let sources = [
        include_str!("mod.rs"),
        include_str!("filter.rs"),
        include_str!("light.rs"),
        include_str!("screen.rs"),
        include_str!("shadow.rs"),
        include_str!("unused.rs"),
    ];
    let ids: Vec<String> = Cli::command().get_arguments().map(|a| a.get_id().to_string()).collect();
    let groups = toml::Table::try_from(Settings::default()).unwrap();
    let mut named = 0;
    for source in sources {
        for quoted in source.split('"').skip(1).step_by(2) {
            let Some((group, _)) = quoted.split_once('.') else { continue };
            let is_path = quoted.chars().all(|c| c.is_ascii_lowercase() || c == '_' || c == '.');
            if !is_path || !groups.contains_key(group) {
                continue;
            }
            let field = quoted.rsplit('.').next().unwrap();
            assert!(
                ids.iter().any(|id| id == field),
                "`{quoted}` names no setting: `{field}` is no flag's id"
            );
            assert!(in_flags(&format!("`{quoted}`")).starts_with("--"), "`{quoted}` has no flag");
            named += 1;
        }
    }
    assert!(named > 40, "only {named} setting paths found in the checks");
}

#[test]
fn a_kind_the_scene_has_no_light_of_is_refused_by_name() {
    let mut scene = crate::builtin::spheres();
    let sun = *scene.light::<DirectionalLight>().unwrap();
    scene.lights.clear();
    scene.replace_listed_lights([crate::SceneLight::listed("key", sun)]);
    let mut s = Settings::default();
    assert!(s.resolve_light(&scene).is_ok(), "the listed sun is the scene's sun");
    s.light.kind = LightKind::Point;
    let e = s.resolve_light(&scene).unwrap_err();
    assert_eq!((e.setting, e.value.as_str()), ("light.kind", "point"));
    assert!(e.to_string().contains("`spheres` has; it has no point light"), "{e}");
}
