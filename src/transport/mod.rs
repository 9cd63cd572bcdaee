//! Monte Carlo photon transport in plane-parallel layer stacks — the ground truth the diffusion profiles of
//! [`crate::diffusion`] approximate (MCML: L. Wang, S. L. Jacques, L. Zheng, Comput. Methods Programs Biomed. 47,
//! 1995). Pure computation: no files, no GPU.
//!
//! - [`stack`]: [`stack::McStack`], layers with σa, σs, HG g and η per channel (JSON, validated).
//! - [`mc`]: the transport and its tallies (R(r), T(r) in mm⁻², totals, absorbed per layer, standard errors from
//!   independent batches), deterministic for any thread count.
//! - [`lanes`]: the photon-lane engine [`mc`] runs: 32 packets per step in packed arithmetic, AVX-512F / AVX2 /
//!   portable paths chosen at run time, the same bytes on each.
//! - [`rng`]: Philox4x32-10, counter-based random numbers keyed by (seed, photon index).
//! - `reference_engine` (tests only): the scalar MCML loop the lane engine is tested against.
//! - [`ziggurat`]: exponential step lengths by the ziggurat method (Marsaglia & Tsang 2000), used by the scalar
//!   reference engine the lane engine is tested against.
//! - [`compare`]: Monte Carlo against a diffusion [`RadialProfile`](crate::diffusion::RadialProfile) (total R,
//!   r·R(r) error) and [`compare::diffusion_counterpart`], the diffusion model of a stack.
//! - [`profile`]: a Monte Carlo run as a [`RadialProfile`](crate::diffusion::RadialProfile) (`--model mc`), with
//!   standard errors; the tissue-like default anisotropy.
//! - [`report`]: a result as CSV (the `rtbake profile --csv` layout) and JSON (with standard errors).

pub mod compare;
pub mod lanes;
pub mod mc;
pub mod profile;
#[cfg(test)]
mod reference_engine;
pub mod report;
pub mod rng;
pub mod stack;
pub mod ziggurat;

pub use mc::{simulate, ChannelResult, Estimate, McResult, McSettings};
pub use stack::{McLayer, McStack};
