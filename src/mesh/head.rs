//! The procedural default head: a mesh every `rtbake run skin` command can render with no input file, with the
//! features the TAP 2009 comparison depends on — a nose (the screen-space halo of TAP §7 "scattering from the nose
//! incorrectly bleeding onto the cheek"), and two thin ears (light through thin features, TAP Fig. 10, thesis ch. 5).
//!
//! Geometry, in metres (glTF's unit; [`super::Mesh::mm_per_unit`] = 1000), y up, the face looking down +z:
//! - the skull: an ellipsoid with semi-axes 75 × 105 × 90 mm (x, y, z) over a latitude–longitude grid
//!   (θ from the top, φ from the front), displaced along the ellipsoid's radial direction by Gaussian bumps for the
//!   nose (22 mm), brow (6 mm), chin (8 mm) and cheeks (4 mm);
//! - the ears: flattened ellipsoids 6 × 60 × 34 mm (x thickness), centred on the skull's sides at eye level.
//!
//! UV unwrap in three islands: the skull's ((φ + π)/2π·0.75, θ/π), the seam at the back, in u ∈ [0, 0.75], the left ear in u ∈ [0.76, 0.99],
//! v ∈ [0.01, 0.49], the right ear below it; v = 0 is the texture's top row. Normals are the area-weighted face
//! normals, averaged over vertices that share a position (the φ seam and the poles), so shading is smooth across
//! the seams.

use super::Mesh;
use std::collections::HashMap;
use std::f32::consts::{PI, TAU};

/// Skull semi-axes (x, y, z), metres.
pub const SKULL_RADII_M: [f32; 3] = [0.075, 0.105, 0.090];
/// Ear semi-axes (x = half thickness, y, z), metres.
pub const EAR_RADII_M: [f32; 3] = [0.003, 0.030, 0.017];

/// A Gaussian bump on the skull: centre (θ, φ) in radians, widths in radians, height in metres.
struct Bump {
    theta: f32,
    phi: f32,
    sigma_theta: f32,
    sigma_phi: f32,
    height_m: f32,
}

const BUMPS: [Bump; 5] = [
    // nose, a vertical ridge just below the equator
    Bump { theta: 0.56 * PI, phi: 0.0, sigma_theta: 0.11, sigma_phi: 0.07, height_m: 0.022 },
    // brow
    Bump { theta: 0.41 * PI, phi: 0.0, sigma_theta: 0.05, sigma_phi: 0.45, height_m: 0.006 },
    // chin
    Bump { theta: 0.79 * PI, phi: 0.0, sigma_theta: 0.07, sigma_phi: 0.30, height_m: 0.008 },
    // cheeks
    Bump { theta: 0.58 * PI, phi: 0.55, sigma_theta: 0.10, sigma_phi: 0.18, height_m: 0.004 },
    Bump { theta: 0.58 * PI, phi: -0.55, sigma_theta: 0.10, sigma_phi: 0.18, height_m: 0.004 },
];

fn wrap_pi(a: f32) -> f32 {
    (a + PI).rem_euclid(TAU) - PI
}

fn skull_point(theta: f32, phi: f32) -> [f32; 3] {
    let d = [theta.sin() * phi.sin(), theta.cos(), theta.sin() * phi.cos()];
    let p = [SKULL_RADII_M[0] * d[0], SKULL_RADII_M[1] * d[1], SKULL_RADII_M[2] * d[2]];
    let h: f32 = BUMPS
        .iter()
        .map(|b| {
            let dt = (theta - b.theta) / b.sigma_theta;
            let dp = wrap_pi(phi - b.phi) / b.sigma_phi;
            b.height_m * (-0.5 * (dt * dt + dp * dp)).exp()
        })
        .sum();
    let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    [p[0] + h * p[0] / l, p[1] + h * p[1] / l, p[2] + h * p[2] / l]
}

/// Appends a latitude–longitude shell (rows × cols quads, the seam column duplicated, one triangle per quad at the
/// poles so none is degenerate).
fn shell(
    rows: usize,
    cols: usize,
    point: impl Fn(f32, f32) -> [f32; 3],
    uv: impl Fn(f32, f32) -> [f32; 2],
    pos: &mut Vec<[f32; 3]>,
    uvs: &mut Vec<[f32; 2]>,
    idx: &mut Vec<u32>,
) {
    let base = pos.len() as u32;
    for i in 0..=rows {
        for j in 0..=cols {
            let (s, t) = (j as f32 / cols as f32, i as f32 / rows as f32);
            pos.push(point(t * PI, s * TAU));
            uvs.push(uv(s, t));
        }
    }
    let at = |i: usize, j: usize| base + (i * (cols + 1) + j) as u32;
    for i in 0..rows {
        for j in 0..cols {
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
            // Counter-clockwise seen from outside: θ grows downwards, φ grows towards +x from the front.
            if i != 0 {
                idx.extend([a, d, b]);
            }
            if i != rows - 1 {
                idx.extend([a, c, d]);
            }
        }
    }
}

