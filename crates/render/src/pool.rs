//! The pool of transient GPU resources, kept across frames: textures (with their
//! views), buffers, query sets and bind groups, each found again by its descriptor.
//!
//! A frame asks the pool for what it needs; the pool hands back a resource of that
//! description that no earlier request of the same frame holds, creating one only
//! when none is free. The same frame asked again therefore gets the same resources in
//! the same order, and so the same bind groups: a steady frame creates nothing.
//! Resources unused for [`KEEP_FRAMES`] frames are dropped, so that a changed
//! setting frees what it no longer needs.
//!
//! Resources handed out stay valid until the pool hands them out again, which is no
//! earlier than the next frame ([`Pool::end_frame`]).

use std::collections::HashMap;

/// Frames an unused resource is kept for.
pub(crate) const KEEP_FRAMES: u64 = 3;

/// How many resources of each kind the pool has created: a steady frame adds none.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Creations {
    /// Textures created.
    pub textures: u64,
    /// Texture views created.
    pub views: u64,
    /// Buffers created.
    pub buffers: u64,
    /// Bind groups created.
    pub bind_groups: u64,
    /// Timestamp query sets created.
    pub query_sets: u64,
}

impl Creations {
    /// Every creation, of every kind.
    pub fn total(&self) -> u64 {
        self.textures + self.views + self.buffers + self.bind_groups + self.query_sets
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct TextureKey {
    size: wgpu::Extent3d,
    mip_level_count: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    dimension: wgpu::TextureDimension,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct BufferKey {
    size: u64,
    usage: wgpu::BufferUsages,
}

/// A view of a pooled texture: its dimension and the layers and mips it covers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub(crate) struct ViewKey {
    pub dimension: Option<wgpu::TextureViewDimension>,
    pub base_layer: u32,
    pub layers: Option<u32>,
    pub base_mip: u32,
    pub mips: Option<u32>,
}

impl ViewKey {
    /// The whole texture, with `dimension`.
    pub fn whole(dimension: wgpu::TextureViewDimension) -> Self {
        Self { dimension: Some(dimension), ..Default::default() }
    }

    /// One array layer as a 2D view.
    pub fn layer(layer: u32) -> Self {
        Self {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_layer: layer,
            layers: Some(1),
            ..Default::default()
        }
    }
}

/// One resource binding of a pooled bind group.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Binding {
    Buffer(wgpu::Buffer),
    /// The first `size` bytes of a buffer, for a binding with a dynamic offset that
    /// moves this window along it.
    BufferWindow {
        buffer: wgpu::Buffer,
        size: u64,
    },
    View(wgpu::TextureView),
    Sampler(wgpu::Sampler),
    /// A top-level acceleration structure, for the ray-query tracer.
    Tlas(wgpu::Tlas),
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct BindGroupKey {
    layout: wgpu::BindGroupLayout,
    bindings: Vec<(u32, Binding)>,
}

/// A pooled value and the frame that last used it.
struct Kept<T> {
    value: T,
    used: u64,
    /// Held past its frame ([`Pool::hold`]): not handed out, not dropped.
    held: bool,
}

/// Entries of one description; `used == frame` marks those this frame holds.
struct Shelf<T>(Vec<Kept<T>>);

impl<T: Clone> Shelf<T> {
    fn take(&mut self, frame: u64) -> Option<T> {
        let free = self.0.iter_mut().find(|k| k.used != frame && !k.held)?;
        free.used = frame;
        Some(free.value.clone())
    }

    fn evict(&mut self, frame: u64) {
        self.0.retain(|k| k.held || k.used + KEEP_FRAMES >= frame);
    }
}

impl<T> Default for Shelf<T> {
    fn default() -> Self {
        Shelf(Vec::new())
    }
}

/// See the module's documentation.
pub(crate) struct Pool {
    device: wgpu::Device,
    frame: u64,
    textures: HashMap<TextureKey, Shelf<wgpu::Texture>>,
    views: HashMap<(wgpu::Texture, ViewKey), Kept<wgpu::TextureView>>,
    buffers: HashMap<BufferKey, Shelf<wgpu::Buffer>>,
    query_sets: HashMap<u32, Shelf<wgpu::QuerySet>>,
    bind_groups: HashMap<BindGroupKey, Kept<wgpu::BindGroup>>,
    created: Creations,
}

impl Pool {
    pub fn new(device: &wgpu::Device) -> Self {
        Self {
            device: device.clone(),
            frame: 0,
            textures: HashMap::new(),
            views: HashMap::new(),
            buffers: HashMap::new(),
            query_sets: HashMap::new(),
            bind_groups: HashMap::new(),
            created: Creations::default(),
        }
    }

    pub fn creations(&self) -> Creations {
        self.created
    }

    /// A 2D texture (array) of this description that this frame does not hold yet.
    pub fn texture(
        &mut self,
        label: &str,
        size: wgpu::Extent3d,
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> wgpu::Texture {
        self.texture_with_mips(label, size, 1, format, usage)
    }

    /// Like [`Pool::texture`], with `mip_level_count` mip levels.
    pub fn texture_with_mips(
        &mut self,
        label: &str,
        size: wgpu::Extent3d,
        mip_level_count: u32,
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> wgpu::Texture {
        let key = TextureKey { size, mip_level_count, format, usage, dimension: wgpu::TextureDimension::D2 };
        let frame = self.frame;
        let shelf = self.textures.entry(key).or_default();
        if let Some(texture) = shelf.take(frame) {
            return texture;
        }
        let texture = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size,
            mip_level_count,
            sample_count: 1,
            dimension: key.dimension,
            format,
            usage,
            view_formats: &[],
        });
        self.created.textures += 1;
        shelf.0.push(Kept { value: texture.clone(), used: frame, held: false });
        texture
    }

    /// A view of a texture, made once per texture and description.
    pub fn view(&mut self, texture: &wgpu::Texture, key: ViewKey) -> wgpu::TextureView {
        let frame = self.frame;
        if let Some(kept) = self.views.get_mut(&(texture.clone(), key)) {
            kept.used = frame;
            return kept.value.clone();
        }
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: key.dimension,
            base_array_layer: key.base_layer,
            array_layer_count: key.layers,
            base_mip_level: key.base_mip,
            mip_level_count: key.mips,
            ..Default::default()
        });
        self.created.views += 1;
        self.views.insert((texture.clone(), key), Kept { value: view.clone(), used: frame, held: false });
        view
    }

