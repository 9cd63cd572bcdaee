//! Partial-derivative wrinkle maps (thesis ch. 8): PD encode → 8-bit storage → reconstruction returns the normal
//! within 8-bit quantisation inside the 45° cone; cone clamping is counted; green flip; difference encoding;
//! mask packing and area downsampling.

use rtbake::facial::wrinkles::*;
use rtbake::image_buf::Image;

/// Deterministic unit normals with tilt up to `max_tan` (tan of the angle from +z).
fn normals(count: usize, max_tan: f64) -> Vec<[f64; 3]> {
    let mut s = 0x1234_5678u32;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        s as f64 / u32::MAX as f64
    };
    (0..count)
        .map(|_| {
            let (a, b) = (2.0 * next() - 1.0, 2.0 * next() - 1.0);
            let l = (a * a + b * b).sqrt().max(1e-9);
            let t = max_tan * next();
            from_pd([a / l * t, b / l * t])
        })
        .collect()
}

fn decode_rg8(s: u8) -> f64 {
    2.0 * s as f64 / 255.0 - 1.0
}

#[test]
fn pd_round_trip_within_8_bit_quantisation_inside_the_cone() {
    // Each stored component is off by at most half a step (1/255); normalize(x, y, 1) is 1-Lipschitz in (x, y).
    let bound = 2f64.sqrt() / 255.0 + 1e-12;
    for n in normals(20000, 1.0) {
        let (pd, clamped) = to_pd(n);
        assert!(!clamped);
        let back = from_pd([decode_rg8(encode_snorm_in_unorm8(pd[0])), decode_rg8(encode_snorm_in_unorm8(pd[1]))]);
        let err = ((back[0] - n[0]).powi(2) + (back[1] - n[1]).powi(2) + (back[2] - n[2]).powi(2)).sqrt();
        assert!(err <= bound, "{n:?}: error {err} > {bound}");
    }
}

#[test]
fn pd_of_an_8_bit_normal_map_round_trips() {
    // A normal map stored as 8-bit RGB: PD conversion of the decoded texels reconstructs the decoded normal
    // (normalised) within the PD storage quantisation.
    let ns = normals(4096, 0.95);
    let data: Vec<f32> =
        ns.iter().flat_map(|n| n.map(|c| (2.0 * (((0.5 + 0.5 * c) * 255.0).round() / 255.0) - 1.0) as f32)).collect();
    let img = Image::from_vec(64, 64, 3, data.clone());
    let pd = normals_to_pd("--normal", &img, GreenConvention::DirectX, ConeMode::Reject).unwrap();
    assert_eq!(pd.cone_clamped, 0);
    let rg = pd_to_rg8(64, 64, &pd.pd);
    for (i, px) in data.chunks_exact(3).enumerate() {
        let l = ((px[0] as f64).powi(2) + (px[1] as f64).powi(2) + (px[2] as f64).powi(2)).sqrt();
        let want = [px[0] as f64 / l, px[1] as f64 / l, px[2] as f64 / l];
        let got = from_pd([decode_rg8(rg.data[2 * i]), decode_rg8(rg.data[2 * i + 1])]);
        let err = ((got[0] - want[0]).powi(2) + (got[1] - want[1]).powi(2) + (got[2] - want[2]).powi(2)).sqrt();
        assert!(err <= 2f64.sqrt() / 255.0 + 1e-6, "texel {i}: {err}");
    }
}

#[test]
fn cone_clamping_is_counted_or_rejected() {
    // Two texels: one at 30°, one at 60° from +z.
    let t30 = from_pd([0.577_350_269, 0.0]);
    let t60 = from_pd([0.0, 1.732_050_808]);
    let data: Vec<f32> = t30.iter().chain(&t60).map(|&v| v as f32).collect();
    let img = Image::from_vec(2, 1, 3, data);
    let pd = normals_to_pd("--normal", &img, GreenConvention::DirectX, ConeMode::Clamp).unwrap();
    assert_eq!(pd.cone_clamped, 1);
    assert!((pd.pd[3] - 1.0).abs() < 1e-6 && pd.pd[2].abs() < 1e-6, "clamped to 45°: {:?}", &pd.pd[2..]);
    let e = normals_to_pd("--normal", &img, GreenConvention::DirectX, ConeMode::Reject).unwrap_err();
    assert!(e.to_string().contains("1 texels lie outside the 45° cone"), "{e}");
}

