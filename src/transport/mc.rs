//! MCML-style photon transport (L. Wang, S. L. Jacques, L. Zheng, "MCML — Monte Carlo modeling of light transport in
//! multi-layered tissues", Comput. Methods Programs Biomed. 47:131–146, 1995; section numbers below are theirs).
//!
//! Per channel, each photon packet starts at the origin heading straight down with weight 1 − Rsp, where
//! Rsp = ((n₀ − n₁)/(n₀ + n₁))² is the specular reflection of the top surface (§3.1; MCML's special case of a
//! clear first layer is not made: a clear layer is simply traced). Then, repeatedly (§3.2–3.8):
//!
//! * **Step**: a dimensionless optical depth s = −ln ξ, exponential of mean 1 (a branch-free logarithm,
//!   [`super::lanes`]), is drawn; in a layer of σt = σa + σs the packet moves s/σt
//!   unless it reaches the layer's face first, in which case it stops there and keeps the rest of s for the next
//!   layer (§3.3.2, with σt = 0 in a clear layer).
//! * **Face**: unpolarised Fresnel reflectance R(θi) = ½(rs² + rp²) between the layer's index and the neighbour's
//!   (the next layer or the ambient medium; total internal reflection past the critical angle); the packet is
//!   reflected if ξ ≤ R, else refracted by Snell's law (§3.5, all-or-none). Leaving through the top face scores
//!   its weight in R(r), through the bottom face in T(r), at r = √(x² + y²).
//! * **Interaction**: implicit capture — the weight w·σa/σt is scored as absorbed in the layer and w keeps the rest
//!   (§3.4); the direction is scattered by the Henyey–Greenstein phase function
//!   cos θ = (1 + g² − ((1 − g²)/(1 − g + 2gξ))²)/(2g) (cos θ = 2ξ − 1 for g = 0), φ uniform on `[0, 2π)`
//!   (§3.5, eq. 3.28–3.30; cos φ and sin φ by polynomials of the angle within a quadrant, [`super::lanes`]).
//! * **Russian roulette** below w = [`ROULETTE_THRESHOLD`]: the packet survives with chance 1/[`ROULETTE_CHANCE`]
//!   with weight w·`ROULETTE_CHANCE`, else ends (§3.6; energy is conserved in expectation).
//!
//! Tallies (§4): R(r) and T(r) in annuli of width Δr, divided by the photon count N and the annulus area
//! π(2i + 1)Δr² (mm⁻², the value at the bin centre (i + ½)Δr is the annulus mean); total diffuse R and T (all exits,
//! including those beyond the last bin); absorbed fraction per layer. Rsp + Rd + T + ΣA = 1 up to roulette noise.
//! Standard errors come from [`McSettings::batches`] independent batches of equal size:
//! SE = √(Σ_b (x_b − x̄)²/(B(B − 1))).
//!
//! Each event draws one Philox block (four 32-bit words) of its photon, block e at the photon's event e, and uses
//! them in fixed roles: word 0 the step (when none is pending), word 1 the HG ξ at an interaction or the Fresnel ξ
//! at a face, word 2 the azimuth, word 3 the roulette ξ; the words an event does not need are skipped. (Before the
//! lane engine, an event drew only what it used, in order: the step by the ziggurat method, [`super::ziggurat`],
//! the Fresnel or HG ξ, the azimuth from a point uniform in the unit disk,
//! [`super::rng::PhotonRng::azimuth_cos_sin`], the roulette ξ. That scalar engine is kept as the reference the lane
//! engine is tested against; the histories of the two differ, their results agree within the standard errors.)
//!
//! **Engine**: photons are traced [`super::lanes::LANES`] at a time by [`super::lanes`], every step computing both
//! the interaction and the face for all lanes in packed arithmetic and keeping one per lane (AVX-512F, AVX2 or
//! portable code, chosen at run time; all give the same bytes).
//!
//! **Determinism**: photon k of channel c draws from Philox keyed with the seed at counter (k, c, event)
//! ([`super::rng`]); photons are traced in chunks of [`CHUNK_PHOTONS`] (within a chunk a lane whose packet ends
//! takes the next photon index, so which lane traces which photon depends only on the histories), chunks in
//! parallel waves of [`WAVE_CHUNKS`], and each batch sums its chunks' tallies in chunk order. The result is the same
//! bytes for any rayon thread count and any instruction-set path, and memory is bounded by (WAVE_CHUNKS + batches)
//! tallies, not by N.
//!
//! [`assemble`] turns raw per-batch [`Tally`]s into the result; the GPU path (`runtime::transport_gpu`, f32,
//! the same Philox streams but consumed MCML's way: −ln ξ, φ = 2πξ, 24-bit uniforms, so its histories are not the
//! CPU's and the two agree statistically) reads its tallies back and calls it too, so both report means and standard errors the
//! same way.

