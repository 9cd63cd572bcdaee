// The wrinkle pass (runtime/skin/wrinkles.rs; thesis ch. 8, Listing 8.1): per covered pixel, the partial-derivative
// wrinkle map and the two zone-mask maps read bilinearly at the mesh's uv, xy = base.xy + sum_z mask_z * weight_z *
// wrinkle.xy (base: flat, the meshes carry no base normal map), n_ts = normalize(xy, 1), then n_ts taken from the
// mesh's tangent frame (T, B = w * N x T, N) to view space. CPU twin: runtime/skin/wrinkles_cpu.rs.

struct Params {
    // frame width, height, PD map width, height
    size: vec4<f32>,
    // mask width, height, 0, 0
    mask: vec4<f32>,
    weights: array<vec4<f32>, 2>,
};

// decoded PD slopes (-1 + 2 * texel)
@group(0) @binding(4) var<storage, read_write> pd: array<vec2<f32>>;
// decoded masks: map 0 then map 1, each mask width x height
@group(0) @binding(5) var<storage, read_write> masks: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> out_n: array<vec4<f32>>;

// Prepended by the host module: `p` (binding 0, this `Params`), `uvc` and the entry point `main`, which calls
// `covered` and `uncovered` below per pixel (pixel_frame.wgsl); `nrm` and `tng` (view_frame.wgsl); `Taps`, `taps`,
// `tap_index` and `bilerp*` (bilinear_taps.wgsl).

fn pd_at(t: Taps) -> vec2<f32> {
    let q = tap_index(t, 0u, u32(p.size.z));
    return bilerp2(t, pd[q.x], pd[q.y], pd[q.z], pd[q.w]);
}

fn mask_at(k: u32, t: Taps) -> vec4<f32> {
    let w = u32(p.mask.x);
    let base = k * w * u32(p.mask.y);
    let q = tap_index(t, base, w);
    return bilerp4(t, masks[q.x], masks[q.y], masks[q.z], masks[q.w]);
}

// Off the mesh: the G-buffer's normal.
fn uncovered(i: u32) {
    out_n[i] = vec4<f32>(nrm[i].xyz, 0.0);
}

fn covered(i: u32, uv: vec2<f32>) {
    let n = nrm[i].xyz;
    // Listing 8.1
    let wr = pd_at(taps(uv.x, uv.y, p.size.z, p.size.w));
    let tm = taps(uv.x, uv.y, p.mask.x, p.mask.y);
    let m1 = mask_at(0u, tm) * p.weights[0];
    let m2 = mask_at(1u, tm) * p.weights[1];
    var xy = vec2<f32>(0.0, 0.0);
    xy = xy + m1.r * wr;
    xy = xy + m1.g * wr;
    xy = xy + m1.b * wr;
    xy = xy + m1.a * wr;
    xy = xy + m2.r * wr;
    xy = xy + m2.g * wr;
    xy = xy + m2.b * wr;
    xy = xy + m2.a * wr;
    let v = vec3<f32>(xy, 1.0);
    let nts = v / sqrt(dot(v, v));
    // The tangent frame: Gram-Schmidt of the interpolated tangent against the normal.
    let t4 = tng[i];
    let to = t4.xyz - n * dot(n, t4.xyz);
    let l = sqrt(dot(to, to));
    if (l < 1e-6) {
        out_n[i] = vec4<f32>(n, 0.0);
        return;
    }
    let t = to / l;
    let b = t4.w * cross(n, t);
    out_n[i] = vec4<f32>(nts.x * t + nts.y * b + nts.z * n, 0.0);
}
