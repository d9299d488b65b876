//! The pages along a virtual map's shadow edges (`shadow.virtual_map.edge_levels`):
//! adaptive shadow maps (Fernando, Fernandez, Bala and Greenberg, SIGGRAPH 2001) on
//! the virtual map's pages.
//!
//! The refinement traces the pixels whose footprint the map is unsure of, a band
//! along every shadow edge as wide as the footprint test's block of texels
//! (`rays/refine_virtual.wgsl`). After a light's trace pass, [`EdgeRequests`] has
//! each listed pixel ask for the pages one level finer than the level it read, round
//! its point (`edge_requests.wgsl`); the next frame reads those bits back
//! ([`EdgeFeedback::collect`]) and draws the pages with the ones its pixels ask for.
//! A pixel reads the finest level whose pages hold its whole footprint
//! (`virtual_read_level` in virtual_visibility.wgsl), where the band is half as wide,
//! and so on down `edge_levels` levels. The pages asked for are kept while the light
//! and the map's levels stand still ([`EdgeFeedback::forget`] drops them when they
//! move): a page stays an edge's as long as nothing moves, and a pixel that reads it
//! is sure and asks for nothing, so dropping it would bring the edge back.

use gnomon_math::virtual_map::{Clipmap, PageKey};

use super::{PageRequestParams, buffer_binding, compute_entry, compute_pipeline, decode, page_words};
use crate::{
    Gpu, RenderError,
    pool::{Binding, Pool},
};

/// The pass that turns a light's list of traced pixels into requests for the pages
/// one level finer round them.
pub(crate) struct EdgeRequests {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    /// Its uniforms and bind groups.
    pool: Pool,
}

/// A light's pages along shadow edges: those asked for so far, and the bits the
/// last frame's pass wrote, waiting to be read.
pub(crate) struct EdgeFeedback {
    /// The pass's bits, in the request pass's layout.
    bits: wgpu::Buffer,
    /// Their copy, read back by the next frame.
    readback: wgpu::Buffer,
    /// The clipmap the bits waiting in `readback` are relative to (their levels'
    /// origins), where a frame recorded the pass.
    pending: Option<Clipmap>,
    /// The pages asked for since the light last moved, in [`PageKey`] order.
    pages: Vec<PageKey>,
    /// Its two buffers, held.
    _pool: Pool,
}

impl EdgeRequests {
    /// Builds the pass on `gpu`; group 1 is the trace pass's (`screen`: the camera,
    /// the prepass, the list and the light's counters).
    pub fn new(gpu: &Gpu, screen: &wgpu::BindGroupLayout) -> Result<EdgeRequests, RenderError> {
        gpu.checked("building the edge-page request pass", || {
            let device = &gpu.device;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("edge page requests"),
                entries: &[
                    compute_entry(1, buffer_binding(wgpu::BufferBindingType::Storage { read_only: false })),
                    compute_entry(2, buffer_binding(wgpu::BufferBindingType::Uniform)),
                ],
            });
            let pipeline = compute_pipeline(
                device,
                "edge page requests",
                edge_requests_wgsl(),
                "request_edge_pages",
                &[&layout, screen],
            );
            EdgeRequests { layout, pipeline, pool: Pool::new(device) }
        })
    }

    /// Records the pass for the light whose list and counters `screen` binds (its
    /// counters at `counter_offset` in `counters`, the dispatch's arguments), into
    /// `feedback`'s bits, cleared first, and their copy for the next frame.
    pub fn record(&mut self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder, target: EdgeTarget<'_>) {
        let EdgeTarget { params, clipmap, screen, counters, counter_offset, feedback } = target;
        let uniform = self.pool.uniform(&gpu.queue, "edge page request parameters", &params);
        let bits = feedback.bits.clone();
        let group = self.pool.bind_group_numbered(
            "edge page requests",
            &self.layout,
            vec![(1, Binding::Buffer(bits.clone())), (2, Binding::Buffer(uniform))],
        );
        encoder.clear_buffer(&bits, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("edge page requests"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.set_bind_group(1, screen, &[counter_offset]);
            pass.dispatch_workgroups_indirect(counters, u64::from(counter_offset));
        }
        encoder.copy_buffer_to_buffer(&bits, 0, &feedback.readback, 0, bits.size());
        feedback.pending = Some(clipmap.clone());
    }

    /// Ends the pass's frame: its uniforms and bind groups may be handed out again.
    pub fn end_frame(&mut self) {
        self.pool.end_frame();
    }
}

/// What [`EdgeRequests::record`] records for one light.
pub(crate) struct EdgeTarget<'a> {
    /// The request pass's parameters for this frame's clipmap, with `edge_levels`.
    pub params: PageRequestParams,
    /// This frame's clipmap, which the bits are relative to.
    pub clipmap: &'a Clipmap,
    /// Group 1 of the trace pass: the camera, the prepass, the list, the counters.
    pub screen: &'a wgpu::BindGroup,
    /// Every light's counters.
    pub counters: &'a wgpu::Buffer,
    /// This light's counters' offset in `counters`.
    pub counter_offset: u32,
    /// The light's feedback.
    pub feedback: &'a mut EdgeFeedback,
}

