//! Virtual shadow maps in whole frames: a renderer kept across frames draws only
//! the pages new or stale, the pages debug view shows them, and the pages along
//! shadow edges narrow what the frame traces (the request pass alone is tested in
//! `virtual_pages.rs`).

/// A frame's virtual pages: a renderer kept across frames draws only pages new or
/// stale, a still sun none, a turned one every page it reads; a pool too small for
/// the view refuses pages, counts them, and their pixels read coarser pages.
mod in_the_frame {
    use glam::{Mat4, Vec3};
    use gnomon_render::{Frame, OutputRequest, PageStats, Renderer};
    use gnomon_scene::{
        Motion, Settings, builtin,
        settings::{LightKind, Partition, Refine},
    };

    use crate::support;

    fn virtual_sun(pool_side: u32) -> Settings {
        let mut s = support::settings(320, 180, 1024);
        s.shadow.partition = Partition::Virtual;
        s.shadow.virtual_map.pool_side = pool_side;
        s.screen.refine = Refine::Off;
        s
    }

    fn pages(frame: &Frame) -> PageStats {
        frame.lights[0].pages.expect("a virtual light reports its pages")
    }

    /// The share of light-facing pixels in shadow (visibility below a half).
    fn shadowed(frame: &Frame) -> f64 {
        let seen: Vec<f32> = frame.visibility.iter().copied().filter(|v| v.is_finite()).collect();
        seen.iter().filter(|&&v| v < 0.5).count() as f64 / seen.len().max(1) as f64
    }

    #[test]
    fn a_still_sun_draws_no_page_and_a_turned_one_draws_every_page_it_reads() {
        let scene = builtin::spheres();
        let s = virtual_sun(24);
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let uploaded = renderer.upload(&scene).unwrap();
        let request = OutputRequest::default();
        let first = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let p = pages(&first);
        assert!(p.requested > 10 && p.drawn == p.requested && p.refused == 0, "{p:?}");
        // A first frame keeps nothing: its pages take the first slots, and only the
        // layers of the pool they lie in (4 rows of 24 tiles each) are cleared whole,
        // their texels counted.
        let layers = u64::from(p.drawn.div_ceil(24 * gnomon_render::virtual_map::POOL_LAYER_ROWS));
        assert!(layers < 6, "{p:?}");
        assert_eq!(first.lights[0].layer_texels, vec![layers * 24 * 128 * 4 * 128]);
        // It is laid out anew, neighbouring pages in neighbouring tiles, drawn in runs.
        assert!(p.runs > 0 && p.runs * 2 <= p.drawn, "{p:?}");
        let still = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let p = pages(&still);
        assert_eq!((p.drawn, p.kept), (0, p.requested), "{p:?}");
        assert_eq!(still.lights[0].layer_texels.iter().sum::<u64>(), 0);
        // The kept pages shade as the drawn ones did.
        assert_eq!(first.visibility.len(), still.visibility.len());
        let differ = first.visibility.iter().zip(&still.visibility).filter(|(a, b)| (*a - *b).abs() > 1e-6);
        assert_eq!(differ.count(), 0);
        let mut turned = s.clone();
        turned.light.sun_azimuth = Some(turned.light.sun_azimuth.unwrap_or(0.0) + 10.0);
        let p = pages(&renderer.render_uploaded(&uploaded, &scene, &turned, &request).unwrap());
        assert_eq!((p.drawn, p.kept), (p.requested - p.refused, 0), "{p:?}");
    }

