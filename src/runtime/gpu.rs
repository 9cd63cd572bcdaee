//! Small wgpu helpers shared by the passes: explicit-format textures, uploads, read-backs, full-screen
//! fragment pipelines and GPU timestamp collection. Nothing here creates a device.
//!
//! Shader modules, pipelines, bind-group layouts and samplers are created once per device and reused by every
//! later frame ([`cached`]), as an engine builds its pipeline state objects at load time: a pass constructed per
//! frame costs its textures and bind groups, never a shader compilation. [`pipelines_created_on_this_thread`]
//! counts the pipelines actually compiled, so a test can assert that none is compiled after the first frame.
//! The cache keys on the device's id, distinct among the devices of one wgpu instance: the runtime's devices come
//! from the one instance of [`crate::runtime::device`]; a caller mixing devices of several instances turns the
//! cache off ([`set_object_cache_enabled`]).

use crate::runtime::RuntimeError;
use std::any::Any;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{LazyLock, Mutex};
use wgpu::TextureUsages as U;

type CacheKey = (wgpu::Device, &'static str, u64);
type CacheMap = HashMap<CacheKey, Box<dyn Any + Send + Sync>>;

/// The per-device objects built so far. A device stays alive while it has entries, so only the objects of the
/// [`CACHED_DEVICES`] most recently used devices are kept (a command has one; a test process makes many).
static CACHE: LazyLock<Mutex<(CacheMap, Vec<wgpu::Device>)>> =
    LazyLock::new(|| Mutex::new((HashMap::new(), Vec::new())));
/// Devices whose objects are kept: the most recently used ones.
const CACHED_DEVICES: usize = 16;
static CACHE_ENABLED: AtomicBool = AtomicBool::new(true);

thread_local! {
    static PIPELINES_CREATED: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    static SUBMISSIONS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    static READ_BACKS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    static BUFFERS_UPLOADED: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Buffers of a frame's per-mesh and per-map data (vertices, indices, a scan's surface maps) created and filled on
/// the calling thread since it started: the uploads the [`Kept`] caches avoid after the first frame.
pub fn buffers_uploaded_on_this_thread() -> u64 {
    BUFFERS_UPLOADED.with(|c| c.get())
}

/// Counts one upload in [`buffers_uploaded_on_this_thread`].
pub(crate) fn count_buffer_upload() {
    BUFFERS_UPLOADED.with(|c| c.set(c.get() + 1));
}

/// A small cache of per-frame work kept across frames: the last `keep` values, found by comparing the whole key
/// (no hash stands for it), the most recently used kept. A key naming a `wgpu::Device` keeps that device alive
/// while its entry is kept. With [`object_cache_enabled`] off every call builds its value again, as before the
/// caches existed (benchmarks measure the difference).
pub struct Kept<K, V> {
    entries: Mutex<Vec<(K, V)>>,
    keep: usize,
}

impl<K: PartialEq, V: Clone> Kept<K, V> {
    /// An empty cache keeping at most `keep` values.
    pub const fn new(keep: usize) -> Self {
        Kept { entries: Mutex::new(Vec::new()), keep }
    }

    /// The value of `key`: built by `make` the first time, a clone of it while it is kept. The lock is not held
    /// while `make` runs; two threads racing build it twice and the first kept wins.
    pub fn get_or_try_insert_with<E>(&self, key: K, make: impl FnOnce() -> Result<V, E>) -> Result<V, E> {
        if !object_cache_enabled() {
            return make();
        }
        {
            let mut kept = self.entries.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(i) = kept.iter().position(|(k, _)| *k == key) {
                let entry = kept.remove(i);
                let v = entry.1.clone();
                kept.push(entry);
                return Ok(v);
            }
        }
        let v = make()?;
        // The evicted entry (GPU buffers, a device handle) is dropped after the lock is released.
        let _evicted = {
            let mut kept = self.entries.lock().unwrap_or_else(|e| e.into_inner());
            if let Some((_, first)) = kept.iter().find(|(k, _)| *k == key) {
                return Ok(first.clone());
            }
            let evicted = (kept.len() >= self.keep).then(|| kept.remove(0));
            kept.push((key, v.clone()));
            evicted
        };
        Ok(v)
    }

    /// [`Kept::get_or_try_insert_with`] for a `make` that cannot fail.
    pub fn get_or_insert_with(&self, key: K, make: impl FnOnce() -> V) -> V {
        match self.get_or_try_insert_with(key, || Ok::<V, std::convert::Infallible>(make())) {
            Ok(v) => v,
            Err(never) => match never {},
        }
    }

    /// Number of values kept.
    pub fn len(&self) -> usize {
        self.entries.lock().unwrap_or_else(|e| e.into_inner()).len()
    }

    /// Whether nothing is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Queue submissions made through [`submit`] on the calling thread since it started (every submission of the
/// skin frame's passes goes through it).
pub fn submissions_on_this_thread() -> u64 {
    SUBMISSIONS.with(|c| c.get())
}

/// Host read-backs ([`map_read`]: the host waits for the GPU and copies a buffer out) on the calling thread since
/// it started.
pub fn read_backs_on_this_thread() -> u64 {
    READ_BACKS.with(|c| c.get())
}

/// Submits `commands` to `queue`, counted in [`submissions_on_this_thread`].
pub fn submit(queue: &wgpu::Queue, commands: wgpu::CommandBuffer) {
    SUBMISSIONS.with(|c| c.set(c.get() + 1));
    queue.submit([commands]);
}

/// Turns the per-device object cache on (the default) or off. Off, every pass constructed recompiles its shader
/// and pipelines as the runtime did before the cache existed: benchmarks measure the difference with it.
pub fn set_object_cache_enabled(enabled: bool) {
    CACHE_ENABLED.store(enabled, Ordering::Relaxed);
}

/// Whether the per-device object cache is on (the runtime's other per-frame caches follow the same switch).
pub fn object_cache_enabled() -> bool {
    CACHE_ENABLED.load(Ordering::Relaxed)
}

/// Render and compute pipelines compiled on the calling thread since it started (cache misses only).
pub fn pipelines_created_on_this_thread() -> u64 {
    PIPELINES_CREATED.with(|c| c.get())
}

/// Number of objects (modules, pipelines, layouts, samplers) cached for `device`.
pub fn cached_objects(device: &wgpu::Device) -> usize {
    CACHE.lock().unwrap_or_else(|e| e.into_inner()).0.keys().filter(|k| &k.0 == device).count()
}

/// A 64-bit hash of `key` (the cache's key within one `kind`).
fn key_hash(key: &impl Hash) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    key.hash(&mut h);
    h.finish()
}

/// The object of `kind` and `key` for `device`: built by `make` the first time, a clone of it afterwards. The lock
/// is not held while `make` runs (it may build other cached objects); two threads racing build it twice, one wins.
pub fn cached<T: Clone + Send + Sync + 'static>(
    device: &wgpu::Device,
    kind: &'static str,
    key: &impl Hash,
    make: impl FnOnce() -> T,
) -> T {
    if !CACHE_ENABLED.load(Ordering::Relaxed) {
        return make();
    }
    let k = (device.clone(), kind, key_hash(key));
    {
        let mut guard = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        let (map, devices) = &mut *guard;
        if let Some(v) = map.get(&k).and_then(|b| b.downcast_ref::<T>()) {
            let v = v.clone();
            // Most recently used last.
            if devices.last() != Some(device) {
                if let Some(i) = devices.iter().position(|d| d == device) {
                    let d = devices.remove(i);
                    devices.push(d);
                }
            }
            return v;
        }
    }
    let v = make();
    // An evicted device's objects are dropped after the lock is released (dropping them calls into the driver).
    let mut evicted = Vec::new();
    {
        let mut guard = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        let (map, devices) = &mut *guard;
        if !devices.contains(device) {
            devices.push(device.clone());
            if devices.len() > CACHED_DEVICES {
                let old = devices.remove(0);
                let keys: Vec<CacheKey> = map.keys().filter(|key| key.0 == old).cloned().collect();
                evicted.extend(keys.iter().filter_map(|key| map.remove(key)));
                evicted.push(Box::new(old));
            }
        }
        map.entry(k).or_insert_with(|| Box::new(v.clone()));
    }
    drop(evicted);
    v
}

