//! Headless adapter and device selection, honouring `WGPU_BACKEND`,
//! `WGPU_ADAPTER_NAME` and `WGPU_POWER_PREF`.

use crate::RenderError;

/// What was picked, for `--verbose` and for reports.
#[derive(Clone, Debug)]
pub struct GpuInfo {
    /// The adapter's name, as the driver reports it (`llvmpipe (LLVM 15.0.6, 256 bits)`, say).
    pub adapter: String,
    /// The graphics API wgpu drives it through (`Vulkan`, `Metal`, `Dx12`, `Gl`).
    pub backend: String,
    /// The kind of device (`DiscreteGpu`, `IntegratedGpu`, `Cpu`, …); `Cpu` for a software
    /// rasterizer such as lavapipe.
    pub device_type: String,
    /// The driver's name.
    pub driver: String,
    /// The driver's version and build details, free-form.
    pub driver_info: String,
}

impl GpuInfo {
    fn of(adapter: wgpu::AdapterInfo) -> Self {
        GpuInfo {
            adapter: adapter.name,
            backend: format!("{:?}", adapter.backend),
            device_type: format!("{:?}", adapter.device_type),
            driver: adapter.driver,
            driver_info: adapter.driver_info,
        }
    }
}

impl std::fmt::Display for GpuInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "adapter: {} ({}), backend: {}, driver: {} {}",
            self.adapter, self.device_type, self.backend, self.driver, self.driver_info
        )
    }
}

/// An open device and its queue: opened by Gnomon with no window
/// ([`Gpu::new_headless`]), or the host application's own ([`Gpu::from_host`]).
/// Cloning shares the device (wgpu's handles are reference-counted).
#[derive(Clone, Debug)]
pub struct Gpu {
    /// The wgpu device every resource is created on.
    pub device: wgpu::Device,
    /// The queue every frame's commands are submitted to.
    pub queue: wgpu::Queue,
    /// Which adapter and driver the device runs on, for logs and reports.
    pub info: GpuInfo,
    /// The limits the device was opened with; settings are checked against them
    /// ([`crate::Renderer::check_limits`]).
    pub limits: wgpu::Limits,
    /// Nanoseconds per timestamp tick, when the device can time passes.
    pub timestamp_period_ns: Option<f32>,
    /// Whether draws can come from a buffer of arguments with their own first
    /// instance: indirect execution and `INDIRECT_FIRST_INSTANCE`. Without it, a
    /// layer's draws are issued one by one (`DrawSubmission`).
    pub indirect_draws: bool,
    /// Whether, besides, a draw can take its count of draws from a buffer
    /// (`MULTI_DRAW_INDIRECT_COUNT`): what lets a compute pass cull a layer's casters
    /// and the layer draw what it kept (`DrawSubmission::GpuCulled`).
    pub indirect_count: bool,
    /// Whether shaders can trace rays through the adapter's own acceleration
    /// structures (`EXPERIMENTAL_RAY_QUERY`): what `Tracer::RayQuery` needs.
    pub ray_queries: bool,
    /// What kind of device it is: a CPU rasterizer such as lavapipe (`Cpu`) runs
    /// ray queries in software, slower than the shader's own BVH, so `Tracer::Auto`
    /// takes them on a GPU only.
    pub device_type: wgpu::DeviceType,
    /// Where a device error raised in a browser waits to be reported
    /// ([`Gpu::deferred_error`]): there Gnomon cannot wait for its error scopes.
    /// A clone of the `Gpu` shares it.
    pub deferred: DeferredErrors,
}

