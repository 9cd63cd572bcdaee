//! Monte Carlo photon transport on the GPU: the algorithm of [`crate::transport::mc`] (MCML: L. Wang,
//! S. L. Jacques, L. Zheng, Comput. Methods Programs Biomed. 47:131–146, 1995 — HG phase, Fresnel at every face
//! with mismatched η, implicit capture, Russian roulette) as a wgpu compute shader (`transport/mc_gpu.wgsl`), one
//! invocation per photon. The CPU path stays the reference; `tests/it/transport_gpu.rs` checks that both give the
//! same tallies within their standard errors.
//!
//! **Random numbers.** Photon k of channel c draws from Philox4x32-10 keyed with the seed at counter
//! (k lo, k hi, c, block), exactly the CPU's words ([`crate::transport::rng`]); the WGSL computes the 32×32 → 64-bit
//! products through 16-bit halves and is checked against Random123's known answers ([`philox_blocks`]). A word
//! becomes a uniform (⌊word/2⁸⌋ + 1)/2²⁴ ∈ (0, 1] (exact in f32; the CPU uses all 32 bits in f64), so a GPU photon
//! starts on the CPU photon's path and departs from it where f32 rounding changes a decision.
//!
//! **State** is f32 (position in mm, direction renormalised after every scattering against f32 drift); positions
//! resolve about 6·10⁻⁸ of the distance travelled, so bins much finer than that (e.g. Δr = 1 µm for photons that
//! wander 100 mm) are not resolved the way the f64 CPU path resolves them.
//!
//! **Tallies** are 64-bit fixed point with [`FIXED_POINT_SCALE`] = 2³² units per unit weight, held as (lo, hi)
//! u32 pairs: lo is added with `atomicAdd` and its carry goes into hi, so every sum is an exact integer whatever
//! the order of the additions. Total R/T, absorbed per layer and the interaction count are first summed per
//! workgroup (64 photons, workgroup atomics) and added once per workgroup; R(r) and T(r) bins are added directly.
//! Each addition truncates its weight to the 2⁻³² grid (a loss below 2⁻³² per addition, one per exit and one per
//! layer visit: a photon's absorbed weight is summed in f32 while it stays in a layer and added when it leaves
//! it), about 10⁻⁹ of a photon's weight, far below any standard error. **Overflow bound**: photons are
//! traced in segments of at most [`SEGMENT_PHOTONS`] = 2²⁴ per channel and read back after each; a 64-bit slot
//! overflows only when the segment deposits 2³² units of weight in it, 256 per photon on average, while a photon
//! deposits 1 in expectation (roulette's ×10 is balanced by its 9/10 loss); interaction counts reach at most
//! 2²⁴ photons × [`MAX_STEPS_PER_PHOTON`] = 2⁴⁸.
//!
//! **Batches** as on the CPU: batch b traces photons b·⌈N/B⌉ .. (b + 1)·⌈N/B⌉ of every channel; each batch's
//! integer sums become f64 weights and go through [`crate::transport::mc::assemble`], the CPU's own reduction, so
//! means and standard errors are computed the same way. Memory: one batch segment's tallies on the GPU
//! (3 × (2·bins + layers + 4) × 8 bytes) plus the CPU's batch tallies — bounded by the tallies, not by N.
//!
//! **Determinism**: for a given stack, settings, adapter and driver the result is the same bytes on every run
//! (integer sums do not depend on the order of the atomics; every photon's f32 arithmetic is fixed by the compiled
//! shader). Different adapters or drivers may round differently and give different (statistically equivalent)
//! numbers; the GPU result is never expected to equal the CPU's bytes.
//!
//! **Limits**: the tally buffer is checked against the device's `max_storage_buffer_binding_size` and
//! `max_buffer_size`, the dispatch against `max_compute_workgroups_per_dimension`, before anything is allocated;
//! an adapter that cannot run compute shaders is refused with [`RuntimeError::Gpu`]. A photon history longer than
//! [`MAX_STEPS_PER_PHOTON`] steps (in practice never: a diffusing photon needs of the order of (thickness in
//! transport mean free paths)² steps to cross a lossless layer, so thousands of them) is stopped, and the run
//! fails naming the count rather than biasing the tallies.

