// Texture-space diffusion recorded into the frame's command encoder (runtime/skin/texture_space.rs
// `one_encoder::render`; d'Eon et al. 2007, thesis ch. 3). Two entry points around the skin-inputs pass, the lit
// stage (shade_frame.wgsl) and the blurs (texture_space.wgsl) of one head:
// - `texels`: each texel of the head's irradiance map as those passes read it: its view-space normal (with a scan's
//   normal map, the one surface_maps.wgsl bent in the texel's MikkTSpace frame) and the thickness the back light
//   crosses to reach its surface point (Listing 5.1, the shadow map of the frame's geometry), alpha 1 on shaded texels and 0 on uncovered, culled (N·V < cos 105°, Listing 3.2) and clipped (outside
//   the view frustum, eq. 3.3–3.4) ones, with the counts of each;
// - `gather`: the head's weighted sum of blurs at each of its pixels' uv (bilinear, normalised by alpha) replaces
//   the pixel's unblurred diffuse where a shaded texel is in reach.
// The host twin is texture_space.rs `render_with`'s per-texel loop and texture_space_cpu.rs `gather`, in f32.
// Prepended: bilinear_taps.wgsl.

struct Params {
    // world → view, view → world
    view: mat4x4<f32>,
    inv_view: mat4x4<f32>,
    // the back light camera's view-projection and view (heads.rs `light_camera`)
    light_vp: mat4x4<f32>,
    light_view: mat4x4<f32>,
    // the six frustum planes in eye space (A, B, C, D)
    planes: array<vec4<f32>, 6>,
    // the eye (world, mesh units), 0
    eye: vec4<f32>,
    // map size (texels), frame width, height, tan(fov_y / 2)
    size: vec4<f32>,
    // mm per mesh unit, the shadow lookup's shrink along the normal (mm), melanin Cm, s_max (mm)
    cfg: vec4<f32>,
    // this head's x offset, the spacing of the heads (mesh units), the centre index, the last head's index
    head: vec4<f32>,
    // cull (1/0), clip (1/0), cos of the culling angle, view-depth world units per m
    flags: vec4<f32>,
    // vec4 per padded row of the texel maps, f32 per padded row of the SSS depth, shadow-map size, u32 per
    // padded row of the shadow map
    rows: vec4<f32>,
    // x: the texels' normals bent by a normal map, read from `mapped` (1), or the UV map's (0); 0, 0, 0
    maps: vec4<f32>,
    // x: the head's index
    stage: vec4<u32>,
};

@group(0) @binding(0) var<uniform> p: Params;
// Per texel of the UV map (cached per mesh and size): (position, covered), (normal, 0), world / mesh units.
@group(0) @binding(1) var<storage, read_write> uv_map: array<vec4<f32>>;
// The shadow map's Rgba16Float G-buffer copied with padded rows: (normal, depth mm), then (u, v, covered, 0).
@group(0) @binding(2) var<storage, read_write> shadow_g: array<u32>;
// Outputs of `texels`: the skin-inputs maps (Cm, H0, thickness mm, 0) and normals of the texels (padded rows), and
// per texel (view normal, shaded 1/0), (0, 0, 0, 0) for the lit stage.
@group(0) @binding(3) var<storage, read_write> texel_maps: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> texel_normals: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> texel_geo: array<vec4<f32>>;
// Per head: covered, culled, clipped, shaded texels, pixels.
@group(0) @binding(6) var<storage, read_write> counts: array<atomic<u32>>;
// The frame's (u, v, covered, 0) per pixel and its SSS depth (view-depth world units, padded rows).
@group(0) @binding(7) var<storage, read_write> uvc: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> depth: array<f32>;
// The head's weighted sum of blurs, premultiplied RGBA per texel; the frame's diffuse layer (RGBA per pixel).
@group(0) @binding(9) var<storage, read_write> sum_map: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> diffuse: array<vec4<f32>>;
// With a normal map: per texel (normal bent by the map, world space, 0), (albedo, 0), surface_maps.wgsl's output
// over the texels (culling and clipping keep the UV map's normal, as the host does).
@group(0) @binding(11) var<storage, read_write> mapped: array<vec4<f32>>;

// Texel (x, y) of the shadow map's image starting at word `words`: two u32 of packed halves.
fn shadow_texel(words: u32, x: u32, y: u32) -> vec4<f32> {
    let k = words + y * u32(p.rows.w) + 2u * x;
    return vec4<f32>(unpack2x16float(shadow_g[k]), unpack2x16float(shadow_g[k + 1u]));
}

