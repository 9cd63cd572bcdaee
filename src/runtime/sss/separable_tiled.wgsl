// Separable subsurface scattering (Jimenez et al., "Separable Subsurface Scattering", CGF 2015; thesis ch. 6) as a
// compute pass: the same arithmetic as `separable.wgsl` (CPU twin `sss/separable_cpu.rs`), one 1-D pass per
// dispatch (dir = (1, 0) then (0, 1)), with the line segment a workgroup blurs and an apron either side read once
// into workgroup memory. A pass moves each texel of colour and depth in and of the result out once; taps beyond the
// apron (a wide kernel close to the camera) read the textures directly.
//
// Along the pass's axis a tap lands at a texel centre's row or column exactly, so its bilinear fetch is the 1-D
// lerp of two neighbours (clamp to edge), written out in f32 for colour and depth alike.
//
// Prepended by the host module: Params, P and color_tex (separable_params.wgsl); depth_tex, out_tex, SEGMENT, APRON,
// SLOTS, tile_color and line_texel (line_tile.wgsl).

var<workgroup> tile_depth: array<f32, 256>;

// The texel at position `along` of line `line` of the pass's axis.
fn texel(along: i32, line: i32) -> vec2<i32> {
    return line_texel(along, line, P.dir.x > 0.5);
}

struct Fetch {
    color: vec3<f32>,
    depth: f32,
}

// Colour and depth of texel `a` (already clamped to the line) from the tile, or the textures beyond it.
fn fetch(a: i32, start: i32, line: i32) -> Fetch {
    let k = a - start;
    if (k >= 0 && k < SLOTS) {
        return Fetch(tile_color[k].rgb, tile_depth[k]);
    }
    let p = texel(a, line);
    return Fetch(textureLoad(color_tex, p, 0).rgb, textureLoad(depth_tex, p, 0).r);
}

@compute @workgroup_size(128, 1, 1)
fn blur(@builtin(local_invocation_id) lid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let size = vec2<i32>(P.rt.zw);
    let horizontal = P.dir.x > 0.5;
    let len = select(size.y, size.x, horizontal);
    let line = i32(wid.y);
    let start = i32(wid.x) * SEGMENT - APRON;
    for (var k = i32(lid.x); k < SLOTS; k = k + SEGMENT) {
        let p = texel(clamp(start + k, 0, len - 1), line);
        tile_color[k] = textureLoad(color_tex, p, 0);
        tile_depth[k] = textureLoad(depth_tex, p, 0).r;
    }
    workgroupBarrier();
    let along = i32(wid.x) * SEGMENT + i32(lid.x);
    if (along >= len) {
        return;
    }
    let p = texel(along, line);
    let color_m = tile_color[APRON + i32(lid.x)];
    let strength = color_m.a;
    if (strength == 0.0) {
        textureStore(out_tex, p, color_m);
        return;
    }
    let depth_m = tile_depth[APRON + i32(lid.x)];
    let dist_to_window = P.cfg.y;
    // The step in uv (as `separable.wgsl`) times the line's length: texels per kernel unit.
    let step_texels = P.cfg.x * (dist_to_window / depth_m) * strength * (1.0 / 3.0) * f32(len);
    let follow = P.cfg.z > 0.5;
    let follow_scale = 300.0 * dist_to_window * P.cfg.x;
    var blurred = color_m.rgb * P.taps[0].rgb;
    let n = i32(P.cfg.w);
    for (var i = 1; i < n; i = i + 1) {
        // Texel-centre coordinates: the centre of `along` is along + 0.5; the bilinear origin is 0.5 below.
        let x = f32(along) + P.taps[i].a * step_texels;
        let x0 = floor(x);
        let f = x - x0;
        let a0 = i32(x0);
        let s0 = fetch(clamp(a0, 0, len - 1), start, line);
        let s1 = fetch(clamp(a0 + 1, 0, len - 1), start, line);
        var c = s0.color + (s1.color - s0.color) * f;
        if (follow) {
            let d = s0.depth + (s1.depth - s0.depth) * f;
            let s = clamp(follow_scale * abs(depth_m - d), 0.0, 1.0);
            c = mix(c, color_m.rgb, s);
        }
        blurred = blurred + P.taps[i].rgb * c;
    }
    textureStore(out_tex, p, vec4<f32>(blurred, color_m.a));
}