/// Compiles a render pipeline, counted in [`pipelines_created_on_this_thread`] (wrap it in [`cached`]).
pub fn create_render_pipeline(device: &wgpu::Device, d: &wgpu::RenderPipelineDescriptor<'_>) -> wgpu::RenderPipeline {
    counted(|| device.create_render_pipeline(d))
}

/// Compiles a compute pipeline, counted in [`pipelines_created_on_this_thread`] (wrap it in [`cached`]).
pub fn create_compute_pipeline(
    device: &wgpu::Device,
    d: &wgpu::ComputePipelineDescriptor<'_>,
) -> wgpu::ComputePipeline {
    counted(|| device.create_compute_pipeline(d))
}

/// Runs a pipeline compilation, counting it.
fn counted<T>(compile: impl FnOnce() -> T) -> T {
    PIPELINES_CREATED.with(|c| c.set(c.get() + 1));
    compile()
}

/// A compute pipeline of `module`'s `entry` with the layout derived from the shader, cached per device.
pub fn compute_pipeline(device: &wgpu::Device, module: &wgpu::ShaderModule, entry: &str) -> wgpu::ComputePipeline {
    cached(device, "compute pipeline", &(module, entry), || {
        create_compute_pipeline(
            device,
            &wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            },
        )
    })
}

