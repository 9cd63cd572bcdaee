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
pub(crate) const STORAGE_USAGE: wgpu::BufferUsages =
    wgpu::BufferUsages::STORAGE.union(wgpu::BufferUsages::COPY_SRC).union(wgpu::BufferUsages::COPY_DST);

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
    let ubo = gpu::uniform_buffer(device, what, &block);
    let binding = wgpu::BufferBinding { buffer: &ubo, offset: 0, size: wgpu::BufferSize::new(slice as u64) };
    let mut group_entries = vec![(0, wgpu::BindingResource::Buffer(binding))];
    group_entries.extend(buffers.iter().enumerate().map(|(i, b)| (i as u32 + 1, b.as_entire_binding())));
    let group = gpu::bind_group(device, what, &bgl, &group_entries);
    for (k, (p, s)) in pipelines.iter().zip(stages).enumerate() {
        let mut pass =
            enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(s.entry), timestamp_writes: None });
        pass.set_pipeline(p);
        pass.set_bind_group(0, &group, &[(k * stride) as u32]);
        pass.dispatch_workgroups(s.groups[0], s.groups[1], s.groups[2]);
    }
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
