//! A small compute-shader runner for the per-pixel skin passes of `run skin` (the rig at the mesh's uv, the
//! wrinkle pass, bloom): one WGSL module, one uniform block at binding 0 and flat `f32` storage buffers at bindings
//! 1..=N (all `var<storage, read_write>`, so every entry point shares one explicit layout), run as a chain of
//! entry points in one submission, one buffer read back ([`run`]), or recorded into a frame's command encoder over
//! GPU buffers the frame's other passes write and read ([`record`]: no submission, no read-back). The module, layout and pipelines are built once per device
//! and chain ([`gpu::cached`]); each run creates only its buffers and bind group. Flat buffers with the filtering done in shader
//! arithmetic keep the passes free of texture formats and filter precision (the CPU twins do the same f32 sums).

use crate::error::InvalidInput;
use crate::runtime::gpu;
use crate::runtime::RuntimeError;

/// A storage buffer of the chain: initial contents, or zeroed with a size in bytes.
pub(crate) enum Buffer<'a> {
    Data(&'a [u8]),
    Zeroed(u64),
}

/// One dispatch: entry point, workgroup counts and four `u32` the stage reads as the last 16 bytes of the
/// uniform block (`stage: vec4<u32>` after the caller's fields; a pyramid level, say), so one entry point serves
/// several dispatches. A module that declares no such field ignores them.
pub(crate) struct Stage<'a> {
    pub entry: &'a str,
    pub groups: [u32; 3],
    pub args: [u32; 4],
}

impl<'a> Stage<'a> {
    /// A dispatch of `entry` over `groups`, arguments 0.
    pub(crate) fn new(entry: &'a str, groups: [u32; 3]) -> Self {
        Stage { entry, groups, args: [0; 4] }
    }
}

/// The uniform block of a per-pixel chain that reads baked maps: the frame's and a map's size, a second map's
/// size or counts, and eight weights (the rig at uv, the wrinkle pass; each module names the fields).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct MapParams {
    pub size: [f32; 4],
    pub cfg: [f32; 4],
    pub weights: [[f32; 4]; 2],
}

/// Bytes of a per-pixel buffer of one vec4 of f32 over a `width`×`height` frame.
pub(crate) fn vec4_per_pixel_bytes(width: u32, height: u32) -> u64 {
    16 * width as u64 * height as u64
}

/// Workgroups of 8×8 covering a `w`×`h` image.
pub(crate) fn groups_8x8(w: u32, h: u32) -> [u32; 3] {
    [w.div_ceil(8), h.div_ceil(8), 1]
}

/// The usages of a chain's storage buffers: bound, and copied from and to (other passes of a frame read them).
pub(crate) const STORAGE_USAGE: wgpu::BufferUsages = crate::runtime::frame_pool::STORAGE_BUFFER_USAGE;

/// Checks `sizes` (bytes of each storage buffer) against the adapter's limits; `what` names the pass.
pub(crate) fn check_buffers(device: &wgpu::Device, what: &str, sizes: &[u64]) -> Result<(), RuntimeError> {
    let limit = device.limits().max_storage_buffer_binding_size;
    if let Some(s) = sizes.iter().find(|&&s| s > limit) {
        return Err(InvalidInput::new(
            what,
            format!("a {s}-byte buffer exceeds the adapter's storage-buffer limit of {limit} bytes"),
        )
        .into());
    }
    if sizes.len() as u32 > device.limits().max_storage_buffers_per_shader_stage {
        return Err(RuntimeError::Gpu(format!("{what}: more storage buffers than the adapter binds")));
    }
    Ok(())
}

/// A storage buffer of at least `bytes` (rounded up to 16: bindings must not be empty and copies are 4-byte
/// multiples), holding `data` at its start when given, zero elsewhere (wgpu zeroes a buffer created unmapped, on
/// the device: no host copy of zeros).
pub(crate) fn storage_buffer(device: &wgpu::Device, what: &str, bytes: u64, data: Option<&[u8]>) -> wgpu::Buffer {
    let buf = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(what),
        size: bytes.div_ceil(16).max(1) * 16,
        usage: STORAGE_USAGE,
        mapped_at_creation: data.is_some(),
    });
    if data.is_none() {
        return buf;
    }
    if let Some(d) = data.filter(|d| !d.is_empty()) {
        let mut view = buf.slice(..d.len() as u64).get_mapped_range_mut().expect("mapped at creation");
        view.copy_from_slice(d);
    }
    buf.unmap();
    buf
}

