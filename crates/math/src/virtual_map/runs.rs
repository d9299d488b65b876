//! Pages drawn in runs: neighbouring pages of one row of a level that hold
//! neighbouring slots of one row of the pool are drawn as one, through one projection
//! ([`Clipmap::run_clip_from_world`](super::Clipmap::run_clip_from_world)) and one
//! viewport across their tiles.
//!
//! Why: a GPU pays for every page drawn alone: a viewport, the casters culled against
//! it, and every caster that overlaps several pages set up once per page. On an H200,
//! Sponza's moving sun paid about 20 µs per page. A frame that keeps nothing (the sun
//! moved) is laid out so that runs are long ([`PagePool::pack`](super::pages::PagePool::pack)):
//! its pages take slots in the order of their level, row and column.

use super::{PageKey, pages::PageGrant};

/// Pages side by side in a level's row, from `first` rightwards, whose tiles lie side
/// by side in one row of the pool from `first.physical` rightwards.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PageRun {
    /// Its leftmost page and tile.
    pub first: PageGrant,
    /// How many pages (and tiles) it spans.
    pub len: u32,
}

impl PageRun {
    /// The grants of its pages, left to right.
    pub fn grants(&self) -> impl Iterator<Item = PageGrant> + '_ {
        (0..self.len).map(|i| PageGrant {
            page: super::PageKey { x: self.first.page.x + i as i32, ..self.first.page },
            physical: self.first.physical + i,
            ..self.first
        })
    }
}

/// `drawn` (grants with distinct slots) joined into the fewest runs that slot order
/// allows, in the order of their first slot: a grant extends the run before it when
/// its page is that run's right neighbour and its slot the next one in the same row
/// of a pool `tiles_per_row` tiles wide, unless its page `starts_layer`: a run is
/// drawn through one projection, which a point light's faces do not share
/// ([`Clipmap::starts_layer`](super::Clipmap::starts_layer)).
pub fn runs(drawn: &[PageGrant], tiles_per_row: u32, starts_layer: impl Fn(PageKey) -> bool) -> Vec<PageRun> {
    let mut sorted = drawn.to_vec();
    sorted.sort_unstable_by_key(|g| g.physical);
    let mut runs: Vec<PageRun> = Vec::new();
    for grant in sorted {
        if let Some(run) = runs.last_mut() {
            let end = run.first.physical + run.len;
            let same_row = grant.physical == end && end % tiles_per_row != 0;
            let neighbour = grant.page.level == run.first.page.level
                && grant.page.y == run.first.page.y
                && grant.page.x == run.first.page.x + run.len as i32
                && !starts_layer(grant.page);
            if same_row && neighbour {
                run.len += 1;
                continue;
            }
        }
        runs.push(PageRun { first: grant, len: 1 });
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{
        test_rng::Lcg,
        virtual_map::{
            PageKey,
            pages::{PagePool, PageState, tests::check_invariant},
        },
    };

    fn page(level: u32, x: i32, y: i32) -> PageKey {
        PageKey { level, x, y }
    }

    #[test]
    fn a_packed_frame_draws_each_row_of_neighbours_as_one_run() {
        // Two rows of level 0 (x 0..5 at y 0, x 2..4 at y 1), a lone page, and a
        // level-1 row: in a pool 4 tiles wide, the first row breaks at the pool's
        // row end.
        let mut requests: Vec<PageKey> = (0..5).map(|x| page(0, x, 0)).collect();
        requests.extend((2..4).map(|x| page(0, x, 1)));
        requests.extend([page(0, 9, 1), page(1, -1, 0), page(1, 0, 0)]);
        let mut pool = PagePool::new(16);
        let mut allocation = pool.allocate(&requests);
        assert!(pool.pack(&mut allocation));
        check_invariant(&pool, &allocation);
        let drawn: Vec<_> = allocation.to_draw().copied().collect();
        assert_eq!(drawn.len(), requests.len());
        let found = runs(&drawn, 4, |_| false);
        let spans: Vec<(PageKey, u32, u32)> =
            found.iter().map(|r| (r.first.page, r.first.physical, r.len)).collect();
        assert_eq!(
            spans,
            vec![
                (page(0, 0, 0), 0, 4),
                (page(0, 4, 0), 4, 1),
                (page(0, 2, 1), 5, 2),
                (page(0, 9, 1), 7, 1),
                (page(1, -1, 0), 8, 2),
            ]
        );
        // The runs hold every page drawn, each in its own slot, once.
        let mut back: Vec<_> = found.iter().flat_map(|r| r.grants().collect::<Vec<_>>()).collect();
        back.sort_unstable_by_key(|g| g.physical);
        let mut expected = drawn.clone();
        expected.sort_unstable_by_key(|g| g.physical);
        assert_eq!(back, expected);
        // A page that starts a layer (a point light's face) starts a run.
        let split = runs(&drawn, 4, |p| p == page(0, 2, 0));
        assert_eq!(
            split.iter().map(|r| (r.first.page, r.len)).take(3).collect::<Vec<_>>(),
            vec![(page(0, 0, 0), 2), (page(0, 2, 0), 2), (page(0, 4, 0), 1)]
        );
    }

    #[test]
    fn a_frame_that_keeps_a_page_is_not_packed() {
        let mut pool = PagePool::new(8);
        let (a, b) = (page(0, 0, 0), page(0, 5, 0));
        pool.allocate(&[b]);
        let mut second = pool.allocate(&[a, b]);
        let before = second.clone();
        assert!(!pool.pack(&mut second), "b is kept: moving it would lose it");
        assert_eq!(second, before);
        check_invariant(&pool, &second);
    }

    #[test]
    fn packing_turned_frames_keeps_the_invariant_and_draws_every_page() {
        let mut rng = Lcg(5);
        let mut pool = PagePool::new(12);
        for step in 0..200 {
            let count = (rng.next() * 20.0) as usize;
            let requests: Vec<PageKey> = (0..count)
                .map(|_| {
                    page((rng.next() * 3.0) as u32, (rng.next() * 6.0) as i32, (rng.next() * 3.0) as i32)
                })
                .collect();
            pool.invalidate_all();
            let mut allocation = pool.allocate(&requests);
            assert!(pool.pack(&mut allocation), "step {step}: a turned light keeps nothing");
            check_invariant(&pool, &allocation);
            assert!(allocation.granted.iter().all(|g| g.state == PageState::New));
            assert_eq!(pool.resident(), allocation.granted.len(), "step {step}: the stale pages are gone");
            // Slots in order of level, row and column: every run's pages are
            // neighbours, and no run could be longer.
            let drawn: Vec<_> = allocation.to_draw().copied().collect();
            let found = runs(&drawn, 5, |_| false);
            assert_eq!(found.iter().map(|r| r.len as usize).sum::<usize>(), drawn.len());
            for pair in found.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                let end = a.first.physical + a.len;
                let joinable = b.first.physical == end
                    && end % 5 != 0
                    && b.first.page == PageKey { x: a.first.page.x + a.len as i32, ..a.first.page };
                assert!(!joinable, "step {step}: {a:?} and {b:?} should be one run");
            }
        }
    }
}
