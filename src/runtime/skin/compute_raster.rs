//! The one-sample G-buffer of [`crate::runtime::skin::mesh_raster`] rasterised by compute shaders straight into
//! the storage buffer the frame's geometry pass reads: a visibility-buffer rasteriser (Burns and Hunt, "The
//! Visibility Buffer: A Cache-Friendly Approach to Deferred Shading", JCGT 2(2), 2013), with the depth-then-resolve
//! order of software rasterisers on compute (Kenzel et al., "A High-Performance Software Graphics Pipeline
//! Architecture for the GPU", SIGGRAPH 2018): three dispatches of `compute_raster.wgsl` through
//! `compute_chain::record` —
//!
//! 1. `depth`, one thread per (triangle, row slice): the three vertices projected as the CPU twin
//!    ([`crate::runtime::skin::mesh_raster_cpu`]) projects them (a triangle with a vertex at or behind half the
//!    near plane skipped, back faces culled: counter-clockwise front faces), every pixel centre of its bounding box
//!    tested with the three edge functions and the top-left rule, z = Σ wᵢ zᵢ (NDC, linear in screen space)
//!    outside [0, 1) rejected (the near plane's clip, the depth buffer's clear), and `atomicMax` of the key
//!    !bits(z) (positive f32 bits are monotonic in z) into a per-pixel buffer;
//! 2. `visible`: the same pixels again; where a triangle's key equals the stored one, `atomicMax` of !index, so the
//!    lowest index at the nearest depth wins — the render pass's less-than test in primitive order, for any
//!    scheduling;
//! 3. `resolve`, one thread per pixel: the winning triangle's normal (renormalised), view depth in mm, uv and
//!    tangent interpolated perspective-correctly at the pixel centre (the twin's `fragment`), written as packed
//!    f16 (`pack2x16float`) in the render pass's target layout after `gpu::encode_texture_to_buffer`: two u32
//!    per texel, rows padded to 256 bytes, target after target, zeros where nothing is covered (the clear).
//!
//! Why: the render pass is bound by fixed-function raster and ROP hardware, of which compute GPUs (NVIDIA H100,
//! H200) have very little — there the 1080p view G-buffer took 1.22 ms against a 0.07 ms bytes-moved bound, and
//! the copies of its targets into buffers another 0.46 ms. The render pass stays for `--msaa 4` and for the
//! callers of [`crate::runtime::skin::mesh_raster::rasterise`]; [`RasterShape`] picks either (the render pass on a
//! software adapter) for A/B runs.
//!
//! The two triangle passes must compute the same key for a pixel: they call one function on the same inputs.

use crate::error::InvalidInput;
use crate::runtime::compute_chain::{self, Stage};
use crate::runtime::frame_pool;
use crate::runtime::skin::mesh_raster::{self, MeshBuffers, RasterJob};
use crate::runtime::RuntimeError;
use std::cell::Cell;

/// How the device frame rasterises its one-sample view G-buffer and shadow map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RasterShape {
    /// The three compute dispatches of this module, written straight into the geometry pass's buffer.
    Compute,
    /// The render pass of [`crate::runtime::skin::mesh_raster`], its targets then copied into that buffer.
    Render,
}

thread_local! {
    static ON_THIS_THREAD: Cell<Option<RasterShape>> = const { Cell::new(None) };
}

impl RasterShape {
    /// The environment variable [`Self::current`] reads.
    pub const ENV: &'static str = "RTBAKE_RASTER";

