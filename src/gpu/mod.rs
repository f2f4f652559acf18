//! The one place that creates the wgpu instance, adapter and device, plus the small helpers
//! every pass shares: error scopes, buffer readback and timestamp queries.

mod timing;

use std::sync::{Arc, Mutex};

pub use timing::{Queries, Span, median};

use crate::error::{Error, Result};

/// The stages this project's shaders run in, for bindings that compute passes and render
/// pipelines share.
pub const ALL_STAGES: wgpu::ShaderStages =
    wgpu::ShaderStages::VERTEX_FRAGMENT.union(wgpu::ShaderStages::COMPUTE);

/// A compute-visible storage buffer entry of a bind group layout.
pub fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, wgpu::BufferBindingType::Storage { read_only })
}

/// A compute-visible uniform buffer entry of a bind group layout.
pub fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, wgpu::BufferBindingType::Uniform)
}

/// A bind group of whole buffers, bound at 0, 1, 2, ... in the order given.
pub fn bind_buffers(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let resources: Vec<_> = buffers.iter().map(|b| b.as_entire_binding()).collect();
    bind_group(device, label, layout, resources)
}

/// A bind group of any resources, bound at 0, 1, 2, ... in the order given.
pub fn bind_group<'a>(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: impl IntoIterator<Item = wgpu::BindingResource<'a>>,
) -> wgpu::BindGroup {
    let numbered = resources.into_iter().enumerate();
    bind_group_at(device, label, layout, numbered.map(|(b, r)| (b as u32, r)))
}

/// A bind group of any resources, each at the binding given with it.
pub fn bind_group_at<'a>(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: impl IntoIterator<Item = (u32, wgpu::BindingResource<'a>)>,
) -> wgpu::BindGroup {
    let entries: Vec<_> = resources
        .into_iter()
        .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A buffer holding `contents`: `wgpu::util::DeviceExt::create_buffer_init` without its panic
/// when the device is lost. The buffer is then invalid, and [`GpuContext::checked`] reports
/// the loss.
pub fn buffer_init(
    device: &wgpu::Device,
    label: &str,
    contents: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let size = (contents.len() as u64).next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT);
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage,
        mapped_at_creation: size > 0,
    });
    if size > 0 {
        if let Ok(mut view) = buffer.get_mapped_range_mut(..) {
            view.slice(..contents.len()).copy_from_slice(contents);
        }
        buffer.unmap();
    }
    buffer
}

/// A square 2D texture array: `layers` layers of `side`² texels, one mip level.
pub fn texture_array(
    device: &wgpu::Device,
    label: &str,
    side: u32,
    layers: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: side,
            height: side,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// A view of one layer of a texture array as a 2D texture, or with `None` of all its layers
/// as an array.
pub fn layer_view(texture: &wgpu::Texture, layer: Option<u32>) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(match layer {
            Some(_) => wgpu::TextureViewDimension::D2,
            None => wgpu::TextureViewDimension::D2Array,
        }),
        base_array_layer: layer.unwrap_or(0),
        array_layer_count: layer.map(|_| 1),
        ..Default::default()
    })
}

fn buffer_entry(binding: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// Records one compute pass that runs `pipeline` once per pixel of `size`, in
/// `WORKGROUP_2D`-square tiles, with `bind_groups` at groups 0, 1, ...
pub fn dispatch_over_image(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    bind_groups: &[&wgpu::BindGroup],
    size: crate::lens::ImageSize,
    timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
) {
    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes,
    });
    pass.set_pipeline(pipeline);
    for (index, group) in bind_groups.iter().enumerate() {
        pass.set_bind_group(index as u32, *group, &[]);
    }
    let tile = crate::shared::WORKGROUP_2D;
    pass.dispatch_workgroups(size.width.div_ceil(tile), size.height.div_ceil(tile), 1);
}

/// Submits one dispatch of `pipeline` (bind group 0) over `count` elements, in workgroups of
/// `WORKGROUP_1D`, for kernels that map arrays of points or directions.
pub fn submit_over_elements(
    ctx: &GpuContext,
    pipeline: &wgpu::ComputePipeline,
    bind_group: &wgpu::BindGroup,
    count: usize,
) {
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups((count as u32).div_ceil(crate::shared::WORKGROUP_1D), 1, 1);
    }
    ctx.queue.submit([encoder.finish()]);
}

