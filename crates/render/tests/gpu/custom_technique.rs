//! A technique defined only here, registered in one line, renders and is checked like
//! a built-in one: its WGSL composes into the lighting pass, its typed parameters reach
//! its WGSL, its stated facts decide which lights and maps it takes, and every message
//! about it is generated from them.

use crate::support;

use glam::{UVec4, Vec2};
use gnomon_render::{
    OutputRequest, RenderError, Renderer,
    techniques::{
        GpuParams, MapPrecision, MapSupport, ShadowTechnique, TechniqueParams, TechniqueRegistry, Tunables,
    },
};
use gnomon_scene::settings::{FilterSettings, LightKind, Settings, Technique, WarpKind};
use support::*;

/// `pcf-cross`: the mean of five hardware 2×2 comparison taps, at the lookup and
/// `reach` texels away along each axis, a footprint no built-in technique has.
struct PcfCross {
    name: Technique,
    reach: f32,
}

/// Its parameters, typed: `CrossParams` in pcf_cross.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct CrossParams {
    reach: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    _pad3: UVec4,
}

impl GpuParams for CrossParams {
    const WGSL_NAME: &'static str = "CrossParams";
}

const CROSS: Technique = Technique::named("pcf-cross");
/// The taps one texel out.
static PCF_CROSS: PcfCross = PcfCross { name: CROSS, reach: 1.0 };
/// The same lookup with its taps three texels out: only its parameters differ.
static PCF_CROSS_WIDE: PcfCross = PcfCross { name: Technique::named("pcf-cross-wide"), reach: 3.0 };

impl ShadowTechnique for PcfCross {
    fn technique(&self) -> Technique {
        self.name.clone()
    }
    fn summary(&self) -> &'static str {
        "Five bilinear comparison taps in a cross (a test's technique)."
    }
    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("pcf_cross.wgsl")]
    }
    fn params(&self, _: &FilterSettings, _: MapPrecision) -> TechniqueParams {
        TechniqueParams::new(CrossParams { reach: self.reach, ..Default::default() })
    }
    /// It only compares depths, so it reads any map; it has no cube lookup.
    fn maps(&self) -> MapSupport {
        MapSupport::ANY
    }
    /// The bias moves its edges; it has no kernel of `pcf_kernel`.
    fn tunables(&self) -> Tunables {
        Tunables::BIAS
    }

    /// `reach` texels each way.
    fn filter_reach_texels(&self, _: &FilterSettings, _: f32) -> f32 {
        self.reach
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
    let registry = TechniqueRegistry::builtin().with(&PCF_CROSS).unwrap();
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

/// A host's typed parameters reach its WGSL: the same lookup with its taps three
/// texels out instead of one spreads the square's edge over a band about twice as
/// wide ((2 × reach + 1) texels: 7 against 3).
#[test]
fn a_registered_technique_reads_its_own_typed_parameters() {
    let registry = TechniqueRegistry::builtin().with(&PCF_CROSS).unwrap().with(&PCF_CROSS_WIDE).unwrap();
    let mut renderer = Renderer::with_techniques(gpu(), registry).unwrap();
    let scene = square_under_sun().scene;
    let mut band = |technique: Technique| {
        let frame =
            renderer.render(&scene, &with(technique, LightKind::Sun), &OutputRequest::default()).unwrap();
        (0..frame.pixel_count())
            .filter(|&i| frame.object_id[i] == 1 && (0.02..0.98).contains(&frame.visibility[i]))
            .count()
    };
    let (narrow, wide) = (band(CROSS), band(PCF_CROSS_WIDE.technique()));
    assert!(narrow > 50, "{narrow} pixels in pcf-cross's band");
    let ratio = wide as f64 / narrow as f64;
    assert!(ratio > 1.6, "reach 3 spreads {wide} pixels against reach 1's {narrow}: ×{ratio:.2}");
    support::figures::figure(
        "custom technique: edge band, reach 3 over reach 1",
        format!("×{ratio:.2}"),
        "> 1.6",
    );
}

#[test]
fn a_registered_technique_is_checked_from_the_facts_it_states() {
    let registry = TechniqueRegistry::builtin().with(&PCF_CROSS).unwrap();
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
