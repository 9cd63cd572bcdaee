// Texture-space diffusion (runtime/skin/texture_space.rs; d'Eon et al. 2007, thesis ch. 3): the chained u/v Gaussian
// blurs of the irradiance map in texture space, each tap step sigma / stretch texels, accumulated into the weighted
// sum of blurs, and the final gather at each visible pixel's uv. Maps are premultiplied RGBA f32 in storage buffers
// (alpha = 1 on shaded texels, 0 on uncovered, culled or clipped ones); bilinear filtering is done here by hand so the
// CPU twin (runtime/skin/texture_space_cpu.rs) reproduces it. Texels with alpha 0 are not blurred (Listing 3.3) and
// contribute nothing to their neighbours (normalised convolution).

struct BlurParams {
    size: u32,
    // 0: along u, 1: along v
    dir: u32,
    // 1: add weight * result to acc (the v pass of each Gaussian)
    accumulate: u32,
    pad0: u32,
    sigma_mm: f32,
    pad1: f32,
    pad2: f32,
    pad3: f32,
    weight: vec4<f32>,
};

@group(0) @binding(0) var<uniform> bp: BlurParams;
@group(0) @binding(1) var<storage, read> src: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> dst: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> stretch: array<vec2<f32>>;
@group(0) @binding(4) var<storage, read_write> acc: array<vec4<f32>>;

var<private> TAP_W: array<f32, 7> = array<f32, 7>(0.006, 0.061, 0.242, 0.382, 0.242, 0.061, 0.006);

fn load_src(x: i32, y: i32) -> vec4<f32> {
    let n = i32(bp.size);
    let cx = clamp(x, 0, n - 1);
    let cy = clamp(y, 0, n - 1);
    return src[u32(cy * n + cx)];
}

// A bilinear sample at texel-space position (px, py) (texel centres at +0.5): the top-left texel and the weights.
struct Bilinear {
    i: vec2<i32>,
    f: vec2<f32>,
}

fn bilinear(px: f32, py: f32) -> Bilinear {
    let x = px - 0.5;
    let y = py - 0.5;
    let x0 = floor(x);
    let y0 = floor(y);
    return Bilinear(vec2<i32>(i32(x0), i32(y0)), vec2<f32>(x - x0, y - y0));
}

// The blend of the sample's four texels (a: top left, b: top right, c: bottom left, d: bottom right).
fn bilinear_blend(t: Bilinear, a: vec4<f32>, b: vec4<f32>, c: vec4<f32>, d: vec4<f32>) -> vec4<f32> {
    let top = a * (1.0 - t.f.x) + b * t.f.x;
    let bottom = c * (1.0 - t.f.x) + d * t.f.x;
    return top * (1.0 - t.f.y) + bottom * t.f.y;
}

// Bilinear sample of the source at texel-space position (px, py), clamp to edge.
fn bilinear_src(px: f32, py: f32) -> vec4<f32> {
    let t = bilinear(px, py);
    let x = t.i.x;
    let y = t.i.y;
    return bilinear_blend(t, load_src(x, y), load_src(x + 1, y), load_src(x, y + 1), load_src(x + 1, y + 1));
}

@compute @workgroup_size(8, 8)
fn blur(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= bp.size || id.y >= bp.size) {
        return;
    }
    let i = id.y * bp.size + id.x;
    let c = src[i];
    var out = vec4<f32>(0.0);
    if (c.a > 0.0) {
        let s = stretch[i];
        var st = s.x;
        var d = vec2<f32>(1.0, 0.0);
        if (bp.dir == 1u) {
            st = s.y;
            d = vec2<f32>(0.0, 1.0);
        }
        let step = bp.sigma_mm / st;
        var sum = vec4<f32>(0.0);
        for (var k = 0; k < 7; k++) {
            let o = f32(k - 3) * step;
            sum = sum + TAP_W[k] * bilinear_src(f32(id.x) + 0.5 + d.x * o, f32(id.y) + 0.5 + d.y * o);
        }
        if (sum.a > 0.0) {
            out = vec4<f32>(sum.rgb / sum.a, 1.0);
        } else {
            out = c;
        }
    }
    dst[i] = out;
    if (bp.accumulate == 1u) {
        acc[i] = vec4<f32>(acc[i].rgb + bp.weight.rgb * out.rgb, out.a);
    }
}

struct GatherParams {
    size: u32,
    count: u32,
    pad0: u32,
    pad1: u32,
};

@group(0) @binding(5) var<uniform> gp: GatherParams;
@group(0) @binding(6) var<storage, read> sum_map: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> uvs: array<vec2<f32>>;
@group(0) @binding(8) var<storage, read_write> gathered: array<vec4<f32>>;

fn load_sum(x: i32, y: i32) -> vec4<f32> {
    let n = i32(gp.size);
    let cx = clamp(x, 0, n - 1);
    let cy = clamp(y, 0, n - 1);
    return sum_map[u32(cy * n + cx)];
}

// The weighted sum of blurs at each pixel's uv (bilinear, normalised by the covered texels' weight); alpha 0 where
// no covered texel is in reach (the host keeps the unblurred diffuse there).
@compute @workgroup_size(64)
fn gather(@builtin(global_invocation_id) id: vec3<u32>) {
    let j = id.x + id.y * 65535u * 64u;
    if (j >= gp.count) {
        return;
    }
    let uv = uvs[j];
    let t = bilinear(uv.x * f32(gp.size), uv.y * f32(gp.size));
    let x = t.i.x;
    let y = t.i.y;
    let s = bilinear_blend(t, load_sum(x, y), load_sum(x + 1, y), load_sum(x, y + 1), load_sum(x + 1, y + 1));
    var out = vec4<f32>(0.0);
    if (s.a > 0.0) {
        out = vec4<f32>(s.rgb / s.a, 1.0);
    }
    gathered[j] = out;
}
