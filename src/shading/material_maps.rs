//! The surface maps of a scanned head (the seeds' demos render the Lee Perry-Smith scan with an albedo and a
//! tangent-space normal map; TAP 2009 §5, thesis §7.6): decoded from 8-bit pixels into the linear values the
//! shaders use, and validated so that a wrong file is refused by name instead of rendered.
//!
//! - **Albedo** is a colour picture, sRGB-encoded (IEC 61966-2-1): [`albedo_linear`] decodes it to linear RGB.
//!   Thesis §7.6 applies it *after* the scattering ("post-scatter texturing": the diffuse light is blurred, then
//!   multiplied by the albedo), so the map's fine detail is not blurred away.
//! - **A tangent-space normal map** is data, not colour: n = 2·c − 1 per channel, no transfer curve
//!   ([`normals_unit`]). Its green channel follows one of two conventions ([`GreenConvention`]): rtbake's frame
//!   (MikkTSpace, [`crate::mesh::tangents`]) has its bitangent along ∂p/∂v, down the texture (DirectX, "Y−"); an
//!   OpenGL ("Y+") map has green flipped. A map is accepted only if it looks like one: its texels' lengths are
//!   near 1 and it points out of the surface (z > 0) on average — a colour picture given as a normal map fails both.

use crate::error::InvalidInput;
use crate::facial::wrinkles::GreenConvention;
use crate::image_buf::{ImageF32, ImageU8};

/// Smallest and largest accepted map edge, texels.
pub const MIN_MAP_EDGE: u32 = 4;
pub const MAX_MAP_EDGE: u32 = 16384;

/// A normal-map texel is "far from unit length" when its decoded length is outside 1 ± this (8-bit JPEG maps stay
/// within a few per cent).
pub const NORMAL_LENGTH_TOLERANCE: f32 = 0.2;
/// Largest share of texels far from unit length a normal map may have.
pub const MAX_NON_UNIT_SHARE: f64 = 0.02;
/// Smallest mean z of a tangent-space normal map (a flat map has 1; the scan's is about 0.9).
pub const MIN_MEAN_Z: f64 = 0.5;

fn check_shape(param: &str, img: &ImageU8, what: &str) -> Result<(), InvalidInput> {
    if !(img.channels == 3 || img.channels == 4) {
        return Err(InvalidInput::new(
            param,
            format!("has {} channel(s); {what} needs RGB or RGBA (3 or 4)", img.channels),
        ));
    }
    for (name, v) in [("width", img.width), ("height", img.height)] {
        if !(MIN_MAP_EDGE..=MAX_MAP_EDGE).contains(&v) {
            return Err(InvalidInput::new(
                param,
                format!("{name} {v} texels; accepted {MIN_MAP_EDGE}..={MAX_MAP_EDGE}"),
            ));
        }
    }
    if img.data.len() != (img.width * img.height * img.channels) as usize {
        return Err(InvalidInput::new(param, "pixel data does not match its size"));
    }
    Ok(())
}

/// Linear RGB (3 channels) of an sRGB-encoded 8-bit RGB(A) albedo map; alpha is ignored. `param` names the flag.
pub fn albedo_linear(param: &str, img: &ImageU8) -> Result<ImageF32, InvalidInput> {
    check_shape(param, img, "an albedo map")?;
    let lut: Vec<f32> = (0..256).map(|i| crate::color::srgb::decode(i as f64 / 255.0) as f32).collect();
    let data = img
        .data
        .chunks_exact(img.channels as usize)
        .flat_map(|p| [p[0], p[1], p[2]].map(|c| lut[c as usize]))
        .collect();
    Ok(ImageF32::from_vec(img.width, img.height, 3, data))
}

/// What [`normals_unit`] measured of a map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalMapStats {
    /// Share of texels whose decoded length is outside 1 ± [`NORMAL_LENGTH_TOLERANCE`].
    pub non_unit_share: f64,
    /// Mean decoded z (before normalising).
    pub mean_z: f64,
}

