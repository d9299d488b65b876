//! The physical page pool of a virtual shadow map: which virtual pages hold memory
//! this frame, which of them must be drawn, and which were refused.
//!
//! **Invariant** (checked after every step by `tests::check_invariant`):
//! - `resident` and `slots` describe one bijection: page `k` is resident in slot `s`
//!   exactly when `slots[s].page == Some(k)` and `resident[k] == s`;
//! - a page requested in a frame is never evicted in that frame, so every page
//!   granted in a frame holds memory until the frame's end;
//! - a page is refused only when every slot holds a page requested in the same frame.
//!
//! Allocation grants the coarse levels first, so that when the pool is too small the
//! pages refused are the finest, and a pixel whose page was refused falls back to a
//! coarser page over the same point that is resident ([`PagePool::resolve`]). Slots
//! are reused least recently used first.

use std::collections::HashMap;

use super::PageKey;

/// What a frame does with a granted page.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PageState {
    /// Newly given memory: drawn this frame.
    New,
    /// Resident, but something in it changed (the light turned, a caster moved over
    /// it): drawn again this frame.
    Dirty,
    /// Resident and unchanged: kept as it is, drawn not at all.
    Kept,
}

/// A page granted memory for this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PageGrant {
    /// The virtual page.
    pub page: PageKey,
    /// Its slot in the pool's texture.
    pub physical: u32,
    /// Whether it is drawn this frame, and why.
    pub state: PageState,
}

/// One frame's allocation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameAllocation {
    /// Every page requested that holds memory, coarse levels first.
    pub granted: Vec<PageGrant>,
    /// Pages requested that the pool had no room for: their pixels read a coarser
    /// page ([`PagePool::resolve`]).
    pub refused: Vec<PageKey>,
    /// Resident pages of earlier frames whose slots this frame took.
    pub evicted: u32,
}

impl FrameAllocation {
    /// The pages to draw this frame: the new and the dirty.
    pub fn to_draw(&self) -> impl Iterator<Item = &PageGrant> {
        self.granted.iter().filter(|g| g.state != PageState::Kept)
    }
}

/// One slot of the pool.
#[derive(Clone, Copy, Debug, Default)]
struct Slot {
    page: Option<PageKey>,
    /// The frame that last requested it (0: never).
    last_used: u64,
    /// Its content no longer matches the scene.
    stale: bool,
    /// The frame that last drew it (0: never).
    drawn_in: u64,
}

/// The pool: a fixed number of physical pages, kept across frames.
#[derive(Clone, Debug)]
pub struct PagePool {
    slots: Vec<Slot>,
    resident: HashMap<PageKey, u32>,
    frame: u64,
}

impl PagePool {
    /// A pool of `capacity` physical pages, all free.
    pub fn new(capacity: u32) -> PagePool {
        PagePool { slots: vec![Slot::default(); capacity as usize], resident: HashMap::new(), frame: 0 }
    }

    /// Physical pages in the pool.
    pub fn capacity(&self) -> u32 {
        self.slots.len() as u32
    }

    /// Pages holding memory now.
    pub fn resident(&self) -> usize {
        self.resident.len()
    }

