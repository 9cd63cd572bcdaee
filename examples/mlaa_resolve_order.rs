//! MLAA before vs after the MSAA resolve (thesis §10.5, Figs. 10.15–10.16) on the procedural shapes scene: edge
//! error against 16× supersampling of the aliased frame, the 4× resolve, MLAA after it and MLAA on each sample
//! before it. `cargo run --example mlaa_resolve_order [-- cpu] [WIDTH HEIGHT]` (default 1280×720, the GPU).

use rtbake::runtime::device::create_headless;
use rtbake::runtime::resolve_order::compare;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let cpu = args.iter().any(|a| a == "cpu");
    let nums: Vec<u32> = args.iter().filter_map(|a| a.parse().ok()).collect();
    let (w, h) = (nums.first().copied().unwrap_or(1280), nums.get(1).copied().unwrap_or(720));
    let baked = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("baked");
    let n = rtbake::runtime::mlaa::DEFAULT_MAX_DISTANCE;
    let bytes = rtbake::runtime::loader::load_mlaa_area(&baked, n).expect("the bake's MLAA area map");
    let map = rtbake::runtime::mlaa::MlaaAreaMap::new(n, bytes).expect("a valid area map");
    let gpu = if cpu { None } else { Some(create_headless(&Default::default()).expect("a GPU adapter")) };
    println!("adapter: {}", gpu.as_ref().map(|g| g.describe()).unwrap_or_else(|| "CPU twins".into()));
    let e = compare(gpu.as_ref(), w, h, &map).expect("the comparison");
    println!("{w}x{h}, {} edge pixels; mean |error| vs 16x supersampling (sRGB 0..1):", e.edge_pixels);
    println!("  aliased (1 sample)      {:.5}", e.aliased);
    println!("  4x MSAA resolve         {:.5}", e.resolve);
    println!("  MLAA after the resolve  {:.5}", e.mlaa_after_resolve);
    println!("  MLAA before the resolve {:.5}", e.mlaa_before_resolve);
}
