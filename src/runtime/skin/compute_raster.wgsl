// The G-buffer of runtime/skin/mesh_raster.wgsl rasterised in compute (runtime/skin/compute_raster.rs): a
// visibility buffer resolved in three dispatches. `depth`, one thread per (triangle, slice of its box): the nearest
// depth key of every covered pixel centre (atomicMax of the inverted f32 bits of NDC z); `visible`: the same
// pixels again, the lowest triangle index whose key equals the stored one; `resolve`, one thread per pixel: the
// winning triangle's attributes interpolated at the pixel centre, written as the render pass's Rgba16Float
// targets would be copied into a buffer (two u32 words of packed f16 per texel, padded rows, zero where nothing
// is covered). The vertex projection, the triangle set-up and the interpolation are the CPU twin's
// (runtime/skin/mesh_raster_cpu.rs) in the same order; the coverage test adds the top-left rule of the hardware.

struct Params {
    view_proj: mat4x4<f32>,
    view: mat4x4<f32>,
    // mm per mesh unit; the clip w at or below which a vertex's triangles are skipped (half the near plane); 0; 0
    cam: vec4<f32>,
    // width, height (pixels), triangles, row slices of the triangle passes
    size: vec4<u32>,
    // u32 words per G-buffer row, targets written (2: normal+depth, uv+cover; 3: and the tangent), column slices
    // of the triangle passes, 0
    out: vec4<u32>,
};

@group(0) @binding(0) var<uniform> p: Params;
// The mesh as mesh_raster.rs `upload_mesh` lays it out: 12 f32 per vertex (position, normal, uv, tangent + w).
@group(0) @binding(1) var<storage, read_write> vertices: array<f32>;
@group(0) @binding(2) var<storage, read_write> indices: array<u32>;
// Per pixel: the nearest depth key (!bits(z), 0 = empty) and the winning triangle (!index, 0 = empty).
@group(0) @binding(3) var<storage, read_write> depth_keys: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> tri_keys: array<atomic<u32>>;
// The G-buffer targets one after another, `out.x` words per row, `size.y` rows each.
@group(0) @binding(5) var<storage, read_write> gbuffer: array<u32>;

// A front-facing triangle on screen: (x, y, z, 1/w) of its vertices (pixels, y down; NDC z), its signed area
// (< 0), which of its edges (b→c, c→a, a→b) are top or left edges, and its pixel bounding box [x0, x1) × [y0, y1).
struct Tri {
    ok: bool,
    v: array<vec4<f32>, 3>,
    area: f32,
    top_left: vec3<bool>,
    x0: u32,
    x1: u32,
    y0: u32,
    y1: u32,
};

fn position(i: u32) -> vec3<f32> {
    let k = 12u * i;
    return vec3<f32>(vertices[k], vertices[k + 1u], vertices[k + 2u]);
}

// The edge function of the edge p → q at (x, y), as the CPU twin's `bary`.
fn edge(p0: vec4<f32>, q: vec4<f32>, x: f32, y: f32) -> f32 {
    return (q.x - p0.x) * (y - p0.y) - (x - p0.x) * (q.y - p0.y);
}

// Whether a pixel centre exactly on the edge p → q of a front face (signed area < 0, y down) is the triangle's:
// the interior lies on the edge's right (a left edge: q below p), or it is horizontal with the interior below
// (a top edge: q left of p).
fn is_top_left(p0: vec4<f32>, q: vec4<f32>) -> bool {
    let dy = q.y - p0.y;
    return dy > 0.0 || (dy == 0.0 && q.x - p0.x < 0.0);
}

// Triangle `t` projected and set up; `ok` false when a vertex lies behind half the near plane or it faces away.
fn setup(t: u32) -> Tri {
    var r: Tri;
    r.ok = false;
    let wf = f32(p.size.x);
    let hf = f32(p.size.y);
    for (var k = 0u; k < 3u; k++) {
        let c = p.view_proj * vec4<f32>(position(indices[3u * t + k]), 1.0);
        if (c.w <= p.cam.y) {
            return r;
        }
        r.v[k] = vec4<f32>((c.x / c.w * 0.5 + 0.5) * wf, (0.5 - c.y / c.w * 0.5) * hf, c.z / c.w, 1.0 / c.w);
    }
    let a = r.v[0];
    let b = r.v[1];
    let c = r.v[2];
    r.area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    // Back faces (area ≥ 0) and NaN areas are culled.
    if (!(r.area < 0.0)) {
        return r;
    }
    r.top_left = vec3<bool>(is_top_left(b, c), is_top_left(c, a), is_top_left(a, b));
    r.x0 = u32(clamp(floor(min(a.x, min(b.x, c.x))), 0.0, wf));
    r.x1 = u32(clamp(ceil(max(a.x, max(b.x, c.x))), 0.0, wf));
    r.y0 = u32(clamp(floor(min(a.y, min(b.y, c.y))), 0.0, hf));
    r.y1 = u32(clamp(ceil(max(a.y, max(b.y, c.y))), 0.0, hf));
    r.ok = true;
    return r;
}

// The edge function of p → q evaluated from its upper (then leftmost) end, negated when that end is q: the two
// triangles sharing an edge get exactly opposite values on it, so a pixel centre on it is exactly one's (no hole,
// no pixel drawn twice — the CPU twin's edge(p, q) and edge(q, p) may round differently).
fn shared_edge(p0: vec4<f32>, q: vec4<f32>, x: f32, y: f32) -> f32 {
    if (p0.y < q.y || (p0.y == q.y && p0.x < q.x)) {
        return edge(p0, q, x, y);
    }
    return -edge(q, p0, x, y);
}

