//! A sun's virtual shadow map (`--partition virtual`, issue 53) against the
//! reference: the map alone, and refined by rays where the page table's footprint
//! test is unsure (`rays/refine_virtual.wgsl`), exact as a single map refined is.

use crate::common;

use common::{
    compare,
    figures::{figure, percent},
    reference, render,
};
use gnomon_scene::{
    Settings, builtin,
    settings::{DebugView, Partition, Refine, Technique},
};

/// Issue 25's bound for `--refine rays` over `pcf2x2`, which a virtual map refined
/// must meet too: 0.02 % of light-facing pixels wrong.
const REFINED_MISMATCH: f64 = 0.0002;

/// The map alone, unrefined: its texels no larger than a pixel's footprint, it is
/// wrong only along shadow edges and terminators.
const UNREFINED_MISMATCH: f64 = 0.005;

fn settings(refine: Refine) -> Settings {
    let mut s = Settings::default();
    s.image.width = 640;
    s.image.height = 360;
    s.shadow.filter.technique = Technique::PCF2X2;
    s.shadow.partition = Partition::Virtual;
    s.screen.refine = refine;
    s
}

#[test]
fn a_virtual_map_refined_by_rays_matches_the_reference_tracing_few_pixels() {
    for scene in [builtin::spheres(), builtin::columns(), builtin::grazing()] {
        let truth = reference(&scene, &settings(Refine::Off));
        let map_frame = render(&scene, &settings(Refine::Off));
        let map = compare(&map_frame, &truth);
        let refined_frame = render(&scene, &settings(Refine::Rays));
        let refined = compare(&refined_frame, &truth);
        let pages = refined_frame.lights[0].pages.expect("a virtual light reports its pages");
        let rays = refined_frame.lights[0].traced_pixels.expect("a refined frame reports its rays");
        figure(
            &format!("{}, virtual map, pcf2x2 alone: mismatch", scene.name),
            percent(map.mismatch_rate),
            percent(UNREFINED_MISMATCH),
        );
        figure(
            &format!("{}, virtual map refined by rays: mismatch ({rays} pixels traced)", scene.name),
            percent(refined.mismatch_rate),
            percent(REFINED_MISMATCH),
        );
        assert!(pages.requested > 0 && pages.refused == 0, "{}: {pages:?}", scene.name);
        assert!(map.mismatch_rate <= UNREFINED_MISMATCH, "{}: {map:?}", scene.name);
        assert!(refined.mismatch_rate <= REFINED_MISMATCH, "{}: {refined:?}", scene.name);
        assert!(refined.compared > 50_000, "{}: {refined:?}", scene.name);
        // Rays decide a small share of the light-facing pixels, not all of them.
        assert!((rays as usize) < refined.compared / 5, "{}: {rays} traced", scene.name);
    }
}

/// The PCF family on a virtual map: each kernel's taps resolve their own page
/// through the table (`techniques/virtual_query.wgsl`), so a kernel straddling pages
/// or levels filters the depths a full map would hold there. Alone, each is wrong only
/// along edges, as the 2×2 lookup is; refined by rays, exact.
#[test]
fn the_pcf_family_reads_a_virtual_map_across_pages() {
    for scene in [builtin::spheres(), builtin::columns()] {
        let truth = reference(&scene, &settings(Refine::Off));
        for technique in [Technique::PCF, Technique::PCF_TENT, Technique::PCF_POISSON] {
            let with = |refine| {
                let mut s = settings(refine);
                s.shadow.filter.technique = technique.clone();
                s
            };
            let map = compare(&render(&scene, &with(Refine::Off)), &truth);
            let refined_frame = render(&scene, &with(Refine::Rays));
            let refined = compare(&refined_frame, &truth);
            let rays = refined_frame.lights[0].traced_pixels.expect("a refined frame reports its rays");
            figure(
                &format!("{}, virtual map, {technique} alone: mismatch", scene.name),
                percent(map.mismatch_rate),
                percent(UNREFINED_MISMATCH),
            );
            figure(
                &format!(
                    "{}, virtual map, {technique} refined by rays: mismatch ({rays} traced)",
                    scene.name
                ),
                percent(refined.mismatch_rate),
                percent(REFINED_MISMATCH),
            );
            assert!(map.mismatch_rate <= UNREFINED_MISMATCH, "{} {technique}: {map:?}", scene.name);
            assert!(refined.mismatch_rate <= REFINED_MISMATCH, "{} {technique}: {refined:?}", scene.name);
            assert!((rays as usize) < refined.compared / 5, "{} {technique}: {rays} traced", scene.name);
        }
    }
}