use super::lanes::{self, Path};
use super::stack::McStack;
use crate::error::InvalidInput;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Weight below which Russian roulette is played (MCML's default, §3.6).
pub const ROULETTE_THRESHOLD: f64 = rtbake_lanes::ROULETTE_THRESHOLD;
/// A packet survives roulette with chance 1/m and weight ×m, m = 10 (MCML §3.6).
pub const ROULETTE_CHANCE: f64 = rtbake_lanes::ROULETTE_CHANCE;
/// Most photons per channel accepted (refused before any work).
pub const MAX_PHOTONS: u64 = 10_000_000_000;
/// Most radial bins accepted.
pub const MAX_BINS: usize = 100_000;
/// Finest radial bin accepted, mm (1 nm; bins finer than this are below what the f64 positions resolve across
/// a stack that is millimetres wide).
pub const MIN_BIN_MM: f64 = 1e-6;
/// Largest tallied radius (bins × Δr), mm.
pub const MAX_RADIUS_MM: f64 = 1e4;
/// Photons per chunk (the unit of parallel work; fixed so the result does not depend on scheduling; large enough
/// that the lanes seldom idle at a chunk's end).
pub const CHUNK_PHOTONS: u64 = 4096;
/// Chunks traced in parallel before their tallies are summed in order.
pub const WAVE_CHUNKS: usize = 64;

/// Run settings, validated by [`McSettings::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct McSettings {
    /// Photons per channel (rounded up to a multiple of `batches`; [`McResult::photons`] is the count traced).
    pub photons: u64,
    pub seed: u64,
    /// Independent batches for the standard errors, 2..=1000.
    pub batches: u32,
    /// Radial bin width Δr, mm.
    pub bin_mm: f64,
    /// Number of radial bins (R and T each).
    pub bins: usize,
}

impl McSettings {
    /// Checks `photons` in 1..=[`MAX_PHOTONS`] (`photons`), `batches` in 2..=1000 (`batches`), `bin_mm` in
    /// [`MIN_BIN_MM`]..=[`MAX_RADIUS_MM`] (`bin_mm`), `bins` in 1..=[`MAX_BINS`] with bins × Δr ≤ [`MAX_RADIUS_MM`]
    /// (`bins`) — before anything is allocated.
    pub fn new(photons: u64, seed: u64, batches: u32, bin_mm: f64, bins: usize) -> Result<Self, InvalidInput> {
        if photons == 0 || photons > MAX_PHOTONS {
            return Err(InvalidInput::new(
                "photons",
                format!("must be in 1..={MAX_PHOTONS} per channel, got {photons}"),
            ));
        }
        crate::error::check_range("batches", batches, 2, 1000, "")?;
        if !(bin_mm.is_finite() && (MIN_BIN_MM..=MAX_RADIUS_MM).contains(&bin_mm)) {
            return Err(InvalidInput::new(
                "bin_mm",
                format!(
                    "must be in {MIN_BIN_MM:e}..={MAX_RADIUS_MM} mm (finer bins are not representable), got {bin_mm}"
                ),
            ));
        }
        if bins == 0 || bins > MAX_BINS || bins as f64 * bin_mm > MAX_RADIUS_MM * (1.0 + 1e-12) {
            return Err(InvalidInput::new(
                "bins",
                format!("must be in 1..={MAX_BINS} with bins x bin_mm <= {MAX_RADIUS_MM} mm, got {bins} x {bin_mm} mm"),
            ));
        }
        Ok(Self { photons, seed, batches, bin_mm, bins })
    }

    /// Photons per batch (⌈N/B⌉).
    pub fn photons_per_batch(&self) -> u64 {
        self.photons.div_ceil(u64::from(self.batches))
    }

