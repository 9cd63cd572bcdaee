// Bloom on the HDR frame before tone mapping (runtime/bloom.rs): bright part B = max(I - threshold, 0), a weighted
// sum of three separable Gaussian blurs K*B (taps beyond the image read 0), out = I + weight * (K*B - B).
// Stage bright writes B, stage h_blur the three horizontal blurs (one walk over the widest radius, each B read
// once), stage v_blur the vertical ones summed and the result.
// CPU twin: runtime/cpu/bloom.rs.

struct Params {
    // width, height, threshold, weight
    size: vec4<f32>,
    // tap radius of blur 0, 1, 2, 0
    radius: vec4<f32>,
    // mix a_k of blur 0, 1, 2 (sum 1), 0
    mix: vec4<f32>,
};

@group(0) @binding(0) var<uniform> p: Params;
@group(0) @binding(1) var<storage, read_write> hdr: array<vec4<f32>>;
// the three kernels, 2r + 1 taps each, one after the other
@group(0) @binding(2) var<storage, read_write> taps: array<f32>;
// three horizontal blurs of B, each width x height
@group(0) @binding(3) var<storage, read_write> tmp: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> result: array<vec4<f32>>;
// B per pixel
@group(0) @binding(5) var<storage, read_write> bright_px: array<vec4<f32>>;

@compute @workgroup_size(8, 8, 1)
fn bright(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(p.size.x);
    if (id.x >= w || id.y >= u32(p.size.y)) {
        return;
    }
    let v = hdr[id.y * w + id.x];
    bright_px[id.y * w + id.x] = vec4<f32>(max(v.xyz - vec3<f32>(p.size.z), vec3<f32>(0.0)), 0.0);
}

fn kernel_start(k: u32) -> u32 {
    var o = 0u;
    for (var j = 0u; j < k; j = j + 1u) {
        o = o + 2u * u32(p.radius[j]) + 1u;
    }
    return o;
}

@compute @workgroup_size(8, 8, 1)
fn h_blur(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(p.size.x);
    let h = u32(p.size.y);
    if (id.x >= w || id.y >= h) {
        return;
    }
    let n = w * h;
    let r = vec3<i32>(i32(p.radius.x), i32(p.radius.y), i32(p.radius.z));
    let o = vec3<u32>(0u, kernel_start(1u), kernel_start(2u));
    let rmax = max(r.x, max(r.y, r.z));
    var s0 = vec4<f32>(0.0);
    var s1 = vec4<f32>(0.0);
    var s2 = vec4<f32>(0.0);
    for (var j = -rmax; j <= rmax; j = j + 1) {
        let x = i32(id.x) + j;
        if (x < 0 || x >= i32(w)) {
            continue;
        }
        let b = bright_px[id.y * w + u32(x)];
        if (abs(j) <= r.x) {
            s0 = s0 + taps[o.x + u32(j + r.x)] * b;
        }
        if (abs(j) <= r.y) {
            s1 = s1 + taps[o.y + u32(j + r.y)] * b;
        }
        if (abs(j) <= r.z) {
            s2 = s2 + taps[o.z + u32(j + r.z)] * b;
        }
    }
    let i = id.y * w + id.x;
    tmp[i] = s0;
    tmp[n + i] = s1;
    tmp[2u * n + i] = s2;
}

@compute @workgroup_size(8, 8, 1)
fn v_blur(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(p.size.x);
    let h = u32(p.size.y);
    if (id.x >= w || id.y >= h) {
        return;
    }
    let n = w * h;
    var kb = vec4<f32>(0.0);
    for (var k = 0u; k < 3u; k = k + 1u) {
        let r = i32(p.radius[k]);
        let o = kernel_start(k);
        var s = vec4<f32>(0.0);
        for (var j = -r; j <= r; j = j + 1) {
            let y = i32(id.y) + j;
            if (y >= 0 && y < i32(h)) {
                s = s + taps[o + u32(j + r)] * tmp[k * n + u32(y) * w + id.x];
            }
        }
        kb = kb + p.mix[k] * s;
    }
    let i = id.y * w + id.x;
    result[i] = hdr[i] + p.size.w * (kb - bright_px[i]);
}