    /// `compute` or `render`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Compute => "compute",
            Self::Render => "render",
        }
    }

    /// `compute` or `render`; anything else is refused naming [`Self::ENV`].
    pub fn parse(value: &str) -> Result<Self, InvalidInput> {
        [Self::Compute, Self::Render]
            .into_iter()
            .find(|s| s.name() == value)
            .ok_or_else(|| InvalidInput::new(Self::ENV, format!("must be compute or render, got {value:?}")))
    }

    /// The shape the frames recorded on the calling thread take from now on (None: [`Self::current`]'s choice),
    /// so a benchmark or test runs both shapes in one process without touching the environment.
    pub fn set_on_this_thread(shape: Option<Self>) {
        ON_THIS_THREAD.with(|s| s.set(shape));
    }

    /// The shape of a frame recorded on the calling thread: [`Self::set_on_this_thread`]'s, else [`Self::ENV`]'s,
    /// else compute on a GPU and the render pass on a `software` adapter (llvmpipe's tiled rasteriser beats
    /// per-triangle compute threads on a few CPU cores: `bench_frame_passes 1280 720 5 both`, dev build, 2 loaded
    /// cores, frames 0.2–0.8 s faster of 0.9–3.3 s), as the SSS passes choose their shape.
    pub fn current(software: bool) -> Result<Self, InvalidInput> {
        let default = if software { Self::Render } else { Self::Compute };
        match ON_THIS_THREAD.with(|s| s.get()) {
            Some(shape) => Ok(shape),
            None => std::env::var(Self::ENV).map_or(Ok(default), |v| Self::parse(&v)),
        }
    }
}

const SOURCE: &str = include_str!("compute_raster.wgsl");

/// How the triangle passes spread a triangle's box over threads: thread (t, k) of triangle t takes rows
/// y0 + k / columns + j·rows and columns x0 + k % columns + i·columns of its box (k < rows · columns), so a large
/// triangle is spread over several threads and the dispatch has enough threads to fill a GPU (a small triangle
/// leaves the extra threads idle after its set-up): [`Slices::for_frame`]. The image is the same for any slicing (the
/// keys are order-independent atomics).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Slices {
    pub rows: u32,
    pub columns: u32,
}

thread_local! {
    static SLICES_ON_THIS_THREAD: Cell<Option<Slices>> = const { Cell::new(None) };
}

impl Slices {
    /// Threads the default slicing aims at: about two per thread slot of a large GPU (an H100 or H200 holds
    /// 132 SMs × 2048).
    const TARGET_THREADS: u32 = 1 << 19;

    /// The slicing of the frames recorded on the calling thread from now on (None: [`Self::for_frame`]), for
    /// benchmarks that compare slicings in one process.
    pub fn set_on_this_thread(slices: Option<Self>) {
        SLICES_ON_THIS_THREAD.with(|s| s.set(slices));
    }

    /// The slicing of a mesh of `triangles` over a `pixels`-pixel image: [`Self::set_on_this_thread`]'s, else
    /// enough threads per triangle (a power of two from 4 to 64) for `TARGET_THREADS` (2¹⁹) in all but no more
    /// than a thread per 4 pixels (small triangles leave extra threads idle), 2 column slices from 8 threads a
    /// triangle and 4 at 64. Measured on an NVIDIA H200 (`bench_frame_passes 1920 1080 5 slices=…`, the default
    /// head's 6720 triangles): the 1080p view's depth and visible passes at 4.5× and 5.1× their bytes-moved bound
    /// with 4×1 slices, 1.6× with 16×1 or 8×2, 1.1× and 0.8× with 16×4; the 512² shadow map's at 3.0× and 2.3×
    /// with 8×2, 4.4× and 3.0× with 16×4.
    pub fn for_frame(triangles: u32, pixels: u64) -> Self {
        if let Some(s) = SLICES_ON_THIS_THREAD.with(|s| s.get()) {
            return s;
        }
        let threads = (Self::TARGET_THREADS as u64).min(pixels / 4).max(1) as u32;
        let per_triangle = threads.div_ceil(triangles.max(1)).next_power_of_two().clamp(4, 64);
        let columns = match per_triangle {
            64.. => 4,
            8.. => 2,
            _ => 1,
        };
        Slices { rows: per_triangle / columns, columns }
    }

    /// `ROWSxCOLUMNS`, both 1..=64 (a benchmark's argument).
    pub fn parse(value: &str) -> Result<Self, InvalidInput> {
        let bad = || InvalidInput::new("slices", format!("must be ROWSxCOLUMNS, each 1..=64, got {value:?}"));
        let (r, c) = value.split_once('x').ok_or_else(bad)?;
        let (rows, columns) = (r.parse::<u32>().map_err(|_| bad())?, c.parse::<u32>().map_err(|_| bad())?);
        if !(1..=64).contains(&rows) || !(1..=64).contains(&columns) {
            return Err(bad());
        }
        Ok(Slices { rows, columns })
    }
}
/// Threads per workgroup of the triangle passes (`@workgroup_size(64, 1, 1)`).
const TRIANGLES_PER_GROUP: u32 = 64;
/// Bytes per pixel of the two visibility buffers (depth key, triangle key): below the geometry pass's per-pixel
/// buffers, so the frame's size checks cover them.
pub(crate) const VISIBILITY_BYTES_PER_PIXEL: u64 = 4;

