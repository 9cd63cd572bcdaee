//! The skin renderer (thesis ch. 3–8, TAP 2009): the passes that make a frame of skin, each beside its WGSL and its
//! CPU twin, and the frames built from them.
//!
//! Passes: [`mesh_raster`] (the G-buffer), [`compute_raster`] (the device frame's one-sample G-buffer by compute), [`inputs`] (albedo from the skin LUT, T(s)·E), [`mesh_inputs`] (the rig's
//! eq. 7.6 at the mesh's uv), [`wrinkles`] (Listing 8.1), [`surface_maps`] (a scan's albedo and normal map at the mesh's uv), [`bloom`], [`texture_space`] (d'Eon et al.'s
//! texture-space diffusion, TAP's "TS").
//! Frames: [`lighting`] (the shared lighting and compositing every frame goes through: skin inputs → diffuse +
//! transmitted light → SSS → post-scatter albedo, specular, bloom → tone map; on a device recorded into one command
//! encoder by [`shade_frame`], one read-back), [`demo`] (the procedural spheres),
//! [`heads`] (heads from a mesh: G-buffer, shadow-map thickness), [`frame`] (`run skin`: picks the SSS shader),
//! [`settings`], [`passes`] (the optional passes of `run skin`).

pub mod bloom;
pub mod bloom_cpu;
pub mod compute_raster;
pub mod demo;
pub mod frame;
mod frame_geometry;
pub mod heads;
pub mod inputs;
pub mod inputs_cpu;
pub mod lighting;
pub mod mesh_inputs;
pub mod mesh_inputs_cpu;
pub mod mesh_raster;
pub mod mesh_raster_cpu;
pub mod passes;
pub mod settings;
pub mod shade_frame;
pub mod surface_maps;
pub mod surface_maps_cpu;
pub mod tap_grid;
pub mod texture_space;
pub mod texture_space_cpu;
mod view_frame;
pub mod wrinkles;
pub mod wrinkles_cpu;
