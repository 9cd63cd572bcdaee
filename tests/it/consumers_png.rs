//! PNGs as engines and colour-managed readers load them: RG data is RGB with B = 0 (an engine reading
//! `AreaTex.png` through the `image` crate, as Bevy does, gets R and G in `.r`/`.g`), data PNGs say linear
//! (`gAMA` 1.0 + `cICP` transfer 8), previews and plots say sRGB (`sRGB` + `cICP` transfer 13).

use crate::support::{baked_dir, baked_files_of_format};
use rtbake::io::png::chunk_types;

fn chunk<'a>(bytes: &'a [u8], name: &[u8; 4]) -> Option<&'a [u8]> {
    let at = bytes.windows(4).position(|w| w == name)?;
    let len = u32::from_be_bytes(bytes[at - 4..at].try_into().unwrap()) as usize;
    Some(&bytes[at + 4..at + 4 + len])
}

#[test]
fn every_baked_png_declares_the_colour_space_of_its_manifest_entry() {
    let files = baked_files_of_format("png");
    assert!(files.len() > 20, "only {} PNGs in baked/", files.len());
    for (path, e) in files {
        let bytes = std::fs::read(&path).unwrap();
        let chunks = chunk_types(&bytes);
        let cicp = chunk(&bytes, b"cICP").unwrap_or_else(|| panic!("{}: no cICP chunk ({chunks:?})", e.path));
        match e.meta.color_space.as_str() {
            "linear" => {
                assert_eq!(cicp, &[1, 8, 0, 1], "{}: cICP", e.path);
                assert_eq!(chunk(&bytes, b"gAMA"), Some(&100_000u32.to_be_bytes()[..]), "{}: gAMA 1.0", e.path);
                assert!(!chunks.contains(b"sRGB"), "{}: linear data tagged sRGB", e.path);
            }
            "srgb" => {
                assert_eq!(cicp, &[1, 13, 0, 1], "{}: cICP", e.path);
                assert!(chunks.contains(b"sRGB"), "{}: no sRGB chunk", e.path);
            }
            other => panic!("{}: colour space {other:?} for a PNG", e.path),
        }
    }
}

#[test]
fn rg_textures_load_with_r_and_g_in_red_and_green() {
    for stem in ["aa/smaa/AreaTex", "aa/mlaa/AreaMap33_v1.4", "facial/wrinkles/example/wrinkle_pd"] {
        let bin = std::fs::read(baked_dir().join(format!("{stem}.bin"))).unwrap();
        let png = std::fs::read(baked_dir().join(format!("{stem}.png"))).unwrap();
        // IHDR: bit depth 8, colour type 2 (RGB).
        assert_eq!((png[24], png[25]), (8, 2), "{stem}.png");
        // What an engine does: decode and expand to RGBA8.
        let rgba = image::load_from_memory(&png).unwrap().to_rgba8();
        assert_eq!(rgba.len() / 4 * 2, bin.len(), "{stem}: texel count");
        let mut wrong_g = 0;
        for (px, rg) in rgba.pixels().zip(bin.chunks_exact(2)) {
            assert_eq!((px[0], px[2], px[3]), (rg[0], 0, 255), "{stem}: R, B = 0, opaque");
            wrong_g += usize::from(px[1] != rg[1]);
        }
        assert_eq!(wrong_g, 0, "{stem}: .g differs in {wrong_g} texels");
    }
}