    /// A buffer of `size` bytes and `usage` that this frame does not hold yet.
    pub fn buffer(&mut self, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
        let key = BufferKey { size, usage };
        let frame = self.frame;
        let shelf = self.buffers.entry(key).or_default();
        if let Some(buffer) = shelf.take(frame) {
            return buffer;
        }
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage,
            mapped_at_creation: false,
        });
        self.created.buffers += 1;
        shelf.0.push(Kept { value: buffer.clone(), used: frame, held: false });
        buffer
    }

    /// Keeps `buffer` (one of the pool's) from being handed out again, past the frame
    /// that took it, until [`Pool::release`]: for a readback mapped frames later.
    pub fn hold(&mut self, buffer: &wgpu::Buffer) {
        self.set_held(buffer, true);
    }

    /// Lets a buffer [`Pool::hold`] kept be handed out again.
    pub fn release(&mut self, buffer: &wgpu::Buffer) {
        self.set_held(buffer, false);
    }

    fn set_held(&mut self, buffer: &wgpu::Buffer, held: bool) {
        let key = BufferKey { size: buffer.size(), usage: buffer.usage() };
        if let Some(kept) =
            self.buffers.get_mut(&key).and_then(|s| s.0.iter_mut().find(|k| &k.value == buffer))
        {
            kept.held = held;
            // Held is in use: its age counts from its release, not from the frame that
            // took it.
            kept.used = self.frame;
        }
    }

    /// A uniform buffer holding `value`, written through the queue.
    pub fn uniform<T: bytemuck::Pod>(&mut self, queue: &wgpu::Queue, label: &str, value: &T) -> wgpu::Buffer {
        let bytes = bytemuck::bytes_of(value);
        let buffer = self.buffer(
            label,
            bytes.len() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        queue.write_buffer(&buffer, 0, bytes);
        buffer
    }

    /// A storage buffer holding `data`, written through the queue.
    pub fn storage<T: bytemuck::Pod>(
        &mut self,
        queue: &wgpu::Queue,
        label: &str,
        data: &[T],
        usage: wgpu::BufferUsages,
    ) -> wgpu::Buffer {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let buffer = self.buffer(
            label,
            bytes.len() as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | usage,
        );
        queue.write_buffer(&buffer, 0, bytes);
        buffer
    }

    /// A timestamp query set of `count` queries that this frame does not hold yet.
    pub fn timestamps(&mut self, count: u32) -> wgpu::QuerySet {
        let frame = self.frame;
        let shelf = self.query_sets.entry(count).or_default();
        if let Some(set) = shelf.take(frame) {
            return set;
        }
        let set = self.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        self.created.query_sets += 1;
        shelf.0.push(Kept { value: set.clone(), used: frame, held: false });
        set
    }

    /// The bind group of `layout` with `bindings` at bindings 0, 1, …, made once per
    /// set of resources.
    pub fn bind_group(
        &mut self,
        label: &str,
        layout: &wgpu::BindGroupLayout,
        bindings: &[Binding],
    ) -> wgpu::BindGroup {
        let numbered: Vec<(u32, Binding)> =
            bindings.iter().cloned().enumerate().map(|(i, b)| (i as u32, b)).collect();
        self.bind_group_numbered(label, layout, numbered)
    }

    /// The bind group of `layout` with each binding at its number, made once per set of
    /// resources.
    pub fn bind_group_numbered(
        &mut self,
        label: &str,
        layout: &wgpu::BindGroupLayout,
        bindings: Vec<(u32, Binding)>,
    ) -> wgpu::BindGroup {
        let frame = self.frame;
        let key = BindGroupKey { layout: layout.clone(), bindings };
        if let Some(kept) = self.bind_groups.get_mut(&key) {
            kept.used = frame;
            return kept.value.clone();
        }
        let entries: Vec<wgpu::BindGroupEntry> = key
            .bindings
            .iter()
            .map(|(binding, b)| wgpu::BindGroupEntry {
                binding: *binding,
                resource: match b {
                    Binding::Buffer(buffer) => buffer.as_entire_binding(),
                    Binding::BufferWindow { buffer, size } => {
                        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer,
                            offset: 0,
                            size: wgpu::BufferSize::new(*size),
                        })
                    }
                    Binding::View(view) => wgpu::BindingResource::TextureView(view),
                    Binding::Sampler(sampler) => wgpu::BindingResource::Sampler(sampler),
                    Binding::Tlas(tlas) => tlas.as_binding(),
                },
            })
            .collect();
        let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout,
            entries: &entries,
        });
        self.created.bind_groups += 1;
        self.bind_groups.insert(key, Kept { value: group.clone(), used: frame, held: false });
        group
    }

    /// Ends a frame: what it held is free again, and what no frame has used for
    /// [`KEEP_FRAMES`] frames is dropped.
    pub fn end_frame(&mut self) {
        self.frame += 1;
        let frame = self.frame;
        self.textures.values_mut().for_each(|s| s.evict(frame));
        self.buffers.values_mut().for_each(|s| s.evict(frame));
        self.query_sets.values_mut().for_each(|s| s.evict(frame));
        self.views.retain(|_, k| k.used + KEEP_FRAMES >= frame);
        self.bind_groups.retain(|_, k| k.used + KEEP_FRAMES >= frame);
    }
}