use crate::error::InvalidInput;
use crate::runtime::gpu;
use crate::runtime::RuntimeError;
use crate::transport::mc::{assemble, specular_reflectance, Tally};
use crate::transport::{McResult, McSettings, McStack};

/// Invocations per workgroup (the shader's `@workgroup_size`).
pub const WORKGROUP_SIZE: u32 = 64;
/// Most photons per channel traced between two read-backs (the overflow bound of the module docs).
pub const SEGMENT_PHOTONS: u64 = 1 << 24;
/// Most workgroups along x of one dispatch (the rest goes along z).
const MAX_GROUPS_X: u32 = 32_768;
/// Longest photon history, in steps (interactions + face hits), before the shader stops it.
pub const MAX_STEPS_PER_PHOTON: u32 = 1 << 24;
/// Fixed-point units per unit photon weight.
pub const FIXED_POINT_SCALE: f64 = 4_294_967_296.0;
/// Layers the shader's workgroup sums hold (= [`crate::transport::stack::MAX_LAYERS`]).
const SHADER_MAX_LAYERS: usize = 64;
/// Workgroup memory of the shader, bytes (136 u32).
const WORKGROUP_STORAGE_BYTES: u32 = 136 * 4;
/// Bottom of a semi-infinite layer in the shader, mm (f32 has no infinity literal; no photon gets this deep).
const SEMI_INFINITE_BOTTOM_MM: f32 = 1e30;

const SHADER: &str = include_str!("mc_gpu.wgsl");

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    key: [u32; 2],
    first_photon: [u32; 2],
    count: u32,
    bins: u32,
    layers: u32,
    max_steps: u32,
    inv_bin_mm: f32,
    eta_above: f32,
    eta_below: f32,
    start_weight: f32,
    groups_x: u32,
    slots_per_channel: u32,
    _pad: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuMedium {
    z_top_mm: f32,
    z_bottom_mm: f32,
    sigma_t: f32,
    absorb_fraction: f32,
    g: f32,
    eta: f32,
    _pad: [f32; 2],
}

/// The GPU resources of one stack and settings, sized and checked against the device: what [`simulate_gpu`] runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GpuPlan {
    /// u32 pairs per channel: 2·bins + layers + 4.
    pub slots_per_channel: u64,
    /// Bytes of the tally buffer (and of its read-back copy).
    pub tally_bytes: u64,
    /// Workgroups along x of a full segment's dispatch (the device's per-dimension limit respected).
    pub groups_x: u32,
}

impl GpuPlan {
    /// Checks `stack` and `settings` against `limits` before anything is allocated: the tally buffer within
    /// `max_storage_buffer_binding_size` and `max_buffer_size` (else `bins` is refused, bad input), the dispatch
    /// within `max_compute_workgroups_per_dimension`, the shader's workgroup size and memory within the device's
    /// (else [`RuntimeError::Gpu`]: the adapter cannot run it).
    pub fn new(limits: &wgpu::Limits, stack: &McStack, settings: &McSettings) -> Result<Self, RuntimeError> {
        Self::split(limits, stack, settings, SEGMENT_PHOTONS, MAX_GROUPS_X)
    }