/// Checks a `width`×`height` frame before any work: a valid image size ([`crate::error::check_size`]) that the
/// device can hold at `bytes_per_texel` ([`crate::runtime::device::check_image_fits`]).
pub fn check_frame(device: &wgpu::Device, width: u32, height: u32, bytes_per_texel: u32) -> Result<(), RuntimeError> {
    crate::error::check_size("image", width as u64, height as u64)?;
    crate::runtime::device::check_image_fits(device, width, height, bytes_per_texel)
}

/// A 2D non-sRGB texture with one mip level and `usage` (the one descriptor the helpers below share).
fn texture_with_usage(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    debug_assert!(!format.is_srgb(), "runtime textures are never sRGB");
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// The usages of [`texture`]: sampled, render target, copy source and destination.
pub(crate) const TARGET_USAGE: U = U::TEXTURE_BINDING.union(U::RENDER_ATTACHMENT).union(U::COPY_DST).union(U::COPY_SRC);
/// The usages of [`data_texture`]: sampled and uploaded to, nothing else.
pub(crate) const DATA_USAGE: U = U::TEXTURE_BINDING.union(U::COPY_DST);
/// The usages of [`storage_texture`]: written by a compute pass, then sampled or copied.
pub(crate) const STORAGE_USAGE: U = U::TEXTURE_BINDING.union(U::STORAGE_BINDING).union(U::COPY_SRC).union(U::COPY_DST);

/// A 2D texture with one mip level, sampled + render target + copy source/destination. `format` is always an
/// explicit non-sRGB format (the runtime never lets the hardware decode sRGB behind its back).
pub fn texture(device: &wgpu::Device, label: &str, w: u32, h: u32, format: wgpu::TextureFormat) -> wgpu::Texture {
    texture_with_usage(device, label, (w, h), format, TARGET_USAGE)
}

/// A sampled, upload-only 2D texture (no render attachment): for inputs such as the `R32Float` linear depth,
/// which not every backend can render to.
pub fn data_texture(device: &wgpu::Device, label: &str, w: u32, h: u32, format: wgpu::TextureFormat) -> wgpu::Texture {
    texture_with_usage(device, label, (w, h), format, DATA_USAGE)
}

/// A 2D texture a compute pass writes (storage) and later passes sample or copy, one mip level.
pub fn storage_texture(device: &wgpu::Device, label: &str, w: u32, h: u32, fmt: wgpu::TextureFormat) -> wgpu::Texture {
    texture_with_usage(device, label, (w, h), fmt, STORAGE_USAGE)
}

/// Bytes per texel of the formats the runtime uses.
pub fn bytes_per_texel(format: wgpu::TextureFormat) -> u32 {
    format.block_copy_size(None).expect("uncompressed colour format")
}

/// Uploads tightly packed texels (top row first) into the whole texture.
/// Uploads an SSS pass's frame: `color` RGBA f32 (linear; alpha = strength) as f16 into `color_tex`
/// (`Rgba16Float`) and `depth` (linear, f32) into `depth_tex`, both `width`×`height`, top row first; other sizes are
/// refused naming `--color/--depth`.
pub fn upload_sss_frame(
    queue: &wgpu::Queue,
    (color_tex, depth_tex): (&wgpu::Texture, &wgpu::Texture),
    color: &[f32],
    depth: &[f32],
) -> Result<(), crate::error::InvalidInput> {
    let (w, h) = (color_tex.width(), color_tex.height());
    let n = w as usize * h as usize;
    if color.len() != 4 * n || depth.len() != n {
        return Err(crate::error::InvalidInput::new("color/depth", format!("must be {w}x{h} (RGBA and one channel)")));
    }
    let half: Vec<half::f16> = color.iter().map(|v| half::f16::from_f32(*v)).collect();
    upload(queue, color_tex, bytemuck::cast_slice(&half));
    upload(queue, depth_tex, bytemuck::cast_slice(depth));
    Ok(())
}

pub fn upload(queue: &wgpu::Queue, tex: &wgpu::Texture, data: &[u8]) {
    let bpt = bytes_per_texel(tex.format());
    let (w, h) = (tex.width(), tex.height());
    assert_eq!(data.len(), (w * h * bpt) as usize, "upload size");
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: tex,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        data,
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(w * bpt), rows_per_image: Some(h) },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
}