    /// Peak memory of [`simulate`] beyond the stack, bytes: ([`WAVE_CHUNKS`] + 3·batches + 1) tallies of 2·bins
    /// f64 plus the result's 4·3·bins estimates.
    pub fn memory_estimate_bytes(&self, layers: usize) -> u64 {
        let tally = (2 * self.bins as u64 + layers as u64 + 4) * 8;
        (WAVE_CHUNKS as u64 + 3 * u64::from(self.batches) + 1) * tally + 12 * 16 * self.bins as u64
    }

    /// Wall time of [`simulate`] (the budget check before any work): three channels of `photons` at
    /// 600 000 photon histories/s per thread (150 000 where the lane engine runs its portable path, no AVX2), below
    /// the slowest case measured with the release build on the project's 2-core machine (semi-infinite, albedo 0.9,
    /// mismatched boundary, `examples/bench_transport`, 2026-11-25, one thread: 2.72 M histories per CPU second on
    /// the AVX-512F path, 1.59 M on the AVX2 path, 0.26 M on the portable path); thin or absorbing stacks run up to
    /// ten times faster, so this is an upper estimate. (The rate is not raised with the lane engine: the same figure
    /// bounds a software GPU adapter, `runtime::chain::transport_estimate`.)
    pub fn time_estimate_seconds(&self, threads: usize) -> f64 {
        let per_thread = if Path::detect() == Path::Portable { 150_000.0 } else { 600_000.0 };
        BUILD_SLOWDOWN * 3.0 * self.photons as f64 / (per_thread * threads.max(1) as f64)
    }

    /// Wall time of [`simulate`] in `stack`, an upper estimate from the stack's optics (before any work): three
    /// channels × `photons` × [`interactions_per_photon_estimate`] interactions at [`INTERACTIONS_PER_SECOND`] per
    /// thread ([`PORTABLE_INTERACTIONS_PER_SECOND`] on the portable path), never below
    /// [`Self::time_estimate_seconds`]. Unlike the per-photon figure, it grows with the albedo and with g (a
    /// high-albedo slab or g → 1 with σs′ kept makes every photon scatter many more times).
    pub fn time_estimate_for_stack(&self, stack: &McStack, threads: usize) -> f64 {
        let rate =
            if Path::detect() == Path::Portable { PORTABLE_INTERACTIONS_PER_SECOND } else { INTERACTIONS_PER_SECOND };
        let per_photon = interactions_per_photon_estimate(stack);
        let t = BUILD_SLOWDOWN * 3.0 * self.photons as f64 * per_photon / (rate * threads.max(1) as f64);
        t.max(self.time_estimate_seconds(threads))
    }

    /// Bin centres (i + ½)Δr, mm.
    pub fn radii_mm(&self) -> Vec<f64> {
        (0..self.bins).map(|i| (i as f64 + 0.5) * self.bin_mm).collect()
    }
}

/// How much slower the engine runs in the dev build (the README's `cargo run`) than in the release build the rates
/// below were measured with: 1. The lane kernel is the `rtbake-lanes` workspace crate, which the dev profile builds
/// at opt-level 3 (`[profile.dev.package.rtbake-lanes]`); a high-albedo slab (`transport --material marble
/// --photons 100000`) took 1.46 CPU-s with the dev build, as with the release build, on the project's 2-core
/// machine (2026-11-26; 24.6 CPU-s, 17×, when the kernel was built at the dev profile's opt-level 1).
pub const BUILD_SLOWDOWN: f64 = 1.0;

/// Interactions per thread and second assumed by [`McSettings::time_estimate_for_stack`] (AVX2 / AVX-512F paths):
/// a third of the rate measured on the project's 2-core machine with the release build (`examples/bench_transport`
/// case (b), 2026-11-25: 1.59 M histories per CPU second on the AVX2 path × 46.5 interactions per history, the
/// count `interaction_estimate_bounds_the_traced_counts` traces = 74 M interactions/s).
pub const INTERACTIONS_PER_SECOND: f64 = 25.0e6;
/// The same on the portable lane path (no AVX2): half of 0.26 M histories/s × 46.5 = 12 M interactions/s.
pub const PORTABLE_INTERACTIONS_PER_SECOND: f64 = 6.0e6;
/// The constant K of [`interactions_per_photon_estimate`] (the survival law's prefactor with margin, calibrated
/// against the interaction counts of the stacks in its test).
pub const SURVIVAL_FACTOR: f64 = 8.0;