    fn split(
        limits: &wgpu::Limits,
        stack: &McStack,
        settings: &McSettings,
        segment: u64,
        max_groups_x: u32,
    ) -> Result<Self, RuntimeError> {
        let layers = stack.layers().len();
        if layers > SHADER_MAX_LAYERS {
            return Err(InvalidInput::new(
                "layers",
                format!("the GPU path holds 1..={SHADER_MAX_LAYERS} layers, got {layers}"),
            )
            .into());
        }
        if limits.max_compute_workgroups_per_dimension == 0
            || limits.max_compute_invocations_per_workgroup < WORKGROUP_SIZE
            || limits.max_compute_workgroup_size_x < WORKGROUP_SIZE
            || limits.max_compute_workgroup_storage_size < WORKGROUP_STORAGE_BYTES
            || limits.max_storage_buffers_per_shader_stage < 2
        {
            return Err(RuntimeError::Gpu(format!(
                "this adapter cannot run the transport shader: it needs compute workgroups of {WORKGROUP_SIZE} \
                 invocations with {WORKGROUP_STORAGE_BYTES} bytes of workgroup memory and 2 storage buffers \
                 (limits: {} invocations, {} bytes, {} storage buffers, {} workgroups per dimension); use the CPU path",
                limits.max_compute_invocations_per_workgroup,
                limits.max_compute_workgroup_storage_size,
                limits.max_storage_buffers_per_shader_stage,
                limits.max_compute_workgroups_per_dimension
            )));
        }
        let slots_per_channel = 2 * settings.bins as u64 + layers as u64 + 4;
        let tally_bytes = 3 * slots_per_channel * 8;
        let cap = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        if tally_bytes > cap {
            return Err(InvalidInput::new(
                "bins",
                format!(
                    "{} bins need a {tally_bytes}-byte GPU tally buffer, this GPU binds at most {cap} bytes \
                     (max_storage_buffer_binding_size, max_buffer_size): at most {} bins here, or the CPU path",
                    settings.bins,
                    (cap / 24).saturating_sub(layers as u64 + 4) / 2
                ),
            )
            .into());
        }
        let per_dim = limits.max_compute_workgroups_per_dimension;
        let segment_photons = settings.photons_per_batch().min(segment);
        let groups_total = segment_photons.div_ceil(u64::from(WORKGROUP_SIZE));
        let groups_x = (groups_total.min(u64::from(max_groups_x.min(per_dim)))).max(1) as u32;
        let groups_z = groups_total.div_ceil(u64::from(groups_x));
        if groups_z > u64::from(per_dim) || per_dim < 3 {
            return Err(RuntimeError::Gpu(format!(
                "a segment of {segment_photons} photons needs {groups_x} x 3 x {groups_z} workgroups, beyond this \
                 adapter's {per_dim} per dimension (max_compute_workgroups_per_dimension); use the CPU path"
            )));
        }
        Ok(Self { slots_per_channel, tally_bytes, groups_x })
    }
}

/// Host memory of [`simulate_gpu`] beyond the stack, bytes: the CPU path's batch tallies and result
/// ([`McSettings::memory_estimate_bytes`], an upper bound here) plus one segment's read-back.
pub fn memory_estimate_bytes(settings: &McSettings, layers: usize) -> u64 {
    settings.memory_estimate_bytes(layers) + 3 * (2 * settings.bins as u64 + layers as u64 + 4) * 8
}

/// The compiled transport pipeline; create once per device and run many stacks.
pub struct TransportGpu {
    pipeline: wgpu::ComputePipeline,
    /// Photons per channel per read-back ([`SEGMENT_PHOTONS`] unless split finer).
    segment_photons: u64,
    /// Most workgroups along x per dispatch.
    max_groups_x: u32,
}