/// Bytes of one row of `tex` in a buffer a texture copy reads or writes: its texels rounded up to
/// `COPY_BYTES_PER_ROW_ALIGNMENT`.
pub fn padded_row_bytes(tex: &wgpu::Texture) -> u32 {
    let row = tex.width() * bytes_per_texel(tex.format());
    row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
}

/// The layout of the whole of `tex` at `offset` bytes of a buffer, rows of [`padded_row_bytes`].
fn padded_copy<'a>(
    tex: &'a wgpu::Texture,
    buffer: &'a wgpu::Buffer,
    offset: u64,
) -> [wgpu::TexelCopyBufferInfo<'a>; 1] {
    let layout = wgpu::TexelCopyBufferLayout {
        offset,
        bytes_per_row: Some(padded_row_bytes(tex)),
        rows_per_image: Some(tex.height()),
    };
    [wgpu::TexelCopyBufferInfo { buffer, layout }]
}

fn whole(tex: &wgpu::Texture) -> (wgpu::TexelCopyTextureInfo<'_>, wgpu::Extent3d) {
    let info = wgpu::TexelCopyTextureInfo {
        texture: tex,
        mip_level: 0,
        origin: wgpu::Origin3d::ZERO,
        aspect: wgpu::TextureAspect::All,
    };
    (info, wgpu::Extent3d { width: tex.width(), height: tex.height(), depth_or_array_layers: 1 })
}

/// Records a copy of the whole of `tex` into `buffer` at `offset` (rows of [`padded_row_bytes`]).
pub fn encode_texture_to_buffer(
    enc: &mut wgpu::CommandEncoder,
    tex: &wgpu::Texture,
    buffer: &wgpu::Buffer,
    offset: u64,
) {
    let (info, size) = whole(tex);
    let [dst] = padded_copy(tex, buffer, offset);
    enc.copy_texture_to_buffer(info, dst, size);
}

/// Records a copy of `buffer` from `offset` (rows of [`padded_row_bytes`]) into the whole of `tex`.
pub fn encode_buffer_to_texture(
    enc: &mut wgpu::CommandEncoder,
    buffer: &wgpu::Buffer,
    offset: u64,
    tex: &wgpu::Texture,
) {
    let (info, size) = whole(tex);
    let [src] = padded_copy(tex, buffer, offset);
    enc.copy_buffer_to_texture(src, info, size);
}

/// Reads a whole texture back as tightly packed texels (top row first). Blocks until the GPU is done.
pub fn read_texture(device: &wgpu::Device, queue: &wgpu::Queue, tex: &wgpu::Texture) -> Result<Vec<u8>, RuntimeError> {
    let enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
    Ok(read_textures(device, queue, enc, &[tex])?.remove(0))
}

/// Submits `enc` with copies of the whole of each of `textures` appended, and reads them back with one wait:
/// tightly packed texels (top row first) per texture.
pub fn read_textures(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mut enc: wgpu::CommandEncoder,
    textures: &[&wgpu::Texture],
) -> Result<Vec<Vec<u8>>, RuntimeError> {
    let sizes: Vec<u64> = textures.iter().map(|t| padded_row_bytes(t) as u64 * t.height() as u64).collect();
    let buf = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: sizes.iter().sum::<u64>().max(4),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut offset = 0;
    for (t, size) in textures.iter().zip(&sizes) {
        encode_texture_to_buffer(&mut enc, t, &buf, offset);
        offset += size;
    }
    submit(queue, enc.finish());
    let bytes = map_read(device, &buf)?;
    let mut offset = 0;
    Ok(textures
        .iter()
        .zip(&sizes)
        .map(|(t, size)| {
            let (padded, row) = (padded_row_bytes(t) as usize, (t.width() * bytes_per_texel(t.format())) as usize);
            let img = &bytes[offset..offset + *size as usize];
            offset += *size as usize;
            img.chunks_exact(padded).flat_map(|r| &r[..row]).copied().collect()
        })
        .collect())
}