#[cfg(test)]
mod tests {
    /// The zero-creation test counts what the pool creates; it proves that a steady
    /// frame creates nothing only if every per-frame creation goes through the pool.
    /// Outside it, only the one-time uploads (the scene, the casters' BVH and
    /// acceleration structures, the GPU culler's shadow items), the
    /// renderer's fixed bindings, the kept depth and moment maps, their depth
    /// pyramids and the penumbra histories (counted in `Renderer::creations`), and `ShadowRays`' batch queries (no frame: buffers
    /// sized to each batch) may create GPU resources.
    #[test]
    fn only_the_pool_creates_per_frame_resources() {
        let allowed = [
            "pool.rs",
            "frame/bindings.rs",
            "frame/map_cache.rs",
            "frame/moment_cache.rs",
            "gpu_scene/mod.rs",
            "gpu_scene/materials.rs",
            "gpu_scene/shadow_items.rs",
            "passes/depth_baseline.rs",
            "rays/accel.rs",
            "rays/mod.rs",
            "rays/query.rs",
            // A virtual map's pool of page tiles: one texture kept across frames,
            // as the kept shadow maps are.
            "virtual_map/draw.rs",
            // Its tests' full-resolution reference maps.
            "virtual_map/draw/tests.rs",
            // A map's depth pyramid and touched layer, kept with the map they were
            // derived from (`frame/derived_cache.rs`), and each light's penumbra
            // history, kept across frames: all counted in `Renderer::creations`.
            "rays/pyramid.rs",
            "rays/touched.rs",
            "frame/penumbra_history.rs",
        ];
        let creations =
            ["create_texture", "create_buffer", "create_bind_group(", "create_query_set", "create_view("];
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut offenders = Vec::new();
        let mut stack = vec![root.clone()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    stack.push(path);
                    continue;
                }
                let name = path.strip_prefix(&root).unwrap().to_string_lossy().replace('\\', "/");
                if !name.ends_with(".rs") || allowed.contains(&name.as_str()) {
                    continue;
                }
                let text = std::fs::read_to_string(&path).unwrap();
                for (n, line) in text.lines().enumerate() {
                    if creations.iter().any(|c| line.contains(&format!(".{c}"))) {
                        offenders.push(format!("{name}:{}: {}", n + 1, line.trim()));
                    }
                }
            }
        }
        assert!(offenders.is_empty(), "GPU resources created outside the pool:\n{}", offenders.join("\n"));
    }
}
