//! A frame's per-pixel buffers and textures kept across frames, as an engine keeps its render targets: a frame
//! opens a [`FrameScope`] on its device, takes its storage buffers, read-back buffers and textures from the
//! device's pool ([`buffer`], [`texture`]) and gives them back when the scope closes — after the frame's
//! submission and read-back. Until then a taken resource is the frame's alone: two frames never alias one, and
//! two threads rendering on one device at once never share one (each thread's open frame lists what it took).
//! A resource the frame leaves on the device for its caller ([`FrameScope::detach`]) returns when the caller drops
//! it.
//!
//! A reused resource is **not** zero (wgpu zeroes a resource only when it is created): a pass that reads what it
//! did not write first must clear it in its encoder. Outside an open frame, or with the pool off
//! on the calling thread ([`set_frame_pool_enabled`], for benchmarks), every call creates a new (zeroed) resource, as before the pool.
//!
//! What the last frames on a device did not use is evicted ([`KEEP_FRAMES`]), and the pools of only the most
//! recently used [`POOLED_DEVICES`] devices are kept (a pool holds its device alive; a test process makes many).
//! [`buffers_created_on_this_thread`] and [`textures_created_on_this_thread`] count the resources created through
//! the pool's functions, so a test can assert that a steady-state frame creates none.

use std::cell::{Cell, RefCell};
use std::sync::{Arc, Mutex};

/// Devices whose pools are kept: the most recently used ones.
pub const POOLED_DEVICES: usize = 8;
/// A free resource is evicted when none of the last `KEEP_FRAMES` frames ended on its device used it.
pub const KEEP_FRAMES: u64 = 2;

thread_local! {
    static ENABLED: Cell<bool> = const { Cell::new(true) };
    static BUFFERS_CREATED: Cell<u64> = const { Cell::new(0) };
    static TEXTURES_CREATED: Cell<u64> = const { Cell::new(0) };
    /// The frames open on this thread, innermost last: the device and what each has taken.
    static OPEN: RefCell<Vec<OpenFrame>> = const { RefCell::new(Vec::new()) };
}

/// Turns the frame pool on (the default) or off for frames opened on the calling thread. Off, every frame
/// creates its buffers and textures as before the pool existed (benchmarks compare the two in one run; a test
/// turns it off on its own thread without touching frames rendered on others).
pub fn set_frame_pool_enabled(enabled: bool) {
    ENABLED.with(|c| c.set(enabled));
}

/// Whether the frame pool is on for the calling thread.
pub fn frame_pool_enabled() -> bool {
    ENABLED.with(|c| c.get())
}

/// Buffers created through [`buffer`] on the calling thread since it started (pool misses and unpooled calls).
pub fn buffers_created_on_this_thread() -> u64 {
    BUFFERS_CREATED.with(|c| c.get())
}

/// Textures created through [`texture`] on the calling thread since it started (pool misses and unpooled calls).
pub fn textures_created_on_this_thread() -> u64 {
    TEXTURES_CREATED.with(|c| c.get())
}

/// What identifies interchangeable textures: size, layers, format, usage and sample count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct TextureKey {
    size: (u32, u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    samples: u32,
}

impl TextureKey {
    fn of(t: &wgpu::Texture) -> Self {
        TextureKey {
            size: (t.width(), t.height(), t.depth_or_array_layers()),
            format: t.format(),
            usage: t.usage(),
            samples: t.sample_count(),
        }
    }
}

/// A pooled resource.
#[derive(Clone, Debug)]
enum Resource {
    Buffer(wgpu::Buffer),
    Texture(wgpu::Texture),
}

impl Resource {
    fn matches_buffer(&self, size: u64, usage: wgpu::BufferUsages) -> bool {
        matches!(self, Resource::Buffer(b) if b.size() == size && b.usage() == usage)
    }

    fn matches_texture(&self, key: &TextureKey) -> bool {
        matches!(self, Resource::Texture(t) if TextureKey::of(t) == *key)
    }
}

struct OpenFrame {
    device: wgpu::Device,
    /// The queue the frame's uniform blocks are written through.
    queue: wgpu::Queue,
    taken: Vec<Resource>,
}

/// One device's free resources, each with the number of the frame that last returned it.
struct DevicePool {
    device: wgpu::Device,
    frames_ended: u64,
    free: Vec<(Resource, u64)>,
}

/// The pools, most recently used last.
static POOLS: Mutex<Vec<DevicePool>> = Mutex::new(Vec::new());

