//! Pass times read without stalling: a live frame's timestamps are mapped in the
//! background and read one frame later, after the next frame is submitted, so that
//! the CPU never waits for the frame it has just submitted and the GPU always has the
//! next one queued. Their readback buffer is held out of the pool until then, so that
//! no frame writes into a buffer still being mapped; two such buffers alternate, which
//! keeps the steady state free of creations whatever the GPU's timing.

use std::collections::VecDeque;

use super::outputs::TimedLights;
use crate::{Gpu, RenderError, pool::Pool, timing::PendingTimes};

/// A frame whose times have not arrived.
struct InFlight {
    times: PendingTimes,
    /// What the frame's lights drew, to be timed.
    lights: TimedLights,
}

/// The ring of frames in flight, and the latest frame timed.
#[derive(Default)]
pub(super) struct LateTimes {
    in_flight: VecDeque<InFlight>,
    /// The latest frame whose times arrived, and how many frames have been pushed
    /// since it was.
    latest: Option<(TimedLights, u32)>,
}

impl LateTimes {
    /// Adds a submitted frame and returns the latest frame's times that have arrived
    /// (this one's at the earliest), its stats replaced by `lights`' draws.
    pub async fn push(
        &mut self,
        gpu: &Gpu,
        pool: &mut Pool,
        times: PendingTimes,
        lights: TimedLights,
    ) -> Result<TimedLights, RenderError> {
        if let Some(buffer) = times.ticks_buffer() {
            pool.hold(buffer);
        }
        if let Some((_, age)) = &mut self.latest {
            *age += 1;
        }
        self.in_flight.push_back(InFlight { times, lights: lights.clone() });
        // Every frame before this one: mapped in the background since its submission,
        // so the read rarely waits.
        while self.in_flight.len() > 1 {
            let InFlight { times, lights: drawn } = self.in_flight.pop_front().expect("a front frame");
            let buffer = times.ticks_buffer().cloned();
            let read = times.read(gpu).await;
            if let Some(buffer) = buffer {
                pool.release(&buffer);
            }
            self.latest = Some((drawn.timed(read?), self.in_flight.len() as u32));
        }
        // This frame's draws, the latest arrived frame's times.
        let mut reported = lights;
        if let Some((timed, _)) = &self.latest {
            for (light, arrived) in reported.lights.iter_mut().zip(&timed.lights) {
                light.layer_ms = arrived.layer_ms.clone();
                light.shadow_ms = arrived.shadow_ms;
                light.filter_ms = arrived.filter_ms;
                light.lighting_ms = arrived.lighting_ms;
                light.mask_ms = arrived.mask_ms;
                light.trace_ms = arrived.trace_ms;
            }
            reported.passes = timed.passes.clone();
            reported.timings = timed.timings;
        }
        Ok(reported)
    }

    /// How many frames old the latest arrived times are.
    pub fn latest_age(&self) -> u32 {
        self.latest.as_ref().map_or(0, |(_, age)| *age)
    }
}