    /// Every resident page and its slot, in no order.
    pub fn resident_pages(&self) -> impl Iterator<Item = (PageKey, u32)> + '_ {
        self.resident.iter().map(|(&page, &slot)| (page, slot))
    }

    /// Marks every resident page stale: the light turned, and every depth in the pool
    /// is of the old direction.
    pub fn invalidate_all(&mut self) {
        for slot in self.slots.iter_mut().filter(|s| s.page.is_some()) {
            slot.stale = true;
        }
    }

    /// Marks stale every resident page for which `overlaps` holds (the pages a moved
    /// caster covered or covers); returns how many it marked.
    pub fn invalidate(&mut self, overlaps: impl Fn(PageKey) -> bool) -> u32 {
        let mut marked = 0;
        for slot in &mut self.slots {
            if let Some(page) = slot.page
                && overlaps(page)
                && !slot.stale
            {
                slot.stale = true;
                marked += 1;
            }
        }
        marked
    }

    /// Grants memory to this frame's requested pages (duplicates allowed), coarse
    /// levels first: a resident page keeps its slot, drawn again only if stale; a new
    /// one takes a free slot, else the least recently used slot no page of this frame
    /// holds; when none is left, it is refused.
    pub fn allocate(&mut self, requests: &[PageKey]) -> FrameAllocation {
        self.frame += 1;
        let frame = self.frame;
        let mut wanted: Vec<PageKey> = requests.to_vec();
        // Coarse levels first, then a fixed order, so that the result does not depend
        // on the order the requests arrived in.
        wanted.sort_unstable_by(|a, b| b.level.cmp(&a.level).then(a.cmp(b)));
        wanted.dedup();
        // Every requested resident page first: none of them may be evicted.
        for page in &wanted {
            if let Some(&slot) = self.resident.get(page) {
                self.slots[slot as usize].last_used = frame;
            }
        }
        // The slots a new page may take, free ones first, then least recently used.
        let mut free: Vec<u32> =
            (0..self.capacity()).filter(|&s| self.slots[s as usize].last_used != frame).collect();
        free.sort_by_key(|&s| {
            let slot = &self.slots[s as usize];
            (slot.page.is_some(), slot.last_used)
        });
        let mut free = free.into_iter();
        let mut allocation = FrameAllocation::default();
        for page in wanted {
            if let Some(&physical) = self.resident.get(&page) {
                let slot = &mut self.slots[physical as usize];
                let state = if slot.stale { PageState::Dirty } else { PageState::Kept };
                if slot.stale {
                    slot.drawn_in = frame;
                }
                slot.stale = false;
                allocation.granted.push(PageGrant { page, physical, state });
                continue;
            }
            let Some(physical) = free.next() else {
                allocation.refused.push(page);
                continue;
            };
            let slot = &mut self.slots[physical as usize];
            if let Some(old) = slot.page.replace(page) {
                self.resident.remove(&old);
                allocation.evicted += 1;
            }
            *slot = Slot { page: Some(page), last_used: frame, stale: false, drawn_in: frame };
            self.resident.insert(page, physical);
            allocation.granted.push(PageGrant { page, physical, state: PageState::New });
        }
        allocation
    }

    /// Whether, after `allocation` (this frame's), every resident page is drawn this
    /// frame or stale: then nothing in the pool is worth keeping, and its whole
    /// texture may be cleared before the frame's draws (a turned light's frames).
    pub fn keeps_nothing(&self, allocation: &FrameAllocation) -> bool {
        allocation.granted.iter().all(|g| g.state != PageState::Kept)
            && self.slots.iter().all(|s| s.page.is_none() || s.stale || s.last_used == self.frame)
    }

    /// Lays a frame that keeps nothing ([`PagePool::keeps_nothing`]) out anew: its
    /// granted pages take slots 0, 1, 2… in the order of their level, row and column,
    /// so that neighbouring pages of a level's row hold neighbouring slots and may be
    /// drawn as one ([`super::runs::runs`]); every one of them is then drawn as new,
    /// and the resident pages not granted (all stale) are evicted. Returns whether it
    /// did: a frame that keeps a page is left as it is, since moving a kept page
    /// without drawing it would lose it.
    pub fn pack(&mut self, allocation: &mut FrameAllocation) -> bool {
        if !self.keeps_nothing(allocation) {
            return false;
        }
        allocation.evicted += (self.resident.len() - allocation.granted.len()) as u32;
        self.resident.clear();
        self.slots.fill(Slot::default());
        let mut order: Vec<&mut PageGrant> = allocation.granted.iter_mut().collect();
        order.sort_unstable_by_key(|g| (g.page.level, g.page.y, g.page.x));
        for (physical, grant) in (0u32..).zip(order) {
            grant.physical = physical;
            grant.state = PageState::New;
            self.slots[physical as usize] =
                Slot { page: Some(grant.page), last_used: self.frame, stale: false, drawn_in: self.frame };
            self.resident.insert(grant.page, physical);
        }
        true
    }

    /// The page a pixel that asked for `page` reads: the page itself if resident,
    /// else the finest coarser page over the same point that is, up to level
    /// `levels − 1`; None when none is.
    pub fn resolve(&self, page: PageKey, levels: u32) -> Option<(PageKey, u32)> {
        let mut key = page;
        loop {
            if let Some(&physical) = self.resident.get(&key) {
                return Some((key, physical));
            }
            if key.level + 1 >= levels {
                return None;
            }
            key = key.coarser();
        }
    }
}

