//! The facial maps' EXRs as the `image` crate's decoder (Bevy's EXR loader) reads them: it needs R, G and B
//! channels, so every one-channel map (`h0`, `*_scale`, `*_bias`, channel `Y`) has an `_rgb.exr` sibling with the
//! value in R that decodes to the same numbers.

use crate::support::baked_dir;

#[test]
fn image_crate_decodes_the_rgb_exr_siblings_to_the_map_values() {
    let dir = baked_dir().join("facial/hemoglobin/example");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        let Some(stem) = name.strip_suffix("_rgb.exr") else { continue };
        let bytes = std::fs::read(dir.join(&name)).unwrap();
        let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::OpenExr)
            .unwrap_or_else(|e| panic!("{name}: the image crate refuses it: {e}"))
            .to_rgba32f();
        let (single, _) =
            rtbake::io::exr::decode(&std::fs::read(dir.join(format!("{stem}.exr"))).unwrap(), stem).unwrap();
        assert_eq!((img.width(), img.height()), (single.width, single.height), "{name}");
        for (px, v) in img.pixels().zip(&single.data) {
            assert_eq!((px[0], px[1], px[2]), (*v, 0.0, 0.0), "{name}");
        }
        // The one-channel file is what the image crate cannot read (why the sibling exists).
        let y = std::fs::read(dir.join(format!("{stem}.exr"))).unwrap();
        assert!(image::load_from_memory_with_format(&y, image::ImageFormat::OpenExr).is_err(), "{stem}.exr");
        checked += 1;
    }
    assert_eq!(checked, 11, "h0 + 5 expressions x (scale, bias)");
}
