// The frame the texture-space compute passes run over (mesh_inputs.wgsl, surface_maps.wgsl, wrinkles.wgsl;
// prepended to each by its Rust module): one invocation per pixel of the rasterised mesh, workgroups of 8 × 8, and
// per pixel the mesh's (u, v) and coverage (`mesh_raster`). The including shader declares the type of its uniform
// block, `Params`, whose `size.xy` is the frame's width and height, and the two functions the entry point `main`
// calls per pixel, `covered` and `uncovered`.

@group(0) @binding(0) var<uniform> p: Params;

// u, v, covered (0 or 1), 0 per pixel, rows top first
@group(0) @binding(1) var<storage, read_write> uvc: array<vec4<f32>>;

// The entry point of every texture-space pass: an invocation past the frame's edge (the last workgroups overhang it)
// does nothing; pixel `i` (row-major) runs the including shader's `covered(i, uv)` where the mesh covers it, at the
// mesh's (u, v), and its `uncovered(i)` elsewhere.
@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= u32(p.size.x) || id.y >= u32(p.size.y)) {
        return;
    }
    let i = id.y * u32(p.size.x) + id.x;
    let c = uvc[i];
    if (c.z < 0.5) {
        uncovered(i);
    } else {
        covered(i, c.xy);
    }
}
