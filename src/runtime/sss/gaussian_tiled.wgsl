// Screen-space sum-of-Gaussians SSS (Jimenez, Sundstedt, Gutierrez, ACM TAP 2009; thesis ch. 4, Listing 4.1) as
// compute passes: the arithmetic of `gaussian.wgsl` (stretch of eq. 4.1–4.4, LOD skip of eq. 4.6, 7 taps, the blend
// of eq. 4.8–4.9; CPU twin `sss/gaussian_cpu.rs`), one 1-D blur per dispatch over the line segment a workgroup
// blurs and a 64-texel apron either side, read once into workgroup memory. Taps beyond the apron (a Gaussian
// wider than 64 texels) read the source texture.
//
// Along the pass's axis a tap lands on a texel centre's row or column exactly, so its bilinear fetch is the 1-D lerp
// of two neighbours (clamp to edge), written out in f32 as the CPU twin does (the fragment form filters with the
// sampler, whose weights the hardware may round).
//
// blur_h: source (the input, then RT1) → RT2. blur_v: RT2 → RT1 (unless blend.w = 0: the last Gaussian) and the
// running sum: sum_out = w′·c + (1 − w′)·sum_in (the blend of eq. 4.9, which the fragment form leaves to the
// hardware's constant blend into RTF), sum_in the previous sum (the input for the first Gaussian). A skipped pixel
// (matte or eq. 4.6) copies: RT2 = source, RT1 = RT2, sum_out = sum_in, as the fragment form leaves it untouched.
// The matte is the source's alpha (RT1 and RT2 carry the input's alpha unchanged), so the input is not read again.
//
// Prepended by the host module: Params, P, src_tex, stretch_width and W (gaussian_params.wgsl); depth_tex, out_tex,
// SEGMENT, APRON, SLOTS, tile_color and line_texel (line_tile.wgsl).

@group(0) @binding(4) var sum_in: texture_2d<f32>;
@group(0) @binding(5) var sum_out: texture_storage_2d<rgba16float, write>;

var<workgroup> tile_depth: array<f32, 128>;

// Colour of texel `a` (already clamped to the line) from the tile, or the source beyond it.
fn fetch(a: i32, start: i32, line: i32, horizontal: bool) -> vec3<f32> {
    let k = a - start;
    if (k >= 0 && k < SLOTS) {
        return tile_color[k].rgb;
    }
    return textureLoad(src_tex, line_texel(a, line, horizontal), 0).rgb;
}

// One pixel of a 1-D pass: where it is, the source there and, unless `skipped`, the blurred colour (source alpha).
struct Pixel {
    p: vec2<i32>,
    inside: bool,
    skipped: bool,
    centre: vec4<f32>,
    blurred: vec4<f32>,
}

// Loads the workgroup's segment and apron, then blurs the thread's pixel along the pass's direction (P.blur.zw).
fn blur_line(lid: u32, wid: vec2<u32>) -> Pixel {
    let horizontal = P.blur.z > 0.5;
    let size = vec2<i32>(P.rt.zw);
    let len = select(size.y, size.x, horizontal);
    let inv_len = select(P.rt.y, P.rt.x, horizontal);
    let line = i32(wid.y);
    let start = i32(wid.x) * SEGMENT - APRON;
    for (var k = i32(lid); k < SLOTS; k = k + SEGMENT) {
        tile_color[k] = textureLoad(src_tex, line_texel(clamp(start + k, 0, len - 1), line, horizontal), 0);
    }
    let along = i32(wid.x) * SEGMENT + i32(lid);
    tile_depth[lid] = textureLoad(depth_tex, line_texel(clamp(along, 0, len - 1), line, horizontal), 0).r;
    workgroupBarrier();
    let p = line_texel(along, line, horizontal);
    let centre = tile_color[APRON + i32(lid)];
    var px = Pixel(p, along < len, true, centre, centre);
    if (!px.inside) {
        return px;
    }
    // The fine derivative within the pixel pair (ddx_fine / ddy_fine): segments start at even positions, so the
    // pair is (lid & ~1, lid | 1); past the end the depth is clamped, as `depth_load` clamps.
    let base = i32(lid) & ~1;
    let w = stretch_width(tile_depth[lid], tile_depth[base + 1] - tile_depth[base], centre.a);
    if (w < 0.0) {
        return px;
    }
    // uv along the line, as the fragment form and the CPU twin step it: from centre − width, width/3 per tap.
    let fw = w * inv_len;
    var offset = (f32(along) + 0.5) * inv_len - fw;
    var color = vec3<f32>(0.0);
    for (var i = 0; i < 7; i = i + 1) {
        let x = offset * f32(len) - 0.5;
        let x0 = floor(x);
        let f = x - x0;
        let a0 = i32(x0);
        let c0 = fetch(clamp(a0, 0, len - 1), start, line, horizontal);
        let c1 = fetch(clamp(a0 + 1, 0, len - 1), start, line, horizontal);
        color = color + W[i] * (c0 + (c1 - c0) * f);
        offset = offset + fw / 3.0;
    }
    px.skipped = false;
    px.blurred = vec4<f32>(color, centre.a);
    return px;
}

@compute @workgroup_size(128, 1, 1)
fn blur_h(@builtin(local_invocation_id) lid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let px = blur_line(lid.x, wid.xy);
    if (px.inside) {
        textureStore(out_tex, px.p, px.blurred);
    }
}

@compute @workgroup_size(128, 1, 1)
fn blur_v(@builtin(local_invocation_id) lid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let px = blur_line(lid.x, wid.xy);
    if (!px.inside) {
        return;
    }
    if (P.blend.w > 0.5) {
        textureStore(out_tex, px.p, px.blurred);
    }
    let sum = textureLoad(sum_in, px.p, 0);
    if (px.skipped) {
        textureStore(sum_out, px.p, sum);
        return;
    }
    let w = P.blend.rgb;
    textureStore(sum_out, px.p, vec4<f32>(px.blurred.rgb * w + sum.rgb * (1.0 - w), sum.a)); // eq. 4.9
}
