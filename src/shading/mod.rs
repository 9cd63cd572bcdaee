//! Surface shading models of the skin renderer that are not subsurface scattering.
//!
//! - [`texture_space`]: texture-space diffusion (d'Eon et al. 2007) — UV rasterisation, stretch, the thesis ch. 3
//!   culling, depth-sized and clipped irradiance maps.
//! - [`material_maps`]: a scanned head's albedo (sRGB → linear, post-scatter texturing of thesis §7.6) and
//!   tangent-space normal map (decoded, validated, either green convention).
//! - [`kelemen`]: the Kelemen/Szirmay-Kalos specular BRDF with a Beckmann distribution and Schlick's Fresnel, as
//!   TAP 2009 §4 and thesis ch. 4 use it for skin (kept apart from the diffuse layer that SSS blurs).

pub mod kelemen;
pub mod material_maps;
pub mod texture_space;
