//! Pass timing: a timestamp query pair around every pass (each shadow-map layer of
//! each light, the moment filter, the screen-space passes, each light's lighting), or,
//! where the adapter has no timestamp queries, CPU wall-clock time around each pass
//! with the frame cut into one submission per pass.

use web_time::Instant;

use crate::{Gpu, RenderError, pool::Pool, readback};

/// Which kind of pass a time belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PassKind {
    /// The mask path's depth-and-normal prepass from the camera.
    Prepass,
    /// One layer (cascade, cube face, hemisphere or the single map) of a light's map.
    Shadow,
    /// What a light derives from its map: a filterable technique's moment pass
    /// (encoding, blur and mipmaps), the depth pyramid of a light with an area, the
    /// touched layer of a map its rays refine (`rays/touched.rs`).
    Filter,
    /// A light's screen-space shadow-mask pass (with refinement by rays, the
    /// classification of its pixels).
    Mask,
    /// A light's trace pass: the rays of the pixels its mask pass was unsure of.
    Trace,
    /// A light's lighting pass.
    Lighting,
}

impl PassKind {
    /// The kind's lower-case name, as reports and tables print it (`"shadow"`, `"lighting"`, …).
    pub fn name(self) -> &'static str {
        match self {
            PassKind::Prepass => "prepass",
            PassKind::Shadow => "shadow",
            PassKind::Filter => "filter",
            PassKind::Mask => "mask",
            PassKind::Trace => "trace",
            PassKind::Lighting => "lighting",
        }
    }
}

/// How a frame's passes were timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingSource {
    /// Timestamp queries written by the GPU at each pass's start and end.
    GpuTimestamps,
    /// CPU wall-clock time around each pass, submitted and waited for alone. It
    /// includes recording and submission, and serializes the frame, so it reads high.
    CpuWallClock,
}

/// How [`crate::Renderer::time_passes`] should time passes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ClockChoice {
    /// Timestamp queries where the adapter has them, else the CPU wall clock.
    #[default]
    Auto,
    /// The CPU wall clock, even where timestamps exist (to compare, or to test it).
    Cpu,
}

/// One pass's time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassTime {
    /// Which kind of pass this is.
    pub kind: PassKind,
    /// The light's index in the frame, for per-light passes.
    pub light: Option<u32>,
    /// The map layer, for shadow passes.
    pub layer: Option<u32>,
    /// The pass's time in milliseconds (GPU, or CPU wall clock: see [`TimingSource`]).
    pub ms: f64,
}

/// Which of a slot's timestamps a pass writes: a slot may time several commands,
/// from the beginning of its opening pass to the end of its closing one (a copy
/// between them included).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SlotPart {
    /// The slot's one pass: both timestamps.
    Whole,
    /// The first of its passes: the beginning timestamp.
    Opening,
    /// The last of its passes: the end timestamp.
    Closing,
}

/// A pass's place in the clock: its label and, for timestamps, its query pair.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Slot(usize);

enum Mode {
    Off,
    Gpu { query_set: wgpu::QuerySet, capacity: u32 },
    Cpu { started: Option<Instant>, ms: Vec<f64>, first: Option<Instant>, last: Option<Instant> },
}

/// Times the passes of one frame as they are recorded.
pub(crate) struct PassClock {
    mode: Mode,
    labels: Vec<(PassKind, Option<u32>, Option<u32>)>,
}