    /// Under a sun, a spot and a point light: the fallbacks asked for are pages of the
    /// light's own levels (a spot's chain has 7, a point light's 5). A sun's or a
    /// spot's view fits under the 4 tiles of a pool 2 a side; a point light's spans
    /// five of its faces, each of whose coarsest levels is 2 × 2 pages: a pool 4 a
    /// side (16 tiles, half the 32 pages its pixels ask for here) holds a coarse page
    /// over each.
    #[test]
    fn an_overfull_pool_refuses_pages_counts_them_and_falls_back_to_coarser_ones() {
        let scene = builtin::spheres();
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        for (kind, full_side) in [(LightKind::Sun, 2), (LightKind::Spot, 2), (LightKind::Point, 4)] {
            let of = |pool_side| {
                let mut s = virtual_sun(pool_side);
                s.light.kind = kind;
                s
            };
            let ample = renderer.render(&scene, &of(24), &OutputRequest::default()).unwrap();
            let full = renderer.render(&scene, &of(full_side), &OutputRequest::default()).unwrap();
            let (a, f) = (pages(&ample), pages(&full));
            let tiles = full_side * full_side;
            assert_eq!(a.refused, 0, "{kind:?}: {a:?}");
            assert_eq!((f.capacity, f.resident), (tiles, tiles), "{kind:?}: {f:?}");
            assert_eq!(f.refused, f.requested - tiles, "{kind:?}: {f:?}");
            // The refused pages' pixels read the coarse resident pages: the spheres'
            // shadows are still there, blurrier, not lost to lit pixels.
            let (sa, sf) = (shadowed(&ample), shadowed(&full));
            assert!(
                sa > 0.02 && sf > 0.5 * sa,
                "{kind:?}: shadowed: {sa} with room, {sf} with {tiles} tiles"
            );
        }
    }

    /// Pixels whose visibility differs between two frames of one view.
    fn differing(a: &Frame, b: &Frame) -> usize {
        assert_eq!(a.visibility.len(), b.visibility.len());
        a.visibility
            .iter()
            .zip(&b.visibility)
            .filter(|(x, y)| (x.is_finite() || y.is_finite()) && x != y)
            .count()
    }

    #[test]
    fn a_moving_caster_redraws_only_the_pages_under_it_and_the_frame_matches_one_from_scratch() {
        let mut scene = builtin::spheres();
        let ball = scene.instances.iter().position(|i| i.name == "sphere 1,1").expect("a sphere");
        scene.instances[ball].motion = Motion::Dynamic;
        // A pool of 5² tiles in layers of 4 rows, for the 24 pages the view asks for:
        // the pages lie in both layers.
        let s = virtual_sun(5);
        let request = OutputRequest::default();
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let mut uploaded = renderer.upload(&scene).unwrap();
        let frame = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let first = pages(&frame);
        assert!((21..=25).contains(&first.requested), "{first:?}");
        assert_eq!((first.drawn, first.refused), (first.requested, 0), "{first:?}");
        assert_eq!(frame.lights[0].layer_texels, vec![2 * (5 * 128) * (4 * 128)], "both layers cleared");

        scene.instances[ball].world_from_object *= Mat4::from_translation(Vec3::new(0.7, 0.3, -0.4));
        renderer.move_instances(&mut uploaded, &scene, &[ball]).unwrap();
        let moved = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let p = pages(&moved);
        // The pages under the ball, where it was and where it is, and no others,
        // each cleared and drawn alone: the kept pages must stay.
        assert!(p.drawn > 0 && p.drawn < p.requested / 2, "{p:?}");
        assert_eq!(moved.lights[0].layer_texels, vec![u64::from(p.drawn) * 128 * 128]);
        assert_eq!(p.drawn + p.kept, p.requested, "{p:?}");
        let scratch = Renderer::new(support::gpu()).unwrap().render(&scene, &s, &request).unwrap();
        assert_eq!(differing(&moved, &scratch), 0, "the kept and redrawn pages shade as pages drawn afresh");
        // Without the redraw the ball's old shadow would stay: the frame before the
        // move differs from this one.
        let before = {
            let mut still = builtin::spheres();
            still.instances[ball].motion = Motion::Dynamic;
            Renderer::new(support::gpu()).unwrap().render(&still, &s, &request).unwrap()
        };
        assert!(differing(&before, &moved) > 50, "the move should change the shadows");
    }
}

mod pages_view {
    use gnomon_render::{Frame, OutputRequest, Renderer};
    use gnomon_scene::{
        Settings, builtin,
        settings::{DebugView, Partition, Refine},
    };