/// A page-table entry: where a virtual page's texels are, for the sampling shaders.
/// Bit 31 says the entry holds a page; bit 28 that the page read was drawn this frame
/// (for the pages debug view); bits 24 to 27 how many levels coarser that page is
/// than the one asked for (0: the page itself; more: a fallback); bits 0 to 23 its
/// slot in the pool.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct TableEntry(pub u32);

impl TableEntry {
    /// No resident page over this one, itself or coarser.
    pub const EMPTY: TableEntry = TableEntry(0);
    const VALID: u32 = 1 << 31;
    const DRAWN: u32 = 1 << 28;
    const SLOT_BITS: u32 = 24;

    /// The entry for a page read from `slot`, `coarser` levels up.
    pub fn new(slot: u32, coarser: u32) -> TableEntry {
        debug_assert!(slot < 1 << Self::SLOT_BITS && coarser < 16);
        TableEntry(Self::VALID | (coarser << Self::SLOT_BITS) | slot)
    }

    /// The entry, saying that its page was drawn this frame where `drawn`.
    pub fn drawn_if(self, drawn: bool) -> TableEntry {
        TableEntry(if drawn { self.0 | Self::DRAWN } else { self.0 & !Self::DRAWN })
    }

    /// Whether the page it reads was drawn this frame.
    pub fn drawn(self) -> bool {
        self.0 & Self::DRAWN != 0
    }

    /// The slot and how many levels coarser, if the entry holds a page.
    pub fn get(self) -> Option<(u32, u32)> {
        (self.0 & Self::VALID != 0)
            .then_some((self.0 & ((1 << Self::SLOT_BITS) - 1), (self.0 >> Self::SLOT_BITS) & 0xf))
    }
}