/// Half floats (`Rgba16Float`, `R16Float`…) as f32 values.
pub fn f16_to_f32(bytes: &[u8]) -> Vec<f32> {
    bytemuck::cast_slice::<u8, half::f16>(bytes).iter().map(|v| v.to_f32()).collect()
}

/// Reads a whole half-float texture (`Rgba16Float`, `R16Float`…) back as f32 values (top row first).
pub fn read_texture_f16(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    tex: &wgpu::Texture,
) -> Result<Vec<f32>, RuntimeError> {
    Ok(f16_to_f32(&read_texture(device, queue, tex)?))
}

/// Maps a `MAP_READ` buffer and copies its content out.
pub fn map_read(device: &wgpu::Device, buf: &wgpu::Buffer) -> Result<Vec<u8>, RuntimeError> {
    READ_BACKS.with(|c| c.set(c.get() + 1));
    let (tx, rx) = std::sync::mpsc::channel();
    buf.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| RuntimeError::Gpu(format!("poll: {e}")))?;
    rx.recv()
        .map_err(|e| RuntimeError::Gpu(format!("map callback lost: {e}")))?
        .map_err(|e| RuntimeError::Gpu(format!("map_async: {e}")))?;
    let out = buf.get_mapped_range(..).map_err(|e| RuntimeError::Gpu(format!("mapped range: {e:?}")))?.to_vec();
    buf.unmap();
    Ok(out)
}

/// Bind group 0 of `pipeline` with `(binding, resource)` pairs.
pub fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    entries: &[(u32, wgpu::BindingResource<'_>)],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> =
        entries.iter().map(|(b, r)| wgpu::BindGroupEntry { binding: *b, resource: r.clone() }).collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}

/// A uniform buffer initialised with `bytes`.
pub fn uniform_buffer(device: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    let buf = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.len() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: true,
    });
    {
        let mut view = buf.slice(..).get_mapped_range_mut().expect("mapped at creation");
        view.copy_from_slice(bytes);
    }
    buf.unmap();
    buf
}

/// A WGSL module from source text, compiled once per device and source (the label of the first caller).
pub fn shader(device: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    cached(device, "shader module", &source, || {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        })
    })
}

/// Nearest, clamp-to-edge sampler (the "PointSampler" of the MLAA listings).
pub fn nearest_clamp_sampler(device: &wgpu::Device) -> wgpu::Sampler {
    clamp_sampler(device, "nearest clamp", wgpu::FilterMode::Nearest)
}

/// Bilinear, clamp-to-edge sampler (the "LinearSampler" of SMAA).
pub fn linear_clamp_sampler(device: &wgpu::Device) -> wgpu::Sampler {
    clamp_sampler(device, "linear clamp", wgpu::FilterMode::Linear)
}

/// A clamp-to-edge sampler filtering with `filter` (mipmaps: nearest), created once per device.
fn clamp_sampler(device: &wgpu::Device, label: &'static str, filter: wgpu::FilterMode) -> wgpu::Sampler {
    cached(device, "sampler", &label, || {
        device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some(label),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: filter,
            min_filter: filter,
            mipmap_filter: wgpu::MipmapFilterMode::Nearest,
            ..Default::default()
        })
    })
}

/// A full-screen-triangle render pipeline: vertex entry `vs_fullscreen`, the given fragment entry, one colour
/// target of `format`, no blending. The bind-group layout is derived from the shader (group 0: exactly the
/// bindings this entry point uses; fetch it with `get_bind_group_layout(0)`).
pub fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    fs_entry: &str,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    let target = wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL };
    fullscreen_pipeline_with(device, label, module, fs_entry, &[Some(target)])
}

/// As [`fullscreen_pipeline`] with the colour `targets` given (several render targets, blending).
pub fn fullscreen_pipeline_with(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    fs_entry: &str,
    targets: &[Option<wgpu::ColorTargetState>],
) -> wgpu::RenderPipeline {
    cached(device, "fullscreen pipeline", &(module, fs_entry, targets), || {
        let descriptor = wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: None,
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(fs_entry),
                compilation_options: Default::default(),
                targets,
            }),
            multiview_mask: None,
            cache: None,
        };
        create_render_pipeline(device, &descriptor)
    })
}

/// Records one full-screen draw into `target` (cleared to zero first), with optional timestamps.
pub fn draw_fullscreen(
    enc: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::RenderPipeline,
    bind_group: &wgpu::BindGroup,
    target: &wgpu::TextureView,
    timer: Option<(&GpuTimer, u32)>,
) {
    let timestamp_writes = timer.map(|(t, i)| t.render_pass_writes(i));
    let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
        })],
        depth_stencil_attachment: None,
        timestamp_writes,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, bind_group, &[]);
    pass.draw(0..3, 0..1);
}

