// The per-pixel geometry of a `run skin` frame from its G-buffer and the back light's shadow map, on the device
// (runtime/skin/frame_geometry.rs), in f32: the same formulas as the CPU code it twins (runtime/skin/heads.rs:
// `geometry`'s per-pixel loop, `thickness_mm` and `ShadowMap::thickness_mm` of thesis Listing 5.1,
// `specular_layer_lit` with the Kelemen/Szirmay-Kalos specular of shading/kelemen.rs). With 4x MSAA the resolved
// G-buffer is divided by its coverage as runtime/skin/mesh_raster.rs `resolve_coverage` does; with a scan's
// surface maps or the wrinkle pass, `unpack` first writes the per-pixel frame those passes read and `main` takes its
// normals from `nrm` (what they leave there) and the albedo map from `geo`.

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
    // normals from `nrm` (1) or the G-buffer (0); albedo map in `geo` (1) or none (0); resolved MSAA (1) or one
    // sample (0); 0
    surf: vec4<f32>,
};

@group(0) @binding(0) var<uniform> p: Params;
// Rgba16Float G-buffer targets copied with padded rows: (normal, depth mm), then (u, v, covered, 0) after
// `size.y` rows, then (with `unpack`) the tangent; two u32 words per texel.
@group(0) @binding(1) var<storage, read_write> view_g: array<u32>;
@group(0) @binding(2) var<storage, read_write> shadow_g: array<u32>;
// Outputs: (u, v, covered, coverage) per pixel; skin-inputs maps (Cm, H0, thickness mm, 0) and normals, padded
// rows (`unpack` leaves the per-pixel view tangent in `normals` for the surface and wrinkle passes, which `main`
// then overwrites); per pixel (normal, skin), (albedo, specular); the SSS pass's linear depth, padded rows.
@group(0) @binding(3) var<storage, read_write> uvc: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> skin_maps: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> normals: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> geo: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> depth: array<f32>;
// The view normal per pixel (normal, 0): written by `unpack`, replaced by the surface and wrinkle passes.
@group(0) @binding(8) var<storage, read_write> nrm: array<vec4<f32>>;

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

// A pixel of the view's G-buffer: covered, its coverage, view normal, depth (mm), uv.
struct GPixel {
    covered: bool,
    cov: f32,
    n: vec3<f32>,
    depth_mm: f32,
    uv: vec2<f32>,
};

// Pixel (x, y) of the G-buffer, decoded as mesh_raster.rs `decode` does (one sample: the texels as stored) or, for
// a resolved MSAA G-buffer, as `resolve_coverage` does (the attributes divided by the coverage, the normal
// renormalised).
fn gpixel(x: u32, y: u32) -> GPixel {
    let row = u32(p.rows.x);
    let a = texel(0u, row, x, y, true);
    let b = texel(row * u32(p.size.y), row, x, y, true);
    var g: GPixel;
    if (p.surf.z < 0.5) {
        g.covered = b.z > 0.5;
        g.cov = 1.0;
        g.n = a.xyz;
        g.depth_mm = a.w;
        g.uv = b.xy;
        return g;
    }
    let cov = b.z;
    g.cov = cov;
    if (cov <= 0.0) {
        g.covered = false;
        return g;
    }
    let n = a.xyz / cov;
    let len = sqrt(dot(n, n));
    // Not covered where the length is zero or NaN.
    g.covered = len > 0.0;
    g.n = n / len;
    g.depth_mm = a.w / cov;
    g.uv = b.xy / cov;
    return g;
}

