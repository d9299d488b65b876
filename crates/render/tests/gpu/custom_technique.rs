//! A technique defined only here, registered in one line, renders and is checked like
//! a built-in one: its WGSL composes into the lighting pass, its stated facts decide
//! which lights and maps it takes, and every message about it is generated from them.

use crate::support;

use glam::Vec2;
use gnomon_render::{
    OutputRequest, RenderError, Renderer,
    techniques::{MapSupport, ShadowTechnique, TechniqueRegistry, Tunables},
};
use gnomon_scene::settings::{FilterSettings, LightKind, Settings, Technique, WarpKind};
use support::*;

/// `pcf-cross`: the mean of five hardware 2×2 comparison taps, at the lookup and one
/// texel away along each axis, a footprint no built-in technique has.
struct PcfCross;

const CROSS: Technique = Technique::named("pcf-cross");

impl ShadowTechnique for PcfCross {
    fn technique(&self) -> Technique {
        CROSS
    }
    fn summary(&self) -> &'static str {
        "Five bilinear comparison taps in a cross (a test's technique)."
    }
    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("pcf_cross.wgsl")]
    }
    /// It only compares depths, so it reads any map; it has no cube lookup.
    fn maps(&self) -> MapSupport {
        MapSupport::ANY
    }
    /// The bias moves its edges; it has no kernel of `pcf_kernel`.
    fn tunables(&self) -> Tunables {
        Tunables::BIAS
    }

    /// One texel each way.
    fn filter_reach_texels(&self, _: &FilterSettings, _: f32) -> f32 {
        1.0
    }
}

fn with(technique: Technique, light: LightKind) -> Settings {
    let mut s = settings(640, 480, 1024);
    s.shadow.filter.technique = technique;
    s.light.kind = light;
    s
}

#[test]
fn a_technique_registered_in_one_line_renders_its_own_lookup() {
    let registry = TechniqueRegistry::builtin().with(&PcfCross).unwrap();
    let mut renderer = Renderer::with_techniques(gpu(), registry).unwrap();
    let SquareOccluder { scene, shadow_center, shadow_half, .. } = square_under_sun();

    let cross = renderer.render(&scene, &with(CROSS, LightKind::Sun), &OutputRequest::default()).unwrap();
    let pcf2x2 = renderer.render(&scene, &with(Technique::PCF2X2, LightKind::Sun), &OutputRequest::default());
    let pcf2x2 = pcf2x2.unwrap();
    assert_eq!(cross.lights[0].technique, CROSS, "the frame reports the technique it drew with");

    // Against the analytic shadow of the square: dark inside, lit outside, beyond the
    // cross's reach (one texel and the bilinear tap's) and a pixel.
    let (mut umbra, mut lit, mut wrong, mut greyed) = (0, 0, 0, 0);
    for i in 0..cross.pixel_count() {
        if cross.object_id[i] != 1 {
            continue;
        }
        let p = cross.position[i];
        let d = square_distance(Vec2::new(p.x, p.z), shadow_center, shadow_half);
        let margin = 2.5 * cross.shadow_texel_world_size(p) + pixel_footprint(&cross, i);
        let v = cross.visibility[i];
        if d < -margin {
            umbra += 1;
            wrong += usize::from(v >= 0.1);
        } else if d > margin {
            lit += 1;
            wrong += usize::from(v <= 0.9);
        } else {
            // Its own footprint shows at the edge: values the 2×2 filter does not give.
            greyed += usize::from((v - pcf2x2.visibility[i]).abs() > 0.02);
        }
    }
    assert!(umbra > 1000 && lit > 20_000, "{umbra} umbra and {lit} lit pixels");
    assert_eq!(wrong, 0, "{wrong} of {} pixels away from the edge are wrong", umbra + lit);
    assert!(greyed > 50, "only {greyed} edge pixels differ from pcf2x2: was the cross drawn?");
    support::figures::figure(
        "custom technique `pcf-cross`: pixels differing from pcf2x2 at the edge",
        greyed,
        "> 50",
    );
}

#[test]
fn a_registered_technique_is_checked_from_the_facts_it_states() {
    let registry = TechniqueRegistry::builtin().with(&PcfCross).unwrap();
    let mut renderer = Renderer::with_techniques(gpu(), registry).unwrap();
    let scene = gnomon_scene::builtin::spheres();

    // No cube lookup: a point light is refused, and the message lists those that have one.
    let point = renderer.render(&scene, &with(CROSS, LightKind::Point), &OutputRequest::default());
    let Err(RenderError::Settings(e)) = point else { panic!("a point light with pcf-cross: {point:?}") };
    assert_eq!((e.setting, e.value.as_str()), ("shadow.filter.technique", "pcf-cross"));
    assert!(
        e.valid.ends_with("(a cube map): hard, pcf2x2, pcf, pcf-tent, pcf-poisson, pcss or raytraced"),
        "{e}"
    );

    // It reads any map: a warped one is accepted, and it is listed among those that do
    // when another technique is refused one.
    let mut warped = with(CROSS, LightKind::Sun);
    warped.shadow.map.warp = WarpKind::Lispsm;
    renderer.render(&scene, &warped, &OutputRequest::default()).unwrap();
    warped.shadow.filter.technique = Technique::VSM;
    let Err(RenderError::Settings(e)) = renderer.check_limits(&warped) else { panic!("VSM warped") };
    assert!(
        e.valid.contains("takes hard, pcf2x2, pcf, pcf-tent, pcf-poisson, raytraced or pcf-cross"),
        "{e}"
    );

    // Its name is the registry's, and the registry's alone.
    assert!(renderer.techniques().choices().iter().any(|(name, _)| name == "pcf-cross"));
    let mut plain = Renderer::new(gpu()).unwrap();
    let unknown = plain.render(&scene, &with(CROSS, LightKind::Sun), &OutputRequest::default());
    let Err(RenderError::Settings(e)) = unknown else { panic!("pcf-cross unregistered: {unknown:?}") };
    assert!(e.valid.starts_with("one of the registered techniques: hard, pcf2x2"), "{e}");
    assert!(!e.valid.contains("pcf-cross"), "{e}");
    assert_eq!("pcf-cross".parse::<Technique>(), Ok(CROSS), "a flag or a scene file may name it");
}