/// The first device error that arrived after the call that raised it had returned
/// (in a browser), kept until [`Gpu::deferred_error`] takes it. Opaque: a host only
/// makes one (`Default`) or copies one along with its `Gpu`.
#[derive(Clone, Debug, Default)]
pub struct DeferredErrors(std::sync::Arc<std::sync::Mutex<Option<(&'static str, String)>>>);

impl Gpu {
    /// Picks an adapter without a surface and opens a device on it, asking for the
    /// adapter's own limits so that large shadow maps are available where supported.
    ///
    /// `GNOMON_MAX_TEXTURE_SIZE=N` caps the 2D texture size below the adapter's, to
    /// check settings against a smaller GPU than the one at hand.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new_headless() -> Result<Self, RenderError> {
        let cap = std::env::var("GNOMON_MAX_TEXTURE_SIZE").ok().and_then(|v| v.trim().parse::<u32>().ok());
        Self::new_headless_with(|limits| {
            if let Some(cap) = cap {
                limits.max_texture_dimension_2d = limits.max_texture_dimension_2d.min(cap.max(1));
            }
        })
    }

    /// Like [`Gpu::new_headless`], letting `adjust` lower the limits asked for.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new_headless_with(adjust: impl FnOnce(&mut wgpu::Limits)) -> Result<Self, RenderError> {
        let adapter = headless_adapter()?;
        Self::with_adapter(&adapter, adjust)
    }

    /// Opens a device on `adapter` (one picked for a window's surface, say), with the
    /// adapter's own limits lowered by `adjust` and the optional features Gnomon uses.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn with_adapter(
        adapter: &wgpu::Adapter,
        adjust: impl FnOnce(&mut wgpu::Limits),
    ) -> Result<Self, RenderError> {
        pollster::block_on(Self::with_adapter_async(adapter, adjust))
    }

    /// [`Gpu::with_adapter`], for a caller that cannot block (a browser, whose
    /// device arrives through a promise).
    pub async fn with_adapter_async(
        adapter: &wgpu::Adapter,
        adjust: impl FnOnce(&mut wgpu::Limits),
    ) -> Result<Self, RenderError> {
        let adapter_info = adapter.get_info();
        let mut limits = adapter.limits();
        adjust(&mut limits);
        let ray_queries = adapter.features().contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY);
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("gnomon"),
                // Timestamps time each pass where the adapter has them (lavapipe does);
                // 32-bit float filtering lets moment maps keep full precision; unclipped
                // depth lets a sun's map clamp casters in front of its near plane onto it
                // ("pancaking"), so the depth range need only span the receivers; a first
                // instance in indirect draws lets a layer's draws be one multi-draw, and
                // indirect count lets the backend issue it as one command; ray queries
                // let the shadow rays use the adapter's own acceleration structures.
                required_features: adapter.features()
                    & (wgpu::Features::TIMESTAMP_QUERY
                        | wgpu::Features::FLOAT32_FILTERABLE
                        | wgpu::Features::DEPTH_CLIP_CONTROL
                        | wgpu::Features::INDIRECT_FIRST_INSTANCE
                        | wgpu::Features::MULTI_DRAW_INDIRECT_COUNT
                        | wgpu::Features::EXPERIMENTAL_RAY_QUERY),
                required_limits: limits.clone(),
                // wgpu names its ray queries experimental and asks for this token before it
                // enables them. Gnomon holds them to the shader tracer's answers
                // (reference/tests/truth/ray_queries.rs) wherever a device has them.
                experimental_features: if ray_queries {
                    // SAFETY: the token only unlocks the EXPERIMENTAL_RAY_QUERY feature
                    // requested above; no other experimental API is used.
                    unsafe { wgpu::ExperimentalFeatures::enabled() }
                } else {
                    wgpu::ExperimentalFeatures::disabled()
                },
                ..Default::default()
            })
            .await
            .map_err(|e| RenderError::DeviceRequest {
                adapter: adapter_info.name.clone(),
                reason: e.to_string(),
            })?;
        let timestamp_period_ns =
            device.features().contains(wgpu::Features::TIMESTAMP_QUERY).then(|| queue.get_timestamp_period());
        let IndirectDraws { indirect_draws, indirect_count } = IndirectDraws::of(adapter, &device);
        let info = GpuInfo::of(adapter_info.clone());
        // wgpu names a browser's adapter by its description, which browsers leave
        // empty; its vendor and architecture say more.
        #[cfg(target_arch = "wasm32")]
        let info = GpuInfo {
            adapter: match info.adapter.is_empty() {
                true => browser_adapter_name().await.unwrap_or_else(|| "WebGPU adapter".into()),
                false => info.adapter,
            },
            ..info
        };
        Ok(Self {
            ray_queries: device.features().contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY),
            device_type: adapter_info.device_type,
            device,
            queue,
            info,
            limits,
            timestamp_period_ns,
            indirect_draws,
            indirect_count,
            deferred: DeferredErrors::default(),
        })
    }

    /// Wraps a device the host application already has, sharing it: Gnomon draws
    /// with whatever features and limits the host asked for, and uses timestamp
    /// queries, 32-bit float filtering, unclipped depth and ray queries only where
    /// the device has them enabled.
    pub fn from_host(adapter: &wgpu::Adapter, device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let adapter_info = adapter.get_info();
        let device_type = adapter_info.device_type;
        let timestamp_period_ns =
            device.features().contains(wgpu::Features::TIMESTAMP_QUERY).then(|| queue.get_timestamp_period());
        let IndirectDraws { indirect_draws, indirect_count } = IndirectDraws::of(adapter, device);
        Self {
            device: device.clone(),
            queue: queue.clone(),
            info: GpuInfo::of(adapter_info),
            limits: device.limits(),
            timestamp_period_ns,
            indirect_draws,
            indirect_count,
            ray_queries: device.features().contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY),
            device_type,
            deferred: DeferredErrors::default(),
        }
    }

    /// Runs `f`, turning any validation, out-of-memory or internal error it raises
    /// into a [`RenderError::Gpu`] instead of wgpu's default panic.
    ///
    /// A browser cannot wait for its error scopes: there `f`'s value is returned at
    /// once and an error it raised is reported by the next [`Gpu::deferred_error`],
    /// which the `async` entry points call once their readbacks have arrived.
    pub(crate) fn checked<T>(&self, during: &'static str, f: impl FnOnce() -> T) -> Result<T, RenderError> {
        let scopes = [
            self.device.push_error_scope(wgpu::ErrorFilter::Internal),
            self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory),
            self.device.push_error_scope(wgpu::ErrorFilter::Validation),
        ];
        let value = f();
        // Popped now, innermost first, as WebGPU asks; answered when awaited.
        let answers: Vec<_> = scopes.into_iter().rev().map(wgpu::ErrorScopeGuard::pop).collect();
        let popped = async move {
            let mut first = None;
            for answer in answers {
                if let Some(e) = answer.await {
                    first.get_or_insert(e.to_string());
                }
            }
            first
        };
        #[cfg(not(target_arch = "wasm32"))]
        {
            match pollster::block_on(popped) {
                Some(message) => Err(RenderError::Gpu { during, message }),
                None => Ok(value),
            }
        }
        #[cfg(target_arch = "wasm32")]
        {
            let deferred = self.deferred.0.clone();
            wasm_bindgen_futures::spawn_local(async move {
                if let Some(message) = popped.await {
                    deferred
                        .lock()
                        .unwrap_or_else(std::sync::PoisonError::into_inner)
                        .get_or_insert((during, message));
                }
            });
            Ok(value)
        }
    }

    /// The first device error Gnomon's passes raised that could not be reported when
    /// it was raised (in a browser), taken so that it is reported once; `Ok` where
    /// there is none (always, on a device Gnomon can wait for).
    pub fn deferred_error(&self) -> Result<(), RenderError> {
        let taken = self.deferred.0.lock().unwrap_or_else(std::sync::PoisonError::into_inner).take();
        match taken {
            Some((during, message)) => Err(RenderError::Gpu { during, message }),
            None => Ok(()),
        }
    }
}