// The per-pixel frame the surface-map and wrinkle passes read (view_frame.wgsl): (u, v, covered, coverage) in
// `uvc`, the view normal in `nrm`, the view tangent (divided by the coverage with MSAA) in `normals`; zeros off
// the mesh, as the host's G-buffer holds.
@compute @workgroup_size(8, 8, 1)
fn unpack(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(p.size.x);
    let h = u32(p.size.y);
    if (id.x >= w || id.y >= h) {
        return;
    }
    let i = id.y * w + id.x;
    let g = gpixel(id.x, id.y);
    if (!g.covered) {
        uvc[i] = vec4<f32>(0.0);
        nrm[i] = vec4<f32>(0.0);
        normals[i] = vec4<f32>(0.0);
        return;
    }
    let row = u32(p.rows.x);
    var t = texel(2u * row * h, row, id.x, id.y, true);
    if (p.surf.z > 0.5) {
        t = t / g.cov;
    }
    uvc[i] = vec4<f32>(g.uv, 1.0, g.cov);
    nrm[i] = vec4<f32>(g.n, 0.0);
    normals[i] = t;
}

// The surface-map pass's normals (per pixel (normal, 0), (albedo, 0) in `geo`) into `nrm`, for the wrinkle pass
// and `main`.
@compute @workgroup_size(8, 8, 1)
fn take_normals(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(p.size.x);
    if (id.x >= w || id.y >= u32(p.size.y)) {
        return;
    }
    let i = id.y * w + id.x;
    nrm[i] = vec4<f32>(geo[2u * i].xyz, 0.0);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(p.size.x);
    let h = u32(p.size.y);
    if (id.x >= w || id.y >= h) {
        return;
    }
    let i = id.y * w + id.x;
    let g = gpixel(id.x, id.y);
    let out = id.y * u32(p.rows.z) + id.x;
    let out_depth = id.y * u32(p.rows.w) + id.x;
    if (!g.covered) {
        uvc[i] = vec4<f32>(0.0);
        skin_maps[out] = vec4<f32>(0.0, 0.0, p.cfg.w, 0.0);
        normals[out] = vec4<f32>(0.0, 0.0, 1.0, 0.0);
        geo[2u * i] = vec4<f32>(0.0, 0.0, 1.0, 0.0);
        geo[2u * i + 1u] = vec4<f32>(0.0);
        depth[out_depth] = 100.0;
        return;
    }
    var nv = g.n;
    if (p.surf.x > 0.5) {
        nv = nrm[i].xyz;
    }
    // The view ray through the pixel's centre at view depth 1 (heads.rs `view_ray`).
    let t = p.size.w;
    let xn = (f32(id.x) + 0.5) / p.size.x * 2.0 - 1.0;
    let yn = 1.0 - (f32(id.y) + 0.5) / p.size.y * 2.0;
    let ray = vec3<f32>(xn * t * (p.size.x / p.size.y), yn * t, -1.0);
    let dist = g.depth_mm / p.cfg.x;
    let pw = p.inv_view * vec4<f32>(ray.x * dist, ray.y * dist, -dist, 1.0);
    let nw = p.inv_view * vec4<f32>(nv, 0.0);
    let thickness = min(thickness_mm(pw.xyz, nw.xyz), p.cfg.w);
    var h0 = 0.0;
    if (p.misc.x < 0.5) {
        h0 = 0.006 * (sin(g.uv.x * 400.0) * cos(g.uv.y * 300.0));
    }
    let v = normalize(vec3<f32>(-ray.x, -ray.y, 1.0));
    let spec = p.key.w * kelemen(nv, p.key.xyz, v);
    var albedo = vec3<f32>(0.0);
    if (p.surf.y > 0.5) {
        albedo = geo[2u * i + 1u].xyz;
    }
    uvc[i] = vec4<f32>(g.uv, 1.0, g.cov);
    skin_maps[out] = vec4<f32>(p.cfg.z, h0, thickness, 0.0);
    normals[out] = vec4<f32>(nv, 0.0);
    geo[2u * i] = vec4<f32>(nv, 1.0);
    geo[2u * i + 1u] = vec4<f32>(albedo, spec);
    depth[out_depth] = g.depth_mm / 1000.0 * p.misc.y;
}
