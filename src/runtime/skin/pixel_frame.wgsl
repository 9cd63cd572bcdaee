// The frame the texture-space compute passes run over (mesh_inputs.wgsl, surface_maps.wgsl, wrinkles.wgsl;
// prepended to each by its Rust module): one invocation per pixel of the rasterised mesh, workgroups of 8 × 8, and
// per pixel the mesh's (u, v) and coverage (`mesh_raster`). The including shader declares the type of its uniform
// block, `Params`, whose `size.xy` is the frame's width and height.

@group(0) @binding(0) var<uniform> p: Params;

// u, v, covered (0 or 1), 0 per pixel, rows top first
@group(0) @binding(1) var<storage, read_write> uvc: array<vec4<f32>>;

// Whether invocation `id` lies outside the frame (the last workgroups overhang it).
fn outside_frame(id: vec3<u32>) -> bool {
    return id.x >= u32(p.size.x) || id.y >= u32(p.size.y);
}

// The row-major index of invocation `id`'s pixel.
fn frame_pixel(id: vec3<u32>) -> u32 {
    return id.y * u32(p.size.x) + id.x;
}