/// Area-weighted vertex normals, averaged over vertices at the same position.
fn smooth_normals(pos: &[[f32; 3]], idx: &[u32]) -> Vec<[f32; 3]> {
    let mut n = vec![[0.0f32; 3]; pos.len()];
    for t in idx.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| pos[i as usize]);
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let f = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        for &i in t {
            for k in 0..3 {
                n[i as usize][k] += f[k];
            }
        }
    }
    let key = |p: [f32; 3]| p.map(|c| (c * 1e6).round() as i64);
    let mut shared: HashMap<[i64; 3], [f32; 3]> = HashMap::new();
    for (p, v) in pos.iter().zip(&n) {
        let s = shared.entry(key(*p)).or_insert([0.0; 3]);
        for k in 0..3 {
            s[k] += v[k];
        }
    }
    pos.iter().map(|p| shared[&key(*p)]).collect()
}

/// The default head at a given tessellation (`rows` × `cols` quads on the skull; the ears get a quarter of each).
/// [`default_head`] is 48 × 64: about 6 000 triangles on the skull and 600 on the ears.
pub fn head(rows: usize, cols: usize) -> Mesh {
    let (rows, cols) = (rows.max(4), cols.max(4));
    let (mut pos, mut uvs, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    // φ from −π to π: the texture seam runs down the back of the head, not the face.
    shell(rows, cols, |th, ph| skull_point(th, ph - PI), |s, t| [0.75 * s, t], &mut pos, &mut uvs, &mut idx);
    for (side, v0) in [(-1.0f32, 0.01f32), (1.0, 0.51)] {
        let centre = [side * (SKULL_RADII_M[0] + 0.001), -0.005, -0.008];
        let ear = move |theta: f32, phi: f32| {
            let d = [theta.sin() * phi.sin(), theta.cos(), theta.sin() * phi.cos()];
            [centre[0] + EAR_RADII_M[0] * d[0], centre[1] + EAR_RADII_M[1] * d[1], centre[2] + EAR_RADII_M[2] * d[2]]
        };
        shell(rows / 4, cols / 4, ear, move |s, t| [0.76 + 0.23 * s, v0 + 0.48 * t], &mut pos, &mut uvs, &mut idx);
    }
    let normals = smooth_normals(&pos, &idx);
    Mesh::new("procedural head", pos, normals, uvs, idx, 1000.0).expect("the procedural head is a valid mesh")
}

/// The head `rtbake run skin` renders when no `--mesh` is given.
pub fn default_head() -> Mesh {
    head(48, 64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_head_is_valid_and_head_sized() {
        let m = default_head();
        assert!((2000..=10_000).contains(&m.triangle_count()), "{}", m.triangle_count());
        let (lo, hi) = m.bounds();
        let size_mm = [0, 1, 2].map(|k| (hi[k] - lo[k]) * m.mm_per_unit);
        // 150 mm wide plus the ears, 210 mm tall, about 200 mm deep with the nose.
        assert!((150.0..175.0).contains(&size_mm[0]) && (205.0..215.0).contains(&size_mm[1]), "{size_mm:?}");
        assert!((185.0..215.0).contains(&size_mm[2]), "{size_mm:?}");
        // The nose is the frontmost point, on the midline, below the centre.
        let front = m.positions.iter().copied().max_by(|a, b| a[2].total_cmp(&b[2])).unwrap();
        assert!(front[0].abs() < 0.003 && front[1] < 0.0 && front[2] > 0.105, "{front:?}");
    }

    #[test]
    fn normals_point_outwards_and_the_ears_are_thin() {
        let m = default_head();
        let skull_vertices = 49 * 65;
        for (i, (p, n)) in m.positions.iter().zip(&m.normals).enumerate().take(skull_vertices) {
            let d = p[0] * n[0] + p[1] * n[1] + p[2] * n[2];
            assert!(d > 0.0, "skull vertex {i} at {p:?} has an inward normal {n:?}");
        }
        // Ear vertices: thickness along x at most 2 × 3 mm, and their normals point away from the ear's centre.
        let ears = &m.positions[skull_vertices..];
        let (xmin, xmax) =
            ears.iter().filter(|p| p[0] > 0.0).fold((f32::MAX, f32::MIN), |(a, b), p| (a.min(p[0]), b.max(p[0])));
        assert!((xmax - xmin) * 1000.0 <= 6.0 + 1e-3, "ear thickness {} mm", (xmax - xmin) * 1000.0);
    }

    #[test]
    fn uv_islands_do_not_overlap_and_cover_the_surface() {
        let m = default_head();
        let skull_vertices = 49 * 65;
        assert!(m.uvs[..skull_vertices].iter().all(|uv| (0.0..=0.75).contains(&uv[0]) && (0.0..=1.0).contains(&uv[1])));
        let ears = &m.uvs[skull_vertices..];
        assert!(ears.iter().all(|uv| (0.76..=0.99).contains(&uv[0])));
        let (left, right) = ears.split_at(ears.len() / 2);
        assert!(left.iter().all(|uv| uv[1] <= 0.49) && right.iter().all(|uv| uv[1] >= 0.51));
        // Every triangle has positive UV area with one orientation (no flipped or collapsed texels).
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.uvs[i as usize]);
            let area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
            assert!(area.abs() > 1e-9, "UV-degenerate triangle {t:?}");
        }
    }
}
