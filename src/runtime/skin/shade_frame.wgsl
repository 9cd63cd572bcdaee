// The skin frame's shading on the GPU, between the passes that stay where they are (runtime/skin/shade_frame.rs):
// lit (the diffuse layer from the skin-inputs pass, lighting.rs `lit_geometry`), pack (that layer as the SSS pass's
// Rgba16Float input, rows padded for a buffer-to-texture copy), composite (post-scatter albedo and the unblurred
// specular layer, the background's linear radiance for bloom, lighting.rs `composite`) and tonemap (1 - e^-L on the
// luminance, sRGB encode, the bloomed background re-encoded) and, with MSAA, coverage (partly covered pixels blended
// with the background in linear light, heads.rs `blend_coverage`). Prepended: aa/srgb.wgsl (the sRGB transfer
// functions, LUMA). CPU twin: lighting.rs, the same f32 arithmetic in the same order.

struct Params {
    // width, height, u32 per padded row of an Rgba16Float image, post-scatter albedo (1) or not (0)
    size: vec4<f32>,
    // direction to the key light (view space, unit), albedo map (1) or the skin LUT's (0)
    key: vec4<f32>,
    // key-light intensity, back-light intensity, bloom (1) or not, SSS pass (1) or not
    cfg: vec4<f32>,
    // the background colour (sRGB-encoded, 0..1), coverage blend (1) or not (0)
    cover: vec4<f32>,
    // The uniform background colour (sRGB, alpha) the `background` entry point fills the frame with.
    fill: vec4<f32>,
};

@group(0) @binding(0) var<uniform> p: Params;
// The skin-inputs pass's albedo (rgb, H) then its transmitted light (T(s)·E, E): Rgba16Float rows as copied from
// the textures (two halves per u32, rows padded).
@group(0) @binding(1) var<storage, read_write> skin16: array<u32>;
// Per pixel two vec4: (view-space normal, skin 1/0), (albedo from the map, specular radiance).
@group(0) @binding(2) var<storage, read_write> geo: array<vec4<f32>>;
// The lit diffuse layer, RGBA f32 (alpha = SSS strength).
@group(0) @binding(3) var<storage, read_write> diffuse: array<vec4<f32>>;
// The SSS pass's input, then (copied back) its output: Rgba16Float rows, padded.
@group(0) @binding(4) var<storage, read_write> sss16: array<u32>;
// The HDR frame before bloom, RGBA f32.
@group(0) @binding(5) var<storage, read_write> hdr: array<vec4<f32>>;
// Bloom's result (rgb), when bloom runs.
@group(0) @binding(6) var<storage, read_write> bloomed: array<vec4<f32>>;
// The background in, the frame out: RGBA8 (sRGB-encoded) packed little-endian.
@group(0) @binding(7) var<storage, read_write> rgba: array<u32>;
// Per pixel (u, v, covered, coverage) of the device's G-buffer, when the coverage blend runs.
@group(0) @binding(8) var<storage, read_write> cover: array<vec4<f32>>;

// The pixel of this invocation, or false outside the frame.
fn pixel(id: vec3<u32>) -> vec2<u32> {
    return vec2<u32>(id.y * u32(p.size.x) + id.x, select(0u, 1u, id.x < u32(p.size.x) && id.y < u32(p.size.y)));
}

// Index of the first u32 of texel (x, y) of half-float image k in a padded buffer.
fn half_at(k: u32, id: vec3<u32>) -> u32 {
    let row = u32(p.size.z);
    return (k * u32(p.size.y) + id.y) * row + 2u * id.x;
}

fn load16(k: u32, id: vec3<u32>) -> vec4<f32> {
    let j = half_at(k, id);
    return vec4<f32>(unpack2x16float(skin16[j]), unpack2x16float(skin16[j + 1u]));
}

fn albedo_at(i: u32, id: vec3<u32>) -> vec3<f32> {
    if (p.key.w > 0.5) {
        return geo[2u * i + 1u].xyz;
    }
    return load16(0u, id).xyz;
}