/// The uniform block of `compute_raster.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    /// View-projection, view (column-major), (mm per unit, half the near plane, 0, 0).
    camera: [f32; 36],
    size: [u32; 4],
    out: [u32; 4],
}

/// Whether the compute shape can rasterise `job` from `buffers` on `device`: the mesh buffers within a storage
/// binding and the triangles within one dispatch row (else the frame takes the render pass).
pub(crate) fn fits(device: &wgpu::Device, job: &RasterJob<'_>, buffers: &MeshBuffers) -> bool {
    let limits = device.limits();
    let triangles = job.mesh.indices.len() as u64 / 3;
    let binding = limits.max_storage_buffer_binding_size;
    job.samples == 1
        && buffers.vertices.size().max(buffers.indices.size()) <= binding
        && buffers.vertices.usage().contains(wgpu::BufferUsages::STORAGE)
        && triangles.div_ceil(TRIANGLES_PER_GROUP as u64) <= limits.max_compute_workgroups_per_dimension as u64
}

/// Where [`record`] writes a G-buffer: `targets` (2: normal+depth, uv+cover; 3: and the tangent) of `row_bytes`
/// per row one after another in `buffer`, as the render pass's targets copied by
/// [`gpu::encode_texture_to_buffer`] would be.
///
/// [`gpu::encode_texture_to_buffer`]: crate::runtime::gpu::encode_texture_to_buffer
pub(crate) struct GBufferRows<'a> {
    pub(crate) buffer: &'a wgpu::Buffer,
    pub(crate) row_bytes: u32,
    pub(crate) targets: u32,
}

