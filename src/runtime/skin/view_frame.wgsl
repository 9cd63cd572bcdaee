// The view-space surface frame the normal-producing compute passes read (surface_maps.wgsl, wrinkles.wgsl;
// prepended to each by its Rust module), per pixel from `mesh_raster`.

// view normal (unit), 0
@group(0) @binding(2) var<storage, read_write> nrm: array<vec4<f32>>;
// view tangent (interpolated), handedness
@group(0) @binding(3) var<storage, read_write> tng: array<vec4<f32>>;
