// The scanned head's surface maps (runtime/skin/surface_maps.rs; thesis §7.6): per covered pixel, the albedo map
// and the tangent-space normal map read bilinearly at the mesh's uv; the normal taken from the MikkTSpace frame
// (T interpolated, B = w * N x T, the result normalised) to view space. CPU twin: runtime/skin/surface_maps_cpu.rs.

struct Params {
    // frame width, height, albedo width, height
    size: vec4<f32>,
    // normal map width, height, has albedo, has normal map
    normal: vec4<f32>,
};

// linear albedo, 0
@group(0) @binding(4) var<storage, read_write> albedo: array<vec4<f32>>;
// unit tangent-space normal, 0
@group(0) @binding(5) var<storage, read_write> nmap: array<vec4<f32>>;
// per pixel: (normal, 0), (albedo, 0)
@group(0) @binding(6) var<storage, read_write> outp: array<vec4<f32>>;

// Prepended by the host module: `p` (binding 0, this `Params`), `uvc` and the entry point `main`, which calls
// `covered` and `uncovered` below per pixel (pixel_frame.wgsl); `nrm` and `tng` (view_frame.wgsl); `Taps`, `taps`,
// `tap_index` and `bilerp*` (bilinear_taps.wgsl).

fn albedo_at(t: Taps) -> vec4<f32> {
    let q = tap_index(t, 0u, u32(p.size.z));
    return bilerp4(t, albedo[q.x], albedo[q.y], albedo[q.z], albedo[q.w]);
}

fn normal_at(t: Taps) -> vec4<f32> {
    let q = tap_index(t, 0u, u32(p.normal.x));
    return bilerp4(t, nmap[q.x], nmap[q.y], nmap[q.z], nmap[q.w]);
}

// Off the mesh: the G-buffer's normal, no albedo.
fn uncovered(i: u32) {
    outp[2u * i] = vec4<f32>(nrm[i].xyz, 0.0);
    outp[2u * i + 1u] = vec4<f32>(0.0);
}

fn covered(i: u32, uv: vec2<f32>) {
    let n = nrm[i].xyz;
    var a = vec3<f32>(0.0);
    if (p.normal.z > 0.5) {
        a = albedo_at(taps(uv.x, uv.y, p.size.z, p.size.w)).xyz;
    }
    var out_n = n;
    if (p.normal.w > 0.5) {
        let s = normal_at(taps(uv.x, uv.y, p.normal.x, p.normal.y)).xyz;
        let ls = sqrt(dot(s, s));
        let t4 = tng[i];
        let t = t4.xyz;
        let b = t4.w * cross(n, t);
        let v = s.x * t + s.y * b + s.z * n;
        let lv = sqrt(dot(v, v));
        if (ls > 1e-6 && lv > 1e-6) {
            out_n = v / lv;
        }
    }
    outp[2u * i] = vec4<f32>(out_n, 0.0);
    outp[2u * i + 1u] = vec4<f32>(a, 0.0);
}