/// Begin/end timestamps for up to `slots` passes (slot i uses queries 2i and 2i+1).
pub struct GpuTimer {
    pub query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    slots: u32,
}

impl GpuTimer {
    /// Needs a device created with `TIMESTAMP_QUERY`.
    pub fn new(device: &wgpu::Device, slots: u32) -> Self {
        let query_set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: 2 * slots,
        });
        let size = 16 * slots as u64;
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps resolve"),
            size,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps readback"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Self { query_set, resolve, readback, slots }
    }

    /// The query set and the begin/end query indices of the pass timed in `slot` (2·slot and 2·slot + 1).
    fn slot_queries(&self, slot: u32) -> (&wgpu::QuerySet, Option<u32>, Option<u32>) {
        (&self.query_set, Some(2 * slot), Some(2 * slot + 1))
    }

    /// The timestamps of a render pass timed in `slot`.
    pub fn render_pass_writes(&self, slot: u32) -> wgpu::RenderPassTimestampWrites<'_> {
        let (query_set, beginning_of_pass_write_index, end_of_pass_write_index) = self.slot_queries(slot);
        wgpu::RenderPassTimestampWrites { query_set, beginning_of_pass_write_index, end_of_pass_write_index }
    }

    /// The timestamps of a compute pass timed in `slot`.
    pub fn compute_pass_writes(&self, slot: u32) -> wgpu::ComputePassTimestampWrites<'_> {
        let (query_set, beginning_of_pass_write_index, end_of_pass_write_index) = self.slot_queries(slot);
        wgpu::ComputePassTimestampWrites { query_set, beginning_of_pass_write_index, end_of_pass_write_index }
    }

    /// Records the resolve; call after the timed passes, before `finish`.
    pub fn resolve(&self, enc: &mut wgpu::CommandEncoder) {
        enc.resolve_query_set(&self.query_set, 0..2 * self.slots, &self.resolve, 0);
        enc.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, 16 * self.slots as u64);
    }

    /// Durations of each slot in milliseconds (after the submission that resolved them).
    pub fn read_ms(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<f64>, RuntimeError> {
        let bytes = map_read(device, &self.readback)?;
        let ticks: &[u64] = bytemuck::cast_slice(&bytes);
        let period_ns = queue.get_timestamp_period() as f64;
        Ok((0..self.slots as usize)
            .map(|i| ticks[2 * i + 1].wrapping_sub(ticks[2 * i]) as f64 * period_ns * 1e-6)
            .collect())
    }
}

/// A measured copy bandwidth: what [`copy_bandwidth`] timed.
#[derive(Clone, Debug)]
pub struct CopyBandwidth {
    /// Bytes read plus bytes written per second.
    pub bytes_per_s: f64,
    /// Median time of one submission's copies, ms.
    pub ms: f64,
    /// Copies per submission and bytes per copy.
    pub copies: u64,
    pub bytes_per_copy: u64,
    /// Medians of how many submissions, and whether timed by timestamps (else wall time of submit + wait).
    pub runs: usize,
    pub by_timestamps: bool,
}

impl CopyBandwidth {
    /// One line: the bandwidth and how it was measured.
    pub fn describe(&self) -> String {
        format!(
            "copy bandwidth: {:.1} GB/s (read + write; {} copies of {} MiB, median of {}, {}: {:.3} ms)",
            self.bytes_per_s * 1e-9,
            self.copies,
            self.bytes_per_copy >> 20,
            self.runs,
            if self.by_timestamps { "timestamps" } else { "wall time" },
            self.ms
        )
    }
}