/// Runs `stages` in order over `buffers` (bindings 1..=N) with `uniform` at binding 0 and returns the bytes of
/// buffer `read` (an index into `buffers`): one submission, one read-back. `what` names the pass in errors (the
/// flag or the pass).
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    what: &str,
    source: &str,
    uniform: &[u8],
    buffers: &[Buffer<'_>],
    stages: &[Stage<'_>],
    read: usize,
) -> Result<Vec<u8>, RuntimeError> {
    let sizes: Vec<u64> = buffers
        .iter()
        .map(|b| match b {
            Buffer::Data(d) => d.len() as u64,
            Buffer::Zeroed(n) => *n,
        })
        .collect();
    check_buffers(device, what, &sizes)?;
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let bufs: Vec<wgpu::Buffer> = buffers
        .iter()
        .zip(&sizes)
        .map(|(b, &size)| match b {
            Buffer::Data(d) => storage_buffer(device, what, size, Some(d)),
            Buffer::Zeroed(_) => storage_buffer(device, what, size, None),
        })
        .collect();
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(what) });
    let bound: Vec<&wgpu::Buffer> = bufs.iter().collect();
    record(device, &mut enc, what, source, uniform, &bound, stages);
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: bufs[read].size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    enc.copy_buffer_to_buffer(&bufs[read], 0, &readback, 0, bufs[read].size());
    gpu::submit(queue, enc.finish());
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(RuntimeError::Gpu(format!("{what}: {e}")));
    }
    let mut out = gpu::map_read(device, &readback)?;
    out.truncate(sizes[read] as usize);
    Ok(out)
}

/// Records `stages` in order into `enc` over the GPU buffers `buffers` (bindings 1..=N, [`STORAGE_USAGE`], sizes
/// checked by the caller with [`check_buffers`]) with `uniform` at binding 0: no submission, no read-back, so a
/// frame chains this pass with others and reads back once. Each stage reads `uniform` followed by its
/// [`Stage::args`] (one 256-byte-aligned slice of one uniform buffer per stage, bound at a dynamic offset).
pub(crate) fn record(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    what: &str,
    source: &str,
    uniform: &[u8],
    buffers: &[&wgpu::Buffer],
    stages: &[Stage<'_>],
) {
    let entry_names: Vec<&str> = stages.iter().map(|s| s.entry).collect();
    let (bgl, pipelines) = gpu::cached(device, "compute chain", &(source, &entry_names, buffers.len()), || {
        chain_pipelines(device, what, source, buffers.len(), &entry_names)
    });
    // The caller's block padded to 16 bytes, then the stage's arguments; one slice per stage.
    let common = uniform.len().div_ceil(16) * 16;
    let slice = (common as u64 + 16) as usize;
    let align = device.limits().min_uniform_buffer_offset_alignment as usize;
    let stride = slice.div_ceil(align) * align;
    let mut block = vec![0u8; stride * stages.len().max(1)];
    for (k, s) in stages.iter().enumerate() {
        block[k * stride..k * stride + uniform.len()].copy_from_slice(uniform);
        block[k * stride + common..k * stride + slice].copy_from_slice(bytemuck::cast_slice(&s.args));
    }
    let ubo = crate::runtime::frame_pool::uniform_buffer(device, what, &block);
    let binding = wgpu::BufferBinding { buffer: &ubo, offset: 0, size: wgpu::BufferSize::new(slice as u64) };
    let mut group_entries = vec![(0, wgpu::BindingResource::Buffer(binding))];
    group_entries.extend(buffers.iter().enumerate().map(|(i, b)| (i as u32 + 1, b.as_entire_binding())));
    let group = gpu::bind_group(device, what, &bgl, &group_entries);
    // Per-pass profiling (off by default: one thread-local check).
    let profile = gpu::profile_timer(device, stages.len() as u32);
    for (k, (p, s)) in pipelines.iter().zip(stages).enumerate() {
        let timestamp_writes = profile.as_ref().and_then(|t| t.as_ref()).map(|t| t.compute_pass_writes(k as u32));
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(s.entry), timestamp_writes });
        pass.set_pipeline(p);
        pass.set_bind_group(0, &group, &[(k * stride) as u32]);
        pass.dispatch_workgroups(s.groups[0], s.groups[1], s.groups[2]);
    }
    if let Some(timer) = profile {
        let sizes: Vec<u64> = buffers.iter().map(|b| b.size()).collect();
        let passes = stages
            .iter()
            .map(|s| {
                let repeated = stages.iter().filter(|o| o.entry == s.entry).count() > 1;
                let label = match repeated {
                    true => format!("{what}: {} {}", s.entry, s.args[0]),
                    false => format!("{what}: {}", s.entry),
                };
                (label, pass_bytes(source, s.entry, &sizes))
            })
            .collect();
        gpu::profile_passes(timer, passes);
    }
}

