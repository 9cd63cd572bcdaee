//! The G-buffer as the view-frame compute passes read it ([`super::surface_maps`], [`super::wrinkles`]): a pass's
//! shader is `pixel_frame.wgsl`, `view_frame.wgsl` and `bilinear_taps.wgsl` ahead of its own WGSL (entry `main`,
//! 8 × 8 workgroups over the frame); bindings 1–3 are the G-buffer's (u, v, covered, 0), (view normal, 0) and view
//! tangent per pixel, bindings 4 and 5 the pass's own maps, binding 6 its output. [`run`] uploads a host G-buffer
//! and reads the output back; [`record`] records the pass into a frame's command encoder over the G-buffer the
//! device already holds (`frame_geometry`), with no submission and no read-back.

use crate::runtime::compute_chain::{self, Buffer, Stage};
use crate::runtime::skin::mesh_raster::MeshGBuffer;
use crate::runtime::RuntimeError;

/// The WGSL every view-frame pass starts with.
const PRELUDES: &str =
    concat!(include_str!("pixel_frame.wgsl"), include_str!("view_frame.wgsl"), include_str!("bilinear_taps.wgsl"));

/// Runs the view-frame pass `what` (`pass_wgsl`) over `g` with the uniform block `params` and the pass's two `maps`,
/// and reads back its output buffer of `out_bytes` (zeroed first).
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    what: &str,
    pass_wgsl: &str,
    params: &[u8],
    g: &MeshGBuffer,
    [map_a, map_b]: [Buffer<'_>; 2],
    out_bytes: u64,
) -> Result<Vec<u8>, RuntimeError> {
    let uvc: Vec<f32> = g.uv.iter().zip(&g.covered).flat_map(|(t, &c)| [t[0], t[1], c as u8 as f32, 0.0]).collect();
    let nrm: Vec<f32> = g.normal_view.iter().flat_map(|v| [v[0], v[1], v[2], 0.0]).collect();
    let frame = [uvc.as_slice(), nrm.as_slice(), bytemuck::cast_slice(&g.tangent_view)]
        .map(|d| Buffer::Data(bytemuck::cast_slice(d)));
    let [uvc, nrm, tng] = frame;
    compute_chain::run(
        device,
        queue,
        what,
        &[PRELUDES, pass_wgsl].concat(),
        params,
        &[uvc, nrm, tng, map_a, map_b, Buffer::Zeroed(out_bytes)],
        &[Stage::new("main", compute_chain::groups_8x8(g.width, g.height))],
        5,
    )
}

/// Records the view-frame pass `what` (`pass_wgsl`) into `enc` over the device's per-pixel `frame` buffers of a
/// `width`×`height` frame ((u, v, covered, coverage), (view normal, 0), view tangent: one vec4 of f32 each per
/// pixel) with the uniform block `params` and the pass's two maps `[a, b]` on the device (uploaded by the pass, or
/// kept across frames by its caller), writing `out`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn record(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    what: &str,
    pass_wgsl: &str,
    params: &[u8],
    (width, height): (u32, u32),
    frame: [&wgpu::Buffer; 3],
    [a, b]: [&wgpu::Buffer; 2],
    out: &wgpu::Buffer,
) -> Result<(), RuntimeError> {
    let sizes = [frame[0].size(), frame[1].size(), frame[2].size(), a.size(), b.size()];
    compute_chain::check_buffers(device, what, &sizes)?;
    let bound = [frame[0], frame[1], frame[2], a, b, out];
    let stages = [Stage::new("main", compute_chain::groups_8x8(width, height))];
    compute_chain::record(device, enc, what, &[PRELUDES, pass_wgsl].concat(), params, &bound, &stages);
    Ok(())
}