impl PassClock {
    /// A clock for at most `capacity` passes: timestamps when the device has them,
    /// else, when a clock is `wanted`, the CPU wall clock, else none at all.
    /// [`ClockChoice::Cpu`] chooses the wall clock even where timestamps exist.
    pub fn new(gpu: &Gpu, pool: &mut Pool, capacity: u32, wanted: Option<ClockChoice>) -> Self {
        let cpu_fallback = wanted.is_some();
        let force_cpu = wanted == Some(ClockChoice::Cpu);
        let mode = match gpu.timestamp_period_ns {
            // Query sets are pooled by size: round the count up to a power of two, so
            // that frames of nearby pass counts share one.
            Some(_) if !force_cpu => {
                Mode::Gpu { query_set: pool.timestamps(2 * capacity.max(1).next_power_of_two()), capacity }
            }
            _ if cpu_fallback || force_cpu => {
                Mode::Cpu { started: None, ms: Vec::new(), first: None, last: None }
            }
            _ => Mode::Off,
        };
        Self { mode, labels: Vec::new() }
    }

    /// A clock that times nothing: for passes recorded into a host's encoder, which
    /// Gnomon neither submits nor waits for.
    pub fn off() -> Self {
        Self { mode: Mode::Off, labels: Vec::new() }
    }

    /// Starts timing a pass. On the CPU clock, everything recorded so far is
    /// submitted and waited for first, so the pass is timed alone.
    pub fn begin(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        kind: PassKind,
        light: Option<u32>,
        layer: Option<u32>,
    ) -> Slot {
        let slot = Slot(self.labels.len());
        self.labels.push((kind, light, layer));
        match &mut self.mode {
            Mode::Gpu { capacity, .. } => {
                assert!(slot.0 < *capacity as usize, "more timed passes than the clock was made for");
            }
            Mode::Cpu { started, first, .. } => {
                flush(gpu, encoder);
                let now = Instant::now();
                *started = Some(now);
                first.get_or_insert(now);
            }
            Mode::Off => {}
        }
        slot
    }

    /// Ends timing the pass `slot` began (after the pass itself has ended).
    pub fn end(&mut self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder, slot: Slot) {
        if let Mode::Cpu { started, ms, last, .. } = &mut self.mode {
            flush(gpu, encoder);
            let now = Instant::now();
            let start = started.take().expect("a pass ends after it begins");
            ms.resize(slot.0 + 1, 0.0);
            ms[slot.0] = (now - start).as_secs_f64() * 1e3;
            *last = Some(now);
        }
    }

    /// The timestamp writes for a render pass in `slot`.
    pub fn render_writes(&self, slot: Slot) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.render_part(slot, SlotPart::Whole)
    }

    /// The timestamp writes for a render pass that is `part` of what `slot` times.
    pub fn render_part(&self, slot: Slot, part: SlotPart) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let (query_set, beginning, end) = self.indices(slot, part)?;
        Some(wgpu::RenderPassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: beginning,
            end_of_pass_write_index: end,
        })
    }

    /// The timestamp writes for a compute pass in `slot`.
    pub fn compute_writes(&self, slot: Slot) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.compute_part(slot, SlotPart::Whole)
    }

    /// The timestamp writes for a compute pass that is `part` of what `slot` times.
    pub fn compute_part(&self, slot: Slot, part: SlotPart) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let (query_set, beginning, end) = self.indices(slot, part)?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: beginning,
            end_of_pass_write_index: end,
        })
    }

    /// The query set and the timestamps a pass that is `part` of `slot` writes.
    fn indices(&self, slot: Slot, part: SlotPart) -> Option<(&wgpu::QuerySet, Option<u32>, Option<u32>)> {
        let Mode::Gpu { query_set, .. } = &self.mode else { return None };
        let (beginning, end) = (2 * slot.0 as u32, 2 * slot.0 as u32 + 1);
        Some(match part {
            SlotPart::Whole => (query_set, Some(beginning), Some(end)),
            SlotPart::Opening => (query_set, Some(beginning), None),
            SlotPart::Closing => (query_set, None, Some(end)),
        })
    }

    /// Records the copy of the timestamps out of the query set, at the frame's end.
    pub fn resolve(self, pool: &mut Pool, encoder: &mut wgpu::CommandEncoder) -> PendingTimes {
        let pending = match &self.mode {
            Mode::Gpu { query_set, .. } if !self.labels.is_empty() => {
                Some(readback::record_timestamps(pool, encoder, query_set, 2 * self.labels.len() as u32))
            }
            Mode::Gpu { .. } | Mode::Cpu { .. } | Mode::Off => None,
        };
        PendingTimes { clock: self, ticks: pending.map(Ticks::Recorded) }
    }
}

