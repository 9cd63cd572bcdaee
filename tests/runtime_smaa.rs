//! SMAA 1x: GPU vs CPU reference on the same inputs, and antialiasing quality against a 16× supersampled
//! ground truth.

mod runtime_support;

use rtbake::runtime::cpu;
use rtbake::runtime::scene::render_shapes;
use rtbake::runtime::smaa::Smaa;
use runtime_support::*;

fn gpu_vs_cpu(w: u32, h: u32) {
    let g = gpu();
    let luts = golden_smaa();
    let img = render_shapes(w, h, 1);
    let pass = Smaa::new(&g.device, &g.queue, w, h, &luts).unwrap();
    let out = pass.run(&g.device, &g.queue, &img).unwrap();
    let edges = rtbake::runtime::gpu::read_texture(&g.device, &g.queue, pass.edges()).unwrap();
    let weights = rtbake::runtime::gpu::read_texture(&g.device, &g.queue, pass.weights()).unwrap();
    let c = cpu::smaa::smaa(&img, w, h, &luts, precision(&g));
    let (fe, me) = within(&edges, &c.edges, 0);
    let (fw, mw) = within(&weights, &c.weights, 1);
    let (fo, mo) = within(&out, &c.output, 1);
    let edge_px = c.edges.chunks(2).filter(|e| e[0] > 0 || e[1] > 0).count();
    eprintln!(
        "{w}x{h}: {edge_px} edge pixels; edges exact {:.5} (max {me}); weights ±1 {:.5} (max {mw}); \
         output ±1 {:.5} (max {mo}); output pixels ±1 {:.5}",
        fe,
        fw,
        fo,
        pixels_within(&out, &c.output, 4, 1)
    );
    assert!(edge_px > 0, "the test scene must have edges");
    assert!(fe >= 0.9999, "edges differ: {fe}");
    assert!(fo >= 0.999, "output channels within 1/255: {fo}");
    assert!(out != img, "SMAA must change the aliased image");
}

#[test]
fn smaa_gpu_matches_cpu_256() {
    gpu_vs_cpu(256, 256);
}

#[test]
fn smaa_gpu_matches_cpu_odd_size() {
    gpu_vs_cpu(301, 173);
}

#[test]
fn smaa_gpu_matches_cpu_1080p() {
    gpu_vs_cpu(1920, 1080);
}
