// MCML-style photon transport, one invocation per photon (rtbake::runtime::transport_gpu; the algorithm and its
// section numbers are those of rtbake::transport::mc: L. Wang, S. L. Jacques, L. Zheng, Comput. Methods Programs
// Biomed. 47, 1995). f32 state, u32 Philox4x32-10 (Salmon et al., SC 2011) with the CPU's counters.
//
// Dispatch (ceil(count / 64) capped at groups_x, 3 channels, z): photon i = (z * groups_x + x_group) * 64 + local,
// channel = workgroup y. Tallies are 64-bit fixed point, 2^-32 weight units, as (lo, hi) u32 pairs: lo is added
// with atomicAdd and a carry goes into hi when it wraps (exact, order-independent integer sums).

struct Params {
    key: vec2<u32>,
    // 64-bit index of this segment's first photon (lo, hi).
    first_photon: vec2<u32>,
    count: u32,
    bins: u32,
    layers: u32,
    max_steps: u32,
    inv_bin_mm: f32,
    eta_above: f32,
    eta_below: f32,
    start_weight: f32,
    groups_x: u32,
    // u32 pairs per channel: 2 * bins + layers + 4.
    slots_per_channel: u32,
    _pad0: u32,
    _pad1: u32,
}

struct Medium {
    z_top_mm: f32,
    z_bottom_mm: f32,
    sigma_t: f32,
    absorb_fraction: f32,
    g: f32,
    eta: f32,
    _pad0: f32,
    _pad1: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
// [channel * layers + layer]
@group(0) @binding(1) var<storage, read> media: array<Medium>;
// Per channel: R bins, T bins, rd, td, absorbed[layers], interactions, capped; each a (lo, hi) pair.
@group(0) @binding(2) var<storage, read_write> tallies: array<atomic<u32>>;

const WG: u32 = 64u;
const MAX_LAYERS: u32 = 64u;
// Workgroup partial sums: rd, td, interactions, capped, absorbed[MAX_LAYERS]; (lo, hi) each.
const WG_SLOTS: u32 = 68u;
const S_RD: u32 = 0u;
const S_TD: u32 = 1u;
const S_INTERACTIONS: u32 = 2u;
const S_CAPPED: u32 = 3u;
const S_ABSORBED: u32 = 4u;
var<workgroup> wg_tally: array<atomic<u32>, 136>;

const PI: f32 = 3.14159265358979;
const BIG: f32 = 3.0e38;
const ROULETTE_THRESHOLD: f32 = 1e-4;
const ROULETTE_CHANCE: f32 = 10.0;

// 32 x 32 -> 64-bit product as (hi, lo), through 16-bit halves (WGSL has no 64-bit integers).
fn mul_hi_lo(a: u32, b: u32) -> vec2<u32> {
    let a0 = a & 0xffffu;
    let a1 = a >> 16u;
    let b0 = b & 0xffffu;
    let b1 = b >> 16u;
    let p00 = a0 * b0;
    let p01 = a0 * b1;
    let p10 = a1 * b0;
    let p11 = a1 * b1;
    let mid = (p00 >> 16u) + (p01 & 0xffffu) + (p10 & 0xffffu);
    let hi = p11 + (p01 >> 16u) + (p10 >> 16u) + (mid >> 16u);
    return vec2<u32>(hi, a * b);
}

// Philox4x32-10 (rtbake::transport::rng::philox4x32_10).
fn philox(counter: vec4<u32>, key: vec2<u32>) -> vec4<u32> {
    var c = counter;
    var k = key;
    for (var round = 0u; round < 10u; round++) {
        if (round > 0u) {
            k = k + vec2<u32>(0x9E3779B9u, 0xBB67AE85u);
        }
        let p0 = mul_hi_lo(0xD2511F53u, c.x);
        let p1 = mul_hi_lo(0xCD9E8D57u, c.z);
        c = vec4<u32>(p1.x ^ c.y ^ k.x, p1.y, p0.x ^ c.w ^ k.y, p0.y);
    }
    return c;
}

// One photon's stream: counter (index lo, index hi, channel, block), four words per block, as on the CPU.
struct Rng {
    counter: vec4<u32>,
    block: vec4<u32>,
    next: u32,
}

// A uniform in (0, 1] on the grid k/2^24 (the word's top 24 bits + 1; exact in f32, never 0).
fn next_uniform(rng: ptr<function, Rng>) -> f32 {
    if ((*rng).next >= 4u) {
        (*rng).block = philox((*rng).counter, params.key);
        (*rng).counter.w = (*rng).counter.w + 1u;
        (*rng).next = 0u;
    }
    let word = (*rng).block[(*rng).next];
    (*rng).next = (*rng).next + 1u;
    return (f32(word >> 8u) + 1.0) * (1.0 / 16777216.0);
}

// Adds a 64-bit (lo, hi) value to the pair at `slot` of the global tallies.
fn add_global(slot: u32, lo: u32, hi: u32) {
    let old = atomicAdd(&tallies[2u * slot], lo);
    let carry = select(0u, 1u, old + lo < old);
    if (hi + carry != 0u) {
        atomicAdd(&tallies[2u * slot + 1u], hi + carry);
    }
}

fn add_wg(slot: u32, lo: u32, hi: u32) {
    let old = atomicAdd(&wg_tally[2u * slot], lo);
    let carry = select(0u, 1u, old + lo < old);
    if (hi + carry != 0u) {
        atomicAdd(&wg_tally[2u * slot + 1u], hi + carry);
    }
}

// A weight w in [0, 2^32) as 64-bit fixed point (lo = fraction * 2^32, exact for an f32 fraction; hi = whole).
fn fixed(w: f32) -> vec2<u32> {
    let whole = floor(w);
    let frac = min((w - whole) * 4294967296.0, 4294967040.0);
    return vec2<u32>(u32(frac), u32(whole));
}

fn add_weight_global(slot: u32, w: f32) {
    if (w > 0.0) {
        let f = fixed(w);
        add_global(slot, f.x, f.y);
    }
}

fn add_weight_wg(slot: u32, w: f32) {
    if (w > 0.0) {
        let f = fixed(w);
        add_wg(slot, f.x, f.y);
    }
}

// Unpolarised Fresnel reflectance and refracted cosine (rtbake::transport::mc::fresnel).
fn fresnel(n_i: f32, n_t: f32, cos_i: f32) -> vec2<f32> {
    if (n_i == n_t) {
        return vec2<f32>(0.0, cos_i);
    }
    let ratio = n_i / n_t;
    let sin_t2 = ratio * ratio * max(1.0 - cos_i * cos_i, 0.0);
    if (sin_t2 >= 1.0) {
        return vec2<f32>(1.0, 0.0);
    }
    let cos_t = sqrt(1.0 - sin_t2);
    let rs = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
    let rp = (n_i * cos_t - n_t * cos_i) / (n_i * cos_t + n_t * cos_i);
    return vec2<f32>(0.5 * (rs * rs + rp * rp), cos_t);
}

// Henyey-Greenstein cos(theta) from a uniform (MCML eq. 3.28).
fn hg_cos_theta(g: f32, xi: f32) -> f32 {
    if (abs(g) < 1e-6) {
        return 2.0 * xi - 1.0;
    }
    let f = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi);
    return clamp((1.0 + g * g - f * f) / (2.0 * g), -1.0, 1.0);
}

