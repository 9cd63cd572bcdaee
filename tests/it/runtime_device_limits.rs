//! The GPU path checks every image against the adapter's real limits before it allocates,
//! and refuses with the limit named (exit 2 from the command) instead of panicking inside wgpu.

use crate::support::{baked_smaa, gpu};
use rtbake::runtime::device::check_image_fits;
use rtbake::runtime::RuntimeError;

#[test]
fn an_image_beyond_the_adapter_texture_limit_is_refused_not_a_panic() {
    let g = gpu();
    let edge = g.device.limits().max_texture_dimension_2d;
    // The device carries the adapter's own limits, not wgpu's defaults (the old 256 MiB buffer cap).
    assert!(g.device.limits().max_buffer_size >= wgpu::Limits::downlevel_defaults().max_buffer_size);
    let too_wide = edge + 1;
    let err = check_image_fits(&g.device, too_wide, 16, 4).unwrap_err();
    assert!(matches!(err, RuntimeError::Invalid(_)), "{err}");
    let msg = err.to_string();
    assert!(
        msg.contains("max_texture_dimension_2d") && msg.contains(&edge.to_string()) && msg.contains("`cpu`"),
        "{msg}"
    );
    // Through a pass: refused before allocating (by the adapter's limit where it is below rtbake's 16384, by
    // rtbake's own range otherwise), an error either way.
    match rtbake::runtime::smaa::Smaa::new(&g.device, &g.queue, too_wide, 16, &baked_smaa()) {
        Ok(_) => panic!("{too_wide}x16 accepted by an adapter whose edge limit is {edge}"),
        Err(e) => assert!(matches!(e, RuntimeError::Invalid(_)), "{e}"),
    }
}

#[test]
fn an_image_needing_a_buffer_beyond_the_adapter_limit_is_refused() {
    let g = gpu();
    let max = g.device.limits().max_buffer_size;
    let edge = g.device.limits().max_texture_dimension_2d;
    // Texels so large that one row of `edge` of them exceeds the largest buffer.
    let bpt = u32::try_from(max / edge as u64 + 1).unwrap_or(u32::MAX);
    let err = check_image_fits(&g.device, edge, edge, bpt).unwrap_err();
    assert!(err.to_string().contains("max_buffer_size"), "{err}");
    assert!(check_image_fits(&g.device, 64, 64, 16).is_ok());
}
