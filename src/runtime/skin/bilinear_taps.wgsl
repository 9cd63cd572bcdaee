// Bilinear fetch set-up shared by the compute passes that sample texture-space maps at a mesh's uv
// (mesh_skin_inputs.wgsl, wrinkle_pass.wgsl; prepended to each by its Rust module): the four clamp-to-edge texel
// indices and the two weights of a bilinear sample at (u, v) of a w × h map, texel centres at (i + 0.5) / size,
// in f32 as the CPU twins compute them.

struct Taps {
    i: vec4<u32>, // (x0, x1, y0, y1)
    f: vec2<f32>,
};

fn taps(u: f32, v: f32, w: f32, h: f32) -> Taps {
    let x = u * w - 0.5;
    let y = v * h - 0.5;
    let x0 = floor(x);
    let y0 = floor(y);
    var t: Taps;
    t.f = vec2<f32>(x - x0, y - y0);
    let xi = i32(x0);
    let yi = i32(y0);
    let wm = i32(w) - 1;
    let hm = i32(h) - 1;
    t.i = vec4<u32>(u32(clamp(xi, 0, wm)), u32(clamp(xi + 1, 0, wm)), u32(clamp(yi, 0, hm)), u32(clamp(yi + 1, 0, hm)));
    return t;
}
