// Importance-sampled screen-space subsurface scattering: one pass over an N-sample disk kernel drawn from the
// profile's radial CDF (the sampling of Unity HDRP's diffusion profiles; Golubev, SIGGRAPH 2018 course "Advances in
// Real-Time Rendering"). CPU twin: `runtime/sss/importance_cpu.rs`; algorithm in `runtime/sss/importance.rs`.
//
// offset (pixels) = (x, y)mm · strength · (H/2)·(1/tan(0.5·FOVy)) / (depth · mm_per_world_unit), strength = colour
// alpha (0: not skin, the pixel passes through). Follow-surface: s = saturate(|Δdepth|·mm_per_world_unit/cutoff_mm),
// sample = mix(sample, centre, s). Colour rgba16float filtered by the sampler; depth r32float loaded four times.
// Two shapes of one per-pixel function (`blur_px`): a full-screen fragment pass (`fs_blur`) or a compute pass
// (`cs_blur`, into a storage texture); both sample through the same sampler, so they write the same bytes.
//
// Prepended by the host module: vs_fullscreen (../fullscreen.wgsl); depth_tex, lin, depth_load and depth_at
// (frame.wgsl).

struct Params {
    // (1/width, 1/height, width, height)
    rt: vec4<f32>,
    // x: (H/2)·(1/tan(0.5·FOVy))/mm_per_world_unit, y: mm_per_world_unit/cutoff_mm, z: follow surface (0/1),
    // w: number of samples
    cfg: vec4<f32>,
    // sample i: [2i] = (x mm, y mm, r mm, 0), [2i + 1] = (w_r, w_g, w_b, 0)
    samples: array<vec4<f32>, 2048>,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var color_tex: texture_2d<f32>;

@group(0) @binding(3) var out_tex: texture_storage_2d<rgba16float, write>;

// The pass at texel `p`, shared by both shapes (the fragment's position is the texel centre, p + 0.5).
fn blur_px(p: vec2<i32>) -> vec4<f32> {
    let pos = vec2<f32>(p) + vec2<f32>(0.5, 0.5);
    let color_m = textureLoad(color_tex, p, 0);
    let strength = color_m.a;
    if (strength == 0.0) {
        return color_m;
    }
    let depth_m = textureLoad(depth_tex, p, 0).r;
    let px_per_mm = P.cfg.x * strength / depth_m;
    var blurred = vec3<f32>(0.0, 0.0, 0.0);
    let n = i32(P.cfg.w);
    for (var i = 0; i < n; i = i + 1) {
        let o = P.samples[2 * i];
        let w = P.samples[2 * i + 1];
        let uv = (pos + o.xy * px_per_mm) * P.rt.xy;
        var c = textureSampleLevel(color_tex, lin, uv, 0.0).rgb;
        if (P.cfg.z > 0.5) {
            let d = depth_at(uv);
            let s = clamp(abs(depth_m - d) * P.cfg.y, 0.0, 1.0);
            c = mix(c, color_m.rgb, s);
        }
        blurred = blurred + w.rgb * c;
    }
    return vec4<f32>(blurred, color_m.a);
}

@fragment
fn fs_blur(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return blur_px(vec2<i32>(floor(pos.xy)));
}

// The compute shape: 8×8 pixels per workgroup, the samples through the sampler and the texture cache as in the
// fragment pass (a 2-D gather whose reach, up to the kernel's cut-off radius at the pixel's depth, is far wider than
// a workgroup tile could hold).
@compute @workgroup_size(8, 8, 1)
fn cs_blur(@builtin(global_invocation_id) id: vec3<u32>) {
    let p = vec2<i32>(id.xy);
    if (any(p >= vec2<i32>(P.rt.zw))) {
        return;
    }
    textureStore(out_tex, p, blur_px(p));
}