/// Unit tangent-space normals (3 channels, rtbake's DirectX frame) of an 8-bit RGB(A) normal map encoded
/// c = 0.5 + 0.5·n; `green` is the map's convention (OpenGL maps get y negated). Refuses, naming `param`, a map
/// that is not a normal map (see the module doc).
pub fn normals_unit(
    param: &str,
    img: &ImageU8,
    green: GreenConvention,
) -> Result<(ImageF32, NormalMapStats), InvalidInput> {
    check_shape(param, img, "a tangent-space normal map")?;
    let n = (img.width * img.height) as usize;
    let (mut far, mut z_sum) = (0usize, 0.0f64);
    let mut data = Vec::with_capacity(3 * n);
    let y_sign = match green {
        GreenConvention::DirectX => 1.0,
        GreenConvention::OpenGl => -1.0,
    };
    for p in img.data.chunks_exact(img.channels as usize) {
        let v = [p[0], p[1], p[2]].map(|c| c as f32 / 255.0 * 2.0 - 1.0);
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if (len - 1.0).abs() > NORMAL_LENGTH_TOLERANCE {
            far += 1;
        }
        z_sum += v[2] as f64;
        let u = if len > 1e-6 { v.map(|c| c / len) } else { [0.0, 0.0, 1.0] };
        data.extend([u[0], y_sign * u[1], u[2]]);
    }
    let stats = NormalMapStats { non_unit_share: far as f64 / n as f64, mean_z: z_sum / n as f64 };
    if stats.non_unit_share > MAX_NON_UNIT_SHARE || stats.mean_z < MIN_MEAN_Z {
        return Err(InvalidInput::new(
            param,
            format!(
                "is not a tangent-space normal map: {:.1} % of its texels decode (2·c − 1) to a length outside \
                 1 ± {NORMAL_LENGTH_TOLERANCE} (accepted at most {:.0} %) and its mean z is {:.2} (accepted ≥ \
                 {MIN_MEAN_Z}); is it a colour picture or an object-space map?",
                100.0 * stats.non_unit_share,
                100.0 * MAX_NON_UNIT_SHARE,
                stats.mean_z
            ),
        ));
    }
    Ok((ImageF32::from_vec(img.width, img.height, 3, data), stats))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encode_normal(n: [f32; 3]) -> [u8; 3] {
        n.map(|c| ((0.5 + 0.5 * c) * 255.0).round() as u8)
    }

    #[test]
    fn albedo_is_decoded_from_srgb_and_alpha_dropped() {
        let img = ImageU8::from_vec(4, 4, 4, [255u8, 188, 0, 7].repeat(16));
        let a = albedo_linear("albedo_map", &img).unwrap();
        assert_eq!(a.channels, 3);
        assert_eq!(a.data[0], 1.0);
        // sRGB 188/255 = 0.737 is linear 0.503.
        assert!((a.data[1] - 0.502_886).abs() < 1e-4, "{}", a.data[1]);
        assert_eq!(a.data[2], 0.0);
    }

    #[test]
    fn wrong_shapes_are_named() {
        let grey = ImageU8::from_vec(8, 8, 1, vec![128; 64]);
        let e = albedo_linear("albedo_map", &grey).unwrap_err();
        assert_eq!(e.param, "albedo_map");
        assert!(e.message.contains("1 channel(s)"), "{e}");
        let tiny = ImageU8::from_vec(2, 8, 3, vec![128; 48]);
        assert!(normals_unit("normal_map", &tiny, GreenConvention::DirectX).unwrap_err().message.contains("width 2"));
    }

    #[test]
    fn a_normal_map_decodes_to_unit_vectors_in_either_green_convention() {
        let n = [0.3f32, -0.4, (1.0f32 - 0.25).sqrt()];
        let img = ImageU8::from_vec(8, 8, 3, encode_normal(n).repeat(64));
        let (dx, stats) = normals_unit("normal_map", &img, GreenConvention::DirectX).unwrap();
        assert!(stats.non_unit_share == 0.0 && stats.mean_z > 0.8);
        let t = &dx.data[..3];
        assert!((t[0] - n[0]).abs() < 0.01 && (t[1] - n[1]).abs() < 0.01 && (t[2] - n[2]).abs() < 0.01, "{t:?}");
        assert!(((t[0] * t[0] + t[1] * t[1] + t[2] * t[2]) - 1.0).abs() < 1e-5);
        let (gl, _) = normals_unit("normal_map", &img, GreenConvention::OpenGl).unwrap();
        assert_eq!(gl.data[1], -dx.data[1]);
        assert_eq!(gl.data[0], dx.data[0]);
    }

    #[test]
    fn a_colour_picture_is_not_a_normal_map() {
        // A skin-coloured picture: lengths far from 1.
        let skin = ImageU8::from_vec(8, 8, 3, [200u8, 150, 120].repeat(64));
        let e = normals_unit("normal_map", &skin, GreenConvention::DirectX).unwrap_err();
        assert_eq!(e.param, "normal_map");
        assert!(e.message.contains("is not a tangent-space normal map"), "{e}");
        // Unit vectors pointing into the surface (an object-space map's back half): mean z < 0.5.
        let inward = ImageU8::from_vec(8, 8, 3, encode_normal([0.0, 0.6, -0.8]).repeat(64));
        assert!(normals_unit("normal_map", &inward, GreenConvention::DirectX).is_err());
    }
}
