//! Soft shadows against the Monte Carlo area-light reference: PCSS, whose kernel
//! follows the blocker distance, beats every fixed-width PCF kernel on `contact`,
//! where penumbrae widen with the distance from each contact; PCSS and VSM are held
//! to absolute error bounds there. Under a low, wide sun, PCSS's penumbrae are as
//! wide as the truth's on a map whose texels are oblong.

use crate::common;

use common::{compare, figures::figure, gpu, reference};
use gnomon_reference::{ReferenceImage, metrics::Metrics};
use gnomon_render::{OutputRequest, Renderer};
use gnomon_scene::{
    Scene, Settings, builtin,
    settings::{LightKind, Refine, Technique},
};

fn measure(renderer: &mut Renderer, scene: &Scene, s: &Settings, truth: &ReferenceImage) -> Metrics {
    compare(&renderer.render(scene, s, &OutputRequest::default()).unwrap(), truth)
}

/// `contact` under a spot light of radius 0.5, 480×270, and its 128-ray reference:
/// penumbrae that widen with the distance from each contact.
fn contact_under_a_disk_light() -> (Scene, Settings, ReferenceImage) {
    let scene = builtin::contact();
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (480, 270);
    s.light.kind = LightKind::Spot;
    s.light.spot_radius = Some(0.5);
    s.reference.samples = 128;
    // The techniques' own penumbrae: under `auto`, a light with an area is beamed,
    // whatever the technique.
    s.screen.refine = Refine::Off;
    let truth = reference(&scene, &s);
    (scene, s, truth)
}

#[test]
fn pcss_beats_every_fixed_pcf_kernel_on_contact() {
    let (scene, mut s, truth) = contact_under_a_disk_light();
    let mut renderer = Renderer::new(gpu()).unwrap();

    s.shadow.filter.technique = Technique::PCSS;
    let pcss = measure(&mut renderer, &scene, &s, &truth);
    let mut best_fixed = (f64::INFINITY, String::new());
    for technique in [Technique::PCF, Technique::PCF_TENT, Technique::PCF_POISSON] {
        for width in [1.0, 2.0, 3.0, 5.0, 9.0, 15.0, 25.0, 32.0] {
            for receiver_plane_bias in [false, true] {
                s.shadow.filter.technique = technique.clone();
                s.shadow.filter.pcf_kernel = width;
                s.shadow.filter.receiver_plane_bias = receiver_plane_bias;
                let m = measure(&mut renderer, &scene, &s, &truth);
                if m.mae < best_fixed.0 {
                    best_fixed = (
                        m.mae,
                        format!(
                            "{} width {width}, receiver-plane bias {receiver_plane_bias}",
                            technique.name()
                        ),
                    );
                }
            }
        }
    }
    println!("pcss MAE {:.4}; best fixed kernel MAE {:.4} ({})", pcss.mae, best_fixed.0, best_fixed.1);
    figure(
        "contact, spot r = 0.5: PCSS MAE (best fixed PCF)",
        format!("{:.4} ({:.4})", pcss.mae, best_fixed.0),
        PCSS_MAE_BOUND,
    );
    assert!(pcss.compared > 50_000, "{} pixels compared", pcss.compared);
    assert!(pcss.mae < PCSS_MAE_BOUND, "PCSS MAE {}", pcss.mae);
    assert!(
        pcss.mae < best_fixed.0,
        "PCSS MAE {} is not below the best fixed kernel's {} ({})",
        pcss.mae,
        best_fixed.0,
        best_fixed.1
    );
}

/// VSM's blurred moments give a fixed-width penumbra: against the area-light
/// reference on `contact` its error is held to an absolute bound, so that light
/// bleeding or a broken blur shows.
#[test]
fn vsm_stays_close_to_the_monte_carlo_reference_on_contact() {
    let (scene, mut s, truth) = contact_under_a_disk_light();
    s.shadow.filter.technique = Technique::VSM;
    let mut renderer = Renderer::new(gpu()).unwrap();
    let vsm = measure(&mut renderer, &scene, &s, &truth);
    figure("contact, spot r = 0.5: VSM MAE", format!("{:.4}", vsm.mae), VSM_MAE_BOUND);
    assert!(vsm.compared > 50_000, "{} pixels compared", vsm.compared);
    assert!(vsm.mae < VSM_MAE_BOUND, "VSM MAE {}", vsm.mae);
}

/// `grazing` under a 2° sun at 480×270: a single map fitted to the receivers under a
/// low sun has texels shorter along the light's travel than across it, and the box's
/// shadow fades over more than 32 of them. PCSS's penumbrae along edge profiles are
/// held to the truth's width within [`PCSS_WIDTH_BIAS_SHARE`].
#[test]
fn pcss_penumbrae_are_as_wide_as_the_truths_under_a_low_sun() {
    let scene = builtin::grazing();
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (480, 270);
    s.light.sun_angular_diameter = Some(2.0);
    s.reference.samples = 128;
    s.shadow.filter.technique = Technique::PCSS;
    // PCSS's own penumbrae, not the beams `auto` traces under a light with an area.
    s.screen.refine = Refine::Off;
    let truth = reference(&scene, &s);
    let mut renderer = Renderer::new(gpu()).unwrap();
    let pcss = measure(&mut renderer, &scene, &s, &truth);
    let width = &pcss.penumbra.width;
    let (bias, truth_width) = (width.bias_px.expect("profiles"), width.reference_px.expect("profiles"));
    figure(
        "grazing, sun 2°, 480×270: PCSS's width bias (the truth's width), px",
        format!("{bias:.2} ({truth_width:.2}); penumbra MAE {:.4}", pcss.penumbra.error.mae),
        format!("|bias| ≤ {PCSS_WIDTH_BIAS_SHARE} × the truth's width"),
    );
    assert!(width.profiles > 200, "{} edge profiles", width.profiles);
    assert!(bias.abs() <= PCSS_WIDTH_BIAS_SHARE * truth_width, "{width:?}");
}

/// How far PCSS's mean penumbra width may stray from the truth's on `grazing`: a
/// quarter. Measured +0.24 px of 10.05 at 480×270 (2 %). The search and the penumbra
/// measured in the longer texel gave −5.80 px (57 %); with the texels' shape but the
/// filter capped at the search's 32 texels, −3.26 px (32 %).
const PCSS_WIDTH_BIAS_SHARE: f64 = 0.25;

/// PCSS's MAE bound on `contact`: 0.0030 measured on lavapipe (1.5×). The best fixed
/// kernel's 0.0063 fails it, and so does a PCSS penumbra estimated 20 % too wide
/// (0.0048).
const PCSS_MAE_BOUND: f64 = 0.0045;

/// VSM's MAE bound on `contact`: 0.0167 measured on lavapipe (its fixed-width blur
/// against penumbrae that widen from each contact; PCSS gets 0.0030 there).
const VSM_MAE_BOUND: f64 = 0.025;