/// PCSS on a virtual sun (`pcss_virtual.wgsl`): its blocker search and kernel, tap by
/// tap through the page table, follow penumbrae that widen from each contact as PCSS
/// on a single 2D map does, against the Monte Carlo reference of a sun 4° wide. Each
/// is held to a single map of the same texel density: these penumbrae are 2.9 px
/// wide, and PCSS's error here follows the texels a pixel spans (the aliasing m the
/// compare command prints): 0.75 for the virtual map, whose texels follow the
/// pixels, and 0.78 for a 512² single map; 0.19 for the virtual map read two levels
/// finer (`lod_bias` 2) and 0.20 for a 2048² one.
#[test]
fn pcss_on_a_virtual_map_follows_the_penumbrae_as_on_a_single_map() {
    let scene = builtin::contact();
    let mut s = settings(Refine::Off);
    (s.image.width, s.image.height) = (320, 180);
    s.light.sun_angular_diameter = Some(4.0);
    s.reference.samples = 128;
    s.shadow.filter.technique = Technique::PCSS;
    let truth = reference(&scene, &s);
    let mut hard = None;
    for (lod_bias, single_resolution) in [(0, 512), (2, 2048)] {
        let mut s = s.clone();
        s.shadow.virtual_map.lod_bias = lod_bias;
        let on_virtual = compare(&render(&scene, &s), &truth);
        s.shadow.partition = Partition::Single;
        s.shadow.map.resolution = single_resolution;
        let on_single = compare(&render(&scene, &s), &truth);
        figure(
            &format!(
                "contact, sun 4°: PCSS MAE on a virtual map, lod bias {lod_bias} (on a {single_resolution}² single map)"
            ),
            format!("{:.4} ({:.4})", on_virtual.mae, on_single.mae),
            format!("≤ 1.25 × {:.4}", on_single.mae),
        );
        // Measured on lavapipe: 0.0022 (0.0023) and 0.0012 (0.0012). Penumbrae three
        // times too wide fail it (0.0192).
        assert!(
            on_virtual.mae <= 1.25 * on_single.mae,
            "lod bias {lod_bias}: {on_virtual:?} against {on_single:?}"
        );
        s.shadow.filter.technique = Technique::PCF2X2;
        let hard = hard.get_or_insert_with(|| compare(&render(&scene, &s), &truth));
        // pcf2x2's 0.0075 on the 512² map: PCSS's penumbrae are there.
        assert!(on_virtual.mae < 0.5 * hard.mae, "{on_virtual:?} against pcf2x2's {hard:?}");
    }
}

/// Levels of 1024² texels read four levels finer than the footprint
/// (`level_resolution` 1024, `lod_bias` 2): each level's window is narrow, and the
/// pixels to the sides of the view lie outside their footprint's level's window. They
/// read the finest coarser level that holds them (`Clipmap::level_for_point`, and
/// `virtual_window_level` in page_lookup.wgsl), so the map alone is still wrong only
/// along edges, and refined exact.
#[test]
fn pixels_outside_their_levels_window_read_a_coarser_level() {
    for scene in [builtin::spheres(), builtin::columns()] {
        let with = |refine| {
            let mut s = settings(refine);
            s.shadow.virtual_map.level_resolution = 1024;
            s.shadow.virtual_map.lod_bias = 2;
            s
        };
        let truth = reference(&scene, &with(Refine::Off));
        let map_frame = render(&scene, &with(Refine::Off));
        let map = compare(&map_frame, &truth);
        let refined = compare(&render(&scene, &with(Refine::Rays)), &truth);
        figure(
            &format!("{}, virtual map of 1024² levels, lod bias 2, alone: mismatch", scene.name),
            percent(map.mismatch_rate),
            percent(UNREFINED_MISMATCH),
        );
        assert!(map.mismatch_rate <= UNREFINED_MISMATCH, "{}: {map:?}", scene.name);
        assert!(refined.mismatch_rate <= REFINED_MISMATCH, "{}: {refined:?}", scene.name);
        let pages = map_frame.lights[0].pages.expect("a virtual light reports its pages");
        assert!(pages.refused == 0, "{}: {pages:?}", scene.name);
    }
}

