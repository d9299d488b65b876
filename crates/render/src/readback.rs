//! Copying textures and buffers back to the CPU: row padding to wgpu's 256-byte
//! alignment on the way out, removed again on the way in; and the wait for a
//! mapping, as a future ([`Mapped`]).
//!
//! Every read is `async`, because a browser cannot block: WebGPU maps a buffer when
//! the page's event loop runs again, so the wait must yield to it. On a native
//! device the future is ready as soon as it is made: making it polls the device
//! until the mapping is done, and `pollster::block_on` drives it to its end at once.

use std::{
    future::Future,
    pin::Pin,
    sync::{Arc, Mutex, PoisonError},
    task::{Context, Poll, Waker},
};

use crate::{Gpu, RenderError, pool::Pool};

/// What a `map_async` callback reports, and who waits for it.
#[derive(Default)]
struct MapState {
    result: Option<Result<(), wgpu::BufferAsyncError>>,
    waker: Option<Waker>,
}

/// A buffer's mapping for reading, as a future: ready once the GPU has finished the
/// work before it and the buffer is mapped.
pub(crate) struct Mapped {
    state: Arc<Mutex<MapState>>,
}

impl Mapped {
    /// Starts mapping `slice` for reading. On a native device it also waits for the
    /// GPU, so that the future is ready at once; in a browser the mapping completes
    /// when the page's event loop next runs.
    fn begin(gpu: &Gpu, slice: &wgpu::BufferSlice<'_>) -> Result<Self, RenderError> {
        let mapped = Self::start(slice);
        wait_for_gpu(gpu)?;
        Ok(mapped)
    }

    /// Starts mapping `slice` for reading, without waiting for the GPU.
    fn start(slice: &wgpu::BufferSlice<'_>) -> Self {
        let state = Arc::new(Mutex::new(MapState::default()));
        let callback_state = state.clone();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            let mut state = callback_state.lock().unwrap_or_else(PoisonError::into_inner);
            state.result = Some(result);
            if let Some(waker) = state.waker.take() {
                waker.wake();
            }
        });
        Self { state }
    }

    /// Whether the mapping has finished (done or failed).
    fn is_done(&self) -> bool {
        self.state.lock().unwrap_or_else(PoisonError::into_inner).result.is_some()
    }
}

impl Future for Mapped {
    type Output = Result<(), RenderError>;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        let mut state = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        match state.result.clone() {
            Some(result) => Poll::Ready(result.map_err(|e| RenderError::Gpu {
                during: "mapping a readback buffer",
                message: e.to_string(),
            })),
            None => {
                state.waker = Some(cx.waker().clone());
                Poll::Pending
            }
        }
    }
}

/// Waits for the GPU to finish what was submitted, which runs the mapping
/// callbacks. A browser has no such wait: its callbacks run from the event loop.
#[cfg(not(target_arch = "wasm32"))]
fn wait_for_gpu(gpu: &Gpu) -> Result<(), RenderError> {
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(drop)
        .map_err(|e| RenderError::Gpu { during: "waiting for the GPU", message: e.to_string() })
}

#[cfg(target_arch = "wasm32")]
fn wait_for_gpu(_gpu: &Gpu) -> Result<(), RenderError> {
    Ok(())
}

/// A texture copy recorded into an encoder, waiting to be mapped.
pub(crate) struct PendingReadback {
    buffer: wgpu::Buffer,
    width: u32,
    height: u32,
    /// Array layers, each `height` rows.
    layers: u32,
    bytes_per_texel: u32,
    padded_bytes_per_row: u32,
}

/// Records a copy of mip 0 of `texture` (of `aspect`), every array layer, into a
/// mappable buffer.
pub(crate) fn record(
    pool: &mut Pool,
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    aspect: wgpu::TextureAspect,
) -> PendingReadback {
    record_level(pool, encoder, texture, aspect, 0)
}

/// [`record`] of mip `level`.
pub(crate) fn record_level(
    pool: &mut Pool,
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    aspect: wgpu::TextureAspect,
    level: u32,
) -> PendingReadback {
    let layers = texture.depth_or_array_layers();
    let (width, height) = ((texture.width() >> level).max(1), (texture.height() >> level).max(1));
    let bytes_per_texel = texture.format().block_copy_size(Some(aspect)).unwrap_or(4);
    let unpadded = width * bytes_per_texel;
    let padded_bytes_per_row =
        unpadded.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = pool.buffer(
        "readback",
        padded_bytes_per_row as u64 * height as u64 * layers as u64,
        wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
    );
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo { texture, mip_level: level, origin: wgpu::Origin3d::ZERO, aspect },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded_bytes_per_row),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d { width, height, depth_or_array_layers: layers },
    );
    PendingReadback { buffer, width, height, layers, bytes_per_texel, padded_bytes_per_row }
}

