//! Headless device creation — the only place the runtime creates a `wgpu::Device`.
//!
//! Passes never create devices: they receive `&wgpu::Device` / `&wgpu::Queue` from their caller (as in wgpu's
//! `hello_compute` example), so tests, benchmarks and engines can hand them any device. This helper is what the
//! command, the tests and the benchmark use. It honours `WGPU_BACKEND` (e.g. `vulkan`, `gl`) and
//! `WGPU_ADAPTER_NAME` (case-insensitive substring of the adapter name) and reports the adapter it got, so that
//! figures measured on a software rasteriser (lavapipe, llvmpipe) are never mistaken for GPU figures.
//!
//! The device is created with the adapter's own limits; [`check_image_fits`] compares an image with them before a
//! pass allocates anything (wgpu panics on an over-limit texture or buffer), and refuses with the limit named.

use crate::runtime::RuntimeError;

/// A device, its queue and a description of the adapter behind them.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter_info: wgpu::AdapterInfo,
    /// Whether timestamp queries were enabled on the device (`wgpu::Features::TIMESTAMP_QUERY`).
    pub timestamps: bool,
}

impl Gpu {
    /// One line describing the adapter: name, backend, device type, driver.
    pub fn describe(&self) -> String {
        describe_adapter(&self.adapter_info)
    }

    /// Whether the adapter is a software rasteriser (lavapipe, llvmpipe: `wgpu::DeviceType::Cpu`), whose time
    /// estimates are its own (slower than a GPU's, and than the CPU twins' for some passes).
    pub fn is_software(&self) -> bool {
        self.adapter_info.device_type == wgpu::DeviceType::Cpu
    }
}

/// One line describing an adapter: name, backend, device type, driver.
pub fn describe_adapter(info: &wgpu::AdapterInfo) -> String {
    let kind = match info.device_type {
        wgpu::DeviceType::Cpu => "CPU (software rasteriser: timings are not GPU figures)",
        wgpu::DeviceType::DiscreteGpu => "discrete GPU",
        wgpu::DeviceType::IntegratedGpu => "integrated GPU",
        wgpu::DeviceType::VirtualGpu => "virtual GPU",
        wgpu::DeviceType::Other => "other",
    };
    format!("{} [{:?}, {kind}, driver {} {}]", info.name, info.backend, info.driver, info.driver_info)
}

/// Options for [`create_headless`].
#[derive(Clone, Debug, Default)]
pub struct DeviceOptions {
    /// Request `TIMESTAMP_QUERY` when the adapter supports it (benchmarks).
    pub timestamps: bool,
}

/// Creates a headless device on the adapter selected by `WGPU_BACKEND` / `WGPU_ADAPTER_NAME` (else the default
/// adapter of any enabled backend). Fails with [`RuntimeError::NoAdapter`] when none is found.
pub fn create_headless(opts: &DeviceOptions) -> Result<Gpu, RuntimeError> {
    // One thread at a time: choosing an adapter enumerates every enabled backend, and wgpu's GL backend makes its
    // EGL context current on the calling thread; two threads doing so at once panic inside wgpu-hal (EGL
    // `BadAccess`, seen on an NVIDIA H100 with the test suite's threads and once on llvmpipe).
    let _one_at_a_time = ADAPTER_CHOICE.lock().unwrap_or_else(|e| e.into_inner());
    pollster::block_on(create_headless_async(opts))
}

/// Held while an adapter and a device are chosen ([`create_headless`]).
static ADAPTER_CHOICE: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// The process's one wgpu instance and its backends. Devices of one instance have distinct ids while alive, which
/// the per-device object cache of [`crate::runtime::gpu::cached`] keys on (ids of two instances may coincide).
static INSTANCE: std::sync::LazyLock<(wgpu::Instance, wgpu::Backends)> = std::sync::LazyLock::new(|| {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::VULKAN | wgpu::Backends::GL);
    let backends = desc.backends;
    (wgpu::Instance::new(desc), backends)
});