/// Interactions per photon history, an upper estimate from the optics (the worst channel):
///
/// * implicit capture multiplies the weight by the single-scattering albedo a = σs/σt at every interaction, so a
///   packet reaches the roulette threshold after n_w = ln(1/[`ROULETTE_THRESHOLD`])/ln(1/a) interactions, and
///   roulette adds (ln m/(m − 1))/ln(1/a) on average (m = [`ROULETTE_CHANCE`]);
/// * a photon entering a half-space through its surface is still inside after n interactions with a chance that
///   falls like √(n_t/n) (the first-passage law of a random walk, n_t = 1/(1 − g) interactions per transport mean
///   free path), so the expected count up to n_w is about n_t + K·√(n_t n_w), K = [`SURVIVAL_FACTOR`];
/// * in a stack of finite reduced optical depth τ′ = Σ σs′ d every photon has left after about n_t(τ′ + 2)²
///   interactions (the diffusive escape time).
///
/// The estimate is the smaller of the bounds, taking for each the worst layer.
pub fn interactions_per_photon_estimate(stack: &McStack) -> f64 {
    let layers = stack.layers();
    let finite = layers.iter().all(|l| l.thickness_mm.is_finite());
    let m = ROULETTE_CHANCE;
    (0..3)
        .map(|c| {
            let (mut n_w, mut n_t, mut tau) = (0.0f64, 1.0f64, 0.0);
            for l in layers {
                let (sa, ss, g) = (l.sigma_a_per_mm[c], l.sigma_s_per_mm[c], l.g[c]);
                if sa + ss <= 0.0 {
                    continue;
                }
                let a = ss / (sa + ss);
                let w = if a < 1.0 {
                    ((1.0 / ROULETTE_THRESHOLD).ln() + m.ln() / (m - 1.0)) / -a.ln() + 1.0
                } else {
                    f64::INFINITY
                };
                n_w = n_w.max(w);
                n_t = n_t.max(1.0 / (1.0 - g.max(0.0)));
                if finite {
                    tau += ss * (1.0 - g) * l.thickness_mm;
                }
            }
            let walk = n_t + SURVIVAL_FACTOR * (n_t * n_w).sqrt();
            let escape = if finite { n_t * (tau + 2.0).powi(2) } else { f64::INFINITY };
            n_w.min(walk).min(escape).max(1.0)
        })
        .fold(1.0, f64::max)
}

/// A Monte Carlo estimate and its standard error.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Estimate {
    pub mean: f64,
    pub se: f64,
}

/// One channel's tallies.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelResult {
    /// R(r) per bin, mm⁻², and its standard error.
    pub reflectance_mm2: Vec<Estimate>,
    /// T(r) per bin, mm⁻² (all zero for a semi-infinite stack).
    pub transmittance_mm2: Vec<Estimate>,
    /// Total diffuse reflectance (every exit through the top, also beyond the last bin).
    pub diffuse_reflectance: Estimate,
    /// Total transmittance (unscattered included).
    pub transmittance: Estimate,
    /// Specular reflectance Rsp (exact).
    pub specular_reflectance: f64,
    /// Absorbed fraction per layer.
    pub absorbed: Vec<Estimate>,
    /// Interactions (absorption + scattering events) traced, for photons-per-second figures.
    pub interactions: u64,
}

/// Tallies of all three channels.
#[derive(Clone, Debug, PartialEq)]
pub struct McResult {
    pub settings: McSettings,
    /// Photons traced per channel (batches × photons per batch).
    pub photons: u64,
    pub channels: [ChannelResult; 3],
}

/// Raw weight sums of a chunk or batch of one channel (photon weights, not yet divided by the photon count or the
/// annulus area). The CPU path fills them per chunk; the GPU path (`runtime::transport_gpu`) reads them back per
/// batch; both hand them to [`assemble`]. (Defined by the lane kernel's crate, which fills it.)
pub use rtbake_lanes::Tally;

/// Per-layer constants of one channel, with what the photon loop would otherwise divide by precomputed.
#[derive(Clone, Copy, Debug)]
pub(super) struct Medium {
    pub(super) z_top_mm: f64,
    pub(super) z_bottom_mm: f64,
    pub(super) sigma_t: f64,
    /// 1/σt (unused in a clear layer).
    pub(super) inv_sigma_t: f64,
    /// σa/σt (0 in a clear layer).
    pub(super) absorb_fraction: f64,
    pub(super) hg: HenyeyGreenstein,
    pub(super) eta: f64,
}

