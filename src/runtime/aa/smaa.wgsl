// SMAA 1x: luma edge detection, blending-weight calculation, neighbourhood blending.
// Jimenez, Echevarria, Sousa, Gutierrez, "SMAA: Enhanced Subpixel Morphological Antialiasing", Eurographics 2012;
// thesis ch. 10. Written for rtbake from the algorithm description; the CPU mirror is `runtime/aa/smaa_cpu.rs`, and
// every arithmetic step here has its twin there (keep them in sync).
//
// Conventions: all positions are in PIXEL units of the frame (pixel (x, y) has its centre at (x + 0.5, y + 0.5),
// top row first), converted to normalised coordinates only at the fetch. This keeps the search arithmetic exact
// (multiples of 1/8) on every backend. Preset HIGH: threshold 0.1, 16 orthogonal / 8 diagonal search steps,
// corner rounding 25 %, local contrast adaptation factor 2.0.
//
// Differences from the reference shader, both exact on exact hardware:
// - the search texture is read with textureLoad at the texel the bilinear edge fetch decodes to (32·e rounded),
//   instead of a bilinear fetch at that texel's centre: adapters whose filtering returns 8-bit results (lavapipe)
//   would otherwise mix neighbouring search texels;
// - edge detection returns 0 instead of discarding (the edges target is cleared to 0 first anyway).
//
// Prepended by the host module: the preset constants THRESHOLD … AREATEX_SUBTEX_ROWS and AREATEX_SIZE (written
// from `smaa::preset`), vs_fullscreen (../fullscreen.wgsl), LUMA and the sRGB transfer functions
// (srgb.wgsl), luma_at, edges_at, color_lin and blend_at (morphological.wgsl).

