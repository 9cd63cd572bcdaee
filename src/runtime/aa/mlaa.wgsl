// Jimenez's MLAA (Jimenez, Masia, Echevarria, Navarro, Gutierrez, "Practical Morphological Antialiasing",
// GPU Pro 2, 2011; thesis ch. 9, Listings 9.1–9.5): luma edge detection, blending weights from distance searches
// (bilinear fetches of two edgels at a time) and a point-sampled precomputed area map of maximum distance N,
// 4-neighbourhood blending. Written for rtbake from the listings; CPU twin: `runtime/aa/mlaa_cpu.rs`.
//
// Positions are in pixel units (pixel centre = x + 0.5), converted at the fetch. Blending happens in linear light
// (the colour texture is Rgba8Unorm holding sRGB-encoded values; the shader decodes and re-encodes).
//
// Prepended by the host module: vs_fullscreen (../fullscreen.wgsl), LUMA and the sRGB transfer functions
// (srgb.wgsl), luma_at, edges_at, color_lin and blend_at (morphological.wgsl).

struct Params {
    // (1/width, 1/height, width, height)
    rt: vec4<f32>,
    // x: N (area-map maximum distance), y: max search steps = (N − 1) / 2, z: edge threshold
    cfg: vec4<f32>,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var color_tex: texture_2d<f32>;
@group(0) @binding(2) var edges_tex: texture_2d<f32>;
@group(0) @binding(3) var area_tex: texture_2d<f32>;
@group(0) @binding(5) var blend_tex: texture_2d<f32>;
@group(0) @binding(6) var lin: sampler;
@group(0) @binding(7) var pnt: sampler;

// Listing 9.1 (luminance variant): R = edge on the left, G = edge on top.
// The fragment entry points below and the compute ones of three_pass.wgsl call edges_px, weights_px, blend_px.
fn edges_px(p: vec2<i32>) -> vec2<f32> {
    let l = luma_at(p);
    let delta = abs(vec2<f32>(l - luma_at(p + vec2<i32>(-1, 0)), l - luma_at(p + vec2<i32>(0, -1))));
    return step(vec2<f32>(P.cfg.z), delta);
}

@fragment
fn fs_edges(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(edges_px(vec2<i32>(floor(pos.xy))), 0.0, 0.0);
}

// Listing 9.3 and its three siblings: distance to the end of the line, two edgels per fetch.
fn search_x_left(pix: vec2<f32>) -> f32 {
    var t = pix - vec2<f32>(1.5, 0.0);
    var e = 0.0;
    var i = 0.0;
    for (; i < P.cfg.y; i = i + 1.0) {
        e = edges_at(t).y;
        if (e < 0.9) { break; }
        t.x = t.x - 2.0;
    }
    return max(-2.0 * i - 2.0 * e, -2.0 * P.cfg.y);
}

fn search_x_right(pix: vec2<f32>) -> f32 {
    var t = pix + vec2<f32>(1.5, 0.0);
    var e = 0.0;
    var i = 0.0;
    for (; i < P.cfg.y; i = i + 1.0) {
        e = edges_at(t).y;
        if (e < 0.9) { break; }
        t.x = t.x + 2.0;
    }
    return min(2.0 * i + 2.0 * e, 2.0 * P.cfg.y);
}

fn search_y_up(pix: vec2<f32>) -> f32 {
    var t = pix - vec2<f32>(0.0, 1.5);
    var e = 0.0;
    var i = 0.0;
    for (; i < P.cfg.y; i = i + 1.0) {
        e = edges_at(t).x;
        if (e < 0.9) { break; }
        t.y = t.y - 2.0;
    }
    return max(-2.0 * i - 2.0 * e, -2.0 * P.cfg.y);
}

fn search_y_down(pix: vec2<f32>) -> f32 {
    var t = pix + vec2<f32>(0.0, 1.5);
    var e = 0.0;
    var i = 0.0;
    for (; i < P.cfg.y; i = i + 1.0) {
        e = edges_at(t).x;
        if (e < 0.9) { break; }
        t.y = t.y + 2.0;
    }
    return min(2.0 * i + 2.0 * e, 2.0 * P.cfg.y);
}

// Listing 9.4: point-sampled area map; dividing by 5N − 1 lands inside texel (N·round(4e) + distance).
fn area(d: vec2<f32>, e1: f32, e2: f32) -> vec2<f32> {
    let n = P.cfg.x;
    let pixcoord = n * round(4.0 * vec2<f32>(e1, e2)) + d;
    return textureSampleLevel(area_tex, pnt, pixcoord / (5.0 * n - 1.0), 0.0).rg;
}

// Listing 9.2.
fn weights_px(pix: vec2<f32>) -> vec4<f32> {
    var weights = vec4<f32>(0.0);
    let e = textureLoad(edges_tex, vec2<i32>(floor(pix)), 0).rg;
    if (e.y > 0.0) {
        let d = vec2<f32>(search_x_left(pix), search_x_right(pix));
        // Sample at −0.25 between edgels to tell which crossing edgel is set.
        let e1 = edges_at(pix + vec2<f32>(d.x, -0.25)).x;
        let e2 = edges_at(pix + vec2<f32>(d.y + 1.0, -0.25)).x;
        let a = area(abs(d), e1, e2);
        weights.x = a.x;
        weights.y = a.y;
    }
    if (e.x > 0.0) {
        let d = vec2<f32>(search_y_up(pix), search_y_down(pix));
        let e1 = edges_at(pix + vec2<f32>(-0.25, d.x)).y;
        let e2 = edges_at(pix + vec2<f32>(-0.25, d.y + 1.0)).y;
        let a = area(abs(d), e1, e2);
        weights.z = a.x;
        weights.w = a.y;
    }
    return weights;
}

@fragment
fn fs_weights(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return weights_px(pos.xy);
}

// Listing 9.5: a = (own north, bottom pixel's g, own west, right pixel's a); each neighbour is blended in by the
// bilinear fetch at an offset of a_k pixels, written out as a lerp; the result is averaged over the lines.
fn blend_px(p: vec2<i32>) -> vec4<f32> {
    let top_left = blend_at(p);
    let bottom = blend_at(p + vec2<i32>(0, 1)).g;
    let right = blend_at(p + vec2<i32>(1, 0)).a;
    let a = vec4<f32>(top_left.r, bottom, top_left.b, right);
    let sum = dot(a, vec4<f32>(1.0));
    if (sum > 0.0) {
        let c = color_lin(p);
        var color = vec4<f32>(0.0);
        color = color + a.x * mix(c, color_lin(p + vec2<i32>(0, -1)), a.x);
        color = color + a.y * mix(c, color_lin(p + vec2<i32>(0, 1)), a.y);
        color = color + a.z * mix(c, color_lin(p + vec2<i32>(-1, 0)), a.z);
        color = color + a.w * mix(c, color_lin(p + vec2<i32>(1, 0)), a.w);
        color = color / sum;
        return vec4<f32>(linear_to_srgb(color.rgb), color.a);
    }
    return textureLoad(color_tex, p, 0);
}

@fragment
fn fs_blend(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return blend_px(vec2<i32>(floor(pos.xy)));
}