/// Henyey–Greenstein sampling constants of one g (MCML eq. 3.28):
/// cos θ = (1 + g² − ((1 − g²)/(1 − g + 2gξ))²)/(2g), cos θ = 2ξ − 1 for |g| < 10⁻⁶.
#[derive(Clone, Copy, Debug)]
pub(super) struct HenyeyGreenstein {
    pub(super) isotropic: bool,
    /// 1 − g², 1 − g, 2g, 1 + g², 1/(2g).
    pub(super) one_minus_g2: f64,
    pub(super) one_minus_g: f64,
    pub(super) two_g: f64,
    pub(super) one_plus_g2: f64,
    pub(super) inv_two_g: f64,
}

impl HenyeyGreenstein {
    fn new(g: f64) -> Self {
        Self {
            isotropic: g.abs() < 1e-6,
            one_minus_g2: 1.0 - g * g,
            one_minus_g: 1.0 - g,
            two_g: 2.0 * g,
            one_plus_g2: 1.0 + g * g,
            inv_two_g: 0.5 / g,
        }
    }
}

/// What every photon of one channel shares.
pub(super) struct Channel<'a> {
    pub(super) media: &'a [Medium],
    pub(super) eta_above: f64,
    pub(super) eta_below: f64,
    /// 1 − Rsp.
    pub(super) start_weight: f64,
    pub(super) index: u32,
    pub(super) seed: u64,
}

/// Which photon loop traces the chunks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Engine {
    /// [`super::lanes`] on the given instruction-set path (every path gives the same bytes).
    Lanes(Path),
    /// The scalar reference (tests only).
    #[cfg(test)]
    Scalar,
}

fn estimate(batch_values: impl Iterator<Item = f64> + Clone, total: f64, batches: usize) -> Estimate {
    let b = batches as f64;
    let mean = batch_values.clone().sum::<f64>() / b;
    let var: f64 = batch_values.map(|v| (v - mean) * (v - mean)).sum::<f64>() / (b * (b - 1.0));
    Estimate { mean: total, se: var.sqrt() }
}

/// Runs the transport in every channel. Deterministic for a given (stack, settings), whatever the thread count.
pub fn simulate(stack: &McStack, settings: &McSettings) -> McResult {
    simulate_with_progress(stack, settings, &|_| {})
}

/// [`simulate`], calling `progress(fraction done)` after every wave of chunks (from the calling thread).
pub fn simulate_with_progress(stack: &McStack, settings: &McSettings, progress: &dyn Fn(f64)) -> McResult {
    simulate_engine(stack, settings, Engine::Lanes(Path::detect()), progress)
}

fn simulate_engine(stack: &McStack, settings: &McSettings, engine: Engine, progress: &dyn Fn(f64)) -> McResult {
    let layers = stack.layers();
    let n_layers = layers.len();
    let batches = settings.batches as usize;
    let per_batch = settings.photons_per_batch();
    let chunks_per_batch = per_batch.div_ceil(CHUNK_PHOTONS);
    let rsp = specular_reflectance(stack);

    // Media per channel.
    let media: Vec<Vec<Medium>> = (0..3)
        .map(|c| {
            let mut z = 0.0;
            layers
                .iter()
                .map(|l| {
                    let sigma_t = l.sigma_a_per_mm[c] + l.sigma_s_per_mm[c];
                    let m = Medium {
                        z_top_mm: z,
                        z_bottom_mm: z + l.thickness_mm,
                        sigma_t,
                        inv_sigma_t: if sigma_t > 0.0 { 1.0 / sigma_t } else { 0.0 },
                        absorb_fraction: if sigma_t > 0.0 { l.sigma_a_per_mm[c] / sigma_t } else { 0.0 },
                        hg: HenyeyGreenstein::new(l.g[c]),
                        eta: l.eta,
                    };
                    z += l.thickness_mm;
                    m
                })
                .collect()
        })
        .collect();

    // Work list: (channel, batch, chunk) in a fixed order; every batch tally sums its chunks in chunk order.
    let total_chunks = 3 * batches as u64 * chunks_per_batch;
    let mut batch_tallies: Vec<Tally> = (0..3 * batches).map(|_| Tally::new(settings.bins, n_layers)).collect();
    let mut next = 0u64;
    while next < total_chunks {
        let end = (next + WAVE_CHUNKS as u64).min(total_chunks);
        let wave: Vec<(usize, Tally)> = (next..end)
            .into_par_iter()
            .map(|g| {
                let channel = g / (batches as u64 * chunks_per_batch);
                let rest = g % (batches as u64 * chunks_per_batch);
                let (batch, chunk) = (rest / chunks_per_batch, rest % chunks_per_batch);
                let first_in_batch = chunk * CHUNK_PHOTONS;
                let count = CHUNK_PHOTONS.min(per_batch - first_in_batch);
                let first = batch * per_batch + first_in_batch;
                let mut t = Tally::new(settings.bins, n_layers);
                let ch = Channel {
                    media: &media[channel as usize],
                    eta_above: stack.eta_above(),
                    eta_below: stack.eta_below(),
                    start_weight: 1.0 - rsp,
                    index: channel as u32,
                    seed: settings.seed,
                };
                match engine {
                    Engine::Lanes(path) => lanes::trace_chunk(path, &ch, settings.bin_mm, first, count, &mut t),
                    #[cfg(test)]
                    Engine::Scalar => {
                        super::reference_engine::trace_chunk_scalar(&ch, settings.bin_mm, first, count, &mut t)
                    }
                }
                ((channel as usize) * batches + batch as usize, t)
            })
            .collect();
        for (slot, t) in &wave {
            batch_tallies[*slot].add(t);
        }
        next = end;
        progress(next as f64 / total_chunks as f64);
    }

    assemble(stack, settings, &batch_tallies)
}