impl RenderError {
    /// No adapter could be found, naming the `WGPU_BACKEND` choice that limited the search.
    pub fn no_adapter() -> Self {
        Self::no_adapter_besides(None)
    }

    /// [`RenderError::no_adapter`], naming the OpenGL adapter that was found and
    /// refused, if one was.
    pub fn no_adapter_besides(gl: Option<&wgpu::AdapterInfo>) -> Self {
        if let Some(info) = gl {
            return RenderError::NoAdapter {
                backends: format!(
                    " but the OpenGL one `{}`, which cannot draw into the 32-bit float targets Gnomon renders to",
                    info.name
                ),
            };
        }
        let backends = match std::env::var("WGPU_BACKEND") {
            Ok(v) => format!(" for WGPU_BACKEND={v:?}"),
            Err(_) => String::new(),
        };
        RenderError::NoAdapter { backends }
    }
}

/// The adapter a headless run uses. `WGPU_BACKEND` (with `WGPU_ADAPTER_NAME` and
/// `WGPU_POWER_PREF`) chooses when set. Otherwise Vulkan, Metal or DX12 is preferred:
/// wgpu would fall back to OpenGL, which cannot render the `Rgba32Float` targets the
/// visibility and AOV outputs need, and a user would meet a validation error instead
/// of the install hint. An OpenGL adapter, chosen or fallen back to, is refused with
/// that hint.
#[cfg(not(target_arch = "wasm32"))]
fn headless_adapter() -> Result<wgpu::Adapter, RenderError> {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    let chosen_by_user = std::env::var_os("WGPU_BACKEND").is_some();
    if !chosen_by_user {
        descriptor.backends = wgpu::Backends::PRIMARY;
    }
    let instance = wgpu::Instance::new(descriptor);
    let found = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(&instance, None));
    match found {
        Ok(adapter) if adapter.get_info().backend != wgpu::Backend::Gl => Ok(adapter),
        Ok(gl) => Err(RenderError::no_adapter_besides(Some(&gl.get_info()))),
        Err(_) if chosen_by_user => Err(RenderError::no_adapter()),
        Err(_) => {
            // Say whether GL was there, so that the message explains why it was not used.
            let mut gl_only = wgpu::InstanceDescriptor::new_without_display_handle();
            gl_only.backends = wgpu::Backends::GL;
            let gl = pollster::block_on(
                wgpu::Instance::new(gl_only).request_adapter(&wgpu::RequestAdapterOptions::default()),
            );
            Err(RenderError::no_adapter_besides(gl.ok().map(|a| a.get_info()).as_ref()))
        }
    }
}