#[test]
fn opengl_green_is_flipped() {
    let n = from_pd([0.2, 0.4]);
    let img = Image::from_vec(1, 1, 3, n.iter().map(|&v| v as f32).collect());
    let dx = normals_to_pd("--normal", &img, GreenConvention::DirectX, ConeMode::Clamp).unwrap();
    let gl = normals_to_pd("--normal", &img, GreenConvention::OpenGl, ConeMode::Clamp).unwrap();
    assert!((dx.pd[1] - 0.4).abs() < 1e-6 && (gl.pd[1] + 0.4).abs() < 1e-6);
    assert_eq!(dx.pd[0], gl.pd[0]);
}

#[test]
fn difference_encoding_matches_the_thesis_formula() {
    let w = [0.3f32, -0.2, 0.932_737_9];
    let b = [0.0f32, 0.0, 1.0];
    let wi = Image::from_vec(1, 1, 3, w.to_vec());
    let bi = Image::from_vec(1, 1, 3, b.to_vec());
    let (d, clamped) = difference_map(&wi, &bi, GreenConvention::DirectX);
    assert_eq!(clamped, 0);
    let l = (w.iter().map(|&v| (v as f64).powi(2)).sum::<f64>()).sqrt();
    for c in 0..3 {
        assert!((d[c] - (0.5 + 0.5 * (w[c] as f64 / l - b[c] as f64))).abs() < 1e-12);
    }
    // Opposite tilts exceed the storable range and are clamped.
    let wi = Image::from_vec(1, 1, 3, vec![0.7f32, 0.0, 0.714]);
    let bi = Image::from_vec(1, 1, 3, vec![-0.7f32, 0.0, 0.714]);
    assert_eq!(difference_map(&wi, &bi, GreenConvention::DirectX).1, 1);
}

#[test]
fn pd_composition_adds_wrinkles_by_zone() {
    // With zero base and one active zone at weight 1, the wrinkle normal is reproduced; weight 0 gives +z.
    let wr = [0.3, -0.1];
    let mut masks = [0.0; 8];
    masks[4] = 1.0;
    let mut weights = [0.0; 8];
    weights[4] = 1.0;
    let n = wrinkled_normal([0.0, 0.0], wr, masks, weights);
    let want = from_pd(wr);
    assert!((0..3).all(|c| (n[c] - want[c]).abs() < 1e-12));
    assert_eq!(wrinkled_normal([0.0, 0.0], wr, masks, [0.0; 8]), [0.0, 0.0, 1.0]);
    // Joy activates the forehead zones red/green fully (Table 8.1).
    let z = zone_weights(&[("joy", 1.0)]).unwrap();
    assert_eq!(z, [1.0, 1.0, 0.2, 0.2, 0.0, 0.0, 0.0, 0.0]);
    assert!(zone_weights(&[("smile", 1.0)]).is_err());
}

#[test]
fn masks_pack_into_two_rgba8_textures_with_area_filtering() {
    let (w, h) = (128u32, 128u32);
    let mut masks: [Option<Vec<f64>>; 8] = Default::default();
    // red: left half 1; gray: constant 0.5; others missing (0).
    masks[0] = Some((0..w * h).map(|i| if i % w < w / 2 { 1.0 } else { 0.0 }).collect());
    masks[7] = Some(vec![0.5; (w * h) as usize]);
    let [m0, m1] = pack_zone_masks(&masks, w, h, 64);
    assert_eq!((m0.width, m0.height, m0.channels), (64, 64, 4));
    assert_eq!(m0.data[0], 255); // red, left
    assert_eq!(m0.data[(63) * 4], 0); // red, right
    assert!(m0.data.iter().skip(1).step_by(4).all(|&v| v == 0)); // green missing
    assert!(m1.data.iter().skip(3).step_by(4).all(|&v| v == 128)); // gray = round(127.5)
                                                                   // Non-integer ratio 128 -> 48 (8/3): the step stays sharp and the mean is preserved.
    let [m0, _] = pack_zone_masks(&masks, w, h, 48);
    let row: Vec<u8> = (0..48).map(|x| m0.data[x * 4]).collect();
    assert_eq!(row[23], 255);
    assert_eq!(row[24], 0);
    let mean_in = 0.5;
    let mean_out = m0.data.iter().step_by(4).map(|&v| v as f64 / 255.0).sum::<f64>() / (48.0 * 48.0);
    assert!((mean_out - mean_in).abs() < 0.01);
}