// Listing 5.1 at the world point `pw` with unit normal `nw` (heads.rs `ShadowMap::thickness_mm`): the distance from
// the point, moved inwards along its normal, to the shadow map's nearest surface on the same light ray; 0 outside
// the map or where it saw nothing.
fn back_light_thickness_mm(pw: vec3<f32>, nw: vec3<f32>) -> f32 {
    let q = vec4<f32>(pw - nw * (p.cfg.y / p.cfg.x), 1.0);
    let c = p.light_vp * q;
    let s = p.rows.z;
    let sx = floor((c.x / c.w * 0.5 + 0.5) * s);
    let sy = floor((0.5 - c.y / c.w * 0.5) * s);
    if (sx < 0.0 || sy < 0.0 || sx >= s || sy >= s) {
        return 0.0;
    }
    let n = u32(s);
    let seen = shadow_texel(u32(p.rows.w) * n, u32(sx), u32(sy));
    if (seen.z <= 0.5) {
        return 0.0;
    }
    let from_light_mm = -(p.light_view * q).z * p.cfg.x;
    return max(from_light_mm - shadow_texel(0u, u32(sx), u32(sy)).w, 0.0);
}

@compute @workgroup_size(8, 8, 1)
fn texels(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = u32(p.size.x);
    if (id.x >= n || id.y >= n) {
        return;
    }
    let t = id.y * n + id.x;
    let row = id.y * u32(p.rows.x) + id.x;
    let counted = 5u * p.stage.x;
    texel_maps[row] = vec4<f32>(0.0, 0.0, p.cfg.w, 0.0);
    texel_normals[row] = vec4<f32>(0.0, 0.0, 1.0, 0.0);
    texel_geo[2u * t] = vec4<f32>(0.0, 0.0, 1.0, 0.0);
    texel_geo[2u * t + 1u] = vec4<f32>(0.0);
    let at = uv_map[2u * t];
    if (at.w < 0.5) {
        return;
    }
    atomicAdd(&counts[counted], 1u);
    let pw = at.xyz + vec3<f32>(p.head.x, 0.0, 0.0);
    let nw = uv_map[2u * t + 1u].xyz;
    let to_eye = p.eye.xyz - pw;
    if (p.flags.x > 0.5 && dot(nw, to_eye) / length(to_eye) < p.flags.z) {
        atomicAdd(&counts[counted + 1u], 1u);
        return;
    }
    let pe = vec4<f32>((p.view * vec4<f32>(pw, 1.0)).xyz, 1.0);
    if (p.flags.y > 0.5) {
        for (var k = 0; k < 6; k++) {
            if (dot(p.planes[k], pe) < 0.0) {
                atomicAdd(&counts[counted + 2u], 1u);
                return;
            }
        }
    }
    atomicAdd(&counts[counted + 3u], 1u);
    var ns = nw;
    if (p.maps.x > 0.5) {
        ns = mapped[2u * t].xyz;
    }
    let nv = (p.view * vec4<f32>(ns, 0.0)).xyz;
    // The texels' albedo is not used: under post-scatter texturing each pixel's own albedo multiplies what it
    // gathers, so the texel's melanin and H0 only feed the skin-inputs pass's unused albedo output.
    texel_maps[row] = vec4<f32>(p.cfg.z, 0.0, min(back_light_thickness_mm(pw, ns), p.cfg.w), 0.0);
    texel_normals[row] = vec4<f32>(nv, 0.0);
    texel_geo[2u * t] = vec4<f32>(nv, 1.0);
}

@compute @workgroup_size(8, 8, 1)
fn gather(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(p.size.y);
    let h = u32(p.size.z);
    if (id.x >= w || id.y >= h) {
        return;
    }
    let i = id.y * w + id.x;
    let c = uvc[i];
    if (c.z < 0.5) {
        return;
    }
    // The pixel's head from its world-space x (texture_space.rs `render_with`): the view ray through the pixel's
    // centre at the pixel's view depth.
    let t = p.size.w;
    let xn = (f32(id.x) + 0.5) / p.size.y * 2.0 - 1.0;
    let yn = 1.0 - (f32(id.y) + 0.5) / p.size.z * 2.0;
    let d = depth[id.y * u32(p.rows.y) + id.x] / p.flags.w * 1000.0 / p.cfg.x;
    let pw = p.inv_view * vec4<f32>(xn * t * (p.size.y / p.size.z) * d, yn * t * d, -d, 1.0);
    let k = u32(clamp(round(pw.x / p.head.y + p.head.z), 0.0, p.head.w));
    if (k != p.stage.x) {
        return;
    }
    atomicAdd(&counts[5u * k + 4u], 1u);
    let size = p.size.x;
    let tap = taps(c.x, c.y, size, size);
    let j = tap_index(tap, 0u, u32(size));
    let s = bilerp4(tap, sum_map[j.x], sum_map[j.y], sum_map[j.z], sum_map[j.w]);
    if (s.a > 0.0) {
        diffuse[i] = vec4<f32>(s.rgb / s.a, diffuse[i].a);
    }
}