fn pools() -> std::sync::MutexGuard<'static, Vec<DevicePool>> {
    POOLS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Takes a free resource of `device` that `fits`, if any.
fn take_free(device: &wgpu::Device, fits: impl Fn(&Resource) -> bool) -> Option<Resource> {
    let mut pools = pools();
    let pool = pools.iter_mut().find(|p| &p.device == device)?;
    let i = pool.free.iter().position(|(r, _)| fits(r))?;
    Some(pool.free.swap_remove(i).0)
}

/// Whether a frame on `device` is open on this thread (its innermost frame), the pool being on.
fn open_on(device: &wgpu::Device) -> bool {
    frame_pool_enabled() && OPEN.with(|o| o.borrow().last().is_some_and(|f| &f.device == device))
}

/// Records `r` as taken by this thread's innermost open frame.
fn note_taken(r: Resource) {
    OPEN.with(|o| {
        if let Some(f) = o.borrow_mut().last_mut() {
            f.taken.push(r);
        }
    });
}

/// Puts `resources` back into `device`'s pool as returned by a frame that just ended, and evicts what the last
/// [`KEEP_FRAMES`] frames did not use; keeps at most [`POOLED_DEVICES`] pools.
fn give_back(device: &wgpu::Device, resources: Vec<Resource>, frame_ended: bool) {
    // What is evicted is dropped after the lock is released: dropping a wgpu resource (or a device's last
    // handle) calls into the driver, which must never wait while this lock is held.
    let mut evicted_pools = Vec::new();
    let evicted;
    {
        let mut pools = pools();
        let i = match pools.iter().position(|p| &p.device == device) {
            Some(i) => i,
            None => {
                pools.push(DevicePool { device: device.clone(), frames_ended: 0, free: Vec::new() });
                if pools.len() > POOLED_DEVICES {
                    evicted_pools.push(pools.remove(0));
                }
                pools.len() - 1
            }
        };
        let mut pool = pools.remove(i);
        pool.frames_ended += frame_ended as u64;
        let now = pool.frames_ended;
        pool.free.extend(resources.into_iter().map(|r| (r, now)));
        let (kept, old): (Vec<_>, Vec<_>) = pool.free.drain(..).partition(|(_, last)| last + KEEP_FRAMES > now);
        pool.free = kept;
        evicted = old;
        pools.push(pool);
    }
    drop(evicted);
    drop(evicted_pools);
}

/// Number of free resources kept for `device` (for tests).
pub fn free_resources(device: &wgpu::Device) -> usize {
    pools().iter().find(|p| &p.device == device).map_or(0, |p| p.free.len())
}

/// An open frame on a device: resources taken through [`buffer`] and [`texture`] on this thread while it is open
/// go back to the pool when it is dropped. Drop it only after the frame's submission (the queue runs submissions
/// in order, so a later frame's use of a returned resource comes after this frame's).
#[must_use = "the frame's resources return to the pool when the scope is dropped"]
pub struct FrameScope {
    device: Option<wgpu::Device>,
}

impl FrameScope {
    /// Opens a frame on `device` for the calling thread (a no-op scope with the pool off); its uniform blocks
    /// are written through `queue` (`uniform_buffer`).
    pub fn open(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        if !frame_pool_enabled() {
            return FrameScope { device: None };
        }
        let frame = OpenFrame { device: device.clone(), queue: queue.clone(), taken: Vec::new() };
        OPEN.with(|o| o.borrow_mut().push(frame));
        FrameScope { device: Some(device.clone()) }
    }

    /// Takes `buffer` out of this frame's resources: it stays the caller's (not reused by any frame) until the
    /// returned handle is dropped, then goes back to the pool.
    pub fn detach(&self, buffer: wgpu::Buffer) -> PooledBuffer {
        let device = self.device.clone();
        if device.is_some() {
            OPEN.with(|o| {
                if let Some(f) = o.borrow_mut().last_mut() {
                    if let Some(i) = f.taken.iter().position(|r| matches!(r, Resource::Buffer(b) if *b == buffer)) {
                        f.taken.swap_remove(i);
                    }
                }
            });
        }
        PooledBuffer { buffer, device: device.map(Arc::new) }
    }
}

impl Drop for FrameScope {
    fn drop(&mut self) {
        let Some(device) = self.device.take() else { return };
        let frame = OPEN.with(|o| o.borrow_mut().pop());
        if let Some(f) = frame {
            debug_assert!(f.device == device, "frames close in the order they opened");
            give_back(&device, f.taken, true);
        }
    }
}