/// The environment variable that injects a fault for tests of the error paths: with the value
/// `device-lost`, every device is destroyed as soon as it is created, as a driver reset would;
/// with `kill-after-images:N`, a dataset run kills itself (SIGKILL) once it has written N
/// images.
pub const FAULT_VARIABLE: &str = "FISHEYE_INJECT_FAULT";

/// Optional device features the project uses when the adapter has them.
pub const OPTIONAL_FEATURES: [(wgpu::Features, &str); 6] = [
    (wgpu::Features::TIMESTAMP_QUERY, "timestamp queries"),
    (
        wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS,
        "timestamps inside encoders",
    ),
    (wgpu::Features::EXPERIMENTAL_RAY_QUERY, "ray query"),
    (wgpu::Features::MULTIVIEW, "multiview"),
    (
        wgpu::Features::SELECTIVE_MULTIVIEW,
        "multiview of some layers",
    ),
    (wgpu::Features::SHADER_F64, "f64 in shaders"),
];

/// Work that makes GPU objects, for [`GpuContext::checked_each`] to run beside other such work
/// (on a thread of its own, except in a web page).
#[cfg(not(target_arch = "wasm32"))]
pub type GpuJob<'a, T> = Box<dyn FnOnce() -> T + Send + 'a>;
/// Work that makes GPU objects, for [`GpuContext::checked_each`] (one after another in a web
/// page, whose GPU objects stay on its one thread).
#[cfg(target_arch = "wasm32")]
pub type GpuJob<'a, T> = Box<dyn FnOnce() -> T + 'a>;

/// A device and its queue: the GPU everything else runs on. [`GpuContext::new`] creates
/// one; [`GpuContext::from_device`] wraps a caller's (a renderer that embeds the library).
#[derive(Clone)]
pub struct GpuContext {
    /// The device; passes take `&Device`.
    pub device: wgpu::Device,
    /// The device's queue.
    pub queue: wgpu::Queue,
    /// Why the device was lost, once it is (devices we create; a caller's device keeps the
    /// caller's own lost callback).
    lost: Arc<Mutex<Option<String>>>,
    /// The first error outside every error scope (wgpu's default handler would panic; a
    /// caller's device keeps the caller's own handler).
    uncaptured: Arc<Mutex<Option<String>>>,
}

/// Ranks adapters: hardware first, software (lavapipe) last; among equals, GL (which lacks
/// ray query and multiview) after the native APIs.
fn preference(info: &wgpu::AdapterInfo) -> (u8, bool) {
    let kind = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    };
    (kind, info.backend == wgpu::Backend::Gl)
}

fn describe(info: &wgpu::AdapterInfo) -> String {
    format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
}

impl GpuContext {
    /// Picks an adapter and creates the device.
    ///
    /// Honours `WGPU_BACKEND` (e.g. `vulkan`, `gl`) and `WGPU_ADAPTER_NAME` (a case-insensitive
    /// substring of the adapter's name); otherwise prefers a hardware adapter and falls back to
    /// a software one. Requests the adapter's own limits and every feature of
    /// [`OPTIONAL_FEATURES`] it has.
    pub fn new() -> Result<Self> {
        Self::without(wgpu::Features::empty())
    }

    /// As [`GpuContext::new`], but never enabling `features`: what an adapter without them
    /// gives (tests use it to check the errors such users see).
    pub fn without(features: wgpu::Features) -> Result<Self> {
        Self::create(Self::choose_adapter()?, features, None)
    }

    /// As [`GpuContext::new`], but with storage bindings of at most `bytes`: what a smaller
    /// adapter gives (tests use it to check the errors such users see, whatever the adapter).
    pub fn with_binding_limit(bytes: u64) -> Result<Self> {
        Self::create(
            Self::choose_adapter()?,
            wgpu::Features::empty(),
            Some(bytes),
        )
    }