impl TransportGpu {
    /// Compiles the shader. A shader or pipeline the device refuses is [`RuntimeError::Gpu`].
    pub fn new(device: &wgpu::Device) -> Result<Self, RuntimeError> {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = gpu::shader(device, "transport", SHADER);
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("transport"),
            layout: None,
            module: &module,
            entry_point: Some("transport"),
            compilation_options: Default::default(),
            cache: None,
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RuntimeError::Gpu(format!("transport shader: {e}")));
        }
        Ok(Self { pipeline, segment_photons: SEGMENT_PHOTONS, max_groups_x: MAX_GROUPS_X })
    }

    /// The same pipeline with finer segments (`segment_photons` in 1..=[`SEGMENT_PHOTONS`] photons per channel
    /// per read-back) and at most `max_groups_x` (≥ 1) workgroups along x, the rest along z. The result does not
    /// change (integer sums; every photon keeps its index): the test of the segment and dispatch indexing, which
    /// the default sizes reach only beyond 2·10⁶ photons per batch.
    pub fn split(self, segment_photons: u64, max_groups_x: u32) -> Result<Self, InvalidInput> {
        crate::error::check_range("segment_photons", segment_photons, 1, SEGMENT_PHOTONS, "")?;
        crate::error::check_range("max_groups_x", max_groups_x, 1, MAX_GROUPS_X, "")?;
        Ok(Self { segment_photons, max_groups_x, ..self })
    }

    /// Runs the transport of every channel; `progress(fraction done)` after every segment. See the module docs.
    pub fn simulate(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        stack: &McStack,
        settings: &McSettings,
        progress: &dyn Fn(f64),
    ) -> Result<McResult, RuntimeError> {
        let plan = GpuPlan::split(&device.limits(), stack, settings, self.segment_photons, self.max_groups_x)?;
        let segment = self.segment_photons;
        let layers = stack.layers();
        let n_layers = layers.len();
        let batches = settings.batches as usize;
        let per_batch = settings.photons_per_batch();
        let rsp = specular_reflectance(stack);

        let mut media = Vec::with_capacity(3 * n_layers);
        for c in 0..3 {
            let mut z = 0.0f64;
            for l in layers {
                let sigma_t = l.sigma_a_per_mm[c] + l.sigma_s_per_mm[c];
                let bottom = z + l.thickness_mm;
                media.push(GpuMedium {
                    z_top_mm: z as f32,
                    z_bottom_mm: if bottom.is_finite() { bottom as f32 } else { SEMI_INFINITE_BOTTOM_MM },
                    sigma_t: sigma_t as f32,
                    absorb_fraction: if sigma_t > 0.0 { (l.sigma_a_per_mm[c] / sigma_t) as f32 } else { 0.0 },
                    g: l.g[c] as f32,
                    eta: l.eta as f32,
                    _pad: [0.0; 2],
                });
                z = bottom;
            }
        }
        let media_buf = storage_buffer(device, "transport media", bytemuck::cast_slice(&media));
        let tallies = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("transport tallies"),
            size: plan.tally_bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("transport tallies readback"),
            size: plan.tally_bytes,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let params_buf = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("transport params"),
            size: std::mem::size_of::<Params>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = gpu::bind_group(
            device,
            "transport",
            &self.pipeline.get_bind_group_layout(0),
            &[
                (0, params_buf.as_entire_binding()),
                (1, media_buf.as_entire_binding()),
                (2, tallies.as_entire_binding()),
            ],
        );

        let segments_per_batch = per_batch.div_ceil(segment);
        let total_segments = batches as u64 * segments_per_batch;
        let mut batch_tallies: Vec<Tally> = (0..3 * batches).map(|_| Tally::new(settings.bins, n_layers)).collect();
        let spc = plan.slots_per_channel as usize;
        let mut capped = 0u64;
        let mut done = 0u64;
        for b in 0..batches {
            for s in 0..segments_per_batch {
                let first_in_batch = s * segment;
                let count = segment.min(per_batch - first_in_batch);
                let first = b as u64 * per_batch + first_in_batch;
                let groups_total = count.div_ceil(u64::from(WORKGROUP_SIZE));
                let groups_x = groups_total.min(u64::from(plan.groups_x)) as u32;
                let groups_z = groups_total.div_ceil(u64::from(groups_x)) as u32;
                let params = Params {
                    key: [settings.seed as u32, (settings.seed >> 32) as u32],
                    first_photon: [first as u32, (first >> 32) as u32],
                    count: count as u32,
                    bins: settings.bins as u32,
                    layers: n_layers as u32,
                    max_steps: MAX_STEPS_PER_PHOTON,
                    inv_bin_mm: (1.0 / settings.bin_mm) as f32,
                    eta_above: stack.eta_above() as f32,
                    eta_below: stack.eta_below() as f32,
                    start_weight: (1.0 - rsp) as f32,
                    groups_x,
                    slots_per_channel: spc as u32,
                    _pad: [0; 2],
                };
                queue.write_buffer(&params_buf, 0, bytemuck::bytes_of(&params));
                let mut enc =
                    device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("transport") });
                enc.clear_buffer(&tallies, 0, None);
                {
                    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("transport"),
                        timestamp_writes: None,
                    });
                    pass.set_pipeline(&self.pipeline);
                    pass.set_bind_group(0, &bind, &[]);
                    pass.dispatch_workgroups(groups_x, 3, groups_z);
                }
                enc.copy_buffer_to_buffer(&tallies, 0, &readback, 0, plan.tally_bytes);
                queue.submit([enc.finish()]);
                let bytes = gpu::map_read(device, &readback)?;
                let words: &[u32] = bytemuck::cast_slice(&bytes);
                let fixed = |slot: usize| u64::from(words[2 * slot]) | (u64::from(words[2 * slot + 1]) << 32);
                let weight = |slot: usize| fixed(slot) as f64 / FIXED_POINT_SCALE;
                for c in 0..3 {
                    let base = c * spc;
                    let bins = settings.bins;
                    let t = &mut batch_tallies[c * batches + b];
                    for i in 0..bins {
                        t.r[i] += weight(base + i);
                        t.t[i] += weight(base + bins + i);
                    }
                    t.rd += weight(base + 2 * bins);
                    t.td += weight(base + 2 * bins + 1);
                    for j in 0..n_layers {
                        t.absorbed[j] += weight(base + 2 * bins + 2 + j);
                    }
                    t.interactions += fixed(base + 2 * bins + 2 + n_layers);
                    capped += fixed(base + 2 * bins + 3 + n_layers);
                }
                done += 1;
                progress(done as f64 / total_segments as f64);
            }
        }
        if capped > 0 {
            return Err(RuntimeError::Gpu(format!(
                "{capped} photon histories exceeded {MAX_STEPS_PER_PHOTON} steps and were stopped; the tallies would \
                 be biased, use the CPU path"
            )));
        }
        Ok(assemble(stack, settings, &batch_tallies))
    }
}

