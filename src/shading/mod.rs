//! Surface shading models of the skin renderer that are not subsurface scattering.
//!
//! - [`texture_space`]: texture-space diffusion (d'Eon et al. 2007) — UV rasterisation, stretch, the thesis ch. 3
//!   culling, depth-sized and clipped irradiance maps.
//! - [`kelemen`]: the Kelemen/Szirmay-Kalos specular BRDF with a Beckmann distribution and Schlick's Fresnel, as
//!   TAP 2009 §4 and thesis ch. 4 use it for skin (kept apart from the diffuse layer that SSS blurs).

pub mod kelemen;
pub mod texture_space;