    /// The adapter [`GpuContext::new`] uses.
    fn choose_adapter() -> Result<wgpu::Adapter> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let backends = wgpu::Backends::from_env().unwrap_or_default();
        let mut adapters = pollster::block_on(instance.enumerate_adapters(backends));
        if adapters.is_empty() {
            return Err(Error::NoAdapter {
                backends: format!("{backends:?}"),
            });
        }
        let adapter = match std::env::var("WGPU_ADAPTER_NAME") {
            Ok(wanted) => {
                let needle = wanted.to_lowercase();
                let found = adapters
                    .iter()
                    .position(|a| a.get_info().name.to_lowercase().contains(&needle));
                match found {
                    Some(i) => adapters.swap_remove(i),
                    None => {
                        let available = adapters
                            .iter()
                            .map(|a| describe(&a.get_info()))
                            .collect::<Vec<_>>()
                            .join("; ");
                        return Err(Error::AdapterNotFound { wanted, available });
                    }
                }
            }
            Err(_) => {
                adapters.sort_by_key(|a| preference(&a.get_info()));
                adapters.swap_remove(0)
            }
        };
        Ok(adapter)
    }

    /// Creates the device on a given adapter (as [`GpuContext::new`] does once it has chosen).
    pub fn with_adapter(adapter: wgpu::Adapter) -> Result<Self> {
        Self::create(adapter, wgpu::Features::empty(), None)
    }

    fn create(
        adapter: wgpu::Adapter,
        left_out: wgpu::Features,
        binding_limit: Option<u64>,
    ) -> Result<Self> {
        let wanted = OPTIONAL_FEATURES
            .iter()
            .fold(wgpu::Features::empty(), |all, (f, _)| all | *f)
            - left_out;
        let features = adapter.features() & wanted;
        let mut limits = adapter.limits();
        let mut experimental = wgpu::ExperimentalFeatures::disabled();
        if features.contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY) {
            limits = limits.using_acceleration_structure_values(adapter.limits());
            // SAFETY: wgpu asks callers of experimental features to accept that bugs in its
            // implementation may be undefined behaviour. We only use ray query through wgpu's
            // validated API, with acceleration structures built from checked, finite geometry.
            experimental = unsafe { wgpu::ExperimentalFeatures::enabled() };
        }
        if let Some(bytes) = binding_limit {
            limits.max_storage_buffer_binding_size =
                bytes.min(limits.max_storage_buffer_binding_size);
        }
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("fisheye.device"),
            required_features: features,
            required_limits: limits,
            experimental_features: experimental,
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|source| Error::RequestDevice {
            adapter: describe(&adapter.get_info()),
            reason: source,
        })?;
        let lost = Arc::new(Mutex::new(None));
        let flag = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            let said = if message.is_empty() {
                String::new()
            } else {
                format!(": {message}")
            };
            *flag.lock().unwrap() = Some(format!("{reason:?}{said}"));
        });
        let uncaptured = Arc::new(Mutex::new(None));
        let first = uncaptured.clone();
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            first.lock().unwrap().get_or_insert(error.to_string());
        }));
        let ctx = Self {
            device,
            queue,
            lost,
            uncaptured,
        };
        if std::env::var(FAULT_VARIABLE).as_deref() == Ok("device-lost") {
            ctx.device.destroy();
        }
        Ok(ctx)
    }

    /// Wraps a device and queue the caller created (and keeps using). Every error of ours is
    /// still caught by error scopes and returned; the caller's uncaptured-error handler and
    /// device-lost callback are left as they are. What a pass needs beyond the defaults
    /// (features, limits) it checks when it is created, naming what is missing.
    pub fn from_device(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        Self {
            device: device.clone(),
            queue: queue.clone(),
            lost: Arc::default(),
            uncaptured: Arc::default(),
        }
    }

    /// What the adapter says of itself.
    pub fn adapter_info(&self) -> wgpu::AdapterInfo {
        self.device.adapter_info()
    }

    /// The adapter's name, backend and type, e.g. `llvmpipe (LLVM 19.1.7, 256 bits) (Vulkan, Cpu)`.
    pub fn adapter_name(&self) -> String {
        describe(&self.adapter_info())
    }

    /// Whether the device was created with `feature`.
    pub fn has(&self, feature: wgpu::Features) -> bool {
        self.device.features().contains(feature)
    }

    /// A human-readable report of the adapter, driver, optional features and key limits.
    pub fn report(&self) -> String {
        let info = self.adapter_info();
        let limits = self.device.limits();
        let mut out = format!(
            "adapter: {}\ndriver: {} {}\nfeatures:\n",
            describe(&info),
            info.driver,
            info.driver_info
        );
        for (feature, name) in OPTIONAL_FEATURES {
            let mark = if self.has(feature) { "yes" } else { "no" };
            out.push_str(&format!("  {name:<28} {mark}\n"));
        }
        out.push_str(&format!(
            "limits:\n  max storage binding          {} MiB\n  storage buffers a stage      {}\n  max buffer size              {} MiB\n  max 2D texture side          {}\n",
            limits.max_storage_buffer_binding_size >> 20,
            limits.max_storage_buffers_per_shader_stage,
            limits.max_buffer_size >> 20,
            limits.max_texture_dimension_2d,
        ));
        if let Some(period) = self.timestamp_period() {
            out.push_str(&format!("  timestamp period             {period} ns\n"));
        }
        out
    }

    /// Nanoseconds per timestamp tick, if the device has timestamp queries.
    pub fn timestamp_period(&self) -> Option<f32> {
        self.has(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| self.queue.get_timestamp_period())
    }

    /// Runs `work` inside validation, out-of-memory and internal error scopes and turns what
    /// they catch, or a lost device, into an [`Error`] naming `during`.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn checked<T>(&self, during: &str, work: impl FnOnce() -> T) -> Result<T> {
        self.check_lost(false)?;
        let scopes = [
            wgpu::ErrorFilter::Internal,
            wgpu::ErrorFilter::OutOfMemory,
            wgpu::ErrorFilter::Validation,
        ]
        .map(|filter| self.device.push_error_scope(filter));
        let value = work();
        // Popped innermost first.
        let mut first = None;
        for scope in scopes.into_iter().rev() {
            if let Some(error) = pollster::block_on(scope.pop()) {
                first.get_or_insert(error);
            }
        }
        self.check_lost(first.is_some())?;
        match first {
            Some(error) => Err(Error::Gpu {
                during: during.to_string(),
                message: error.to_string(),
            }),
            None => Ok(value),
        }
    }

    /// Runs `jobs` as [`GpuContext::checked`] runs one, each on a thread of its own: a driver
    /// compiles a pipeline on the thread that makes it (lavapipe takes most of a second over a
    /// tracing kernel), so kernels made side by side are ready sooner. Their values in order,
    /// or the first job's error in order.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn checked_each<T: Send>(&self, during: &str, jobs: Vec<GpuJob<'_, T>>) -> Result<Vec<T>> {
        std::thread::scope(|scope| {
            let running: Vec<_> = jobs
                .into_iter()
                .map(|job| scope.spawn(move || self.checked(during, job)))
                .collect();
            running
                .into_iter()
                .map(|job| {
                    job.join()
                        .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
                })
                .collect()
        })
    }

    /// Runs `jobs` one after another as [`GpuContext::checked`] runs one (a web page has no
    /// threads to run them on side by side).
    #[cfg(target_arch = "wasm32")]
    pub fn checked_each<T>(&self, during: &str, jobs: Vec<GpuJob<'_, T>>) -> Result<Vec<T>> {
        jobs.into_iter()
            .map(|job| self.checked(during, job))
            .collect()
    }

    /// Runs `work`, after an error if the device was lost or earlier work failed. A web page
    /// cannot block on error scopes' promises, so there errors reach the uncaptured-error
    /// handler and the next check reports them.
    #[cfg(target_arch = "wasm32")]
    pub fn checked<T>(&self, _during: &str, work: impl FnOnce() -> T) -> Result<T> {
        self.check_lost(false)?;
        Ok(work())
    }

    /// An error if the device was lost or an error escaped the error scopes. wgpu calls the
    /// lost callback from a poll, so after an error (`failed`, or one that escaped the scopes)
    /// this polls once, for a lost device to explain it; on the error-free path of every frame
    /// it does not.
    fn check_lost(&self, failed: bool) -> Result<()> {
        if failed || self.uncaptured.lock().unwrap().is_some() {
            let _ = self.device.poll(wgpu::PollType::Poll);
        }
        if let Some(reason) = self.lost.lock().unwrap().as_ref() {
            return Err(Error::DeviceLost(reason.clone()));
        }
        match self.uncaptured.lock().unwrap().as_ref() {
            Some(message) => Err(Error::Gpu {
                during: "earlier GPU work".into(),
                message: message.clone(),
            }),
            None => Ok(()),
        }
    }

    /// Blocks until the GPU has finished all submitted work.
    pub fn wait(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::Gpu {
                during: "waiting for the GPU".into(),
                message: e.to_string(),
            })?;
        // The blocking poll above has called the lost callback if the device is gone.
        self.check_lost(false)
    }

    /// Copies `buffer` (which must have `COPY_SRC`) to the CPU as `T`s.
    pub fn read_buffer<T: bytemuck::Pod>(&self, buffer: &wgpu::Buffer) -> Result<Vec<T>> {
        self.read_buffer_range(buffer, 0, buffer.size())
    }

    /// Reads `size` bytes of `buffer` from byte `offset` on back (both multiples of 4).
    pub fn read_buffer_range<T: bytemuck::Pod>(
        &self,
        buffer: &wgpu::Buffer,
        offset: u64,
        size: u64,
    ) -> Result<Vec<T>> {
        let bytes = self.read_back(size, |encoder, staging| {
            encoder.copy_buffer_to_buffer(buffer, offset, staging, 0, size);
        })?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// Reads a 2D texture (or array) with four f32 channels back, layer after layer, row-major.
    pub fn read_texture(&self, texture: &wgpu::Texture) -> Result<Vec<[f32; 4]>> {
        assert_eq!(texture.format().block_copy_size(None), Some(16));
        Ok(bytemuck::pod_collect_to_vec(
            &self.read_texture_bytes(texture)?,
        ))
    }

    /// Reads a 2D texture (or array) back as its texels' bytes, layer after layer, row-major.
    pub fn read_texture_bytes(&self, texture: &wgpu::Texture) -> Result<Vec<u8>> {
        let texel = texture
            .format()
            .block_copy_size(None)
            .expect("a colour format with one texel a block") as usize;
        let size = texture.size();
        let row = texel * size.width as usize;
        // Copies pad each row to a multiple of 256 bytes.
        let padded = row.next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize);
        let rows = (size.height * size.depth_or_array_layers) as usize;
        let bytes = self.read_back((padded * rows) as u64, |encoder, staging| {
            encoder.copy_texture_to_buffer(
                texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: staging,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(padded as u32),
                        rows_per_image: Some(size.height),
                    },
                },
                size,
            );
        })?;
        Ok(bytes
            .chunks_exact(padded)
            .flat_map(|r| &r[..row])
            .copied()
            .collect())
    }

    /// Records `copy` into a staging buffer of `size` bytes, runs it and maps the result.
    fn read_back(
        &self,
        size: u64,
        copy: impl FnOnce(&mut wgpu::CommandEncoder, &wgpu::Buffer),
    ) -> Result<Vec<u8>> {
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fisheye.readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("fisheye.readback"),
            });
        copy(&mut encoder, &staging);
        self.queue.submit([encoder.finish()]);
        let (sender, receiver) = std::sync::mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = sender.send(r);
        });
        self.wait()?;
        let mapped = receiver
            .recv()
            .map_err(|_| Error::DeviceLost("the readback was never answered".into()))?;
        let map_error = |message: String| Error::Gpu {
            during: "reading back from the GPU".into(),
            message,
        };
        mapped.map_err(|e| map_error(e.to_string()))?;
        let view = staging
            .get_mapped_range(..)
            .map_err(|e| map_error(e.to_string()))?;
        let out = view.to_vec();
        drop(view);
        staging.unmap();
        Ok(out)
    }

    /// Checks that an image of `size` fits the adapter's 2D texture limit, as every image we
    /// make must, to be drawn, copied or handed on as a texture.
    pub fn check_image(&self, size: crate::lens::ImageSize) -> Result<()> {
        let max = self.device.limits().max_texture_dimension_2d;
        if size.width > max || size.height > max {
            return Err(crate::error::LensError::ImageSize {
                text: format!("{}x{}", size.width, size.height),
                reason: format!("above this adapter's 2D texture limit of {max} pixels a side"),
            }
            .into());
        }
        Ok(())
    }

    /// Checks that a storage binding of `bytes` fits the device, naming `what` if not.
    pub fn check_binding(&self, what: &str, bytes: u64) -> Result<()> {
        let limit = self.device.limits().max_storage_buffer_binding_size;
        if bytes > limit {
            return Err(Error::Limit(format!(
                "{what} needs a storage buffer of {:.2} MiB, above this adapter's limit of \
                 {:.2} MiB per binding; use a smaller image",
                bytes as f64 / f64::from(1 << 20),
                limit as f64 / f64::from(1 << 20)
            )));
        }
        Ok(())
    }
}
