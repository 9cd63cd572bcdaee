//! Monte Carlo photon transport on the GPU: [`mc_gpu`] (`mc_gpu.wgsl`); its CPU twin is the library's reference
//! engine, [`crate::transport::mc`].

pub mod mc_gpu;