/// A buffer a frame left on the device for its caller: back to the pool when dropped.
#[derive(Debug)]
pub struct PooledBuffer {
    buffer: wgpu::Buffer,
    device: Option<Arc<wgpu::Device>>,
}

impl PooledBuffer {
    /// The buffer.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }
}

impl Drop for PooledBuffer {
    fn drop(&mut self) {
        if let Some(device) = self.device.take() {
            give_back(&device, vec![Resource::Buffer(self.buffer.clone())], false);
        }
    }
}

/// A buffer of exactly `size` bytes and `usage` for the frame open on this thread: a free one of the device's
/// pool (its content is whatever a former frame left: **not zero**), or a new one (zeroed) when none is free, the
/// pool is off or no frame is open on `device`.
pub fn buffer(device: &wgpu::Device, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    let pooled = open_on(device);
    if pooled {
        if let Some(Resource::Buffer(b)) = take_free(device, |r| r.matches_buffer(size, usage)) {
            note_taken(Resource::Buffer(b.clone()));
            return b;
        }
    }
    BUFFERS_CREATED.with(|c| c.set(c.get() + 1));
    let b =
        device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false });
    if pooled {
        note_taken(Resource::Buffer(b.clone()));
    }
    b
}

/// A texture for the frame open on this thread like the one `make` creates (which must create a texture of
/// `size` (width, height, layers), `format`, `usage` and `samples`): a free one of the device's pool (content
/// left by a former frame), or `make`'s when none is free, the pool is off or no frame is open on `device`.
pub fn texture(
    device: &wgpu::Device,
    (size, format, usage, samples): ((u32, u32, u32), wgpu::TextureFormat, wgpu::TextureUsages, u32),
    make: impl FnOnce() -> wgpu::Texture,
) -> wgpu::Texture {
    let key = TextureKey { size, format, usage, samples };
    let pooled = open_on(device);
    if pooled {
        if let Some(Resource::Texture(t)) = take_free(device, |r| r.matches_texture(&key)) {
            note_taken(Resource::Texture(t.clone()));
            return t;
        }
    }
    TEXTURES_CREATED.with(|c| c.set(c.get() + 1));
    let t = make();
    debug_assert_eq!(TextureKey::of(&t), key, "the texture made is not the one described");
    if pooled {
        note_taken(Resource::Texture(t.clone()));
    }
    t
}

/// The usages of a compute chain's storage buffers: bound, and copied from and to (other passes of a frame read
/// them); `compute_chain::STORAGE_USAGE`.
pub(crate) const STORAGE_BUFFER_USAGE: wgpu::BufferUsages =
    wgpu::BufferUsages::STORAGE.union(wgpu::BufferUsages::COPY_SRC).union(wgpu::BufferUsages::COPY_DST);

/// A storage buffer of a frame's compute chain ([`STORAGE_BUFFER_USAGE`]) of at least `bytes` (rounded up to 16
/// as `compute_chain::storage_buffer` rounds): see [`buffer`] (**not zero** when reused).
pub(crate) fn storage_buffer(device: &wgpu::Device, what: &str, bytes: u64) -> wgpu::Buffer {
    buffer(device, what, bytes.div_ceil(16).max(1) * 16, STORAGE_BUFFER_USAGE)
}

/// A uniform buffer holding `bytes` for the frame: a pooled one written through the open frame's queue
/// (`queue.write_buffer`, ordered after every earlier submission), or a new one initialised with `bytes` (as
/// [`crate::runtime::gpu::uniform_buffer`]) when none is free, the pool is off or no frame is open on `device`.
pub(crate) fn uniform_buffer(device: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    let queue = OPEN.with(|o| o.borrow().last().filter(|f| &f.device == device).map(|f| f.queue.clone()));
    let size = bytes.len() as u64;
    match queue.filter(|_| frame_pool_enabled() && size > 0 && size.is_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT)) {
        Some(queue) => {
            let b = buffer(device, label, size, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
            queue.write_buffer(&b, 0, bytes);
            b
        }
        None => {
            BUFFERS_CREATED.with(|c| c.set(c.get() + 1));
            crate::runtime::gpu::uniform_buffer(device, label, bytes)
        }
    }
}