// Screen-space barycentrics of pixel (x, y)'s centre, each the signed area opposite a vertex.
fn bary(r: Tri, x: u32, y: u32) -> vec3<f32> {
    let px = f32(x) + 0.5;
    let py = f32(y) + 0.5;
    let e = vec3<f32>(
        shared_edge(r.v[1], r.v[2], px, py),
        shared_edge(r.v[2], r.v[0], px, py),
        shared_edge(r.v[0], r.v[1], px, py),
    );
    return e / r.area;
}

// The depth key of pixel (x, y) for the triangle (inverted f32 bits of NDC z: larger is nearer), 0 where the
// triangle does not cover the centre (the top-left rule on its edges) or z lies outside [0, 1) (the near plane's
// clip and the depth buffer's clear value).
fn depth_key(r: Tri, x: u32, y: u32) -> u32 {
    let w = bary(r, x, y);
    let inside = (w > vec3<f32>(0.0)) | ((w == vec3<f32>(0.0)) & r.top_left);
    if (!all(inside)) {
        return 0u;
    }
    let z = w.x * r.v[0].z + w.y * r.v[1].z + w.z * r.v[2].z;
    if (!(z >= 0.0 && z < 1.0)) {
        return 0u;
    }
    // |z|'s bits (−0 as +0) are monotonic in z ≥ 0.
    return ~(bitcast<u32>(z) & 0x7fffffffu);
}

@compute @workgroup_size(64, 1, 1)
fn depth(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= p.size.z) {
        return;
    }
    let r = setup(id.x);
    if (!r.ok) {
        return;
    }
    // Slice id.y of the box: rows y0 + id.y / columns + j·rows, columns x0 + id.y % columns + i·columns.
    for (var y = r.y0 + id.y / p.out.z; y < r.y1; y += p.size.w) {
        for (var x = r.x0 + id.y % p.out.z; x < r.x1; x += p.out.z) {
            let key = depth_key(r, x, y);
            if (key != 0u) {
                atomicMax(&depth_keys[y * p.size.x + x], key);
            }
        }
    }
}

@compute @workgroup_size(64, 1, 1)
fn visible(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= p.size.z) {
        return;
    }
    let r = setup(id.x);
    if (!r.ok) {
        return;
    }
    // Slice id.y of the box: rows y0 + id.y / columns + j·rows, columns x0 + id.y % columns + i·columns.
    for (var y = r.y0 + id.y / p.out.z; y < r.y1; y += p.size.w) {
        for (var x = r.x0 + id.y % p.out.z; x < r.x1; x += p.out.z) {
            let key = depth_key(r, x, y);
            let i = y * p.size.x + x;
            // Of the triangles at the nearest depth, the first in index order (the render pass's less-than test).
            if (key != 0u && key == atomicLoad(&depth_keys[i])) {
                atomicMax(&tri_keys[i], ~id.x);
            }
        }
    }
}

// Two f16 of a texel's half, finite (the render target would store ±inf past f16's range; WGSL leaves the packing
// of such values undefined).
fn pack(v: vec2<f32>) -> u32 {
    return pack2x16float(clamp(v, vec2<f32>(-65504.0), vec2<f32>(65504.0)));
}

@compute @workgroup_size(8, 8, 1)
fn resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= p.size.x || id.y >= p.size.y) {
        return;
    }
    let key = atomicLoad(&tri_keys[id.y * p.size.x + id.x]);
    var g: array<vec4<f32>, 3>;
    if (key != 0u) {
        let t = ~key;
        let r = setup(t);
        let w = bary(r, id.x, id.y);
        // The CPU twin's `fragment`: barycentrics divided by clip w, the attributes of mesh_raster.wgsl's vs_mesh.
        let pw = w * vec3<f32>(r.v[0].w, r.v[1].w, r.v[2].w);
        let s = 1.0 / (pw.x + pw.y + pw.z);
        var n = vec3<f32>(0.0);
        var d = 0.0;
        var uv = vec2<f32>(0.0);
        var tg = vec4<f32>(0.0);
        for (var k = 0u; k < 3u; k++) {
            let i = indices[3u * t + k];
            let b = 12u * i;
            let pos = vec4<f32>(vertices[b], vertices[b + 1u], vertices[b + 2u], 1.0);
            let nv = (p.view * vec4<f32>(vertices[b + 3u], vertices[b + 4u], vertices[b + 5u], 0.0)).xyz;
            let t_view = (p.view * vec4<f32>(vertices[b + 8u], vertices[b + 9u], vertices[b + 10u], 0.0)).xyz;
            n += pw[k] * nv;
            d += pw[k] * (-(p.view * pos).z * p.cam.x);
            uv += pw[k] * vec2<f32>(vertices[b + 6u], vertices[b + 7u]);
            tg += pw[k] * vec4<f32>(t_view, vertices[b + 11u]);
        }
        n *= s;
        g[0] = vec4<f32>(n / sqrt(n.x * n.x + n.y * n.y + n.z * n.z), d * s);
        g[1] = vec4<f32>(uv * s, 1.0, 0.0);
        g[2] = tg * s;
    }
    let row = p.out.x;
    let target_words = row * p.size.y;
    let o = id.y * row + 2u * id.x;
    gbuffer[o] = pack(g[0].xy);
    gbuffer[o + 1u] = pack(g[0].zw);
    gbuffer[target_words + o] = pack(g[1].xy);
    gbuffer[target_words + o + 1u] = pack(g[1].zw);
    if (p.out.y > 2u) {
        gbuffer[2u * target_words + o] = pack(g[2].xy);
        gbuffer[2u * target_words + o + 1u] = pack(g[2].zw);
    }
}
