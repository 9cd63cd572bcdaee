// Screen-space sum-of-Gaussians subsurface scattering (Jimenez, Sundstedt, Gutierrez, "Screen-Space Perceptual
// Rendering of Human Skin", ACM TAP 2009; thesis ch. 4, Listing 4.1). One Gaussian = a horizontal pass (RT1 →
// RT2) and a vertical pass (RT2 → RT1 and, blended with the constant w′ᵢ of eq. 4.8–4.9, into RTF).
// CPU twin: `runtime/sss/gaussian_cpu.rs`.
//
// Stretch (eq. 4.1–4.4): s = α / (d + β·min(|∂d|, γ)) · a(x, y), a = alpha of the diffuse image (local SSS level;
// 0 = not skin, the matte). ∂d is the fine screen-space derivative of the quad (ddx/ddy) written out with loads so
// that it is deterministic. Depth LOD (eq. 4.6): the Gaussian is skipped where d ≥ lod·sqrt(vᵢ)·α (lod = 2 is the
// exact half-pixel rule; the thesis ships 0.5). A skipped pixel is left untouched by the vertical pass (the
// thesis uses the depth test); the horizontal pass copies it so RT2 never holds stale texels.
//
// Prepended by the host module: Params, P, src_tex, stretch_width and W (gaussian_params.wgsl); vs_fullscreen
// (../fullscreen.wgsl); depth_tex, lin, depth_load (frame.wgsl).

@group(0) @binding(3) var matte_tex: texture_2d<f32>;

struct VOut {
    @location(0) rt1: vec4<f32>,
    @location(1) rtf: vec4<f32>,
}

// Fine derivative along `dir` within the 2×2 quad, like ddx_fine / ddy_fine.
fn depth_derivative(p: vec2<i32>, dir: vec2<i32>) -> f32 {
    let base = p - dir * ((p.x * dir.x + p.y * dir.y) & 1);
    return depth_load(base + dir) - depth_load(base);
}

// Returns the blur step (uv per tap) or a negative x when the pixel is skipped.
fn stretch_step(p: vec2<i32>) -> vec2<f32> {
    let d = depth_load(p);
    let a = textureLoad(matte_tex, p, 0).a;
    let dir = vec2<i32>(P.blur.zw);
    let w = stretch_width(d, depth_derivative(p, dir), a);
    if (w < 0.0) {
        return vec2<f32>(-1.0, 0.0);
    }
    let final_width = w * P.rt.xy * P.blur.zw;
    return final_width;
}

fn blur(p: vec2<i32>, pos: vec2<f32>, final_width: vec2<f32>) -> vec4<f32> {
    var offset = pos * P.rt.xy - final_width;
    var color = vec3<f32>(0.0);
    for (var i = 0; i < 7; i = i + 1) {
        color = color + W[i] * textureSampleLevel(src_tex, lin, offset, 0.0).rgb;
        offset = offset + final_width / 3.0;
    }
    return vec4<f32>(color, textureLoad(src_tex, p, 0).a);
}

@fragment
fn fs_horizontal(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(floor(pos.xy));
    let fw = stretch_step(p);
    if (fw.x < 0.0) {
        return textureLoad(src_tex, p, 0);
    }
    return blur(p, pos.xy, fw);
}

@fragment
fn fs_vertical(@builtin(position) pos: vec4<f32>) -> VOut {
    let p = vec2<i32>(floor(pos.xy));
    let fw = stretch_step(p);
    if (fw.x < 0.0) {
        discard;
    }
    let c = blur(p, pos.xy, fw);
    return VOut(c, c);
}
