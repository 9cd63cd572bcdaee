//! rtbake — precomputation and asset baking for real-time skin rendering and morphological antialiasing
//! (J. Jimenez, *Practical Real-Time Strategies for Photorealistic Skin Rendering and Antialiasing*, 2012).
//!
//! The library is the whole tool; `bin/rtbake` only parses flags and calls into it.
//! See `ARCHITECTURE.md` for the code map and the invariants each module keeps.

pub mod aa;
pub mod bake;
pub mod baked_dir;
pub mod baked_layout;
pub mod color;
pub mod diffusion;
pub mod error;
pub mod facial;
pub mod fitting;
pub mod image_buf;
pub mod io;
pub mod manifest;
pub mod plot;
pub mod runtime;
pub mod separable;
pub mod skin_color;
pub mod spectral;
pub mod transmittance;