/// Under a sun with an angular size, rays refine a virtual map where the map shows
/// casters over part of the sun's cone (`virtual_area_unsure`, refine_virtual.wgsl),
/// as on a 2D map, not at every pixel as before (all 38,007 light-facing pixels of
/// `grazing`). Its search reads the level whose texels span the cone in at most
/// PCSS's cap, and the page requests ask for those pages: a search capped in the
/// pixel's own fine texels covers a fraction of a wide sun's cone and misses
/// penumbrae (`grazing`, 10°: penumbra MAE 0.069 against four cascades' 0.044; no
/// search at all, 0.076), where reading the coarser level gives 0.026 (measured on
/// lavapipe). Tracing fewer than half the pixels, the penumbrae are no worse than
/// four cascades refined by the same search make them.
#[test]
fn penumbrae_of_a_wide_sun_are_traced_only_where_the_map_shows_them() {
    for scene in [builtin::grazing(), builtin::contact(), builtin::columns()] {
        let mut s = settings(Refine::Rays);
        (s.image.width, s.image.height) = (320, 180);
        s.light.sun_angular_diameter = Some(10.0);
        s.reference.samples = 128;
        s.shadow.filter.technique = Technique::PCSS;
        let truth = reference(&scene, &s);
        let refined_frame = render(&scene, &s);
        let refined = compare(&refined_frame, &truth);
        let rays = refined_frame.lights[0].traced_pixels.expect("a refined frame reports its rays");
        s.shadow.partition = Partition::Cascades;
        // Cascades' penumbrae gather a beam every fourth frame; four frames give each
        // unsure pixel the one beam the virtual map's frame gives it.
        s.screen.penumbra_frames = 4;
        let cascades = compare(&render(&scene, &s), &truth);
        figure(
            &format!(
                "{}, sun 10°, PCSS refined by rays: penumbra MAE on a virtual map ({rays} pixels traced), on four cascades",
                scene.name
            ),
            format!("{:.4}, {:.4}", refined.penumbra.error.mae, cascades.penumbra.error.mae),
            format!("≤ 1.1 × {:.4}", cascades.penumbra.error.mae),
        );
        assert!(refined.penumbra.error.pixels > 1000, "{}: {refined:?}", scene.name);
        assert!(
            (rays as usize) < refined.compared / 2,
            "{}: {rays} of {} traced",
            scene.name,
            refined.compared
        );
        assert!(
            refined.penumbra.error.mae <= 1.1 * cascades.penumbra.error.mae,
            "{}: {refined:?} against {cascades:?}",
            scene.name
        );
    }
}

/// A pixel's visibility this far from the reference's is wrong outright, not noisy:
/// 16 stratified rays over the sun's disk and the reference's 64 rays differ by
/// less (a half-lit pixel's 16 rays: a standard error of 0.125 unstratified).
const GROSS_ERROR: f32 = 0.35;

/// Compared pixels of `frame` whose visibility is `GROSS_ERROR` or more from the
/// reference's.
fn gross_errors(frame: &gnomon_render::Frame, truth: &gnomon_reference::ReferenceImage) -> usize {
    let raster = gnomon_reference::metrics::RasterView {
        visibility: &frame.visibility,
        object_id: &frame.object_id,
        depth: &frame.depth,
    };
    let classes = gnomon_reference::metrics::classify(raster, truth);
    (0..classes.len())
        .filter(|&i| {
            classes[i] == gnomon_reference::metrics::PixelClass::Compared
                && (frame.visibility[i] - truth.visibility[i]).abs() >= GROSS_ERROR
        })
        .count()
}