    use crate::support;

    fn pages_view(pool_side: u32) -> Settings {
        let mut s = support::settings(320, 180, 1024);
        s.shadow.partition = Partition::Virtual;
        s.shadow.virtual_map.pool_side = pool_side;
        s.screen.refine = Refine::Off;
        s.image.debug_view = DebugView::Pages;
        s
    }

    /// Each pixel's RGB, 0 to 255.
    fn rgb(frame: &Frame) -> Vec<[f32; 3]> {
        frame.color.chunks(4).map(|p| [f32::from(p[0]), f32::from(p[1]), f32::from(p[2])]).collect()
    }

    fn sum(pixel: &[f32; 3]) -> f32 {
        pixel.iter().sum()
    }

    #[test]
    fn the_pages_view_tints_levels_darkens_borders_and_brightens_the_pages_drawn() {
        let scene = builtin::spheres();
        let request = OutputRequest::default();
        let plain_settings = Settings { image: support::settings(320, 180, 1024).image, ..pages_view(24) };
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let uploaded = renderer.upload(&scene).unwrap();
        let plain = renderer.render_uploaded(&uploaded, &scene, &plain_settings, &request).unwrap();
        // The same pages kept, seen through the view: only the colours change.
        let kept = renderer.render_uploaded(&uploaded, &scene, &pages_view(24), &request).unwrap();
        assert_eq!(kept.lights[0].pages.unwrap().drawn, 0);
        let shadows_differ =
            plain.visibility.iter().zip(&kept.visibility).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
        assert_eq!(shadows_differ, 0, "a debug view changes no shadow");
        let (plain_rgb, kept_rgb) = (rgb(&plain), rgb(&kept));
        let tinted = plain_rgb.iter().zip(&kept_rgb).filter(|(a, b)| a != b).count();
        assert!(tinted > plain_rgb.len() / 2, "{tinted} of {} pixels tinted", plain_rgb.len());
        // Page borders: a texel wide, darkened to a quarter (about half in sRGB's
        // steps), where a level's tint keeps 83 % or more.
        let borders =
            plain_rgb.iter().zip(&kept_rgb).filter(|(a, b)| sum(a) > 60.0 && sum(b) < 0.6 * sum(a)).count();
        assert!(borders > 100 && borders < plain_rgb.len() / 10, "{borders} border pixels");
        // A first frame draws every page: brighter than the kept ones.
        let drawn = Renderer::new(support::gpu()).unwrap().render(&scene, &pages_view(24), &request).unwrap();
        // (×1.5 in linear light, about ×1.2 in sRGB's steps): every tinted pixel not
        // already near white.
        let shaded: Vec<(&[f32; 3], [f32; 3])> = plain_rgb
            .iter()
            .zip(&kept_rgb)
            .zip(rgb(&drawn))
            .filter(|((a, b), _)| a != b && sum(b) > 30.0 && sum(b) < 500.0)
            .map(|((_, b), c)| (b, c))
            .collect();
        let brighter = shaded.iter().filter(|(kept, drawn)| sum(drawn) > 1.1 * sum(kept)).count();
        assert!(brighter * 10 > shaded.len() * 9, "{brighter} of {} brighter where drawn", shaded.len());
        // A pool too small: the pixels a coarser page stands in for are reddened.
        let full = Renderer::new(support::gpu()).unwrap().render(&scene, &pages_view(2), &request).unwrap();
        let p = full.lights[0].pages.unwrap();
        assert!(p.refused > 0, "{p:?}");
        // Redder than the same pixel with room for every page (a red share of its
        // colour a tenth higher), and never the other way.
        let red_share = |p: &[f32; 3]| p[0] / sum(p).max(1.0);
        let (full_rgb, roomy_rgb) = (rgb(&full), rgb(&drawn));
        let redder = |a: &[[f32; 3]], b: &[[f32; 3]]| {
            a.iter().zip(b).filter(|(x, y)| red_share(x) > red_share(y) + 0.1).count()
        };
        let (reddened, paler) = (redder(&full_rgb, &roomy_rgb), redder(&roomy_rgb, &full_rgb));
        assert!(reddened > full_rgb.len() / 20 && paler == 0, "{reddened} pixels reddened, {paler} paler");
    }
}