@compute @workgroup_size(8, 8, 1)
fn lit(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = pixel(id);
    if (px.y == 0u) {
        return;
    }
    let i = px.x;
    let g = geo[2u * i];
    if (g.w < 0.5) {
        diffuse[i] = vec4<f32>(0.0);
        return;
    }
    let lambert = max(g.x * p.key.x + g.y * p.key.y + g.z * p.key.z, 0.0);
    let e = p.cfg.x * lambert + 0.1;
    let light = vec3<f32>(e) + p.cfg.y * load16(1u, id).xyz;
    var c = light;
    if (p.size.w < 0.5) {
        c = albedo_at(i, id) * light;
    }
    diffuse[i] = vec4<f32>(c, 1.0);
}

@compute @workgroup_size(8, 8, 1)
fn pack(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = pixel(id);
    if (px.y == 0u) {
        return;
    }
    let v = diffuse[px.x];
    let j = half_at(0u, id);
    sss16[j] = pack2x16float(v.xy);
    sss16[j + 1u] = pack2x16float(v.zw);
}

// The RGBA8 frame filled with the uniform background colour (the frame's buffer is reused across frames: it holds
// a former frame until this runs).
@compute @workgroup_size(8, 8, 1)
fn background(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = pixel(id);
    if (px.y == 0u) {
        return;
    }
    rgba[px.x] = pack4x8unorm(p.fill);
}

fn background_linear(i: u32) -> vec3<f32> {
    let c = unpack4x8unorm(rgba[i]);
    return srgb_to_linear(c.xyz);
}

@compute @workgroup_size(8, 8, 1)
fn composite(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = pixel(id);
    if (px.y == 0u) {
        return;
    }
    let i = px.x;
    if (geo[2u * i].w < 0.5) {
        // The background enters bloom as its linear radiance.
        hdr[i] = select(vec4<f32>(0.0), vec4<f32>(background_linear(i), 0.0), p.cfg.z > 0.5);
        return;
    }
    var blurred = diffuse[i].xyz;
    if (p.cfg.w > 0.5) {
        let j = half_at(0u, id);
        blurred = vec3<f32>(unpack2x16float(sss16[j]), unpack2x16float(sss16[j + 1u]).x);
    }
    if (p.size.w > 0.5) {
        blurred = blurred * albedo_at(i, id);
    }
    hdr[i] = vec4<f32>(blurred + vec3<f32>(geo[2u * i + 1u].w), 0.0);
}

fn unorm8(v: vec3<f32>) -> vec3<u32> {
    return vec3<u32>(round(clamp(v, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0));
}

@compute @workgroup_size(8, 8, 1)
fn tonemap(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = pixel(id);
    if (px.y == 0u) {
        return;
    }
    let i = px.x;
    var v = hdr[i].xyz;
    if (p.cfg.z > 0.5) {
        v = bloomed[i].xyz;
    }
    let old = rgba[i];
    if (geo[2u * i].w < 0.5) {
        // The background is display-referred: re-encoded only where bloom added light to it.
        if (p.cfg.z > 0.5 && any(v != hdr[i].xyz)) {
            let c = unorm8(linear_to_srgb(clamp(v, vec3<f32>(0.0), vec3<f32>(1.0))));
            rgba[i] = c.x | (c.y << 8u) | (c.z << 16u) | (old & 0xff000000u);
        }
        return;
    }
    // Tone map the luminance (1 - e^-L), keeping the channel ratios.
    let l = dot(LUMA, v);
    let scale = select(0.0, (1.0 - exp(-l)) / l, l > 0.0);
    let c = unorm8(linear_to_srgb(min(v * scale, vec3<f32>(1.0))));
    rgba[i] = c.x | (c.y << 8u) | (c.z << 16u) | 0xff000000u;
}

// MSAA: the tone-mapped skin of a partly covered pixel blended with the background by its coverage, in linear light.
@compute @workgroup_size(8, 8, 1)
fn coverage(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = pixel(id);
    if (px.y == 0u) {
        return;
    }
    let i = px.x;
    let c = cover[i].w;
    if (c <= 0.0 || c >= 1.0) {
        return;
    }
    let old = rgba[i];
    let skin = srgb_to_linear(unpack4x8unorm(old).xyz);
    let bg = srgb_to_linear(p.cover.xyz);
    let v = unorm8(linear_to_srgb(c * skin + (1.0 - c) * bg));
    rgba[i] = v.x | (v.y << 8u) | (v.z << 16u) | (old & 0xff000000u);
}
