// The per-pixel geometry of a `run skin` frame from its G-buffer and the back light's shadow map, on the device
// (runtime/skin/frame_geometry.rs), in f32: the same formulas as the CPU code it twins (runtime/skin/heads.rs:
// `geometry`'s per-pixel loop, `thickness_mm` and `ShadowMap::thickness_mm` of thesis Listing 5.1,
// `specular_layer_lit` with the Kelemen/Szirmay-Kalos specular of shading/kelemen.rs).

struct Params {
    // view → world
    inv_view: mat4x4<f32>,
    // the light camera's view-projection and view
    light_vp: mat4x4<f32>,
    light_view: mat4x4<f32>,
    // frame width, height, shadow-map size, tan(fov_y / 2)
    size: vec4<f32>,
    // row strides: G-buffer words (u32) of the view, of the shadow map, vec4 texels of the skin maps and normals,
    // f32 texels of the SSS depth
    rows: vec4<f32>,
    // mm per mesh unit, the shrink along the normal (mm), melanin Cm, s_max (mm)
    cfg: vec4<f32>,
    // key light direction (view space, unit), its intensity
    key: vec4<f32>,
    // 1: the rig's hemoglobin is written later (H0 0 here), 0: the procedural H0; view-depth world units per m
    misc: vec4<f32>,
};

@group(0) @binding(0) var<uniform> p: Params;
// Rgba16Float G-buffer targets copied with padded rows: (normal, depth mm), then (u, v, covered, 0) after
// `size.y` rows; two u32 words per texel.
@group(0) @binding(1) var<storage, read_write> view_g: array<u32>;
@group(0) @binding(2) var<storage, read_write> shadow_g: array<u32>;
// Outputs: (u, v, covered, 0) per pixel; skin-inputs maps (Cm, H0, thickness mm, 0) and normals, padded rows;
// per pixel (normal, skin), (albedo 0, specular); the SSS pass's linear depth, padded rows.
@group(0) @binding(3) var<storage, read_write> uvc: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> skin_maps: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> normals: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> geo: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> depth: array<f32>;

fn texel(words: u32, row_words: u32, x: u32, y: u32, buf_is_view: bool) -> vec4<f32> {
    let k = words + y * row_words + 2u * x;
    var a: u32;
    var b: u32;
    if (buf_is_view) {
        a = view_g[k];
        b = view_g[k + 1u];
    } else {
        a = shadow_g[k];
        b = shadow_g[k + 1u];
    }
    return vec4<f32>(unpack2x16float(a), unpack2x16float(b));
}

// ShadowMap::thickness_mm: Listing 5.1 at the world point `pw` with unit normal `nw` (mesh units).
fn thickness_mm(pw: vec3<f32>, nw: vec3<f32>) -> f32 {
    let shrink = p.cfg.y / p.cfg.x;
    let q = vec4<f32>(pw - nw * shrink, 1.0);
    let c = p.light_vp * q;
    let s = p.size.z;
    let sx = (c.x / c.w * 0.5 + 0.5) * s;
    let sy = (0.5 - c.y / c.w * 0.5) * s;
    let d_light_mm = -(p.light_view * q).z * p.cfg.x;
    let ix = floor(sx);
    let iy = floor(sy);
    if (ix < 0.0 || iy < 0.0 || ix >= s || iy >= s) {
        return 0.0;
    }
    let row = u32(p.rows.y);
    let n = u32(s);
    let d = texel(0u, row, u32(ix), u32(iy), false);
    let cover = texel(row * n, row, u32(ix), u32(iy), false);
    if (cover.z <= 0.5) {
        return 0.0;
    }
    return max(d_light_mm - d.w, 0.0);
}

// shading/kelemen.rs `specular` with skin's m = 0.3, rho_s = 0.18, F0 = 0.028.
fn kelemen(n: vec3<f32>, l: vec3<f32>, v: vec3<f32>) -> f32 {
    let n_dot_l = dot(n, l);
    if (n_dot_l <= 0.0) {
        return 0.0;
    }
    let h = l + v;
    let hh = dot(h, h);
    if (hh <= 1e-12) {
        return 0.0;
    }
    let hn = h * (1.0 / sqrt(hh));
    let n_dot_h = dot(n, hn);
    var d = 0.0;
    if (n_dot_h > 0.0) {
        let m = 0.3;
        let c2 = n_dot_h * n_dot_h;
        let tan2 = (1.0 - c2) / c2;
        d = exp(-tan2 / (m * m)) / (m * m * c2 * c2);
    }
    let base = 1.0 - clamp(dot(hn, v), 0.0, 1.0);
    let f = 0.028 + (1.0 - 0.028) * (base * base * base * base * base);
    return max(0.18 * n_dot_l * d * f / hh, 0.0);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(p.size.x);
    let h = u32(p.size.y);
    if (id.x >= w || id.y >= h) {
        return;
    }
    let i = id.y * w + id.x;
    let row = u32(p.rows.x);
    let a = texel(0u, row, id.x, id.y, true);
    let b = texel(row * h, row, id.x, id.y, true);
    let out = id.y * u32(p.rows.z) + id.x;
    let out_depth = id.y * u32(p.rows.w) + id.x;
    if (b.z <= 0.5) {
        uvc[i] = vec4<f32>(0.0);
        skin_maps[out] = vec4<f32>(0.0, 0.0, p.cfg.w, 0.0);
        normals[out] = vec4<f32>(0.0, 0.0, 1.0, 0.0);
        geo[2u * i] = vec4<f32>(0.0, 0.0, 1.0, 0.0);
        geo[2u * i + 1u] = vec4<f32>(0.0);
        depth[out_depth] = 100.0;
        return;
    }
    let nv = a.xyz;
    // The view ray through the pixel's centre at view depth 1 (heads.rs `view_ray`).
    let t = p.size.w;
    let xn = (f32(id.x) + 0.5) / p.size.x * 2.0 - 1.0;
    let yn = 1.0 - (f32(id.y) + 0.5) / p.size.y * 2.0;
    let ray = vec3<f32>(xn * t * (p.size.x / p.size.y), yn * t, -1.0);
    let dist = a.w / p.cfg.x;
    let pw = p.inv_view * vec4<f32>(ray.x * dist, ray.y * dist, -dist, 1.0);
    let nw = p.inv_view * vec4<f32>(nv, 0.0);
    let thickness = min(thickness_mm(pw.xyz, nw.xyz), p.cfg.w);
    var h0 = 0.0;
    if (p.misc.x < 0.5) {
        h0 = 0.006 * (sin(b.x * 400.0) * cos(b.y * 300.0));
    }
    let v = normalize(vec3<f32>(-ray.x, -ray.y, 1.0));
    let spec = p.key.w * kelemen(nv, p.key.xyz, v);
    uvc[i] = vec4<f32>(b.x, b.y, 1.0, 0.0);
    skin_maps[out] = vec4<f32>(p.cfg.z, h0, thickness, 0.0);
    normals[out] = vec4<f32>(nv, 0.0);
    geo[2u * i] = vec4<f32>(nv, 1.0);
    geo[2u * i + 1u] = vec4<f32>(0.0, 0.0, 0.0, spec);
    depth[out_depth] = a.w / 1000.0 * p.misc.y;
}