/// The pages along shadow edges (`shadow.virtual_map.edge_levels`): the pixels a
/// frame traces ask for finer pages round them, which narrow the band the next
/// frame traces, without changing its answer; a still view settles and then draws
/// nothing; a light that turns forgets them.
mod along_edges {
    use gnomon_render::{Frame, OutputRequest, PageStats, Renderer};
    use gnomon_scene::{
        Settings, builtin,
        settings::{Partition, Refine},
    };

    use crate::support;

    fn virtual_sun(edge_levels: u32, refine: Refine) -> Settings {
        let mut s = support::settings(320, 180, 1024);
        s.shadow.partition = Partition::Virtual;
        s.shadow.virtual_map.edge_levels = edge_levels;
        s.screen.refine = refine;
        s
    }

    fn pages(frame: &Frame) -> PageStats {
        frame.lights[0].pages.expect("a virtual light reports its pages")
    }

    fn traced(frame: &Frame) -> u32 {
        frame.lights[0].traced_pixels.expect("a refined light counts its traced pixels")
    }

    /// Light-facing pixels whose shadow (lit or not, at a half) differs from `truth`'s.
    fn wrong(frame: &Frame, truth: &Frame) -> usize {
        let side = |v: f32| v.is_finite().then_some(v >= 0.5);
        frame.visibility.iter().zip(&truth.visibility).filter(|(a, b)| side(**a) != side(**b)).count()
    }

    #[test]
    fn finer_pages_along_edges_halve_the_traced_pixels_keep_the_answer_and_settle() {
        let scene = builtin::spheres();
        let request = OutputRequest::default();
        let render =
            |s: &Settings| Renderer::new(support::gpu()).unwrap().render(&scene, s, &request).unwrap();
        // Every pixel traced: the ray-traced answer the others are held to.
        let truth = render(&virtual_sun(0, Refine::EveryPixel));
        let plain = render(&virtual_sun(0, Refine::Auto));
        let p = pages(&plain);
        assert_eq!((p.edges, p.edge_levels), (0, 0), "{p:?}");

        let s = virtual_sun(2, Refine::Auto);
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let uploaded = renderer.upload(&scene).unwrap();
        let settled = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let p = pages(&settled);
        assert!(p.edges > 0 && p.edge_levels == 2 && p.refused == 0, "{p:?}");
        // Each level halves the band of unsure texels round an edge: two levels
        // should leave well under half the pixels to rays.
        let (before, after) = (traced(&plain), traced(&settled));
        assert!(before > 1000 && 2 * after < before, "traced {before} without the pages, {after} with");
        // The map is sure only where it is right: no pixel more is wrong.
        let (plain_wrong, settled_wrong) = (wrong(&plain, &truth), wrong(&settled, &truth));
        assert!(settled_wrong <= plain_wrong, "wrong: {plain_wrong} without the pages, {settled_wrong} with");

        // Settled: the same view again asks for no new page and draws none.
        let again = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let p = pages(&again);
        assert_eq!((p.drawn, p.edges_new), (0, Some(0)), "{p:?}");
        assert_eq!(traced(&again), after);
        // A turned sun's edges are elsewhere: its first frame forgets them, and it
        // settles as a renderer that never saw the old sun does.
        let mut turned = s.clone();
        turned.light.sun_azimuth = Some(turned.light.sun_azimuth.unwrap_or(0.0) + 10.0);
        let kept = renderer.render_uploaded(&uploaded, &scene, &turned, &request).unwrap();
        let fresh = render(&turned);
        let (k, f) = (pages(&kept), pages(&fresh));
        assert!(f.edges > 0, "{f:?}");
        assert_eq!(
            (k.edges, k.requested, traced(&kept)),
            (f.edges, f.requested, traced(&fresh)),
            "{k:?} {f:?}"
        );
    }
}