async fn create_headless_async(opts: &DeviceOptions) -> Result<Gpu, RuntimeError> {
    let (instance, backends) = &*INSTANCE;
    let adapter = match std::env::var("WGPU_ADAPTER_NAME") {
        Ok(want) if !want.is_empty() => {
            let want_lc = want.to_lowercase();
            let adapters = instance.enumerate_adapters(*backends).await;
            let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
            adapters.into_iter().find(|a| a.get_info().name.to_lowercase().contains(&want_lc)).ok_or_else(|| {
                RuntimeError::NoAdapter(format!(
                    "WGPU_ADAPTER_NAME={want:?} matches none of the adapters found ({})",
                    if names.is_empty() { "none".to_string() } else { names.join(", ") }
                ))
            })?
        }
        _ => instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: false,
                compatible_surface: None,
                ..Default::default()
            })
            .await
            .map_err(|e| {
                RuntimeError::NoAdapter(format!(
                    "{e} (backends {backends:?}; on a machine without a GPU install a software driver, e.g. \
                     `apt-get install mesa-vulkan-drivers`)"
                ))
            })?,
    };
    let info = adapter.get_info();
    let timestamps = opts.timestamps && adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
    let mut required_features = if timestamps { wgpu::Features::TIMESTAMP_QUERY } else { wgpu::Features::empty() };
    // The adapter's own format features where they let the antialiasing's edge pass write its `Rg8Unorm` edges as
    // a storage texture (`runtime::aa::pass_shape::EdgeFormat`; else it writes the portable `Rgba8Unorm`).
    if writes_rg8_storage(&adapter) {
        required_features |= wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES;
    }
    let (device, queue) = adapter
        .request_device(&wgpu::DeviceDescriptor {
            label: Some("rtbake runtime"),
            required_features,
            // The adapter's real limits (not wgpu's 256 MiB default buffer cap): every pass checks its image against
            // them with `check_image_fits` before allocating, so an oversized image is refused, never a panic.
            required_limits: adapter.limits(),
            ..Default::default()
        })
        .await
        .map_err(|e| RuntimeError::NoAdapter(format!("{}: cannot create a device: {e}", info.name)))?;
    Ok(Gpu { device, queue, adapter_info: info, timestamps })
}

/// Whether `adapter` lets a compute pass write `Rg8Unorm` as a storage texture (through its own format features).
fn writes_rg8_storage(adapter: &wgpu::Adapter) -> bool {
    let f = adapter.get_texture_format_features(wgpu::TextureFormat::Rg8Unorm);
    adapter.features().contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES)
        && f.allowed_usages.contains(wgpu::TextureUsages::STORAGE_BINDING)
        && f.flags.contains(wgpu::TextureFormatFeatureFlags::STORAGE_WRITE_ONLY)
}

/// Bytes of a read-back buffer of a `width`×`height` image of `bytes_per_texel`-byte texels, rows padded to
/// wgpu's copy alignment (what [`check_image_fits`] compares with `max_buffer_size`).
pub fn readback_bytes(width: u32, height: u32, bytes_per_texel: u32) -> u64 {
    let row = (width as u64 * bytes_per_texel as u64).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64)
        * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64;
    row * height as u64
}

/// Refuses, before any allocation, a `width`×`height` image that the device cannot hold: its 2-D texture edge
/// limit, or the largest buffer the pass needs (a tightly padded read-back of `bytes_per_texel`-byte texels).
/// The error is bad input (exit 2) naming the limit and the way out (`--cpu`, or a smaller image).
pub fn check_image_fits(
    device: &wgpu::Device,
    width: u32,
    height: u32,
    bytes_per_texel: u32,
) -> Result<(), RuntimeError> {
    let limits = device.limits();
    let edge = limits.max_texture_dimension_2d;
    if width > edge || height > edge {
        return Err(crate::error::InvalidInput::new(
            "image",
            format!(
                "{width}x{height} exceeds this GPU's largest 2-D texture, {edge}x{edge} texels \
                 (max_texture_dimension_2d); use `cpu` or an image of at most {edge} texels per side"
            ),
        )
        .into());
    }
    let bytes = readback_bytes(width, height, bytes_per_texel);
    if bytes > limits.max_buffer_size {
        return Err(crate::error::InvalidInput::new(
            "image",
            format!(
                "{width}x{height} needs a {bytes}-byte GPU buffer, this GPU allows at most {} bytes (max_buffer_size); \
                 use `cpu` or a smaller image",
                limits.max_buffer_size
            ),
        )
        .into());
    }
    Ok(())
}
