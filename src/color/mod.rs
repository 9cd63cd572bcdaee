//! Colour transfer functions shared by the physics modules and the encoders.

pub mod srgb;
