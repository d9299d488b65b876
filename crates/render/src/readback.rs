//! Copying textures back to the CPU: row padding to wgpu's 256-byte alignment on
//! the way out, and removed again on the way in.

use crate::{Gpu, RenderError, pool::Pool};

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
    let (width, height, layers) = (texture.width(), texture.height(), texture.depth_or_array_layers());
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
        wgpu::TexelCopyTextureInfo { texture, mip_level: 0, origin: wgpu::Origin3d::ZERO, aspect },
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

/// Copies mip 0 of a colour `texture` back to the CPU and waits for it: texels
/// row-major, top row first, in the texture's own format.
pub fn read_texture<T: bytemuck::Pod>(gpu: &Gpu, texture: &wgpu::Texture) -> Result<Vec<T>, RenderError> {
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let pending = record(&mut Pool::new(&gpu.device), &mut encoder, texture, wgpu::TextureAspect::All);
    gpu.queue.submit([encoder.finish()]);
    pending.read(gpu)
}

/// Maps `slice` for reading and waits until it is.
fn map_blocking(gpu: &Gpu, slice: &wgpu::BufferSlice<'_>) -> Result<(), RenderError> {
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = sender.send(r);
    });
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| RenderError::Gpu { during: "waiting for the GPU", message: e.to_string() })?;
    receiver
        .recv()
        .map_err(|e| RenderError::Gpu { during: "reading back", message: e.to_string() })?
        .map_err(|e| RenderError::Gpu { during: "mapping a readback buffer", message: e.to_string() })
}

/// Timestamp queries resolved and copied into a mappable buffer.
pub(crate) struct PendingTimestamps {
    buffer: wgpu::Buffer,
}

/// Timestamps being mapped in the background.
pub(crate) struct MappingTimestamps {
    buffer: wgpu::Buffer,
    state: std::sync::Arc<std::sync::Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>,
}

impl MappingTimestamps {
    fn state(&self) -> Option<Result<(), wgpu::BufferAsyncError>> {
        self.state.lock().unwrap_or_else(std::sync::PoisonError::into_inner).clone()
    }

    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// The ticks, waiting for the mapping if it has not finished.
    pub fn read(self, gpu: &Gpu) -> Result<Vec<u64>, RenderError> {
        while self.state().is_none() {
            gpu.device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| RenderError::Gpu { during: "waiting for the GPU", message: e.to_string() })?;
        }
        if let Some(Err(e)) = self.state() {
            return Err(RenderError::Gpu { during: "mapping timestamps", message: e.to_string() });
        }
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

    /// Starts mapping the buffer (after the submission) without waiting: the ticks
    /// are ready once [`MappingTimestamps::is_ready`] says so.
    pub fn begin_map(self) -> MappingTimestamps {
        let state = std::sync::Arc::new(std::sync::Mutex::new(None));
        let sender = state.clone();
        self.buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            *sender.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(r);
        });
        MappingTimestamps { buffer: self.buffer, state }
    }
}

impl PendingReadback {
    /// Maps the buffer (after the copy's submission) and returns the tightly packed
    /// texels, top row first, layer after layer.
    pub fn read<T: bytemuck::Pod>(self, gpu: &Gpu) -> Result<Vec<T>, RenderError> {
        let slice = self.buffer.slice(..);
        map_blocking(gpu, &slice)?;
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
pub(crate) fn read_buffer<T: bytemuck::Pod>(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<T>, RenderError> {
    let slice = buffer.slice(..);
    map_blocking(gpu, &slice)?;
    let out = {
        let mapped = slice
            .get_mapped_range()
            .map_err(|e| RenderError::Gpu { during: "mapping a readback buffer", message: e.to_string() })?;
        bytemuck::pod_collect_to_vec(&mapped)
    };
    buffer.unmap();
    Ok(out)
}