/// The adapter's buffer-to-buffer copy bandwidth, the figure a pass's bytes-moved bound divides by: the median of
/// `runs` submissions (after one warm-up) of four copies between two buffers of up to 256 MiB, timed by
/// timestamps around the copies (empty compute passes either side) when `timestamps` (the device has
/// `TIMESTAMP_QUERY`), else by wall time of submit + wait.
pub fn copy_bandwidth(device: &wgpu::Device, queue: &wgpu::Queue, timestamps: bool, runs: usize) -> CopyBandwidth {
    let size = (256u64 << 20).min(device.limits().max_buffer_size / 2) / 16 * 16;
    let mk = |label| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    };
    let (a, b) = (mk("copy a"), mk("copy b"));
    let copies = 4u64;
    let timer = timestamps.then(|| GpuTimer::new(device, 2));
    let (mut gpu_ms, mut wall_ms) = (Vec::new(), Vec::new());
    for run in 0..runs.max(1) + 1 {
        let mut enc = device.create_command_encoder(&Default::default());
        let mark = |enc: &mut wgpu::CommandEncoder, slot: u32| {
            if let Some(t) = &timer {
                let timestamp_writes = Some(t.compute_pass_writes(slot));
                drop(enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: None, timestamp_writes }));
            }
        };
        mark(&mut enc, 0);
        for k in 0..copies {
            let (src, dst) = if k % 2 == 0 { (&a, &b) } else { (&b, &a) };
            enc.copy_buffer_to_buffer(src, 0, dst, 0, size);
        }
        mark(&mut enc, 1);
        if let Some(t) = &timer {
            t.resolve(&mut enc);
        }
        let t0 = std::time::Instant::now();
        queue.submit([enc.finish()]);
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        if run == 0 {
            continue;
        }
        wall_ms.push(ms);
        if let Some(t) = &timer {
            // Slot 0 ends before the copies, slot 1 begins after them.
            if let Ok(bytes) = map_read(device, &t.readback) {
                let ticks: &[u64] = bytemuck::cast_slice(&bytes);
                gpu_ms.push(ticks[2].wrapping_sub(ticks[1]) as f64 * queue.get_timestamp_period() as f64 * 1e-6);
            }
        }
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let n = wall_ms.len();
    let by_gpu = !gpu_ms.is_empty() && median(gpu_ms.clone()) > 0.0;
    let ms = if by_gpu { median(gpu_ms) } else { median(wall_ms) };
    CopyBandwidth {
        bytes_per_s: (2 * copies * size) as f64 / (ms * 1e-3),
        ms,
        copies,
        bytes_per_copy: size,
        runs: n,
        by_timestamps: by_gpu,
    }
}

/// Per-pass GPU profiling of the compute chains a frame records ([`crate::runtime::compute_chain::record`]), off by
/// default. On (for the calling thread, [`set_pass_profiling`]), every compute pass a chain records gets begin/end
/// timestamps (where the device has `TIMESTAMP_QUERY`), its label and the bytes it must move; [`profile_mark`]
/// stamps a point in an encoder (the start of a frame) so that the work before the next chain pass — render passes,
/// copies, passes recorded outside compute chains — is timed as one span. [`take_pass_profile`] resolves them after
/// the frame's submission. Off, a chain checks one thread-local flag and records what it always did.
struct PassProfile {
    /// Chain recordings and marks in recording order.
    recorded: Vec<Recorded>,
}

/// A profiled chain recording or a mark: its timer (None without timestamps) and per slot its label and bytes
/// moved (one slot, bytes None, for a mark).
struct Recorded {
    timer: Option<GpuTimer>,
    passes: Vec<(String, Option<u64>)>,
    mark: bool,
}

thread_local! {
    static PASS_PROFILE: std::cell::RefCell<Option<PassProfile>> = const { std::cell::RefCell::new(None) };
}

/// One timed piece of a profiled frame, in recording order.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTime {
    /// A chain pass: `"<chain>: <entry point>"` (plus the stage's first argument, a pyramid level, where the chain
    /// dispatches the entry point more than once). A span: `"<from> → <to>"`, the points it lies between.
    pub label: String,
    /// GPU milliseconds between the pass's (span's) begin and end timestamps; None where the device has no
    /// timestamp queries.
    pub gpu_ms: Option<f64>,
    /// Bytes the pass must move (`runtime::compute_chain`'s rule); None for a span, whose work is not a
    /// chain's.
    pub bytes: Option<u64>,
    /// Whether this is a span (the work between two timed points) rather than a chain pass.
    pub span: bool,
}

/// Turns per-pass profiling on or off for frames recorded on the calling thread. On starts an empty profile
/// (dropping one not taken); off drops it.
pub fn set_pass_profiling(on: bool) {
    PASS_PROFILE.with(|p| *p.borrow_mut() = on.then(|| PassProfile { recorded: Vec::new() }));
}

/// Whether per-pass profiling is on for the calling thread.
pub fn pass_profiling() -> bool {
    PASS_PROFILE.with(|p| p.borrow().is_some())
}

/// A timer of `slots` passes for a profiled recording on `device`: None when profiling is off, the device has no
/// timestamp queries or there is nothing to time (`Some(None)`: profiling on, no timestamps).
pub(crate) fn profile_timer(device: &wgpu::Device, slots: u32) -> Option<Option<GpuTimer>> {
    if !pass_profiling() {
        return None;
    }
    let timed = slots > 0 && device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
    Some(timed.then(|| GpuTimer::new(device, slots)))
}