/// Rsp = ((n₀ − n₁)/(n₀ + n₁))², the specular reflection of the top surface under normal incidence (MCML §3.1).
pub fn specular_reflectance(stack: &McStack) -> f64 {
    let n1 = stack.layers()[0].eta;
    ((stack.eta_above() - n1) / (stack.eta_above() + n1)).powi(2)
}

/// The result from the raw tallies of every (channel, batch), channel-major (`batch_tallies[c * batches + b]`):
/// means over all photons, standard errors over the batches (module docs), R(r)/T(r) per annulus area. Shared by
/// the CPU path and the GPU path so both report the same quantities the same way.
///
/// # Panics
/// When `batch_tallies` does not hold 3 × batches tallies of `settings.bins` bins and the stack's layer count.
pub fn assemble(stack: &McStack, settings: &McSettings, batch_tallies: &[Tally]) -> McResult {
    let n_layers = stack.layers().len();
    let batches = settings.batches as usize;
    assert_eq!(batch_tallies.len(), 3 * batches, "one tally per channel and batch");
    assert!(batch_tallies.iter().all(|t| t.r.len() == settings.bins && t.absorbed.len() == n_layers));
    let per_batch = settings.photons_per_batch();
    let photons = per_batch * u64::from(settings.batches);
    let rsp = specular_reflectance(stack);
    let area = |i: usize| PI * (2 * i + 1) as f64 * settings.bin_mm * settings.bin_mm;
    let channels = [0, 1, 2].map(|c| {
        let bt = &batch_tallies[c * batches..(c + 1) * batches];
        let mut sum = Tally::new(settings.bins, n_layers);
        for t in bt {
            sum.add(t);
        }
        let (n, nb) = (photons as f64, per_batch as f64);
        let est = |f: &dyn Fn(&Tally) -> f64, scale: f64| {
            estimate(bt.iter().map(|t| f(t) / (nb * scale)), f(&sum) / (n * scale), batches)
        };
        ChannelResult {
            reflectance_mm2: (0..settings.bins).map(|i| est(&|t: &Tally| t.r[i], area(i))).collect(),
            transmittance_mm2: (0..settings.bins).map(|i| est(&|t: &Tally| t.t[i], area(i))).collect(),
            diffuse_reflectance: est(&|t: &Tally| t.rd, 1.0),
            transmittance: est(&|t: &Tally| t.td, 1.0),
            specular_reflectance: rsp,
            absorbed: (0..n_layers).map(|j| est(&|t: &Tally| t.absorbed[j], 1.0)).collect(),
            interactions: sum.interactions,
        }
    });
    McResult { settings: *settings, photons, channels }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transport::stack::McLayer;

    /// A mismatched three-layer stack: a clear layer (gliding, refraction only), an anisotropic layer and an
    /// isotropic semi-infinite one, so that every branch of the lane engine (faces, total internal reflection,
    /// layer changes, roulette) is taken.
    fn stack() -> McStack {
        let layer = |t: f64, eta: f64, sa: f64, ss: f64, g: f64| McLayer {
            thickness_mm: t,
            eta,
            sigma_a_per_mm: [sa, 2.0 * sa, 4.0 * sa],
            sigma_s_per_mm: [ss; 3],
            g: [g; 3],
        };
        McStack::new(
            1.0,
            1.2,
            vec![
                layer(0.05, 1.5, 0.0, 0.0, 0.0),
                layer(0.2, 1.4, 0.3, 15.0, 0.8),
                layer(f64::INFINITY, 1.33, 0.1, 5.0, 0.0),
            ],
        )
        .unwrap()
    }

    /// The interaction estimate of the time budget bounds the counts traced (skin-like stacks at g = 0 and 0.8,
    /// a thin high-albedo slab, a semi-infinite high-albedo medium) without being absurdly pessimistic (≤ 10×; traced 107, 577, 47, 226, 46 against estimates 203, 1011, 144,
    /// 350, 77), and
    /// it grows without bound for the stacks that used to run forever (albedo → 1 in a thick slab, g → 1 with σs′
    /// kept), so `--max-seconds` refuses them before any work.
    #[test]
    fn interaction_estimate_bounds_the_traced_counts() {
        use crate::diffusion::layered::{Layer, LayerStack};
        let skin = LayerStack::new(
            1.0,
            1.4,
            vec![
                Layer { thickness_mm: 0.25, eta: 1.4, sigma_a: [0.5, 1.0, 2.0], sigma_s_prime: [4.0, 5.0, 6.0] },
                Layer { thickness_mm: 20.0, eta: 1.4, sigma_a: [0.03, 0.2, 0.4], sigma_s_prime: [2.0, 2.5, 3.0] },
            ],
        )
        .unwrap();
        let cases = [
            McStack::from_layer_stack(&skin, 0.0).unwrap(),
            McStack::from_layer_stack(&skin, 0.8).unwrap(),
            McStack::slab(1.0, [0.001; 3], [10.0; 3], 0.0, 1.4).unwrap(),
            McStack::semi_infinite([0.005; 3], [1.0; 3], 0.0, 1.3).unwrap(),
            // `examples/bench_transport` case (b): semi-infinite, albedo 0.9, n 1.5.
            McStack::semi_infinite([1.0; 3], [9.0; 3], 0.0, 1.5).unwrap(),
        ];
        let settings = McSettings::new(600, 2, 2, 0.1, 10).unwrap();
        for (i, stack) in cases.iter().enumerate() {
            let r = simulate(stack, &settings);
            let traced = r.channels.iter().map(|c| c.interactions as f64 / r.photons as f64).fold(0.0, f64::max);
            let est = interactions_per_photon_estimate(stack);
            assert!(est >= traced && est <= 10.0 * traced, "case {i}: estimate {est} vs traced {traced}");
        }
        let thick_white = McStack::slab(100.0, [1e-6; 3], [10.0; 3], 0.0, 1.4).unwrap();
        let forward = McStack::slab(1.0, [0.01; 3], [1.0; 3], 0.99999, 1.4).unwrap();
        for stack in [thick_white, forward] {
            let s = McSettings::new(1_000_000, 1, 10, 0.1, 10).unwrap();
            assert!(s.time_estimate_for_stack(&stack, 2) > 600.0, "{:?}", interactions_per_photon_estimate(&stack));
        }
    }

    /// Spectral Monte Carlo of a physiological skin (the per-wavelength stacks of `spectral::skin_layers`,
    /// projected to linear sRGB) from the lane engine against the scalar reference engine (its own draws: ziggurat
    /// steps, disk azimuths), at g = 0 and g = 0.8: the projected totals agree within max(3 %, 4 combined standard
    /// errors) in every channel. A subset of wavelength groups (405–765 nm) keeps it cheap.
    #[test]
    fn spectral_skin_agrees_with_the_scalar_reference() {
        use crate::spectral::skin_layers::{spectral_skin_stacks, SkinPhysiology};
        let stacks = spectral_skin_stacks(&SkinPhysiology::default(), 0.1, 0.1, Default::default(), 10).unwrap();
        let settings = McSettings::new(1500, 11, 10, 0.1, 5).unwrap();
        for g in [0.0, 0.8] {
            let (mut lanes, mut scalar) = ([0.0; 3], [0.0; 3]);
            let (mut var_l, mut var_s) = ([0.0; 3], [0.0; 3]);
            for j in [1, 5, 9, 12] {
                let stack = McStack::from_layer_stack(&stacks.stacks[j], g).unwrap();
                let l = simulate_engine(&stack, &settings, Engine::Lanes(Path::detect()), &|_| {});
                let s = simulate_engine(&stack, &settings, Engine::Scalar, &|_| {});
                for (k, wk) in stacks.weights[j].iter().enumerate() {
                    let (el, es) = (l.channels[k].diffuse_reflectance, s.channels[k].diffuse_reflectance);
                    for c in 0..3 {
                        lanes[c] += wk[c] * el.mean;
                        scalar[c] += wk[c] * es.mean;
                        var_l[c] += (wk[c] * el.se).powi(2);
                        var_s[c] += (wk[c] * es.se).powi(2);
                    }
                }
            }
            for c in 0..3 {
                let se = (var_l[c] + var_s[c]).sqrt();
                let tol = (0.03 * scalar[c].abs()).max(4.0 * se);
                assert!((lanes[c] - scalar[c]).abs() <= tol, "g {g} channel {c}: {lanes:?} vs {scalar:?} (se {se})");
            }
        }
    }

    /// The AVX-512F, AVX2 and portable lane loops give the same bytes (those this CPU supports), on 1 and 2
    /// threads.
    #[test]
    fn every_dispatch_path_gives_the_same_bytes() {
        let (stack, settings) = (stack(), McSettings::new(3000, 5, 4, 0.05, 30).unwrap());
        let run = |path: Path, threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| simulate_engine(&stack, &settings, Engine::Lanes(path), &|_| {}))
        };
        let portable = run(Path::Portable, 1);
        assert!(portable.channels[0].diffuse_reflectance.mean > 0.0);
        assert_eq!(run(Path::Portable, 2), portable);
        for path in [Path::Avx512, Path::Avx2] {
            if path.supported() {
                assert_eq!(run(path, 2), portable, "{path:?}");
            }
        }
        assert_eq!(simulate(&stack, &settings), portable, "the detected path");
    }

    /// The lane engine (its own draw order) against the scalar reference engine: total R, absorbed per layer and
    /// R(r) of the first bins agree within 4 combined standard errors in every channel.
    #[test]
    fn the_lane_engine_agrees_with_the_scalar_reference() {
        let (stack, settings) = (stack(), McSettings::new(20_000, 9, 10, 0.1, 10).unwrap());
        let lanes = simulate_engine(&stack, &settings, Engine::Lanes(Path::detect()), &|_| {});
        let scalar = simulate_engine(&stack, &settings, Engine::Scalar, &|_| {});
        let agree = |what: &str, a: Estimate, b: Estimate| {
            let se = (a.se * a.se + b.se * b.se).sqrt();
            assert!(se > 0.0 && (a.mean - b.mean).abs() <= 4.0 * se, "{what}: lanes {a:?}, scalar {b:?}");
        };
        for (c, (l, s)) in lanes.channels.iter().zip(&scalar.channels).enumerate() {
            agree(&format!("channel {c} Rd"), l.diffuse_reflectance, s.diffuse_reflectance);
            for j in 1..3 {
                agree(&format!("channel {c} A{j}"), l.absorbed[j], s.absorbed[j]);
            }
            assert_eq!((l.absorbed[0].mean, s.absorbed[0].mean), (0.0, 0.0), "the clear layer absorbs nothing");
            for i in 0..4 {
                agree(&format!("channel {c} R bin {i}"), l.reflectance_mm2[i], s.reflectance_mm2[i]);
            }
            // Everything that enters is reflected or absorbed (semi-infinite): energy closes in both.
            for r in [l, s] {
                let total = r.specular_reflectance
                    + r.diffuse_reflectance.mean
                    + r.absorbed.iter().map(|a| a.mean).sum::<f64>();
                let se = r.diffuse_reflectance.se + r.absorbed.iter().map(|a| a.se).sum::<f64>();
                assert!((total - 1.0).abs() <= 4.0 * se + 1e-12, "channel {c}: {total} ± {se}");
            }
        }
    }
}
