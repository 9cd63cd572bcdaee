//! SMAA and MLAA with rtbake's baked textures give the same image as with the upstream golden textures.
//!
//! The textures from `baked/` go through the manifest-checked loader; the golden files come from
//! `$RTBAKE_REFERENCE_DIR` (default `../shared/reference`). The same aliased test scene is antialiased on the
//! GPU and with the CPU reference, once per texture set; the output bytes must be identical (and so must the
//! blending weights, where the textures enter). A missing reference folder is reported on stderr and the
//! comparison is not run; with `RTBAKE_REQUIRE_REFERENCE=1` it fails.

use crate::support::*;
use rtbake::runtime::cpu;
use rtbake::runtime::gpu::read_texture;
use rtbake::runtime::mlaa::{Mlaa, MlaaAreaMap};
use rtbake::runtime::scene::render_shapes;
use rtbake::runtime::smaa::Smaa;

#[test]
fn smaa_with_baked_textures_equals_smaa_with_golden_textures() {
    let Some(_) = reference_dir_checked() else { return };
    let (baked, golden) = (baked_smaa(), golden_smaa());
    let (w, h) = (320, 240);
    let img = render_shapes(w, h, 1);
    let g = gpu();
    let run = |t| {
        let pass = Smaa::new(&g.device, &g.queue, w, h, t).unwrap();
        let out = pass.run(&g.device, &g.queue, &img).unwrap();
        (out, read_texture(&g.device, &g.queue, pass.weights()).unwrap())
    };
    let ((gpu_b, wb), (gpu_g, wg)) = (run(&baked), run(&golden));
    assert!(gpu_b != img, "SMAA must change the aliased scene");
    assert!(wb.iter().any(|v| *v > 0), "the scene must produce blending weights");
    assert!(wb == wg, "GPU SMAA blending weights differ between baked and golden textures");
    assert!(gpu_b == gpu_g, "GPU SMAA output differs between baked and golden textures");
    let p = precision(&g);
    let (cpu_b, cpu_g) = (cpu::smaa::smaa(&img, w, h, &baked, p), cpu::smaa::smaa(&img, w, h, &golden, p));
    assert!(cpu_b.weights == cpu_g.weights, "CPU SMAA blending weights differ");
    assert!(cpu_b.output == cpu_g.output, "CPU SMAA output differs between baked and golden textures");
}

#[test]
fn mlaa_with_baked_area_map_33_equals_mlaa_with_golden_map() {
    let Some(_) = reference_dir_checked() else { return };
    let n = 33;
    let baked = MlaaAreaMap::new(n, baked_mlaa(n)).unwrap();
    let golden = MlaaAreaMap::new(n, golden_mlaa(n)).unwrap();
    let (w, h) = (320, 240);
    let img = render_shapes(w, h, 1);
    let g = gpu();
    let run = |m| {
        let pass = Mlaa::new(&g.device, &g.queue, w, h, m).unwrap();
        let out = pass.run(&g.device, &g.queue, &img).unwrap();
        (out, read_texture(&g.device, &g.queue, pass.weights()).unwrap())
    };
    let ((gpu_b, wb), (gpu_g, wg)) = (run(&baked), run(&golden));
    assert!(gpu_b != img, "MLAA must change the aliased scene");
    assert!(wb == wg, "GPU MLAA blending weights differ between baked and golden area maps");
    assert!(gpu_b == gpu_g, "GPU MLAA output differs between baked and golden area maps");
    let p = precision(&g);
    let (cpu_b, cpu_g) = (cpu::mlaa::mlaa(&img, w, h, &baked, p), cpu::mlaa::mlaa(&img, w, h, &golden, p));
    assert!(cpu_b.weights == cpu_g.weights, "CPU MLAA blending weights differ");
    assert!(cpu_b.output == cpu_g.output, "CPU MLAA output differs between baked and golden area maps");
}