/// Submits what `encoder` holds and waits for the GPU to finish it.
fn flush(gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) {
    let done = std::mem::replace(encoder, gpu.device.create_command_encoder(&Default::default()));
    gpu.queue.submit([done.finish()]);
    // A failed wait leaves the time long, not wrong in kind; the error scope around
    // the frame reports any device error.
    let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
}

/// A frame's pass times, waiting for the GPU.
pub(crate) struct PendingTimes {
    clock: PassClock,
    ticks: Option<Ticks>,
}

/// The GPU's timestamps: copied out in the frame's commands, then (after the frame's
/// submission) being mapped.
enum Ticks {
    Recorded(readback::PendingTimestamps),
    Mapping(readback::MappingTimestamps),
}

/// A frame's pass times and the span of the whole frame.
#[derive(Clone, Debug)]
pub(crate) struct FrameTimes {
    pub passes: Vec<PassTime>,
    pub frame_ms: f64,
    pub source: TimingSource,
}

impl PendingTimes {
    /// Starts mapping the timestamps in the background: call once the frame is
    /// submitted.
    pub fn submitted(self) -> Self {
        let ticks = self.ticks.map(|t| match t {
            Ticks::Recorded(recorded) => Ticks::Mapping(recorded.begin_map()),
            mapping @ Ticks::Mapping(_) => mapping,
        });
        PendingTimes { clock: self.clock, ticks }
    }

    /// The buffer the GPU's timestamps are copied into, while they are pending.
    pub fn ticks_buffer(&self) -> Option<&wgpu::Buffer> {
        match &self.ticks {
            None => None,
            Some(Ticks::Recorded(recorded)) => Some(recorded.buffer()),
            Some(Ticks::Mapping(mapping)) => Some(mapping.buffer()),
        }
    }

    /// The times, waiting for them if they are not ready; None when the frame was
    /// not timed.
    pub async fn read(self, gpu: &Gpu) -> Result<Option<FrameTimes>, RenderError> {
        let labels = &self.clock.labels;
        let pass = |i: usize, ms: f64| {
            let (kind, light, layer) = labels[i];
            PassTime { kind, light, layer, ms }
        };
        match (self.clock.mode, self.ticks) {
            (Mode::Gpu { .. }, Some(ticks)) => {
                let ticks = match ticks {
                    Ticks::Recorded(recorded) => recorded.begin_map().read(gpu).await?,
                    Ticks::Mapping(mapping) => mapping.read(gpu).await?,
                };
                let period = f64::from(gpu.timestamp_period_ns.unwrap_or(1.0)) * 1e-6;
                let passes = (0..labels.len())
                    .map(|i| pass(i, ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64 * period));
                let first = (0..labels.len()).map(|i| ticks[2 * i]).min().unwrap_or(0);
                let last = (0..labels.len()).map(|i| ticks[2 * i + 1]).max().unwrap_or(0);
                Ok(Some(FrameTimes {
                    passes: passes.collect(),
                    frame_ms: last.saturating_sub(first) as f64 * period,
                    source: TimingSource::GpuTimestamps,
                }))
            }
            (Mode::Cpu { ms, first: Some(first), last: Some(last), .. }, _) => Ok(Some(FrameTimes {
                passes: ms.into_iter().enumerate().map(|(i, ms)| pass(i, ms)).collect(),
                frame_ms: (last - first).as_secs_f64() * 1e3,
                source: TimingSource::CpuWallClock,
            })),
            (Mode::Gpu { .. }, None) | (Mode::Cpu { .. }, _) | (Mode::Off, _) => Ok(None),
        }
    }
}