/// Which storage buffers (bindings 1..=N, as indices 0..N) an entry point of a chain's module reads and writes.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct BufferUse {
    pub read: Vec<usize>,
    pub written: Vec<usize>,
}

/// The buffers `entry` of the WGSL `source` reads and writes, by naga's static analysis of the module (what the
/// entry point and every function it calls may load or store; `arrayLength` is neither): None when the module
/// does not parse or has no such entry point. Analyses are kept per module source.
pub(crate) fn buffer_use(source: &str, entry: &str) -> Option<BufferUse> {
    type Uses = Option<std::sync::Arc<std::collections::HashMap<String, BufferUse>>>;
    static ANALYSED: std::sync::LazyLock<std::sync::Mutex<std::collections::HashMap<String, Uses>>> =
        std::sync::LazyLock::new(Default::default);
    let mut seen = ANALYSED.lock().unwrap_or_else(|e| e.into_inner());
    let uses = seen.entry(source.to_string()).or_insert_with(|| analyse(source).map(std::sync::Arc::new));
    uses.as_ref()?.get(entry).cloned()
}

/// Per entry point of `source`, the storage buffers of group 0 (binding b ≥ 1 → index b − 1) it reads and writes.
fn analyse(source: &str) -> Option<std::collections::HashMap<String, BufferUse>> {
    use wgpu::naga;
    let module = naga::front::wgsl::parse_str(source).ok()?;
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .ok()?;
    let storage: Vec<_> = module
        .global_variables
        .iter()
        .filter(|(_, v)| matches!(v.space, naga::AddressSpace::Storage { .. }))
        .filter_map(|(h, v)| v.binding.as_ref().filter(|b| b.group == 0 && b.binding >= 1).map(|b| (h, b.binding)))
        .collect();
    let mut out = std::collections::HashMap::new();
    for (i, ep) in module.entry_points.iter().enumerate() {
        let f = info.get_entry_point(i);
        let mut u = BufferUse::default();
        for &(h, binding) in &storage {
            let index = binding as usize - 1;
            if f[h].contains(naga::valid::GlobalUse::READ) {
                u.read.push(index);
            }
            if f[h].contains(naga::valid::GlobalUse::WRITE) {
                u.written.push(index);
            }
        }
        u.read.sort_unstable();
        u.written.sort_unstable();
        out.insert(ep.name.clone(), u);
    }
    Some(out)
}

/// The bytes a dispatch of `entry` must move over storage buffers of `sizes` bytes (binding order), the figure
/// its bytes-moved bound divides by the copy bandwidth: every buffer it reads counts its whole size once, every
/// buffer it writes counts its whole size once (a buffer both read and written counts twice), whatever the
/// number of times a texel is touched; the uniform block is left out. A dispatch over part of a buffer (a pyramid
/// level in a buffer of all levels, a shadow map sampled where the frame needs it) is counted whole, so for such a
/// pass the figure is an upper bound of its traffic and its time/bound a lower bound. None when the module
/// cannot be analysed ([`buffer_use`]).
pub(crate) fn pass_bytes(source: &str, entry: &str, sizes: &[u64]) -> Option<u64> {
    let u = buffer_use(source, entry)?;
    let size = |i: &usize| sizes.get(*i).copied().unwrap_or(0);
    Some(u.read.iter().map(size).sum::<u64>() + u.written.iter().map(size).sum::<u64>())
}

