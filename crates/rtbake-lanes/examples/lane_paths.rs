//! Photon histories of the lane kernel, one thread, on one layer stack: the benchmark side of
//! `scripts/bench_mcml.sh`, which runs it under `/usr/bin/time` (CPU seconds) beside MCML on the same problem.
//!
//! `RTBAKE_LANE_PATH=portable|avx2|avx512 cargo run --release -p rtbake-lanes --example lane_paths -- PHOTONS
//! ETA_ABOVE ETA_BELOW LAYER...` with each LAYER `thickness_mm,eta,mu_a_per_mm,mu_s_per_mm,g` (thickness `inf` for
//! a semi-infinite last layer). Traces PHOTONS photons in chunks of 4096 (as `rtbake::transport::mc` does) on
//! [`Path::detect`] and prints the path, Rd, T and a checksum of the bits of every tally (equal on every path).

use rtbake_lanes::{trace_chunk, Channel, Medium, Path, Tally};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: lane_paths PHOTONS ETA_ABOVE ETA_BELOW thickness_mm,eta,mu_a,mu_s,g ...";
    assert!(a.len() >= 4, "{usage}");
    let num = |s: &str| -> f64 {
        if s == "inf" {
            f64::INFINITY
        } else {
            s.parse().unwrap_or_else(|_| panic!("not a number: {s} ({usage})"))
        }
    };
    let photons = num(&a[0]) as u64;
    let (eta_above, eta_below) = (num(&a[1]), num(&a[2]));
    let mut z = 0.0;
    let media: Vec<Medium> = a[3..]
        .iter()
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(num).collect();
            assert_eq!(v.len(), 5, "{usage}");
            let (d, eta, mu_a, mu_s, g) = (v[0], v[1], v[2], v[3], v[4]);
            let sigma_t = mu_a + mu_s;
            let m = Medium {
                z_top_mm: z,
                z_bottom_mm: z + d,
                sigma_t_per_mm: sigma_t,
                inv_sigma_t_mm: 1.0 / sigma_t,
                absorb_fraction: mu_a / sigma_t,
                isotropic: g.abs() < 1e-6,
                hg: [1.0 - g * g, 1.0 - g, 2.0 * g, 1.0 + g * g, 0.5 / g],
                eta,
            };
            z += d;
            m
        })
        .collect();
    let eta1 = media[0].eta;
    let rsp = ((eta_above - eta1) / (eta_above + eta1)).powi(2);
    let ch = Channel { media: &media, eta_above, eta_below, start_weight: 1.0 - rsp, index: 0, seed: 1 };
    let path = Path::detect();
    let mut tally = Tally::new(100, media.len());
    let mut first = 0;
    while first < photons {
        let n = 4096.min(photons - first);
        let mut chunk = Tally::new(100, media.len());
        trace_chunk(path, &ch, 0.1, first, n, &mut chunk);
        tally.add(&chunk);
        first += n;
    }
    // FNV-1a over the bits of every tally.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let words =
        tally.r.iter().chain(&tally.t).chain(&tally.absorbed).chain([&tally.rd, &tally.td]).map(|v| v.to_bits());
    for w in words.chain([tally.interactions]) {
        h = (h ^ w).wrapping_mul(0x0000_0100_0000_01b3);
    }
    println!(
        "path {path:?} photons {photons} Rd {:.5} T {:.5} interactions/photon {:.1} checksum {h:016x}",
        tally.rd / photons as f64,
        tally.td / photons as f64,
        tally.interactions as f64 / photons as f64
    );
}
