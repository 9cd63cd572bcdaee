//! A small compute-shader runner for the per-pixel skin passes of `run skin` (the rig at the mesh's uv, the
//! wrinkle pass, bloom): one WGSL module, one uniform block at binding 0 and flat `f32` storage buffers at bindings
//! 1..=N (all `var<storage, read_write>`, so every entry point shares one explicit layout), run as a chain of
//! entry points in one submission, one buffer read back. The module, layout and pipelines are built once per device
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

/// One dispatch: entry point and workgroup counts.
pub(crate) struct Stage<'a> {
    pub entry: &'a str,
    pub groups: [u32; 3],
}

/// Workgroups of 8×8 covering a `w`×`h` image.
pub(crate) fn groups_8x8(w: u32, h: u32) -> [u32; 3] {
    [w.div_ceil(8), h.div_ceil(8), 1]
}

/// Runs `stages` in order over `buffers` (bindings 1..=N) with `uniform` at binding 0 and returns the bytes of
/// buffer `read` (an index into `buffers`). `what` names the pass in errors (the flag or the pass).
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
    let limit = device.limits().max_storage_buffer_binding_size;
    let sizes: Vec<u64> = buffers
        .iter()
        .map(|b| match b {
            Buffer::Data(d) => d.len() as u64,
            Buffer::Zeroed(n) => *n,
        })
        .collect();
    if let Some(s) = sizes.iter().find(|&&s| s > limit) {
        return Err(InvalidInput::new(
            what,
            format!("a {s}-byte buffer exceeds the adapter's storage-buffer limit of {limit} bytes"),
        )
        .into());
    }
    if buffers.len() as u32 > device.limits().max_storage_buffers_per_shader_stage {
        return Err(RuntimeError::Gpu(format!("{what}: more storage buffers than the adapter binds")));
    }
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let entry_names: Vec<&str> = stages.iter().map(|s| s.entry).collect();
    let (bgl, pipelines) = gpu::cached(device, "compute chain", &(source, &entry_names, buffers.len()), || {
        chain_pipelines(device, what, source, buffers.len(), &entry_names)
    });
    let mut padded = uniform.to_vec();
    padded.resize(uniform.len().div_ceil(16).max(1) * 16, 0);
    let ubo = gpu::uniform_buffer(device, what, &padded);
    let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
    let bufs: Vec<wgpu::Buffer> = buffers
        .iter()
        .zip(&sizes)
        .map(|(b, &size)| {
            // Bindings must not be empty and copies are 4-byte multiples: round up to 16 bytes.
            let size = size.div_ceil(16).max(1) * 16;
            let buf = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(what),
                size,
                usage,
                mapped_at_creation: true,
            });
            if let Buffer::Data(d) = b {
                if !d.is_empty() {
                    let mut view = buf.slice(..d.len() as u64).get_mapped_range_mut().expect("mapped at creation");
                    view.copy_from_slice(d);
                }
            }
            buf.unmap();
            buf
        })
        .collect();
    let mut group_entries = vec![(0, ubo.as_entire_binding())];
    group_entries.extend(bufs.iter().enumerate().map(|(i, b)| (i as u32 + 1, b.as_entire_binding())));
    let group = gpu::bind_group(device, what, &bgl, &group_entries);
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: bufs[read].size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(what) });
    for (p, s) in pipelines.iter().zip(stages) {
        let mut pass =
            enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(s.entry), timestamp_writes: None });
        pass.set_pipeline(p);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(s.groups[0], s.groups[1], s.groups[2]);
    }
    enc.copy_buffer_to_buffer(&bufs[read], 0, &readback, 0, bufs[read].size());
    queue.submit([enc.finish()]);
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(RuntimeError::Gpu(format!("{what}: {e}")));
    }
    let mut out = gpu::map_read(device, &readback)?;
    out.truncate(sizes[read] as usize);
    Ok(out)
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
            has_dynamic_offset: false,
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