/// The chain's layout (uniform at 0, `buffers` read-write storage buffers at 1..=N) and one pipeline per entry.
fn chain_pipelines(
    device: &wgpu::Device,
    what: &str,
    source: &str,
    buffers: usize,
    entries_named: &[&str],
) -> (wgpu::BindGroupLayout, Vec<wgpu::ComputePipeline>) {
    let module = gpu::shader(device, what, source);
    let mut entries = vec![wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: None,
        },
        count: None,
    }];
    for i in 0..buffers {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: i as u32 + 1,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        });
    }
    let bgl =
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(what), entries: &entries });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(what),
        bind_group_layouts: &[Some(&bgl)],
        immediate_size: 0,
    });
    let pipelines = entries_named
        .iter()
        .map(|entry| {
            gpu::create_compute_pipeline(
                device,
                &wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&layout),
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                },
            )
        })
        .collect();
    (bgl, pipelines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::device::{create_headless, DeviceOptions};

    /// A chain of three entry points over three vec4 buffers: `copy` reads a, writes b; `scale` reads and writes
    /// b; `sum` reads a and b through a helper function and writes c, and asks a's length (a query, not a read).
    const CHAIN: &str = "
        struct P { size: vec4<f32>, stage: vec4<u32> }
        @group(0) @binding(0) var<uniform> p: P;
        @group(0) @binding(1) var<storage, read_write> a: array<vec4<f32>>;
        @group(0) @binding(2) var<storage, read_write> b: array<vec4<f32>>;
        @group(0) @binding(3) var<storage, read_write> c: array<vec4<f32>>;
        fn both(i: u32) -> vec4<f32> { return a[i] + b[i]; }
        @compute @workgroup_size(8, 8, 1)
        fn copy(@builtin(global_invocation_id) id: vec3<u32>) {
            let i = id.y * u32(p.size.x) + id.x;
            b[i] = a[i];
        }
        @compute @workgroup_size(8, 8, 1)
        fn scale(@builtin(global_invocation_id) id: vec3<u32>) {
            let i = id.y * u32(p.size.x) + id.x;
            b[i] = 2.0 * b[i];
        }
        @compute @workgroup_size(8, 8, 1)
        fn sum(@builtin(global_invocation_id) id: vec3<u32>) {
            let i = id.y * u32(p.size.x) + id.x;
            if (i < arrayLength(&a)) { c[i] = both(i); }
        }
    ";

    #[test]
    fn the_buffers_an_entry_point_reads_and_writes_come_from_the_module() {
        let u = |read: &[usize], written: &[usize]| BufferUse { read: read.to_vec(), written: written.to_vec() };
        assert_eq!(buffer_use(CHAIN, "copy"), Some(u(&[0], &[1])));
        assert_eq!(buffer_use(CHAIN, "scale"), Some(u(&[1], &[1])));
        assert_eq!(buffer_use(CHAIN, "sum"), Some(u(&[0, 1], &[2])));
        assert_eq!(buffer_use(CHAIN, "missing"), None);
        assert_eq!(buffer_use("not wgsl", "copy"), None);
    }

    /// A 64×32 frame through the chain with profiling on: the bytes of each pass by hand (a, b, c of 16 bytes per
    /// pixel: copy reads a and writes b, scale reads and writes b, sum reads a and b and writes c), the labels in
    /// recording order, the chain's result unchanged, and GPU times where the device has timestamps.
    #[test]
    fn a_profiled_chain_reports_each_pass_with_its_hand_counted_bytes() {
        let g = create_headless(&DeviceOptions { timestamps: true }).expect("an adapter");
        let (w, h) = (64u32, 32u32);
        let frame = vec4_per_pixel_bytes(w, h);
        assert_eq!(frame, 32768);
        let a: Vec<f32> = (0..4 * w * h).map(|i| i as f32).collect();
        let uniform: [f32; 4] = [w as f32, h as f32, 0.0, 0.0];
        let groups = groups_8x8(w, h);
        let stages = [Stage::new("copy", groups), Stage::new("scale", groups), Stage::new("sum", groups)];
        let buffers = [Buffer::Data(bytemuck::cast_slice(&a)), Buffer::Zeroed(frame), Buffer::Zeroed(frame)];
        let run_chain =
            || run(&g.device, &g.queue, "test chain", CHAIN, bytemuck::bytes_of(&uniform), &buffers, &stages, 2);
        let plain = run_chain().unwrap();
        gpu::set_pass_profiling(true);
        let profiled = run_chain().unwrap();
        let passes = gpu::take_pass_profile(&g.device, &g.queue).unwrap();
        gpu::set_pass_profiling(false);
        assert_eq!(plain, profiled, "profiling changed the chain's result");
        let c: &[f32] = bytemuck::cast_slice(&plain);
        assert_eq!(&c[..8], &[0.0, 3.0, 6.0, 9.0, 12.0, 15.0, 18.0, 21.0]);
        let got: Vec<(&str, Option<u64>, bool)> = passes.iter().map(|p| (p.label.as_str(), p.bytes, p.span)).collect();
        let expected = vec![
            ("test chain: copy", Some(2 * frame), false),
            ("test chain: scale", Some(2 * frame), false),
            ("test chain: sum", Some(3 * frame), false),
        ];
        assert_eq!(got, expected);
        for p in &passes {
            assert_eq!(p.gpu_ms.is_some(), g.timestamps, "{p:?}");
            assert!(p.gpu_ms.is_none_or(|ms| ms.is_finite() && ms >= 0.0), "{p:?}");
        }
        // Off: nothing is recorded.
        run_chain().unwrap();
        assert!(gpu::take_pass_profile(&g.device, &g.queue).unwrap().is_empty());
    }
}
