// Separable subsurface scattering (Jimenez, Zsolnai, Jarabo, Freude, Auzinger, Wu, von der Pahlen, Wimmer,
// Gutierrez, "Separable Subsurface Scattering", Computer Graphics Forum 2015; thesis ch. 6), one 1-D pass.
// Run twice: dir = (1, 0) then (0, 1). CPU twin: `runtime/sss/separable_cpu.rs`.
//
// step (uv) = sssWidth · (1/tan(0.5·FOVy)) / depth · dir · strength / 3, strength = colour alpha (0: not skin,
// the pixel passes through unchanged — the matte). Follow-surface: s = saturate(300 · (1/tan(0.5·FOVy)) ·
// sssWidth · |Δdepth|), tap = lerp(tap, centre, s). Kernel: N taps (rgb weight, a offset), centre first.
// Colour: rgba16float, linear, filtered by the sampler; depth: r32float (not filterable without
// FLOAT32_FILTERABLE), so its bilinear fetch is written out with four loads.
//
// Prepended by the host module: Params, P and color_tex (separable_params.wgsl), vs_fullscreen
// (../fullscreen.wgsl); depth_tex, lin, depth_load and depth_at (frame.wgsl).

@fragment
fn fs_blur(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(floor(pos.xy));
    let uv = pos.xy * P.rt.xy;
    let color_m = textureLoad(color_tex, p, 0);
    let strength = color_m.a;
    if (strength == 0.0) {
        return color_m;
    }
    let depth_m = textureLoad(depth_tex, p, 0).r;
    let dist_to_window = P.cfg.y;
    let scale = dist_to_window / depth_m;
    let final_step = P.cfg.x * scale * P.dir.xy * strength * (1.0 / 3.0);
    var blurred = color_m.rgb * P.taps[0].rgb;
    let n = i32(P.cfg.w);
    for (var i = 1; i < n; i = i + 1) {
        let offset = uv + P.taps[i].a * final_step;
        var c = textureSampleLevel(color_tex, lin, offset, 0.0).rgb;
        if (P.cfg.z > 0.5) {
            let d = depth_at(offset);
            let s = clamp(300.0 * dist_to_window * P.cfg.x * abs(depth_m - d), 0.0, 1.0);
            c = mix(c, color_m.rgb, s);
        }
        blurred = blurred + P.taps[i].rgb * c;
    }
    return vec4<f32>(blurred, color_m.a);
}
