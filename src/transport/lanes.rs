//! The photon-lane engine [`super::mc`] runs: the `rtbake-lanes` workspace crate (32 packets per step in packed
//! arithmetic, in groups of the path's register width; AVX-512F / AVX2 / portable paths chosen at run time, the
//! same bytes on each; its crate docs give the draws, the determinism argument and why it is a crate of its own:
//! it is built with opt-level 3 in the dev profile too). This module hands it a channel's media and takes its
//! tallies.

use super::mc::{Channel, Tally};
pub use rtbake_lanes::{Path, LANES};

/// Traces photons `first..first + count` of channel `ch` into `tally` on `path`.
///
/// # Panics
/// When `path` is not [`Path::supported`] on this CPU.
pub(super) fn trace_chunk(path: Path, ch: &Channel<'_>, bin_mm: f64, first: u64, count: u64, tally: &mut Tally) {
    let media: Vec<rtbake_lanes::Medium> = ch
        .media
        .iter()
        .map(|m| rtbake_lanes::Medium {
            z_top_mm: m.z_top_mm,
            z_bottom_mm: m.z_bottom_mm,
            sigma_t_per_mm: m.sigma_t,
            inv_sigma_t_mm: m.inv_sigma_t,
            absorb_fraction: m.absorb_fraction,
            isotropic: m.hg.isotropic,
            hg: [m.hg.one_minus_g2, m.hg.one_minus_g, m.hg.two_g, m.hg.one_plus_g2, m.hg.inv_two_g],
            eta: m.eta,
        })
        .collect();
    let channel = rtbake_lanes::Channel {
        media: &media,
        eta_above: ch.eta_above,
        eta_below: ch.eta_below,
        start_weight: ch.start_weight,
        index: ch.index,
        seed: ch.seed,
    };
    rtbake_lanes::trace_chunk(path, &channel, bin_mm, first, count, tally);
}