/// Compiles the pipeline and runs [`TransportGpu::simulate`] once.
pub fn simulate_gpu(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    stack: &McStack,
    settings: &McSettings,
) -> Result<McResult, RuntimeError> {
    TransportGpu::new(device)?.simulate(device, queue, stack, settings, &|_| {})
}

fn storage_buffer(device: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    let mut padded = bytes.to_vec();
    padded.resize(bytes.len().next_multiple_of(16).max(16), 0);
    let buf = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: padded.len() as u64,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: true,
    });
    buf.slice(..).get_mapped_range_mut().expect("mapped at creation").copy_from_slice(&padded);
    buf.unmap();
    buf
}

/// Philox4x32-10 blocks of `counters` under `key` computed by the shader's `philox` (the WGSL the transport uses),
/// for the known-answer test against [`crate::transport::rng::philox4x32_10`]. At most 65 536 counters.
pub fn philox_blocks(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    counters: &[[u32; 4]],
    key: [u32; 2],
) -> Result<Vec<[u32; 4]>, RuntimeError> {
    if counters.is_empty() || counters.len() > 65_536 {
        return Err(
            InvalidInput::new("counters", format!("must hold 1..=65536 counters, got {}", counters.len())).into()
        );
    }
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = gpu::shader(device, "transport", SHADER);
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("philox kat"),
        layout: None,
        module: &module,
        entry_point: Some("philox_kat"),
        compilation_options: Default::default(),
        cache: None,
    });
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(RuntimeError::Gpu(format!("philox shader: {e}")));
    }
    let size = (counters.len() * 16) as u64;
    let input = storage_buffer(device, "philox in", bytemuck::cast_slice(counters));
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("philox out"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("philox readback"),
        size,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let key_buf = gpu::uniform_buffer(device, "philox key", bytemuck::cast_slice(&[key[0], key[1], 0, 0]));
    let bind = gpu::bind_group(
        device,
        "philox kat",
        &pipeline.get_bind_group_layout(0),
        &[(3, input.as_entire_binding()), (4, output.as_entire_binding()), (5, key_buf.as_entire_binding())],
    );
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("philox kat") });
    {
        let mut pass =
            enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("philox kat"), timestamp_writes: None });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups((counters.len() as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&output, 0, &readback, 0, size);
    queue.submit([enc.finish()]);
    let bytes = gpu::map_read(device, &readback)?;
    Ok(bytemuck::cast_slice::<u8, [u32; 4]>(&bytes).to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transport::McLayer;

    fn stack(layers: usize) -> McStack {
        let l =
            McLayer { thickness_mm: 0.1, eta: 1.4, sigma_a_per_mm: [1.0; 3], sigma_s_per_mm: [9.0; 3], g: [0.8; 3] };
        McStack::new(1.0, 1.0, vec![l; layers]).unwrap()
    }

    #[test]
    fn plan_refuses_what_the_limits_cannot_hold() {
        let s = McSettings::new(1000, 1, 10, 0.01, 100).unwrap();
        let limits = wgpu::Limits::downlevel_defaults();
        let plan = GpuPlan::new(&limits, &stack(2), &s).unwrap();
        assert_eq!(plan.slots_per_channel, 2 * 100 + 2 + 4);
        assert_eq!(plan.tally_bytes, 3 * 206 * 8);
        // A binding limit smaller than the tallies: `bins` is refused as bad input.
        let small = wgpu::Limits { max_storage_buffer_binding_size: 1024, ..limits.clone() };
        match GpuPlan::new(&small, &stack(2), &s) {
            Err(RuntimeError::Invalid(e)) => assert_eq!(e.param, "bins", "{e}"),
            other => panic!("{other:?}"),
        }
        // No compute at all (WebGL2-like limits): the adapter is refused.
        let no_compute = wgpu::Limits::downlevel_webgl2_defaults();
        assert!(matches!(GpuPlan::new(&no_compute, &stack(2), &s), Err(RuntimeError::Gpu(_))));
        // A big segment on a small per-dimension limit: refused, not a panic.
        let big = McSettings::new(1 << 26, 1, 2, 0.01, 100).unwrap();
        let tiny_dim = wgpu::Limits { max_compute_workgroups_per_dimension: 16, ..limits };
        assert!(matches!(GpuPlan::new(&tiny_dim, &stack(1), &big), Err(RuntimeError::Gpu(_))));
    }

    #[test]
    fn params_layout_matches_the_shader() {
        // WGSL struct Params: 16 scalars of 4 bytes (vec2 fields aligned to 8), 64 bytes; Medium: 8 f32.
        assert_eq!(std::mem::size_of::<Params>(), 64);
        assert_eq!(std::mem::size_of::<GpuMedium>(), 32);
        use wgpu::naga;
        let module = naga::front::wgsl::parse_str(SHADER).unwrap_or_else(|e| panic!("{}", e.emit_to_string(SHADER)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
            .validate(&module)
            .expect("WGSL validates");
        // The host structs mirror the shader's: the same size (the shader's Params spells its pad as two u32 members).
        let shader_struct = |name: &str| {
            module
                .types
                .iter()
                .find_map(|(_, t)| match &t.inner {
                    naga::TypeInner::Struct { members, span } if t.name.as_deref() == Some(name) => {
                        Some((*span as usize, members.len()))
                    }
                    _ => None,
                })
                .unwrap_or_else(|| panic!("no struct {name} in the shader"))
        };
        assert_eq!(shader_struct("Params"), (std::mem::size_of::<Params>(), 14));
        assert_eq!(shader_struct("Medium"), (std::mem::size_of::<GpuMedium>(), 8));
    }
}