/// Records the three dispatches rasterising `job` (one sample per pixel) from its uploaded mesh `buffers` into
/// `out`. `what` names the passes in profiles and errors. The caller checked [`fits`].
pub(crate) fn record(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    what: &str,
    job: &RasterJob<'_>,
    buffers: &MeshBuffers,
    out: &GBufferRows<'_>,
) -> Result<(), RuntimeError> {
    mesh_raster::check_job(device, job)?;
    let RasterJob { mesh, camera, width, height, .. } = *job;
    let GBufferRows { buffer: gbuffer, row_bytes, targets } = *out;
    if job.samples != 1 || !(2..=3).contains(&targets) || (row_bytes as u64) < 8 * width as u64 {
        return Err(RuntimeError::Gpu(format!("{what}: one sample, 2 or 3 targets of whole rows")));
    }
    let pixels = width as u64 * height as u64 * VISIBILITY_BYTES_PER_PIXEL;
    let sizes = [buffers.vertices.size(), buffers.indices.size(), pixels, pixels, gbuffer.size()];
    compute_chain::check_buffers(device, what, &sizes)?;
    let depth_keys = frame_pool::storage_buffer(device, what, pixels);
    let tri_keys = frame_pool::storage_buffer(device, what, pixels);
    // Empty keys are 0: cleared here, so a buffer reused across frames starts empty too.
    enc.clear_buffer(&depth_keys, 0, None);
    enc.clear_buffer(&tri_keys, 0, None);
    let mut uniform = mesh_raster::camera_uniform(mesh, camera, width, height);
    uniform[33] = 0.5 * camera.near;
    let triangles = (mesh.indices.len() / 3) as u32;
    let slices = Slices::for_frame(triangles, width as u64 * height as u64);
    let params = Params {
        camera: uniform,
        size: [width, height, triangles, slices.rows],
        out: [row_bytes / 4, targets, slices.columns, 0],
    };
    let tri_groups = [triangles.div_ceil(TRIANGLES_PER_GROUP), slices.rows * slices.columns, 1];
    let stages = [
        Stage::new("depth", tri_groups),
        Stage::new("visible", tri_groups),
        Stage::new("resolve", compute_chain::groups_8x8(width, height)),
    ];
    let bound = [&buffers.vertices, &buffers.indices, &depth_keys, &tri_keys, gbuffer];
    compute_chain::record(device, enc, what, SOURCE, bytemuck::bytes_of(&params), &bound, &stages);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::camera::Camera;
    use crate::mesh::head::default_head;
    use crate::mesh::Mesh;
    use crate::runtime::device::Gpu;
    use crate::runtime::gpu;
    use crate::runtime::skin::mesh_raster::MeshGBuffer;
    use crate::runtime::skin::mesh_raster_cpu;

    #[test]
    fn the_shape_parses_its_two_names_and_refuses_others_naming_the_variable() {
        assert_eq!(RasterShape::parse("compute").unwrap(), RasterShape::Compute);
        assert_eq!(RasterShape::parse("render").unwrap(), RasterShape::Render);
        let e = RasterShape::parse("fragment").unwrap_err();
        assert_eq!(e.param, RasterShape::ENV);
        assert!(e.message.contains("compute or render"), "{e}");
        RasterShape::set_on_this_thread(Some(RasterShape::Render));
        assert_eq!(RasterShape::current(false).unwrap(), RasterShape::Render);
        RasterShape::set_on_this_thread(None);
        if std::env::var_os(RasterShape::ENV).is_none() {
            assert_eq!(RasterShape::current(false).unwrap(), RasterShape::Compute, "on a GPU");
            assert_eq!(RasterShape::current(true).unwrap(), RasterShape::Render, "on a software adapter");
        }
    }

    /// A device for one test, the tests taking turns (adapters enumerated from two threads at once can fail on
    /// the GL backend).
    fn device() -> (std::sync::MutexGuard<'static, ()>, Gpu) {
        static TURN: std::sync::Mutex<()> = std::sync::Mutex::new(());
        let turn = TURN.lock().unwrap_or_else(|e| e.into_inner());
        (turn, crate::runtime::device::create_headless(&Default::default()).expect("an adapter (lavapipe)"))
    }

    /// `mesh` seen by `camera` at `w`×`h` through the compute rasteriser, its three targets read back and decoded
    /// as the render pass's are.
    fn compute_gbuffer(g: &Gpu, mesh: &Mesh, camera: &Camera, w: u32, h: u32) -> MeshGBuffer {
        let tangents = crate::mesh::tangents::vertex_tangents(mesh);
        let job = RasterJob { mesh, tangents: &tangents, camera, width: w, height: h, samples: 1 };
        let buffers = mesh_raster::upload_mesh(&g.device, mesh, &tangents).unwrap();
        assert!(fits(&g.device, &job, &buffers));
        let row = (8 * w).div_ceil(256) * 256;
        let bytes = 3 * row as u64 * h as u64;
        let out = compute_chain::storage_buffer(&g.device, "test raster", bytes, None);
        let mut enc = g.device.create_command_encoder(&Default::default());
        let rows = GBufferRows { buffer: &out, row_bytes: row, targets: 3 };
        record(&g.device, &mut enc, "test raster", &job, &buffers, &rows).unwrap();
        let read = g.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("test read-back"),
            size: out.size(),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        enc.copy_buffer_to_buffer(&out, 0, &read, 0, out.size());
        gpu::submit(&g.queue, enc.finish());
        let words = gpu::map_read(&g.device, &read).unwrap();
        // Each target's rows without their padding, as f32.
        let target = |k: usize| -> Vec<f32> {
            let (row, plane) = (row as usize, row as usize * h as usize);
            (0..h as usize)
                .flat_map(|y| gpu::f16_to_f32(&words[k * plane + y * row..k * plane + y * row + 8 * w as usize]))
                .collect()
        };
        mesh_raster::decode(w, h, 1, &target(0), &target(1), &target(2))
    }

    /// How two G-buffers of one frame differ: pixels covered by one only; of those both cover, the ones whose depth
    /// differs by more than 1 mm (another surface won), and the largest depth (mm), uv and tangent difference and
    /// the smallest normal dot product over the rest.
    #[derive(Debug)]
    struct Differences {
        covered: usize,
        coverage: usize,
        other_surface: usize,
        depth_mm: f32,
        min_dot: f32,
        uv: f32,
        tangent: f32,
    }

    fn differences(a: &MeshGBuffer, b: &MeshGBuffer) -> Differences {
        let mut d = Differences {
            covered: a.covered.iter().filter(|&&c| c).count(),
            coverage: a.covered.iter().zip(&b.covered).filter(|(x, y)| x != y).count(),
            other_surface: 0,
            depth_mm: 0.0,
            min_dot: 1.0,
            uv: 0.0,
            tangent: 0.0,
        };
        for i in (0..a.covered.len()).filter(|&i| a.covered[i] && b.covered[i]) {
            let dd = (a.depth_mm[i] - b.depth_mm[i]).abs();
            if dd > 1.0 {
                d.other_surface += 1;
                continue;
            }
            let (n, m) = (a.normal_view[i], b.normal_view[i]);
            d.depth_mm = d.depth_mm.max(dd);
            d.min_dot = d.min_dot.min(n[0] * m[0] + n[1] * m[1] + n[2] * m[2]);
            d.uv = d.uv.max((a.uv[i][0] - b.uv[i][0]).abs().max((a.uv[i][1] - b.uv[i][1]).abs()));
            let dt = (0..4).map(|k| (a.tangent_view[i][k] - b.tangent_view[i][k]).abs()).fold(0.0, f32::max);
            d.tangent = d.tangent.max(dt);
        }
        d
    }

    /// The tolerances of the render pass against the CPU twin (`tests/it/mesh_raster.rs`): f16 storage, depth
    /// ~600 mm at a 0.5 mm spacing, unit normals and uv to 1/1024 (tangents to 1e-2, as the wrinkle test).
    fn assert_within_f16(d: &Differences, what: &str) {
        assert!(d.depth_mm <= 0.5, "{what}: depth differs by {} mm ({d:?})", d.depth_mm);
        assert!(d.min_dot >= 0.999, "{what}: normals differ ({d:?})");
        assert!(d.uv <= 2.0 / 1024.0, "{what}: uv differs ({d:?})");
        assert!(d.tangent <= 1e-2, "{what}: tangents differ ({d:?})");
    }

    /// The default head at 0.6 m, 256×192, as `tests/it/mesh_raster.rs` rasterises it: the compute G-buffer
    /// covers exactly the CPU twin's pixels (the same projection and set-up arithmetic; the twin draws a centre on
    /// a shared edge from both triangles and keeps the first, the top-left rule from one — the same pixels), the
    /// same surface everywhere, the attributes within f16 storage (measured: depth one f16 step, 0.5 mm; normals
    /// dot ≥ 0.9993; uv equal); against the render pass the coverage may differ on a few silhouette pixels (the
    /// hardware snaps vertices to 1/256 pixel; measured: none of 9 138), the attributes within the same tolerances
    /// (measured: uv 1/2048, tangents 2.4e-3).
    /// The G-buffer is the same for every slicing of the triangles' boxes (one thread per triangle, rows only,
    /// rows and columns, uneven counts) and the default slicing gives a power of two of 4 to 64 threads per
    /// triangle; a bad slicing argument is refused naming it.
    #[test]
    fn every_slicing_of_the_triangle_boxes_gives_the_same_gbuffer() {
        let (_turn, g) = device();
        let head = default_head();
        let cam = Camera::facing(0.6).unwrap();
        let (w, h) = (160, 120);
        let frames: Vec<MeshGBuffer> = [(1, 1), (4, 1), (16, 4), (3, 5)]
            .into_iter()
            .map(|(rows, columns)| {
                Slices::set_on_this_thread(Some(Slices { rows, columns }));
                let f = compute_gbuffer(&g, &head, &cam, w, h);
                Slices::set_on_this_thread(None);
                f
            })
            .collect();
        assert!(frames[0].covered.iter().filter(|&&c| c).count() > 2000);
        for f in &frames[1..] {
            assert!(f == &frames[0], "a slicing changed the G-buffer");
        }
        // (triangles, pixels) → slicing: the 1080p view and the 512² shadow map of the default head and the scan.
        let cases = [
            (6720, 1920 * 1080, (16, 4)),
            (6720, 512 * 512, (8, 2)),
            (17684, 1920 * 1080, (16, 2)),
            (17684, 512 * 512, (4, 1)),
            (1, 64 * 64, (16, 4)),
            (1 << 20, 1920 * 1080, (4, 1)),
        ];
        for (triangles, pixels, (rows, columns)) in cases {
            assert_eq!(Slices::for_frame(triangles, pixels), Slices { rows, columns }, "{triangles} over {pixels}");
        }
        assert_eq!(Slices::parse("16x4").unwrap(), Slices { rows: 16, columns: 4 });
        for bad in ["16", "0x4", "65x1", "ax2"] {
            assert_eq!(Slices::parse(bad).unwrap_err().param, "slices", "{bad}");
        }
    }

    #[test]
    fn the_compute_gbuffer_matches_the_cpu_twin_and_the_render_pass() {
        let (_turn, g) = device();
        let head = default_head();
        let cam = Camera::facing(0.6).unwrap();
        let (w, h) = (256, 192);
        let compute = compute_gbuffer(&g, &head, &cam, w, h);
        let cpu = mesh_raster_cpu::rasterise(&head, &cam, w, h);
        let render = mesh_raster::rasterise(&g.device, &g.queue, &head, &cam, w, h).unwrap();
        let d = differences(&compute, &cpu);
        eprintln!("compute vs cpu {d:?}");
        let r = differences(&compute, &render);
        eprintln!("compute vs render {r:?}");
        assert!(d.covered > 8000, "{} pixels covered", d.covered);
        assert_eq!((d.coverage, d.other_surface), (0, 0), "against the CPU twin: {d:?}");
        assert_within_f16(&d, "against the CPU twin");
        assert!(r.coverage <= 8, "against the render pass: {r:?}");
        assert!(r.other_surface as f64 <= 0.001 * r.covered as f64, "against the render pass: {r:?}");
        assert_within_f16(&r, "against the render pass");
    }

    /// `mesh` with a copy of it moved by `offset` (mesh units).
    fn with_copy(mesh: &Mesh, offset: [f32; 3]) -> Mesh {
        let n = mesh.positions.len() as u32;
        let moved = mesh.positions.iter().map(|p| [p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]]);
        Mesh::new(
            "two heads",
            mesh.positions.iter().copied().chain(moved).collect(),
            [mesh.normals.clone(), mesh.normals.clone()].concat(),
            [mesh.uvs.clone(), mesh.uvs.clone()].concat(),
            mesh.indices.iter().copied().chain(mesh.indices.iter().map(|i| i + n)).collect(),
            mesh.mm_per_unit,
        )
        .unwrap()
    }

    /// Two heads, the second 8 cm to the side and 15 cm behind the first, so the first hides part of it: where
    /// both project, the G-buffer holds the nearer surface (the depth test: each pixel's depth is the smaller of
    /// the two heads rasterised alone), the overlap is hundreds of pixels, and the frame agrees with the CPU twin
    /// as one head does.
    #[test]
    fn overlapping_heads_keep_the_nearer_surface() {
        let (_turn, g) = device();
        let head = default_head();
        let two = with_copy(&head, [0.08, 0.0, -0.15]);
        let back = with_copy(&head, [0.0; 3]);
        let back =
            Mesh { positions: back.positions.iter().map(|p| [p[0] + 0.08, p[1], p[2] - 0.15]).collect(), ..back };
        let cam = Camera::facing(0.6).unwrap();
        let (w, h) = (256, 192);
        let both = compute_gbuffer(&g, &two, &cam, w, h);
        let (front_alone, back_alone) =
            (compute_gbuffer(&g, &head, &cam, w, h), compute_gbuffer(&g, &back, &cam, w, h));
        let overlap: Vec<usize> =
            (0..both.covered.len()).filter(|&i| front_alone.covered[i] && back_alone.covered[i]).collect();
        assert!(overlap.len() > 500, "{} pixels where both heads project", overlap.len());
        for &i in &overlap {
            let nearer = front_alone.depth_mm[i].min(back_alone.depth_mm[i]);
            assert_eq!(both.depth_mm[i], nearer, "pixel {i}: the nearer surface");
        }
        let d = differences(&both, &mesh_raster_cpu::rasterise(&two, &cam, w, h));
        assert_eq!((d.coverage, d.other_surface), (0, 0), "against the CPU twin: {d:?}");
        assert_within_f16(&d, "against the CPU twin");
    }

    /// A square facing the camera 1 m away (the background), a triangle wholly behind the camera, a triangle from
    /// 0.6 to 4 times the near plane (0.05 m) in front of the eye — its part nearer than the near plane is cut
    /// (z < 0), the rest covers the square —, and a triangle with one vertex behind the camera: the compute
    /// G-buffer equals the CPU twin's coverage (the last triangle skipped by both) and, without the last triangle,
    /// the render pass's (which clips it), up to a few edge pixels (measured: coverage equal, one pixel of 5 184 on
    /// the other surface).
    #[test]
    fn triangles_behind_the_camera_and_across_the_near_plane_are_cut_as_the_twin_cuts_them() {
        let (_turn, g) = device();
        let cam = Camera::facing(1.0).unwrap();
        let q = 0.2;
        // Eye at z = 1 looking down −z: view depth = 1 − z.
        let positions = vec![
            [-q, -q, 0.0],
            [q, -q, 0.0],
            [q, q, 0.0],
            [-q, q, 0.0],
            // Behind the camera.
            [-0.1, -0.1, 1.5],
            [0.1, -0.1, 1.5],
            [0.0, 0.1, 1.5],
            // Across the near plane: view depth 0.03 to 0.2.
            [-0.005, -0.01, 0.97],
            [0.03, -0.01, 0.8],
            [0.0, 0.03, 0.8],
            // One vertex behind the camera.
            [-0.05, 0.02, 0.9],
            [0.0, 0.02, 1.2],
            [-0.05, 0.06, 0.9],
        ];
        let indices = vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12];
        let n = positions.len();
        let mesh = |indices: Vec<u32>| {
            let (p, nrm, uv) = (positions.clone(), vec![[0.0, 0.0, 1.0]; n], vec![[0.5, 0.5]; n]);
            Mesh::new("near plane", p, nrm, uv, indices, 1000.0).unwrap()
        };
        let (w, h) = (128, 96);
        let all = mesh(indices.clone());
        let compute = compute_gbuffer(&g, &all, &cam, w, h);
        let cpu = mesh_raster_cpu::rasterise(&all, &cam, w, h);
        let d = differences(&compute, &cpu);
        // Pixels whose depth lies within rounding of the near-plane cut may fall either side of it: exact on
        // lavapipe, 3 of 5181 covered pixels on an NVIDIA H200 (its fused multiply-adds round the plane's z
        // differently from the twin's separate f32 operations). A wrong cut or depth compare moves hundreds.
        assert!(d.coverage <= 8 && d.other_surface == 0, "against the CPU twin: {d:?}");
        // The near triangle shows in front of the square (view depth < 1000 mm), cut at the near plane (≥ 50 mm).
        let near: Vec<f32> =
            compute.depth_mm.iter().zip(&compute.covered).filter(|(&z, &c)| c && z < 900.0).map(|(&z, _)| z).collect();
        assert!(near.len() > 100, "{} pixels of the near triangle", near.len());
        assert!(near.iter().all(|&z| z >= 49.9), "nearest {:?} mm", near.iter().copied().fold(f32::MAX, f32::min));
        let without_last = mesh(indices[..12].to_vec());
        let compute = compute_gbuffer(&g, &without_last, &cam, w, h);
        let render = mesh_raster::rasterise(&g.device, &g.queue, &without_last, &cam, w, h).unwrap();
        let r = differences(&compute, &render);
        eprintln!("near plane vs render {r:?}");
        assert!(r.coverage <= 4 && r.other_surface <= 4, "against the render pass: {r:?}");
    }

    /// Two squares facing the camera with edges through pixel centres (x = 0 and y = 0 project onto the centres
    /// of column 32 and row 24 of a 65×49 frame): one right of and above x = y = 0, one left of and below. The
    /// top-left rule gives a centre on a left or top edge to the triangle and on a right or bottom edge to none:
    /// column 32 is the first square's (its left edge), not the second's (its right edge); row 24 the second's
    /// (its top edge), not the first's (its bottom edge) — as the render pass draws it, where the CPU twin, which
    /// draws every centre on an edge, covers both.
    #[test]
    fn edges_through_pixel_centres_follow_the_top_left_rule() {
        let (_turn, g) = device();
        let cam = Camera::facing(1.0).unwrap();
        let q = 0.1;
        let positions = vec![
            [0.0, 0.0, 0.0],
            [q, 0.0, 0.0],
            [q, q, 0.0],
            [0.0, q, 0.0],
            [-q, -q, 0.0],
            [0.0, -q, 0.0],
            [0.0, 0.0, 0.0],
            [-q, 0.0, 0.0],
        ];
        let indices = vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];
        let mesh =
            Mesh::new("squares", positions, vec![[0.0, 0.0, 1.0]; 8], vec![[0.5, 0.5]; 8], indices, 1000.0).unwrap();
        let (w, h) = (65, 49);
        let compute = compute_gbuffer(&g, &mesh, &cam, w, h);
        let render = mesh_raster::rasterise(&g.device, &g.queue, &mesh, &cam, w, h).unwrap();
        let cpu = mesh_raster_cpu::rasterise(&mesh, &cam, w, h);
        let at = |gb: &MeshGBuffer, x: u32, y: u32| gb.covered[(y * w + x) as usize];
        // (pixel, covered): on the first square's left edge, its bottom edge; the second's right edge, top edge.
        let on_edges = [((32, 20), true), ((35, 24), false), ((32, 28), false), ((29, 24), true)];
        for ((x, y), covered) in on_edges {
            assert_eq!(at(&compute, x, y), covered, "compute, pixel ({x}, {y})");
            assert!(at(&cpu, x, y), "the CPU twin draws ({x}, {y})");
        }
        assert!(at(&compute, 34, 20) && at(&compute, 30, 28), "inside the squares");
        assert_eq!(compute.covered, render.covered, "against the render pass");
    }

    /// A whole `run skin` frame (separable SSS, bloom, the committed bake's rig; 160×96) through both shapes: the
    /// compute shape records its three dispatches per G-buffer and no render pass (the profile's labels), the
    /// render shape its two marks, and the frames agree within 2/255 on 99 % of the channels, the tolerance the
    /// device frame keeps against its CPU twin (`tests/it/runtime_pipeline_cache.rs`).
    #[test]
    fn a_run_skin_frame_is_the_same_frame_through_either_shape() {
        use crate::runtime::skin::frame::render_with;
        use crate::runtime::skin::lighting::DemoAssets;
        use crate::runtime::skin::passes::SkinPasses;
        use crate::runtime::skin::settings::{SkinRenderSettings, SkinShader, StretchPreset};
        let (_turn, g) = device();
        let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/baked"));
        let assets = DemoAssets::load(dir).unwrap();
        let s = SkinRenderSettings {
            shader: SkinShader::Separable,
            heads: 1,
            distance_m: 0.6,
            width: 160,
            height: 96,
            melanin: 0.02,
            stretch: StretchPreset::Tap2009,
        };
        let head = default_head();
        let frame = |shape| {
            RasterShape::set_on_this_thread(Some(shape));
            gpu::set_pass_profiling(true);
            let img = render_with(Some(&g), &head, &s, &SkinPasses::default(), &assets);
            let profile = gpu::take_pass_profile(&g.device, &g.queue).unwrap();
            gpu::set_pass_profiling(false);
            RasterShape::set_on_this_thread(None);
            let labels: Vec<String> = profile.into_iter().map(|p| p.label).collect();
            (img.unwrap(), labels)
        };
        let ((compute, c_labels), (render, r_labels)) = (frame(RasterShape::Compute), frame(RasterShape::Render));
        for (labels, ours, theirs) in [
            (&c_labels, "view raster: resolve", "view G-buffer rasterised"),
            (&r_labels, "view G-buffer rasterised", "view raster: resolve"),
        ] {
            assert!(labels.iter().any(|l| l.ends_with(ours)), "{labels:?}");
            assert!(!labels.iter().any(|l| l.contains(theirs)), "{labels:?}");
        }
        for pass in ["view raster: depth", "view raster: visible", "shadow raster: depth", "shadow raster: resolve"] {
            assert!(c_labels.iter().any(|l| l == pass), "{pass} in {c_labels:?}");
        }
        let close = compute.data.iter().zip(&render.data).filter(|(a, b)| a.abs_diff(**b) <= 2).count();
        assert!(
            close as f64 >= 0.99 * compute.data.len() as f64,
            "{close} of {} channels within 2/255",
            compute.data.len()
        );
    }
}
