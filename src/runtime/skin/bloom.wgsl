// Bloom on the HDR frame before tone mapping (runtime/skin/bloom.rs): a downsampled pyramid after Jimenez 2014
// ("Next Generation Post Processing in Call of Duty: Advanced Warfare", SIGGRAPH course): the bright part
// B = max(I - threshold, 0) is reduced level by level with the 13-tap filter (five overlapping 2x2 boxes: the
// central one weighted 0.5, the four corner ones 0.125 each), then accumulated back from the coarsest level with
// a 3x3 tent on bilinear reads, U_l = mix * D_l + tent(U_{l+1}); out = I + weight * (tent(U_1) - B).
// Texels beyond a level read 0. CPU twin: runtime/skin/bloom_cpu.rs (the same sums in the same order).

struct Params {
    // width, height, threshold, weight
    size: vec4<f32>,
    // levels N, mix per level (1 / N), 0, 0
    lv: vec4<f32>,
    // per dispatch (compute_chain's stage arguments): the level l a `down` / `up` dispatch writes, 0, 0, 0
    stage: vec4<u32>,
};

@group(0) @binding(0) var<uniform> p: Params;
@group(0) @binding(1) var<storage, read_write> hdr: array<vec4<f32>>;
// D_1..D_N, one level after the other
@group(0) @binding(2) var<storage, read_write> down_px: array<vec4<f32>>;
// U_1..U_N, laid out as down_px
@group(0) @binding(3) var<storage, read_write> up_px: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> result: array<vec4<f32>>;

fn dims(l: u32) -> vec2<u32> {
    var d = vec2<u32>(u32(p.size.x), u32(p.size.y));
    for (var k = 0u; k < l; k = k + 1u) {
        d = (d + vec2<u32>(1u)) / 2u;
    }
    return d;
}

// Offset of level l >= 1 in down_px / up_px.
fn offset(l: u32) -> u32 {
    var o = 0u;
    for (var k = 1u; k < l; k = k + 1u) {
        let d = dims(k);
        o = o + d.x * d.y;
    }
    return o;
}

fn bright(i: u32) -> vec4<f32> {
    return vec4<f32>(max(hdr[i].xyz - vec3<f32>(p.size.z), vec3<f32>(0.0)), 0.0);
}

// Texel (x, y) of D_l (D_0 = B), 0 outside.
fn src(l: u32, x: i32, y: i32) -> vec4<f32> {
    let d = dims(l);
    if (x < 0 || y < 0 || x >= i32(d.x) || y >= i32(d.y)) {
        return vec4<f32>(0.0);
    }
    let i = u32(y) * d.x + u32(x);
    if (l == 0u) {
        return bright(i);
    }
    return down_px[offset(l) + i];
}

// The 2x2 box anchored at (x, y): one bilinear read halfway between texels.
fn box(l: u32, x: i32, y: i32) -> vec4<f32> {
    return 0.25 * (src(l, x, y) + src(l, x + 1, y) + src(l, x, y + 1) + src(l, x + 1, y + 1));
}

fn down_level(l: u32, id: vec3<u32>) {
    let d = dims(l);
    if (id.x >= d.x || id.y >= d.y) {
        return;
    }
    let s = l - 1u;
    let x = 2 * i32(id.x);
    let y = 2 * i32(id.y);
    var v = 0.125 * (box(s, x - 1, y - 1) + box(s, x + 1, y - 1) + box(s, x - 1, y + 1) + box(s, x + 1, y + 1));
    v = v + 0.125 * box(s, x, y);
    v = v + 0.0625 * (box(s, x - 2, y) + box(s, x + 2, y) + box(s, x, y - 2) + box(s, x, y + 2));
    v = v + 0.03125 * (box(s, x - 2, y - 2) + box(s, x + 2, y - 2) + box(s, x - 2, y + 2) + box(s, x + 2, y + 2));
    let i = offset(l) + id.y * d.x + id.x;
    down_px[i] = v;
    if (l == u32(p.lv.x)) {
        up_px[i] = p.lv.y * v;
    }
}

// Texel (x, y) of U_l, 0 outside.
fn acc(l: u32, x: i32, y: i32) -> vec4<f32> {
    let d = dims(l);
    if (x < 0 || y < 0 || x >= i32(d.x) || y >= i32(d.y)) {
        return vec4<f32>(0.0);
    }
    return up_px[offset(l) + u32(y) * d.x + u32(x)];
}

fn bilinear(l: u32, u: f32, v: f32) -> vec4<f32> {
    let fx = floor(u);
    let fy = floor(v);
    let a = u - fx;
    let b = v - fy;
    let x = i32(fx);
    let y = i32(fy);
    let top = (1.0 - a) * acc(l, x, y) + a * acc(l, x + 1, y);
    let bottom = (1.0 - a) * acc(l, x, y + 1) + a * acc(l, x + 1, y + 1);
    return (1.0 - b) * top + b * bottom;
}

// The 3x3 tent (1 2 1)^2 / 16 over U_c read at the centre of texel (x, y) of the level below c.
fn tent(c: u32, x: u32, y: u32) -> vec4<f32> {
    let u = (f32(x) + 0.5) * 0.5 - 0.5;
    let v = (f32(y) + 0.5) * 0.5 - 0.5;
    var s = vec4<f32>(0.0);
    for (var j = -1; j <= 1; j = j + 1) {
        for (var i = -1; i <= 1; i = i + 1) {
            let w = f32((2 - abs(i)) * (2 - abs(j))) / 16.0;
            s = s + w * bilinear(c, u + f32(i), v + f32(j));
        }
    }
    return s;
}

fn up_level(l: u32, id: vec3<u32>) {
    let d = dims(l);
    if (id.x >= d.x || id.y >= d.y) {
        return;
    }
    let i = offset(l) + id.y * d.x + id.x;
    up_px[i] = p.lv.y * down_px[i] + tent(l + 1u, id.x, id.y);
}

@compute @workgroup_size(8, 8, 1)
fn combine(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(p.size.x);
    if (id.x >= w || id.y >= u32(p.size.y)) {
        return;
    }
    let i = id.y * w + id.x;
    result[i] = hdr[i] + p.size.w * (tent(1u, id.x, id.y) - bright(i));
}

// D_l from D_{l-1}, l = p.stage.x in 1..=N.
@compute @workgroup_size(8, 8, 1)
fn down(@builtin(global_invocation_id) id: vec3<u32>) {
    down_level(p.stage.x, id);
}

// U_l from D_l and U_{l+1}, l = p.stage.x in 1..N-1.
@compute @workgroup_size(8, 8, 1)
fn up(@builtin(global_invocation_id) id: vec3<u32>) {
    up_level(p.stage.x, id);
}