/// Adds a profiled recording: `timer`'s slots are the passes named in `passes` (label, bytes moved).
pub(crate) fn profile_passes(timer: Option<GpuTimer>, passes: Vec<(String, Option<u64>)>) {
    PASS_PROFILE.with(|p| {
        if let Some(p) = p.borrow_mut().as_mut() {
            p.recorded.push(Recorded { timer, passes, mark: false });
        }
    });
}

/// When profiling is on, stamps the current point of `enc` as `label` (an empty compute pass with timestamps):
/// the work recorded between it and the next chain pass comes back as one span. Nothing when off.
pub fn profile_mark(device: &wgpu::Device, enc: &mut wgpu::CommandEncoder, label: &str) {
    let Some(timer) = profile_timer(device, 1) else { return };
    if let Some(t) = &timer {
        let timestamp_writes = Some(t.compute_pass_writes(0));
        drop(enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes }));
    }
    PASS_PROFILE.with(|p| {
        if let Some(p) = p.borrow_mut().as_mut() {
            p.recorded.push(Recorded { timer, passes: vec![(label.to_string(), None)], mark: true });
        }
    });
}

/// The passes profiled on the calling thread since profiling was turned on or last taken, in recording order, with
/// the spans between them (call after the frame's submission; one more submission resolves the timestamps).
/// Profiling stays on with an empty profile. After a mark (the start of a frame recorded into one encoder), the
/// GPU time from the mark to the next chain pass is a span, and so is the time from the end of one chain recording
/// to the beginning of the next; chains recorded before any mark (each in its own submission, say) have no spans
/// between them, as idle time between submissions would count in them.
pub fn take_pass_profile(device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<PassTime>, RuntimeError> {
    let recorded = PASS_PROFILE.with(|p| p.borrow_mut().as_mut().map(|p| std::mem::take(&mut p.recorded)));
    let recorded = recorded.unwrap_or_default();
    let timed = recorded.iter().any(|r| r.timer.is_some());
    let mut ticks = Vec::new();
    if timed {
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pass profile") });
        for t in recorded.iter().filter_map(|r| r.timer.as_ref()) {
            t.resolve(&mut enc);
        }
        submit(queue, enc.finish());
        for r in &recorded {
            ticks.push(match &r.timer {
                Some(t) => Some(bytemuck::cast_slice::<u8, u64>(&map_read(device, &t.readback)?).to_vec()),
                None => None,
            });
        }
    } else {
        ticks.resize(recorded.len(), None);
    }
    let ns = queue.get_timestamp_period() as f64;
    let ms = |from: u64, to: u64| to.wrapping_sub(from) as i64 as f64 * ns * 1e-6;
    let mut out = Vec::new();
    // The last timed point (ticks, label): a mark's beginning or a chain's last end.
    let mut last: Option<(Option<u64>, String)> = None;
    let mut after_mark = false;
    for (Recorded { passes, mark, .. }, t) in recorded.iter().zip(&ticks) {
        if *mark {
            let here = t.as_ref().map(|t| t[0]);
            // A mark after a mark or a chain closes the span since that point.
            if let (true, Some((from, from_label))) = (after_mark, &last) {
                let gpu_ms = from.zip(here).map(|(from, here)| ms(from, here));
                out.push(PassTime {
                    label: format!("{from_label} → {}", passes[0].0),
                    gpu_ms,
                    bytes: None,
                    span: true,
                });
            }
            last = Some((here, passes[0].0.clone()));
            after_mark = true;
            continue;
        }
        if let (true, Some((from, from_label)), Some((to, _))) = (after_mark, &last, passes.first()) {
            let gpu_ms = from.zip(t.as_ref()).map(|(from, t)| ms(from, t[0]));
            out.push(PassTime { label: format!("{from_label} → {to}"), gpu_ms, bytes: None, span: true });
        }
        for (k, (label, bytes)) in passes.iter().enumerate() {
            let gpu_ms = t.as_ref().map(|t| ms(t[2 * k], t[2 * k + 1]));
            out.push(PassTime { label: label.clone(), gpu_ms, bytes: *bytes, span: false });
        }
        if let Some((label, _)) = passes.last() {
            last = Some((t.as_ref().map(|t| t[2 * passes.len() - 1]), label.clone()));
        }
    }
    Ok(out)
}