impl EdgeFeedback {
    /// Feedback for a clipmap of `clipmap`'s shape, nothing asked for yet.
    pub fn new(gpu: &Gpu, clipmap: &Clipmap) -> EdgeFeedback {
        let mut pool = Pool::new(&gpu.device);
        let bytes = 4 * page_words(clipmap);
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let bits = pool.buffer("edge page bits", bytes, usage);
        let readback = pool.buffer(
            "edge page bits, read back",
            bytes,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        );
        pool.hold(&bits);
        pool.hold(&readback);
        EdgeFeedback { bits, readback, pending: None, pages: vec![], _pool: pool }
    }

    /// Whether it was made for a clipmap of `clipmap`'s shape.
    pub fn fits(&self, clipmap: &Clipmap) -> bool {
        self.bits.size() == 4 * page_words(clipmap)
    }

    /// Reads back the pages the last frame's pass asked for, if it ran, and adds
    /// them to those asked for before. Returns how many pages are new; `None` where
    /// no pass ran since the light last moved.
    pub async fn collect(&mut self, gpu: &Gpu) -> Result<Option<u32>, RenderError> {
        let Some(clipmap) = self.pending.take() else { return Ok(None) };
        let words: Vec<u32> = crate::readback::read_buffer(gpu, &self.readback).await?;
        let before = self.pages.len();
        self.pages.extend(decode(&words, &clipmap));
        self.pages.sort_unstable();
        self.pages.dedup();
        Ok(Some((self.pages.len() - before) as u32))
    }

    /// Drops every page asked for, and the bits waiting: the light or the map's
    /// levels changed, and with them where the edges are.
    pub fn forget(&mut self) {
        self.pending = None;
        self.pages.clear();
    }

    /// The pages asked for that a frame of `clipmap` draws with `requested` (in
    /// [`PageKey`] order) in a pool with `room` tiles left ([`edge_pages_to_add`]).
    pub fn pages_to_add(&self, clipmap: &Clipmap, requested: &[PageKey], room: usize) -> Vec<PageKey> {
        edge_pages_to_add(&self.pages, clipmap, requested, room)
    }
}

/// Of the pages along edges `edges`, those in `clipmap`'s levels' windows and not in
/// `requested` (in [`PageKey`] order), coarse levels first (a pixel reads a level
/// only where it read the one above), at most `room` of them.
pub(crate) fn edge_pages_to_add(
    edges: &[PageKey],
    clipmap: &Clipmap,
    requested: &[PageKey],
    room: usize,
) -> Vec<PageKey> {
    let side = clipmap.shape.pages_per_side() as i32;
    let mut pages: Vec<PageKey> = edges
        .iter()
        .filter(|page| {
            clipmap.origins.get(page.level as usize).is_some_and(|origin| {
                (0..side).contains(&(page.x - origin.x)) && (0..side).contains(&(page.y - origin.y))
            })
        })
        .filter(|page| requested.binary_search(page).is_err())
        .copied()
        .collect();
    pages.sort_by_key(|page| std::cmp::Reverse(page.level));
    pages.truncate(room);
    pages
}

/// `edge_requests.wgsl` (with `page_requests.wgsl`), composed.
pub(crate) fn edge_requests_wgsl() -> String {
    use crate::passes::{CAMERA_STRUCT_WGSL, OWN_CAMERA_BINDING, camera_binding_wgsl};
    let camera = camera_binding_wgsl(OWN_CAMERA_BINDING);
    let groups = crate::rays::refine::list_wgsl();
    crate::passes::compose_wgsl(&[CAMERA_STRUCT_WGSL, &camera, &groups, include_str!("edge_requests.wgsl")])
}

#[cfg(test)]
mod tests {
    use glam::{IVec2, Vec3};
    use gnomon_math::{
        Aabb,
        virtual_map::{Clipmap, ClipmapShape, PageKey},
    };

    use super::edge_pages_to_add;

    #[test]
    fn edge_pages_are_those_in_the_windows_not_asked_for_coarse_first_within_the_room() {
        let bounds = Aabb::new(Vec3::splat(-50.0), Vec3::splat(50.0));
        let clipmap =
            Clipmap::new(ClipmapShape::DEFAULT, Vec3::new(-0.3, -1.0, 0.2), Vec3::ZERO, &bounds, 0.01);
        let side = clipmap.shape.pages_per_side() as i32;
        let at = |level: u32, offset: IVec2| {
            let o = clipmap.origins[level as usize] + offset;
            PageKey { level, x: o.x, y: o.y }
        };
        let (a, b, c) = (at(0, IVec2::new(3, 4)), at(1, IVec2::new(0, 0)), at(2, IVec2::new(side - 1, 2)));
        let outside = at(1, IVec2::new(side, 0));
        let asked = at(0, IVec2::new(5, 5));
        let mut edges = vec![a, b, c, outside, asked];
        edges.sort_unstable();
        let requested = vec![asked];
        assert_eq!(edge_pages_to_add(&edges, &clipmap, &requested, 10), vec![c, b, a]);
        assert_eq!(edge_pages_to_add(&edges, &clipmap, &requested, 2), vec![c, b]);
        assert_eq!(edge_pages_to_add(&edges, &clipmap, &requested, 0), vec![]);
    }
}
