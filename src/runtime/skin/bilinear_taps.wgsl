// Bilinear fetch shared by the compute passes that sample texture-space maps at a mesh's uv
// (mesh_inputs.wgsl, surface_maps.wgsl, wrinkles.wgsl; prepended to each by its Rust module): the four clamp-to-edge
// texel indices and the two weights of a bilinear sample at (u, v) of a w × h map, texel centres at (i + 0.5) / size,
// and the blend of the four texels, in f32 as the CPU twins compute them.

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

// The storage indices of the four taps in a map `w` texels wide whose first texel is element `base`:
// (x0 y0, x1 y0, x0 y1, x1 y1), rows top first.
fn tap_index(t: Taps, base: u32, w: u32) -> vec4<u32> {
    let r0 = base + t.i.z * w;
    let r1 = base + t.i.w * w;
    return vec4<u32>(r0 + t.i.x, r0 + t.i.y, r1 + t.i.x, r1 + t.i.y);
}

// The bilinear blend of the four taps' values (a: x0 y0, b: x1 y0, c: x0 y1, d: x1 y1), one per element type.
fn bilerp4(t: Taps, a: vec4<f32>, b: vec4<f32>, c: vec4<f32>, d: vec4<f32>) -> vec4<f32> {
    let top = a + (b - a) * t.f.x;
    let bottom = c + (d - c) * t.f.x;
    return top + (bottom - top) * t.f.y;
}

fn bilerp2(t: Taps, a: vec2<f32>, b: vec2<f32>, c: vec2<f32>, d: vec2<f32>) -> vec2<f32> {
    let top = a + (b - a) * t.f.x;
    let bottom = c + (d - c) * t.f.x;
    return top + (bottom - top) * t.f.y;
}

fn bilerp1(t: Taps, a: f32, b: f32, c: f32, d: f32) -> f32 {
    let top = a + (b - a) * t.f.x;
    let bottom = c + (d - c) * t.f.x;
    return top + (bottom - top) * t.f.y;
}