impl PagePool {
    /// The page table of `clipmap`: for every page of every level's window, level
    /// after level and row after row from each level's first page, where its texels
    /// are, resolved to a coarser resident page where it is not resident itself
    /// ([`PagePool::resolve`]). What the sampling shaders read.
    ///
    /// Built in one sweep from the coarsest level down, each entry that holds no page
    /// taking its parent's one level further up (each level's window lies inside the
    /// next one's, so a page's parent is in the table): linear in the table's size,
    /// where resolving each entry alone walked up the levels through the pool's map.
    pub fn page_table(&self, clipmap: &super::Clipmap) -> Vec<TableEntry> {
        let shape = clipmap.shape;
        let side = shape.pages_per_side() as i32;
        let per_level = (side * side) as usize;
        let levels = clipmap.origins.len();
        let mut table = vec![TableEntry::EMPTY; levels * per_level];
        let index = |page: PageKey| -> Option<usize> {
            let origin = clipmap.origins.get(page.level as usize)?;
            let (x, y) = (page.x - origin.x, page.y - origin.y);
            ((0..side).contains(&x) && (0..side).contains(&y))
                .then(|| page.level as usize * per_level + (y * side + x) as usize)
        };
        for (&page, &slot) in &self.resident {
            if let Some(i) = index(page) {
                let drawn = self.slots[slot as usize].drawn_in == self.frame;
                table[i] = TableEntry::new(slot, 0).drawn_if(drawn);
            }
        }
        for level in (0..levels.saturating_sub(1)).rev() {
            let origin = clipmap.origins[level];
            for y in 0..side {
                for x in 0..side {
                    let i = level * per_level + (y * side + x) as usize;
                    if table[i] != TableEntry::EMPTY {
                        continue;
                    }
                    let page = PageKey { level: level as u32, x: origin.x + x, y: origin.y + y };
                    let parent = index(page.coarser()).map(|p| table[p]);
                    if let Some((entry, (slot, coarser))) = parent.and_then(|e| Some((e, e.get()?))) {
                        table[i] = TableEntry::new(slot, coarser + 1).drawn_if(entry.drawn());
                    }
                }
            }
        }
        table
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::test_rng::Lcg;

    /// The invariant stated at the top of this module.
    pub(crate) fn check_invariant(pool: &PagePool, allocation: &FrameAllocation) {
        for (s, slot) in pool.slots.iter().enumerate() {
            if let Some(page) = slot.page {
                assert_eq!(pool.resident.get(&page), Some(&(s as u32)), "slot {s} holds {page:?}");
            }
        }
        for (page, &s) in &pool.resident {
            assert_eq!(pool.slots[s as usize].page, Some(*page), "{page:?} is resident in slot {s}");
        }
        for grant in &allocation.granted {
            assert_eq!(pool.resident.get(&grant.page), Some(&grant.physical), "{grant:?} was evicted");
        }
        let slots: std::collections::HashSet<u32> = allocation.granted.iter().map(|g| g.physical).collect();
        assert_eq!(slots.len(), allocation.granted.len(), "two grants share a slot");
        if !allocation.refused.is_empty() {
            assert_eq!(allocation.granted.len() as u32, pool.capacity(), "refused with room left");
        }
    }

    fn page(level: u32, x: i32, y: i32) -> PageKey {
        PageKey { level, x, y }
    }

    #[test]
    fn a_still_scene_draws_no_page_after_the_first_frame() {
        let mut pool = PagePool::new(16);
        let requests = [page(0, 0, 0), page(0, 1, 0), page(1, 0, 0), page(0, 0, 0)];
        let first = pool.allocate(&requests);
        check_invariant(&pool, &first);
        assert_eq!(first.to_draw().count(), 3);
        let second = pool.allocate(&requests);
        check_invariant(&pool, &second);
        assert_eq!(second.to_draw().count(), 0, "{second:?}");
        assert_eq!(second.granted.len(), 3);
    }

    #[test]
    fn a_turned_light_draws_every_page_again_in_the_same_slots() {
        let mut pool = PagePool::new(8);
        let requests = [page(0, 0, 0), page(2, -1, 3)];
        let first = pool.allocate(&requests);
        pool.invalidate_all();
        let second = pool.allocate(&requests);
        check_invariant(&pool, &second);
        assert!(second.granted.iter().all(|g| g.state == PageState::Dirty), "{second:?}");
        let slots = |a: &FrameAllocation| a.granted.iter().map(|g| g.physical).collect::<Vec<_>>();
        assert_eq!(slots(&first), slots(&second));
        assert_eq!(pool.allocate(&requests).to_draw().count(), 0);
    }

    #[test]
    fn an_overfull_pool_refuses_the_finest_pages_and_they_fall_back() {
        let mut pool = PagePool::new(3);
        let coarse = page(3, 0, 0);
        let fine: Vec<PageKey> = (0..4).map(|i| page(0, i, 0)).collect();
        let mut requests = fine.clone();
        requests.push(coarse);
        let allocation = pool.allocate(&requests);
        check_invariant(&pool, &allocation);
        assert_eq!(allocation.refused.len(), 2, "{allocation:?}");
        assert!(allocation.granted.iter().any(|g| g.page == coarse), "the coarse page goes first");
        for refused in &allocation.refused {
            let (read, _) = pool.resolve(*refused, 4).expect("a coarser page is resident");
            assert_eq!(read, coarse, "{refused:?} reads the resident level-3 page over it");
        }
        // Nothing coarser is resident over a point elsewhere.
        assert_eq!(pool.resolve(page(0, 100, 0), 4), None);
    }

    #[test]
    fn pages_requested_this_frame_are_never_evicted_and_the_least_recently_used_go_first() {
        let mut pool = PagePool::new(4);
        pool.allocate(&[page(0, 0, 0), page(0, 1, 0)]);
        pool.allocate(&[page(0, 2, 0), page(0, 3, 0)]);
        // Touch (0, 0) again, so (0, 1) is the least recently used.
        pool.allocate(&[page(0, 0, 0)]);
        let allocation = pool.allocate(&[page(0, 0, 0), page(0, 9, 0)]);
        check_invariant(&pool, &allocation);
        assert_eq!(allocation.evicted, 1);
        assert!(pool.resolve(page(0, 1, 0), 1).is_none(), "the least recently used page left");
        assert!(pool.resolve(page(0, 2, 0), 1).is_some());
    }

    #[test]
    fn invalidating_a_region_dirties_only_the_resident_pages_in_it() {
        let mut pool = PagePool::new(8);
        let requests: Vec<PageKey> = (0..6).map(|i| page(0, i, 0)).collect();
        pool.allocate(&requests);
        let marked = pool.invalidate(|p| (2..=3).contains(&p.x));
        assert_eq!(marked, 2);
        let allocation = pool.allocate(&requests);
        let drawn: Vec<i32> = allocation.to_draw().map(|g| g.page.x).collect();
        assert_eq!(drawn, vec![2, 3]);
        assert!(allocation.to_draw().all(|g| g.state == PageState::Dirty));
    }

    #[test]
    fn the_invariant_holds_over_random_frames() {
        let mut rng = Lcg(7);
        let mut pool = PagePool::new(24);
        for _ in 0..300 {
            let count = (rng.next() * 40.0) as usize;
            let requests: Vec<PageKey> = (0..count)
                .map(|_| {
                    page((rng.next() * 4.0) as u32, (rng.next() * 12.0) as i32 - 6, (rng.next() * 3.0) as i32)
                })
                .collect();
            if rng.next() < 0.1 {
                pool.invalidate_all();
            }
            let allocation = pool.allocate(&requests);
            check_invariant(&pool, &allocation);
            let distinct: std::collections::HashSet<PageKey> = requests.iter().copied().collect();
            assert_eq!(allocation.granted.len() + allocation.refused.len(), distinct.len());
            // Refused pages are never coarser than a granted new one.
            if let Some(coarsest_refused) = allocation.refused.iter().map(|p| p.level).max() {
                let new = allocation.granted.iter().filter(|g| g.state == PageState::New);
                assert!(new.into_iter().all(|g| g.page.level >= coarsest_refused));
            }
        }
    }

    #[test]
    fn the_page_table_points_every_page_at_itself_or_its_fallback() {
        use glam::Vec3;
        let shape = super::super::ClipmapShape { virtual_resolution: 1024, page_size: 128, levels: 4 };
        let bounds = crate::Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
        let clipmap = super::super::Clipmap::new(shape, Vec3::NEG_Y, Vec3::ZERO, &bounds, 0.5);
        let origin = clipmap.origins[0];
        let fine = page(0, origin.x + 2, origin.y + 3);
        let coarse = fine.coarser().coarser();
        let mut pool = PagePool::new(2);
        pool.allocate(&[fine, coarse]);
        let table = pool.page_table(&clipmap);
        let side = shape.pages_per_side() as usize;
        assert_eq!(table.len(), 4 * side * side);
        let index = |p: PageKey| {
            let o = clipmap.origins[p.level as usize];
            p.level as usize * side * side + (p.y - o.y) as usize * side + (p.x - o.x) as usize
        };
        let slot = |p: PageKey| pool.resident[&p];
        // Every page of every window: itself where resident, else the coarse page two
        // levels up from level 0 (one from level 1) where it lies under it, else none.
        for level in 0..4u32 {
            let o = clipmap.origins[level as usize];
            for y in 0..side as i32 {
                for x in 0..side as i32 {
                    let p = page(level, o.x + x, o.y + y);
                    let ancestor = (level..2).fold(p, |k, _| k.coarser());
                    let expected = if p == fine {
                        Some((slot(fine), 0))
                    } else if level <= 2 && ancestor == coarse {
                        Some((slot(coarse), 2 - level))
                    } else {
                        None
                    };
                    assert_eq!(table[index(p)].get(), expected, "{p:?}");
                }
            }
        }
        let valid = table.iter().filter(|e| e.get().is_some()).count();
        // The coarse page (level 2) covers 4×4 pages of level 0 and 2×2 of level 1.
        assert_eq!(valid, 16 + 4 + 1);
        // Both were drawn this frame, and every entry that reads them says so; the
        // next frame keeps them, drawn in no frame but the first.
        assert!(table.iter().all(|e| e.get().is_none() || e.drawn()));
        pool.allocate(&[fine, coarse]);
        let kept = pool.page_table(&clipmap);
        assert!(kept.iter().all(|e| !e.drawn()));
        assert_eq!(kept.iter().filter(|e| e.get().is_some()).count(), valid);
        // A stale page drawn again is marked, the other not.
        pool.invalidate(|p| p == fine);
        pool.allocate(&[fine, coarse]);
        let redrawn = pool.page_table(&clipmap);
        assert!(redrawn[index(fine)].drawn() && !redrawn[index(coarse)].drawn());
    }

    /// The sweep that builds the table gives every entry what resolving it alone
    /// gives, for pools filled at random over a moving window.
    #[test]
    fn the_page_table_resolves_each_entry_as_resolve_does() {
        use glam::Vec3;
        let shape = super::super::ClipmapShape { virtual_resolution: 2048, page_size: 128, levels: 5 };
        let bounds = crate::Aabb::new(Vec3::splat(-40.0), Vec3::splat(40.0));
        let mut rng = Lcg(11);
        let mut pool = PagePool::new(40);
        for step in 0..6 {
            let camera = Vec3::new(3.0 * step as f32, 0.0, -2.0 * step as f32);
            let clipmap = super::super::Clipmap::new(shape, Vec3::new(0.3, -1.0, 0.2), camera, &bounds, 0.4);
            let side = shape.pages_per_side() as i32;
            let requests: Vec<PageKey> = (0..60)
                .map(|_| {
                    let level = (rng.next() * shape.levels as f32) as u32 % shape.levels;
                    let o = clipmap.origins[level as usize];
                    let (x, y) = ((rng.next() * side as f32) as i32, (rng.next() * side as f32) as i32);
                    page(level, o.x + x.min(side - 1), o.y + y.min(side - 1))
                })
                .collect();
            pool.allocate(&requests);
            let table = pool.page_table(&clipmap);
            let mut i = 0;
            for (level, o) in clipmap.origins.iter().enumerate() {
                for y in 0..side {
                    for x in 0..side {
                        let p = page(level as u32, o.x + x, o.y + y);
                        let resolved =
                            pool.resolve(p, shape.levels).map(|(found, slot)| (slot, found.level - p.level));
                        assert_eq!(table[i].get(), resolved, "step {step}, {p:?}");
                        i += 1;
                    }
                }
            }
        }
    }

    #[test]
    fn a_pool_keeps_nothing_only_when_every_resident_page_is_drawn_or_stale() {
        let mut pool = PagePool::new(4);
        let (a, b, c) = (page(0, 0, 0), page(0, 1, 0), page(1, 0, 0));
        assert!(pool.keeps_nothing(&pool.clone().allocate(&[a, b])), "a first frame draws every page");
        pool.allocate(&[a, b]);
        // A still frame keeps both.
        let still = pool.allocate(&[a, b]);
        assert!(!pool.keeps_nothing(&still));
        // A page not asked for, still valid, must survive: nothing may be cleared.
        let other = pool.allocate(&[c]);
        assert!(!pool.keeps_nothing(&other), "a and b are resident, valid, and not drawn");
        // The light turns: every page is stale, those asked for drawn again.
        pool.invalidate_all();
        let turned = pool.allocate(&[a]);
        assert!(turned.granted.iter().all(|g| g.state == PageState::Dirty));
        assert!(pool.keeps_nothing(&turned), "b and c are stale");
    }
}