/// Copies mip 0 of a colour `texture` back to the CPU: texels row-major, top row
/// first, in the texture's own format.
pub async fn read_texture_async<T: bytemuck::Pod>(
    gpu: &Gpu,
    texture: &wgpu::Texture,
) -> Result<Vec<T>, RenderError> {
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let pending = record(&mut Pool::new(&gpu.device), &mut encoder, texture, wgpu::TextureAspect::All);
    gpu.queue.submit([encoder.finish()]);
    pending.read(gpu).await
}

/// [`read_texture_async`], waiting for it (not in a browser, which cannot wait).
#[cfg(not(target_arch = "wasm32"))]
pub fn read_texture<T: bytemuck::Pod>(gpu: &Gpu, texture: &wgpu::Texture) -> Result<Vec<T>, RenderError> {
    pollster::block_on(read_texture_async(gpu, texture))
}

/// Timestamp queries resolved and copied into a mappable buffer.
pub(crate) struct PendingTimestamps {
    buffer: wgpu::Buffer,
}

/// Timestamps being mapped in the background.
pub(crate) struct MappingTimestamps {
    buffer: wgpu::Buffer,
    mapped: Mapped,
}

impl MappingTimestamps {
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// The ticks, once the mapping has finished.
    pub async fn read(self, gpu: &Gpu) -> Result<Vec<u64>, RenderError> {
        if !self.mapped.is_done() {
            wait_for_gpu(gpu)?;
        }
        self.mapped.await?;
        let ticks = {
            let mapped = self
                .buffer
                .slice(..)
                .get_mapped_range()
                .map_err(|e| RenderError::Gpu { during: "mapping timestamps", message: e.to_string() })?;
            bytemuck::cast_slice::<u8, u64>(&mapped).to_vec()
        };
        self.buffer.unmap();
        Ok(ticks)
    }
}

/// Records the resolve of `count` timestamps from `query_set` and their copy out.
pub(crate) fn record_timestamps(
    pool: &mut Pool,
    encoder: &mut wgpu::CommandEncoder,
    query_set: &wgpu::QuerySet,
    count: u32,
) -> PendingTimestamps {
    let size = (count as u64) * wgpu::QUERY_SIZE as u64;
    let resolve = pool.buffer(
        "timestamp resolve",
        size,
        wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
    );
    let buffer =
        pool.buffer("timestamp readback", size, wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ);
    encoder.resolve_query_set(query_set, 0..count, &resolve, 0);
    encoder.copy_buffer_to_buffer(&resolve, 0, &buffer, 0, size);
    PendingTimestamps { buffer }
}

impl PendingTimestamps {
    /// The buffer the ticks are copied into.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Starts mapping the buffer (after the submission) without waiting for the GPU:
    /// [`MappingTimestamps::read`] waits, if it must, when the ticks are wanted.
    pub fn begin_map(self) -> MappingTimestamps {
        let mapped = Mapped::start(&self.buffer.slice(..));
        MappingTimestamps { buffer: self.buffer, mapped }
    }
}

impl PendingReadback {
    /// Maps the buffer (after the copy's submission) and returns the tightly packed
    /// texels, top row first, layer after layer.
    pub async fn read<T: bytemuck::Pod>(self, gpu: &Gpu) -> Result<Vec<T>, RenderError> {
        let slice = self.buffer.slice(..);
        Mapped::begin(gpu, &slice)?.await?;
        let row = (self.width * self.bytes_per_texel) as usize;
        let rows = (self.height * self.layers) as usize;
        let mut bytes = Vec::with_capacity(row * rows);
        {
            let mapped = slice.get_mapped_range().map_err(|e| RenderError::Gpu {
                during: "mapping a readback buffer",
                message: e.to_string(),
            })?;
            // With rows_per_image = height, layer after layer is row after row.
            for y in 0..rows {
                let start = y * self.padded_bytes_per_row as usize;
                bytes.extend_from_slice(&mapped[start..start + row]);
            }
        }
        self.buffer.unmap();
        // Copy into a properly aligned vector of T.
        let mut out = vec![T::zeroed(); bytes.len() / std::mem::size_of::<T>()];
        bytemuck::cast_slice_mut::<T, u8>(&mut out).copy_from_slice(&bytes);
        Ok(out)
    }
}

/// Maps `buffer` (a MAP_READ copy destination, after the copy's submission) and
/// returns its contents.
pub(crate) async fn read_buffer<T: bytemuck::Pod>(
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
) -> Result<Vec<T>, RenderError> {
    let slice = buffer.slice(..);
    Mapped::begin(gpu, &slice)?.await?;
    let out = {
        let mapped = slice
            .get_mapped_range()
            .map_err(|e| RenderError::Gpu { during: "mapping a readback buffer", message: e.to_string() })?;
        bytemuck::pod_collect_to_vec(&mapped)
    };
    buffer.unmap();
    Ok(out)
}