// Rotates u by polar cos_t and azimuth phi (MCML eq. 3.30-3.31), renormalised (f32 drift).
fn spin(u: vec3<f32>, cos_t: f32, phi: f32) -> vec3<f32> {
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    let cos_p = cos(phi);
    let sin_p = sin(phi);
    var v: vec3<f32>;
    if (abs(u.z) > 0.99999) {
        v = vec3<f32>(sin_t * cos_p, sin_t * sin_p, cos_t * sign(u.z));
    } else {
        let tmp = sqrt(1.0 - u.z * u.z);
        v = vec3<f32>(
            sin_t * (u.x * u.z * cos_p - u.y * sin_p) / tmp + u.x * cos_t,
            sin_t * (u.y * u.z * cos_p + u.x * sin_p) / tmp + u.y * cos_t,
            -sin_t * cos_p * tmp + u.z * cos_t,
        );
    }
    return v * inverseSqrt(dot(v, v));
}

fn bin_of(x: f32, y: f32) -> u32 {
    let r = sqrt(x * x + y * y) * params.inv_bin_mm;
    return select(params.bins, u32(r), r < f32(params.bins));
}

fn trace(photon: u32, channel: u32) {
    let base = channel * params.slots_per_channel;
    let bins = params.bins;
    let last = params.layers - 1u;
    let m0 = channel * params.layers;
    // 64-bit photon index = first_photon + photon.
    let lo = params.first_photon.x + photon;
    let hi = params.first_photon.y + select(0u, 1u, lo < photon);
    var rng: Rng;
    rng.counter = vec4<u32>(lo, hi, channel, 0u);
    rng.next = 4u;
    var p = vec3<f32>(0.0, 0.0, 0.0);
    var u = vec3<f32>(0.0, 0.0, 1.0);
    var w = params.start_weight;
    var layer = 0u;
    var s_left = 0.0;
    var interactions = 0u;
    // Weight absorbed in `layer` since the photon entered it (flushed on leaving it and at the end).
    var absorbed = 0.0;
    var steps = 0u;
    loop {
        steps = steps + 1u;
        if (steps > params.max_steps) {
            // Runaway history (see MAX_STEPS_PER_PHOTON): scored as absorbed where it is and counted.
            absorbed = absorbed + w;
            add_wg(S_CAPPED, 1u, 0u);
            break;
        }
        let m = media[m0 + layer];
        if (s_left == 0.0) {
            s_left = -log(next_uniform(&rng));
        }
        var d_face = BIG;
        if (u.z > 0.0) {
            d_face = min((m.z_bottom_mm - p.z) / u.z, BIG);
        } else if (u.z < 0.0) {
            d_face = min((m.z_top_mm - p.z) / u.z, BIG);
        }
        var d_step = BIG;
        if (m.sigma_t > 0.0) {
            d_step = s_left / m.sigma_t;
        }
        if (d_step >= BIG && d_face >= BIG) {
            // Gliding parallel to the faces of a clear layer.
            absorbed = absorbed + w;
            break;
        }
        if (d_face <= d_step) {
            let down = u.z > 0.0;
            p = vec3<f32>(p.x + u.x * d_face, p.y + u.y * d_face, select(m.z_top_mm, m.z_bottom_mm, down));
            if (m.sigma_t > 0.0) {
                s_left = max(s_left - d_face * m.sigma_t, 0.0);
            }
            var n_t: f32;
            if (!down) {
                n_t = select(media[m0 + layer - 1u].eta, params.eta_above, layer == 0u);
            } else {
                n_t = select(media[m0 + layer + 1u].eta, params.eta_below, layer == last);
            }
            let fr = fresnel(m.eta, n_t, abs(u.z));
            if (fr.x > 0.0) {
                if (fr.x >= 1.0 || next_uniform(&rng) <= fr.x) {
                    u.z = -u.z;
                    continue;
                }
            }
            let ratio = m.eta / n_t;
            u = vec3<f32>(u.x * ratio, u.y * ratio, select(-fr.y, fr.y, down));
            if (!down && layer == 0u) {
                add_weight_wg(S_RD, w);
                let b = bin_of(p.x, p.y);
                if (b < bins) {
                    add_weight_global(base + b, w);
                }
                break;
            }
            if (down && layer == last) {
                add_weight_wg(S_TD, w);
                let b = bin_of(p.x, p.y);
                if (b < bins) {
                    add_weight_global(base + bins + b, w);
                }
                break;
            }
            add_weight_wg(S_ABSORBED + layer, absorbed);
            absorbed = 0.0;
            layer = select(layer + 1u, layer - 1u, !down);
            continue;
        }
        // Interaction inside the layer: implicit capture, HG scattering, roulette.
        p = p + u * d_step;
        s_left = 0.0;
        interactions = interactions + 1u;
        let dw = w * m.absorb_fraction;
        absorbed = absorbed + dw;
        w = w - dw;
        let cos_t = hg_cos_theta(m.g, next_uniform(&rng));
        u = spin(u, cos_t, 2.0 * PI * next_uniform(&rng));
        if (w < ROULETTE_THRESHOLD) {
            if (w == 0.0) {
                break;
            }
            if (next_uniform(&rng) <= 1.0 / ROULETTE_CHANCE) {
                w = w * ROULETTE_CHANCE;
            } else {
                break;
            }
        }
    }
    add_weight_wg(S_ABSORBED + layer, absorbed);
    add_wg(S_INTERACTIONS, interactions, 0u);
}