struct Params {
    // (1/width, 1/height, width, height)
    rt: vec4<f32>,
    // Subsample indices (SMAA 1x: all zero); x: vertical orthogonal, y: horizontal orthogonal, z/w: diagonal.
    subsample: vec4<f32>,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var color_tex: texture_2d<f32>;
@group(0) @binding(2) var edges_tex: texture_2d<f32>;
@group(0) @binding(3) var area_tex: texture_2d<f32>;
@group(0) @binding(4) var search_tex: texture_2d<f32>;
@group(0) @binding(5) var blend_tex: texture_2d<f32>;
@group(0) @binding(6) var lin: sampler;

// ---------------------------------------------------------------------------------------------------------
// Pass 1: luma edge detection with local contrast adaptation. R = edge on the left, G = edge on top.

// The edges of texel `p`; the fragment entry point below and `cs_edges` (three_pass.wgsl) call it.
fn edges_px(p: vec2<i32>) -> vec2<f32> {
    let l = luma_at(p);
    let l_left = luma_at(p + vec2<i32>(-1, 0));
    let l_top = luma_at(p + vec2<i32>(0, -1));
    let delta_lt = abs(vec2<f32>(l - l_left, l - l_top));
    var edges = step(vec2<f32>(THRESHOLD), delta_lt);
    if (edges.x + edges.y == 0.0) {
        return vec2<f32>(0.0);
    }
    let l_right = luma_at(p + vec2<i32>(1, 0));
    let l_bottom = luma_at(p + vec2<i32>(0, 1));
    var max_delta = max(delta_lt, abs(vec2<f32>(l - l_right, l - l_bottom)));
    let l_leftleft = luma_at(p + vec2<i32>(-2, 0));
    let l_toptop = luma_at(p + vec2<i32>(0, -2));
    max_delta = max(max_delta, abs(vec2<f32>(l_left - l_leftleft, l_top - l_toptop)));
    let final_delta = max(max_delta.x, max_delta.y);
    // Local contrast adaptation: drop an edge when a neighbouring edge is LOCAL_CONTRAST_ADAPTATION times stronger.
    edges = edges * step(vec2<f32>(final_delta), LOCAL_CONTRAST_ADAPTATION * delta_lt);
    return edges;
}

@fragment
fn fs_edges(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(edges_px(vec2<i32>(floor(pos.xy))), 0.0, 0.0);
}

// ---------------------------------------------------------------------------------------------------------
// Pass 2: blending-weight calculation.

// Bilinear fetch of the area texture at a position in area-texture texels.
fn area_at(t: vec2<f32>) -> vec2<f32> {
    return textureSampleLevel(area_tex, lin, t / AREATEX_SIZE, 0.0).rg;
}

// Undo the bilinear mix of a diagonal search fetch made 0.25 px to the right: R keeps the right pixel's bit.
fn decode_diag(e: vec2<f32>) -> vec2<f32> {
    return round(vec2<f32>(e.x * abs(5.0 * e.x - 5.0 * 0.75), e.y));
}

// Diagonal search; returns (steps taken, last edge mean) and the last fetched edges in `end`.
fn search_diag1(p: vec2<f32>, dir: vec2<f32>, end: ptr<function, vec2<f32>>) -> vec2<f32> {
    var c = vec4<f32>(p, -1.0, 1.0);
    var e = vec2<f32>(0.0);
    while (c.z < MAX_SEARCH_STEPS_DIAG - 1.0 && c.w > 0.9) {
        c = vec4<f32>(c.xy + dir, c.z + 1.0, c.w);
        e = edges_at(c.xy);
        c.w = dot(e, vec2<f32>(0.5, 0.5));
    }
    *end = e;
    return c.zw;
}

fn search_diag2(p: vec2<f32>, dir: vec2<f32>, end: ptr<function, vec2<f32>>) -> vec2<f32> {
    var c = vec4<f32>(p.x + 0.25, p.y, -1.0, 1.0);
    var e = vec2<f32>(0.0);
    while (c.z < MAX_SEARCH_STEPS_DIAG - 1.0 && c.w > 0.9) {
        c = vec4<f32>(c.xy + dir, c.z + 1.0, c.w);
        e = decode_diag(edges_at(c.xy));
        c.w = dot(e, vec2<f32>(0.5, 0.5));
    }
    *end = e;
    return c.zw;
}

fn area_diag(dist: vec2<f32>, e: vec2<f32>, offset: f32) -> vec2<f32> {
    var t = AREATEX_MAX_DISTANCE_DIAG * e + dist + vec2<f32>(0.5, 0.5);
    t.x = t.x + 80.0;
    t.y = t.y + AREATEX_SUBTEX_ROWS * offset;
    return area_at(t);
}

fn diag_weights(p: vec2<f32>, e: vec2<f32>) -> vec2<f32> {
    var weights = vec2<f32>(0.0);
    var end = vec2<f32>(0.0);
    var d = vec4<f32>(0.0);
    // Main diagonal (bottom-left to top-right).
    if (e.x > 0.0) {
        let r = search_diag1(p, vec2<f32>(-1.0, 1.0), &end);
        d.x = r.x + select(0.0, 1.0, end.y > 0.9);
        d.z = r.y;
    }
    let r1 = search_diag1(p, vec2<f32>(1.0, -1.0), &end);
    d.y = r1.x;
    d.w = r1.y;
    if (d.x + d.y > 2.0) {
        let c0 = edges_at(vec2<f32>(p.x - d.x + 0.25, p.y + d.x) + vec2<f32>(-1.0, 0.0));
        let c1 = edges_at(vec2<f32>(p.x + d.y, p.y - d.y - 0.25) + vec2<f32>(1.0, 0.0));
        let dec = vec4<f32>(decode_diag(c0), decode_diag(c1));
        // c.yxwz = decoded(c.xyzw)
        let c = vec4<f32>(dec.y, dec.x, dec.w, dec.z);
        var cc = 2.0 * c.xz + c.yw;
        if (d.z >= 0.9) { cc.x = 0.0; }
        if (d.w >= 0.9) { cc.y = 0.0; }
        weights = weights + area_diag(d.xy, cc, P.subsample.z);
    }
    // Anti-diagonal (top-left to bottom-right).
    let r2 = search_diag2(p, vec2<f32>(-1.0, -1.0), &end);
    d.x = r2.x;
    d.z = r2.y;
    if (edges_at(p + vec2<f32>(1.0, 0.0)).x > 0.0) {
        let r3 = search_diag2(p, vec2<f32>(1.0, 1.0), &end);
        d.y = r3.x + select(0.0, 1.0, end.y > 0.9);
        d.w = r3.y;
    } else {
        d.y = 0.0;
        d.w = 0.0;
    }
    if (d.x + d.y > 2.0) {
        let q0 = vec2<f32>(p.x - d.x, p.y - d.x);
        let q1 = vec2<f32>(p.x + d.y, p.y + d.y);
        var c = vec4<f32>(0.0);
        c.x = edges_at(q0 + vec2<f32>(-1.0, 0.0)).y;
        c.y = edges_at(q0 + vec2<f32>(0.0, -1.0)).x;
        let c1 = edges_at(q1 + vec2<f32>(1.0, 0.0));
        c.z = c1.y;
        c.w = c1.x;
        var cc = 2.0 * c.xz + c.yw;
        if (d.z >= 0.9) { cc.x = 0.0; }
        if (d.w >= 0.9) { cc.y = 0.0; }
        weights = weights + area_diag(d.xy, cc, P.subsample.w).yx;
    }
    return weights;
}

// Search-length correction: decodes the bilinear fetch `e` (four edge bits, multiples of 1/32) through the
// search texture; `offset` 0 for left/up searches, 0.5 for right/down. Returns 0, 127/255 or 254/255.
fn search_length(e: vec2<f32>, offset: f32) -> f32 {
    let ix = i32(round(32.0 * e.x)) + select(0, 33, offset > 0.0);
    let iy = 32 - i32(round(32.0 * e.y));
    let q = clamp(vec2<i32>(ix, iy), vec2<i32>(0, 0), vec2<i32>(63, 15));
    return textureLoad(search_tex, q, 0).r;
}

fn search_x_left(start: vec2<f32>, end: f32) -> f32 {
    var t = start;
    var e = vec2<f32>(0.0, 1.0);
    while (t.x > end && e.y > 0.8281 && e.x == 0.0) {
        e = edges_at(t);
        t.x = t.x - 2.0;
    }
    let offset = -(255.0 / 127.0) * search_length(e, 0.0) + 3.25;
    return t.x + offset;
}

fn search_x_right(start: vec2<f32>, end: f32) -> f32 {
    var t = start;
    var e = vec2<f32>(0.0, 1.0);
    while (t.x < end && e.y > 0.8281 && e.x == 0.0) {
        e = edges_at(t);
        t.x = t.x + 2.0;
    }
    let offset = -(255.0 / 127.0) * search_length(e, 0.5) + 3.25;
    return t.x - offset;
}

fn search_y_up(start: vec2<f32>, end: f32) -> f32 {
    var t = start;
    var e = vec2<f32>(1.0, 0.0);
    while (t.y > end && e.x > 0.8281 && e.y == 0.0) {
        e = edges_at(t);
        t.y = t.y - 2.0;
    }
    let offset = -(255.0 / 127.0) * search_length(e.yx, 0.0) + 3.25;
    return t.y + offset;
}

fn search_y_down(start: vec2<f32>, end: f32) -> f32 {
    var t = start;
    var e = vec2<f32>(1.0, 0.0);
    while (t.y < end && e.x > 0.8281 && e.y == 0.0) {
        e = edges_at(t);
        t.y = t.y + 2.0;
    }
    let offset = -(255.0 / 127.0) * search_length(e.yx, 0.5) + 3.25;
    return t.y - offset;
}

// Orthogonal area lookup: crossing-edge values e1, e2 (0, 0.25, 0.75, 1), square-rooted distances.
fn area_ortho(sqrt_d: vec2<f32>, e1: f32, e2: f32, offset: f32) -> vec2<f32> {
    var t = AREATEX_MAX_DISTANCE * round(4.0 * vec2<f32>(e1, e2)) + sqrt_d + vec2<f32>(0.5, 0.5);
    t.y = t.y + AREATEX_SUBTEX_ROWS * offset;
    return area_at(t);
}

fn corner_factor(d: vec2<f32>) -> vec2<f32> {
    let left_right = step(d, d.yx);
    return (1.0 - CORNER_ROUNDING_NORM) * left_right / (left_right.x + left_right.y);
}

// The blending weights of the pixel centred at `pix` (pixel units); `fs_weights` and `cs_weights` call it.
fn weights_px(pix: vec2<f32>) -> vec4<f32> {
    var weights = vec4<f32>(0.0);
    var e = textureLoad(edges_tex, vec2<i32>(floor(pix)), 0).rg;
    let span = 2.0 * MAX_SEARCH_STEPS;

    if (e.y > 0.0) {
        // Edge at north. Diagonals first; they take priority.
        let dw = diag_weights(pix, e);
        weights.x = dw.x;
        weights.y = dw.y;
        if (dw.x == -dw.y) {
            let left = search_x_left(pix + vec2<f32>(-0.25, -0.125), pix.x - 0.25 - span);
            let y1 = pix.y - 0.25;
            let e1 = edges_at(vec2<f32>(left, y1)).x;
            let right = search_x_right(pix + vec2<f32>(1.25, -0.125), pix.x + 1.25 + span);
            let d = abs(round(vec2<f32>(left, right) - vec2<f32>(pix.x, pix.x)));
            let e2 = edges_at(vec2<f32>(right + 1.0, y1)).x;
            var w = area_ortho(sqrt(d), e1, e2, P.subsample.y);
            // Sharp-corner rounding.
            let r = corner_factor(d);
            var f = vec2<f32>(1.0, 1.0);
            f.x = f.x - r.x * edges_at(vec2<f32>(left, pix.y + 1.0)).x;
            f.x = f.x - r.y * edges_at(vec2<f32>(right + 1.0, pix.y + 1.0)).x;
            f.y = f.y - r.x * edges_at(vec2<f32>(left, pix.y - 2.0)).x;
            f.y = f.y - r.y * edges_at(vec2<f32>(right + 1.0, pix.y - 2.0)).x;
            w = w * clamp(f, vec2<f32>(0.0), vec2<f32>(1.0));
            weights.x = w.x;
            weights.y = w.y;
        } else {
            e.x = 0.0;
        }
    }

    if (e.x > 0.0) {
        // Edge at west.
        let up = search_y_up(pix + vec2<f32>(-0.125, -0.25), pix.y - 0.25 - span);
        let x1 = pix.x - 0.25;
        let e1 = edges_at(vec2<f32>(x1, up)).y;
        let down = search_y_down(pix + vec2<f32>(-0.125, 1.25), pix.y + 1.25 + span);
        let d = abs(round(vec2<f32>(up, down) - vec2<f32>(pix.y, pix.y)));
        let e2 = edges_at(vec2<f32>(x1, down + 1.0)).y;
        var w = area_ortho(sqrt(d), e1, e2, P.subsample.x);
        let r = corner_factor(d);
        var f = vec2<f32>(1.0, 1.0);
        f.x = f.x - r.x * edges_at(vec2<f32>(pix.x + 1.0, up)).y;
        f.x = f.x - r.y * edges_at(vec2<f32>(pix.x + 1.0, down + 1.0)).y;
        f.y = f.y - r.x * edges_at(vec2<f32>(pix.x - 2.0, up)).y;
        f.y = f.y - r.y * edges_at(vec2<f32>(pix.x - 2.0, down + 1.0)).y;
        w = w * clamp(f, vec2<f32>(0.0), vec2<f32>(1.0));
        weights.z = w.x;
        weights.w = w.y;
    }
    return weights;
}

@fragment
fn fs_weights(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return weights_px(pos.xy);
}

// ---------------------------------------------------------------------------------------------------------
// Pass 3: neighbourhood blending, in linear light (the colour image holds sRGB-encoded values; the texture is
// Rgba8Unorm, so the shader decodes and re-encodes itself).

// The blended colour of texel `p`; `fs_blend` and `cs_blend` call it.
fn blend_px(p: vec2<i32>) -> vec4<f32> {
    let here = blend_at(p);
    // x: right neighbour's left weight, y: bottom neighbour's top weight, z: own right, w: own top... as in SMAA:
    // a = (right.a, bottom.g, own.b, own.r).
    let a = vec4<f32>(blend_at(p + vec2<i32>(1, 0)).a, blend_at(p + vec2<i32>(0, 1)).g, here.b, here.r);
    let c = color_lin(p);
    if (dot(a, vec4<f32>(1.0)) < 1e-5) {
        return textureLoad(color_tex, p, 0);
    }
    let h = max(a.x, a.z) > max(a.y, a.w);
    var w: vec2<f32>;
    var n0: vec4<f32>;
    var n1: vec4<f32>;
    if (h) {
        w = vec2<f32>(a.x, a.z);
        n0 = color_lin(p + vec2<i32>(1, 0));
        n1 = color_lin(p + vec2<i32>(-1, 0));
    } else {
        w = vec2<f32>(a.y, a.w);
        n0 = color_lin(p + vec2<i32>(0, 1));
        n1 = color_lin(p + vec2<i32>(0, -1));
    }
    let wn = w / (w.x + w.y);
    // Each term is the bilinear fetch of the reference shader at an offset of w.x (w.y) pixels, written out.
    let out = wn.x * mix(c, n0, w.x) + wn.y * mix(c, n1, w.y);
    return vec4<f32>(linear_to_srgb(out.rgb), out.a);
}

@fragment
fn fs_blend(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return blend_px(vec2<i32>(floor(pos.xy)));
}
