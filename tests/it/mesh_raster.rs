//! The mesh G-buffer pass (`runtime::mesh_raster`) against its CPU twin on the procedural default head,
//! and the geometry it must show: the nose tip nearest the camera at the distance the mesh puts it, the silhouette
//! as wide as the head's projection, normals facing the camera on the visible side.

use crate::support::gpu;
use rtbake::mesh::camera::Camera;
use rtbake::mesh::head::default_head;
use rtbake::runtime::cpu;
use rtbake::runtime::mesh_raster::rasterise;

#[test]
fn the_default_head_rasterises_alike_on_gpu_and_cpu() {
    let g = gpu();
    let head = default_head();
    let cam = Camera::facing(0.6).unwrap();
    let (w, h) = (256u32, 192u32);
    let gpu_g = rasterise(&g.device, &g.queue, &head, &cam, w, h).unwrap();
    let cpu_g = cpu::mesh_raster::rasterise(&head, &cam, w, h);
    let covered_cpu = cpu_g.covered.iter().filter(|&&c| c).count();
    let mismatched = gpu_g.covered.iter().zip(&cpu_g.covered).filter(|(a, b)| a != b).count();
    assert!(covered_cpu > 8000, "{covered_cpu} pixels covered");
    // Coverage differs only where a pixel centre lies on an edge (top-left rule) or at f32/fixed-point ties.
    assert!(
        (mismatched as f64) <= 0.002 * covered_cpu as f64,
        "{mismatched} of {covered_cpu} pixels differ in coverage"
    );
    let (mut worst_depth, mut worst_dot, mut worst_uv, mut both) = (0.0f32, 1.0f32, 0.0f32, 0usize);
    let mut far_off = 0usize;
    for i in 0..(w * h) as usize {
        if !(gpu_g.covered[i] && cpu_g.covered[i]) {
            continue;
        }
        both += 1;
        let dd = (gpu_g.depth_mm[i] - cpu_g.depth_mm[i]).abs();
        let (a, b) = (gpu_g.normal_view[i], cpu_g.normal_view[i]);
        let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let du = (gpu_g.uv[i][0] - cpu_g.uv[i][0]).abs().max((gpu_g.uv[i][1] - cpu_g.uv[i][1]).abs());
        // Where the ear meets the skull two surfaces are within a depth ulp: either may win.
        if dd > 1.0 {
            far_off += 1;
            continue;
        }
        worst_depth = worst_depth.max(dd);
        worst_dot = worst_dot.min(dot);
        worst_uv = worst_uv.max(du);
    }
    assert!(far_off as f64 <= 0.001 * both as f64, "{far_off} of {both} pixels show different surfaces");
    // f16 storage: depth ~600 mm has a 0.5 mm spacing; unit normals and uv 1/1024.
    assert!(worst_depth <= 0.5, "depth differs by {worst_depth} mm");
    assert!(worst_dot >= 0.999, "normals differ: min dot {worst_dot}");
    assert!(worst_uv <= 2.0 / 1024.0, "uv differs by {worst_uv}");

    // Geometry: the nearest covered pixel is the nose tip, 600 mm − (90 + 22) mm ≈ 488 mm away (the bump adds
    // a little less than its height where the ellipsoid curves away), facing the camera.
    let (i_near, d_near) = gpu_g
        .depth_mm
        .iter()
        .enumerate()
        .filter(|(i, _)| gpu_g.covered[*i])
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, d)| (i, *d))
        .unwrap();
    assert!((485.0..=495.0).contains(&d_near), "nearest point at {d_near} mm");
    let (x, y) = (i_near as u32 % w, i_near as u32 / w);
    assert!((x as i32 - w as i32 / 2).abs() <= 2 && y > h / 2, "nose tip at pixel ({x}, {y})");
    assert!(gpu_g.normal_view[i_near][2] > 0.9, "{:?}", gpu_g.normal_view[i_near]);
    // Silhouette height: the 210 mm head at ~0.6 m under a 30° field of view spans about
    // 210 / (2 · 600 · tan 15°) · 192 ≈ 125 rows (a little more: the top and bottom are nearer than 600 mm).
    let rows = (0..h).filter(|&y| (0..w).any(|x| gpu_g.covered[(y * w + x) as usize])).count();
    assert!((118..=140).contains(&rows), "{rows} rows covered");
}