/// Under a 10° sun, at a user's 640×360 rather than the test above's 320×180: the
/// pixels the search over the sun's cone leaves to the map are right, on a virtual
/// map, a single map and four cascades. Two ways a search that reads coarse texels
/// went wrong here (refine_map.wgsl's `search_tap` and `cone_unsure`): the box's
/// whole lead over the ground in its long shadow lay inside a coarse texel's margin,
/// so the search saw only light under a footprint that saw the box (a page-shaped
/// square of PCSS's umbra inside the penumbra); and the posts, thinner than the
/// search's texels, were missed by it while the footprint saw them (their shadows'
/// cores). On four cascades and a single map, a search capped short of the cone saw
/// casters alone and kept PCSS's umbra where the truth is a penumbra.
#[test]
fn the_pixels_a_wide_suns_search_leaves_to_the_map_are_right() {
    let scene = builtin::grazing();
    let mut s = settings(Refine::Rays);
    s.light.sun_angular_diameter = Some(10.0);
    s.reference.samples = 64;
    s.shadow.filter.technique = Technique::PCSS;
    let truth = reference(&scene, &s);
    let mut wrong = Vec::new();
    let mut penumbra_mae = Vec::new();
    for partition in [Partition::Virtual, Partition::Single, Partition::Cascades] {
        s.shadow.partition = partition;
        let frame = render(&scene, &s);
        let metrics = compare(&frame, &truth);
        // The pixels rays decide: beamed this frame, or before, or filled from those.
        let rays = frame.lights[0].unsure_pixels.expect("a refined frame reports its rays") as usize;
        let gross = gross_errors(&frame, &truth);
        figure(
            &format!(
                "grazing, sun 10°, PCSS refined by rays, {partition:?}: pixels {GROSS_ERROR} or more off ({rays} traced of {}; penumbra MAE {:.4})",
                metrics.compared, metrics.penumbra.error.mae
            ),
            gross.to_string(),
            format!("≤ {}", metrics.compared / 1000),
        );
        penumbra_mae.push(metrics.penumbra.error.mae);
        // A single map's search still beams most of the floor here (lavapipe: 106,532
        // of 152,439; the truth shades 35 %): `a_single_maps_search_under_a_low_wide_sun_beams_under_half`.
        let beams_too_many = partition != Partition::Single && rays >= metrics.compared / 2;
        if gross > metrics.compared / 1000 || beams_too_many {
            wrong.push(format!("{partition:?}: {gross} pixels off, {rays} traced; {metrics:?}"));
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
    // The penumbrae as a whole: the virtual map's and a single map's within 10 % of
    // each other (lavapipe: 0.0252 and 0.0253; both 0.0317 before the virtual map's
    // finer grids and the 2D maps' wider ones, and every pixel traced 0.0245).
    // Taking the taps within a coarse texel's margin of the receiver for light
    // (`TAP_EITHER`) made the virtual map's 0.0359; a single map's second look with
    // its taps on the cone's rim alone (`wider_radius`), the single map's 0.0359.
    let (on_virtual, on_single) = (penumbra_mae[0], penumbra_mae[1]);
    assert!(
        on_virtual <= 1.1 * on_single && on_single <= 1.1 * on_virtual,
        "penumbra MAE, virtual and single: {penumbra_mae:?}"
    );
}

/// Under the same 10° sun 6° up, a single map's penumbra classification beams less
/// than half of the pixels, as four cascades' does (54,625 of 152,439 on lavapipe).
/// Open (issue 74): it beams 106,532, the floor nearest the camera and past the
/// posts' shadows, which the cascades find lit.
#[test]
#[ignore = "open in issue 74: a single map beams 70 % of the floor under a 10° sun 6° up"]
fn a_single_maps_search_under_a_low_wide_sun_beams_under_half() {
    let scene = builtin::grazing();
    let mut s = settings(Refine::Rays);
    s.light.sun_angular_diameter = Some(10.0);
    s.shadow.filter.technique = Technique::PCSS;
    s.shadow.partition = Partition::Single;
    let frame = render(&scene, &s);
    let rays = frame.lights[0].unsure_pixels.expect("a refined frame reports its rays") as usize;
    let pixels = (s.image.width * s.image.height) as usize;
    assert!(rays < pixels / 2, "{rays} of {pixels} pixels beamed");
}

/// The posts of `grazing` close up (`--camera-eye -4,2.5,8 --camera-target -2,0,0`)
/// under a 10° sun: their long penumbrae are right on a virtual map, whose penumbra
/// error is within 10 % of a single map's. The search over the sun's cone reads a
/// level whose texels span the cone in `--max-radius`, its taps a sixth of the cone
/// apart; the posts, 0.2 wide, fell between them, so that the search saw light
/// alone and PCSS's answer, lit, stood in dashes along the posts' penumbrae (virtual
/// 0.0360 against single 0.0233 here). The grids in the two finer levels
/// (`finer_grids`, refine_virtual.wgsl) find them: 0.0233 (with one, 0.0270). Four
/// cascades are held to the same: their search, capped at `--max-radius` texels of
/// the finest cascade, saw light alone and kept PCSS's answer along the posts' long
/// penumbrae (0.0462 at 128 reference rays) until the wider grids
/// (`wider_grids_find_casters`, refine_map.wgsl). PCSS alone, without rays, is held
/// to within 1.25× of a single map's there.
#[test]
fn the_posts_penumbrae_close_up_are_right_on_a_virtual_map() {
    let mut scene = builtin::grazing();
    scene.camera.eye = glam::Vec3::new(-4.0, 2.5, 8.0);
    scene.camera.target = glam::Vec3::new(-2.0, 0.0, 0.0);
    let mut s = settings(Refine::Rays);
    s.light.sun_angular_diameter = Some(10.0);
    s.reference.samples = 64;
    s.shadow.filter.technique = Technique::PCSS;
    let truth = reference(&scene, &s);
    let mut penumbra_mae = Vec::new();
    for partition in [Partition::Virtual, Partition::Single, Partition::Cascades] {
        s.shadow.partition = partition;
        let metrics = compare(&render(&scene, &s), &truth);
        figure(
            &format!("grazing close up, sun 10°, PCSS refined by rays, {partition:?}: penumbra MAE"),
            format!("{:.4}", metrics.penumbra.error.mae),
            "within 10 % of each other".to_string(),
        );
        penumbra_mae.push(metrics.penumbra.error.mae);
    }
    let (least, most) = penumbra_mae.iter().fold((f64::MAX, 0.0f64), |(l, m), e| (l.min(*e), m.max(*e)));
    assert!(most <= 1.1 * least, "penumbra MAE, virtual, single and cascades: {penumbra_mae:?}");

    // PCSS alone: on the virtual map, whose level here has texels about a pixel wide,
    // the cone spans hundreds of texels. Its search and filter read the levels where
    // the cone and the penumbra span at most their caps (pcss_virtual.wgsl), so the
    // penumbrae are as on a single map, whose texels are coarser. Searched and
    // filtered in the pixel's level alone, both were clipped at their caps and the
    // penumbrae fell short. Measured on lavapipe: 0.0433 against the single map's
    // 0.0395; 0.0658 in the pixel's level alone. Searching the coarser level alone
    // misses the posts, which its texels sample too sparsely (0.0808 at 128 rays).
    s.screen.refine = Refine::Off;
    let mut alone = Vec::new();
    for partition in [Partition::Virtual, Partition::Single] {
        s.shadow.partition = partition;
        alone.push(compare(&render(&scene, &s), &truth).penumbra.error.mae);
    }
    figure(
        "grazing close up, sun 10°, PCSS alone: penumbra MAE on a virtual map (on a single map)",
        format!("{:.4} ({:.4})", alone[0], alone[1]),
        format!("≤ 1.25 × {:.4}", alone[1]),
    );
    assert!(alone[0] <= 1.25 * alone[1], "PCSS alone, virtual and single: {alone:?}");
}

/// A roof high over a floor under a sun 3° wide, on four cascades: the search over
/// the sun's cone, capped at `--max-radius` texels of the finest cascade, sees the
/// roof alone under it, short of the cone at the roof's height. Such a search is
/// not proof of an umbra (`wider_look`, refine_map.wgsl), so it looks again past
/// the cone there, finds the roof and keeps the map's umbra: rays trace only the
/// penumbrae round the roof's shadow, not the floor under it, and the answer is
/// right. Without the second look every pixel under the roof was traced (47 % of
/// Sponza's view). Counted: the pixels of the reference's umbra that the traced
/// view tints. (Until the 2D maps' wider grids, `wider_grids_find_casters`, the
/// bound was on all pixels traced, the penumbrae and half the umbra: those grids
/// trace lit pixels beside the penumbra too, within their taps' spacing.)
#[test]
fn the_umbra_under_a_high_roof_is_not_traced() {
    let roof_height = 12.0;
    let mut scene = common::scene_of(
        vec![
            (gnomon_scene::geometry::plane(40.0, 40.0), glam::Mat4::IDENTITY),
            (
                gnomon_scene::geometry::cuboid(glam::Vec3::new(5.0, 0.1, 5.0)),
                glam::Mat4::from_translation(glam::Vec3::new(0.0, roof_height, 0.0)),
            ),
        ],
        gnomon_scene::Material::new("grey", glam::Vec3::splat(0.7)),
    );
    // Under the roof, looking along the floor at the shadow's edge.
    scene.camera.eye = glam::Vec3::new(0.0, 2.0, 7.0);
    scene.camera.target = glam::Vec3::new(0.0, 0.0, -2.0);
    let mut s = settings(Refine::Rays);
    (s.image.width, s.image.height) = (320, 180);
    s.light.sun_elevation = Some(75.0);
    s.light.sun_angular_diameter = Some(4.0);
    s.reference.samples = 64;
    s.shadow.filter.technique = Technique::PCSS;
    s.shadow.partition = Partition::Cascades;
    let truth = reference(&scene, &s);
    let frame = render(&scene, &s);
    let metrics = compare(&frame, &truth);
    let rays = frame.lights[0].traced_pixels.expect("a refined frame reports its rays") as usize;
    // The pixels rays decided: those the traced view tints.
    s.image.debug_view = DebugView::Traced;
    let tinted = render(&scene, &s);
    let traced: Vec<bool> = frame
        .color
        .chunks(4)
        .zip(tinted.color.chunks(4))
        .map(|(p, q)| p.iter().zip(q).any(|(x, y)| x.abs_diff(*y) > 2))
        .collect();
    let umbra: Vec<bool> = truth.visibility.iter().map(|v| *v == 0.0).collect();
    let shadowed = umbra.iter().filter(|u| **u).count();
    let traced_in_umbra = umbra.iter().zip(&traced).filter(|(u, t)| **u && **t).count();
    let penumbra = truth.visibility.iter().filter(|v| **v > 0.0 && **v < 1.0).count();
    let gross = gross_errors(&frame, &truth);
    figure(
        &format!(
            "a roof {roof_height} up, sun 4°, cascades, PCSS refined: pixels of the umbra traced ({shadowed} in the umbra, {penumbra} in penumbrae, {rays} traced in all; {gross} pixels {GROSS_ERROR} or more off)"
        ),
        traced_in_umbra.to_string(),
        format!("≤ {}", shadowed / 2),
    );
    assert!(shadowed > metrics.compared / 4, "{shadowed} of {} in the umbra", metrics.compared);
    // The view tints every pixel rays decide: beamed this frame, before it, or
    // filled from those.
    let unsure = frame.lights[0].unsure_pixels.expect("a refined frame reports its rays") as usize;
    let tinted_count = traced.iter().filter(|t| **t).count();
    assert!(
        tinted_count.abs_diff(unsure) * 50 <= unsure,
        "the tinted pixels ({tinted_count}) are those rays decide ({unsure})"
    );
    // Measured: 4,070 of the umbra's 11,771 traced (12,624 pixels in all); with no
    // second look, 9,133 (17,600).
    assert!(traced_in_umbra <= shadowed / 2, "{traced_in_umbra} of the umbra's {shadowed} traced");
    assert!(gross <= metrics.compared / 1000, "{gross} pixels off; {metrics:?}");
}