/// What indirect drawing a device can do ([`Gpu::indirect_draws`], [`Gpu::indirect_count`]).
struct IndirectDraws {
    indirect_draws: bool,
    indirect_count: bool,
}

impl IndirectDraws {
    /// What `device` on `adapter` can do: draw from a buffer of arguments that each
    /// carry their first instance, and besides take the count of draws from a buffer.
    fn of(adapter: &wgpu::Adapter, device: &wgpu::Device) -> Self {
        let execution =
            adapter.get_downlevel_capabilities().flags.contains(wgpu::DownlevelFlags::INDIRECT_EXECUTION);
        let indirect_draws = execution && device.features().contains(wgpu::Features::INDIRECT_FIRST_INSTANCE);
        let indirect_count =
            indirect_draws && device.features().contains(wgpu::Features::MULTI_DRAW_INDIRECT_COUNT);
        Self { indirect_draws, indirect_count }
    }
}

/// The browser's own words for its WebGPU adapter (`google swiftshader`), from
/// `navigator.gpu.requestAdapter()`'s `info`.
#[cfg(target_arch = "wasm32")]
async fn browser_adapter_name() -> Option<String> {
    use wasm_bindgen::{JsCast, JsValue};
    let get = |object: &JsValue, key: &str| js_sys::Reflect::get(object, &key.into()).ok();
    let gpu = get(&get(&js_sys::global(), "navigator")?, "gpu")?;
    let request: js_sys::Function = get(&gpu, "requestAdapter")?.dyn_into().ok()?;
    let promise: js_sys::Promise = request.call0(&gpu).ok()?.dyn_into().ok()?;
    let adapter = wasm_bindgen_futures::JsFuture::from(promise).await.ok()?;
    let info = get(&adapter, "info")?;
    let parts: Vec<String> = ["vendor", "architecture", "description"]
        .iter()
        .filter_map(|key| get(&info, key)?.as_string().filter(|s| !s.is_empty()))
        .collect();
    (!parts.is_empty()).then(|| format!("{} (WebGPU)", parts.join(" ")))
}