@compute @workgroup_size(64)
fn transport(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    for (var s = local; s < 2u * WG_SLOTS; s += WG) {
        atomicStore(&wg_tally[s], 0u);
    }
    workgroupBarrier();
    let photon = (group.z * params.groups_x + group.x) * WG + local;
    let channel = group.y;
    if (photon < params.count) {
        trace(photon, channel);
    }
    workgroupBarrier();
    // Flush the workgroup's sums: rd, td, then absorbed per layer, interactions, capped (global slot order).
    let base = channel * params.slots_per_channel + 2u * params.bins;
    for (var s = local; s < 4u + params.layers; s += WG) {
        let lo = atomicLoad(&wg_tally[2u * s]);
        let hi = atomicLoad(&wg_tally[2u * s + 1u]);
        var g: u32;
        if (s == S_RD) {
            g = base;
        } else if (s == S_TD) {
            g = base + 1u;
        } else if (s == S_INTERACTIONS) {
            g = base + 2u + params.layers;
        } else if (s == S_CAPPED) {
            g = base + 3u + params.layers;
        } else {
            g = base + 2u + (s - S_ABSORBED);
        }
        if (lo != 0u || hi != 0u) {
            add_global(g, lo, hi);
        }
    }
}

// Known-answer check of the WGSL Philox against the CPU's: block i of counters[i] under params.key.
// (Bindings 3-5: an entry point's bind-group layout holds only the bindings it uses.)
@group(0) @binding(3) var<storage, read> kat_in: array<vec4<u32>>;
@group(0) @binding(4) var<storage, read_write> kat_out: array<vec4<u32>>;
@group(0) @binding(5) var<uniform> kat_key: vec4<u32>;

@compute @workgroup_size(64)
fn philox_kat(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x < arrayLength(&kat_in)) {
        kat_out[id.x] = philox(kat_in[id.x], kat_key.xy);
    }
}