/// A read-back buffer (copy destination, mapped for reading) of `bytes`: see [`buffer`].
pub(crate) fn readback_buffer(device: &wgpu::Device, bytes: u64) -> wgpu::Buffer {
    buffer(device, "readback", bytes, wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ)
}

/// A 2D single-sample texture of one layer for the frame, created by `make` (one of `runtime::gpu`'s texture
/// helpers, say) when none is free: see [`texture`].
pub(crate) fn texture_2d(
    device: &wgpu::Device,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    make: impl FnOnce() -> wgpu::Texture,
) -> wgpu::Texture {
    texture(device, ((width, height, 1), format, usage, 1), make)
}

/// [`crate::runtime::gpu::texture`] (sampled, render target, copied) for the frame: see [`texture`].
pub(crate) fn target(device: &wgpu::Device, label: &str, w: u32, h: u32, f: wgpu::TextureFormat) -> wgpu::Texture {
    let usage = crate::runtime::gpu::TARGET_USAGE;
    texture_2d(device, (w, h), f, usage, || crate::runtime::gpu::texture(device, label, w, h, f))
}

/// [`crate::runtime::gpu::storage_texture`] for the frame: see [`texture`].
pub(crate) fn storage_target(
    device: &wgpu::Device,
    label: &str,
    w: u32,
    h: u32,
    f: wgpu::TextureFormat,
) -> wgpu::Texture {
    let usage = crate::runtime::gpu::STORAGE_USAGE;
    texture_2d(device, (w, h), f, usage, || crate::runtime::gpu::storage_texture(device, label, w, h, f))
}

/// [`crate::runtime::gpu::data_texture`] (sampled, uploaded to) for the frame: see [`texture`].
pub(crate) fn data_target(device: &wgpu::Device, label: &str, w: u32, h: u32, f: wgpu::TextureFormat) -> wgpu::Texture {
    let usage = crate::runtime::gpu::DATA_USAGE;
    texture_2d(device, (w, h), f, usage, || crate::runtime::gpu::data_texture(device, label, w, h, f))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn device() -> crate::runtime::device::Gpu {
        crate::runtime::device::create_headless(&Default::default()).expect("an adapter (lavapipe)")
    }

    /// Within one frame two takes of the same size are two buffers; the next frame gets the first frame's back
    /// (nothing created); a frame that does not use a size lets it be evicted after [`KEEP_FRAMES`] frames; a
    /// detached buffer is not reused until dropped; with no frame open nothing is pooled.
    #[test]
    fn frames_reuse_buffers_never_alias_and_evict_what_they_stop_using() {
        let g = device();
        let d = &g.device;
        let usage = wgpu::BufferUsages::STORAGE;
        let created = buffers_created_on_this_thread;
        let (a, b) = {
            let _f = FrameScope::open(d, &g.queue);
            (buffer(d, "a", 256, usage), buffer(d, "b", 256, usage))
        };
        assert_ne!(a, b, "two takes in one frame alias");
        assert_eq!(free_resources(d), 2);
        let before = created();
        {
            let _f = FrameScope::open(d, &g.queue);
            let (c, e) = (buffer(d, "c", 256, usage), buffer(d, "e", 256, usage));
            assert!((c == a || c == b) && (e == a || e == b) && c != e, "the first frame's buffers are reused");
        }
        assert_eq!(created(), before, "a steady frame creates nothing");
        for _ in 0..KEEP_FRAMES {
            let _f = FrameScope::open(d, &g.queue);
            let _ = buffer(d, "other", 512, usage);
        }
        assert_eq!(free_resources(d), 1, "the 256-byte buffers unused for {KEEP_FRAMES} frames are evicted");
        let kept = {
            let f = FrameScope::open(d, &g.queue);
            f.detach(buffer(d, "out", 512, usage))
        };
        {
            let _f = FrameScope::open(d, &g.queue);
            let other = buffer(d, "next", 512, usage);
            assert_ne!(&other, kept.buffer(), "a detached buffer was handed to another frame");
        }
        let kept_buffer = kept.buffer().clone();
        drop(kept);
        {
            let _f = FrameScope::open(d, &g.queue);
            let first = buffer(d, "x", 512, usage);
            let second = buffer(d, "y", 512, usage);
            assert!(first == kept_buffer || second == kept_buffer, "a dropped detached buffer returns to the pool");
        }
        let loose = buffer(d, "no frame", 512, usage);
        let _f = FrameScope::open(d, &g.queue);
        assert_ne!(buffer(d, "z", 1024, usage), loose);
    }
}
