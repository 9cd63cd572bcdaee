//! Pictures a person opens: every preview of a float table is readable (a one-row table is a labelled band, not a
//! 1-pixel line), carries a title, axis names and ticks, and keeps the table's colours; the normalised fit plot says
//! that it is normalised.

use rtbake::bake::BakedFile;

fn bake(asset: &str) -> Vec<BakedFile> {
    let a = rtbake::bake::registry().into_iter().find(|a| a.name == asset).unwrap();
    a.run(&(a.default_params)()).unwrap()
}

/// Rows of `img` (RGB) that hold dark text-like pixels in columns `x0..x1`.
fn dark_rows(img: &image::RgbImage, x0: u32, x1: u32) -> Vec<u32> {
    (0..img.height())
        .filter(|&y| (x0..x1.min(img.width())).any(|x| img.get_pixel(x, y).0.iter().all(|&v| v < 80)))
        .collect()
}

#[test]
fn float_table_previews_are_framed_readable_pictures_of_the_table() {
    let mut checked = 0;
    for asset in ["transmittance", "skin-color-lut"] {
        let files = bake(asset);
        for f in files.iter().filter(|f| f.meta.kind.as_str() == "preview") {
            let img = image::load_from_memory(&f.bytes).unwrap().to_rgb8();
            assert_eq!((img.width(), img.height()), (f.meta.width, f.meta.height), "{}: manifest size", f.path);
            assert!(img.height() >= 100 && img.width() >= 512, "{}: {}x{}", f.path, img.width(), img.height());
            // Title above the table, tick labels and axis name below it.
            let rows = dark_rows(&img, 0, img.width());
            assert!(rows.iter().any(|&y| y < 25), "{}: no title", f.path);
            assert!(rows.iter().any(|&y| y > img.height() - 25), "{}: no x-axis name", f.path);
            // The table's first texel, sRGB-encoded, fills the frame's top-left corner (64, 30 are the margins).
            let stem = f.path.trim_end_matches("_preview_srgb.png");
            let exr = files.iter().find(|e| e.path == format!("{stem}.exr")).unwrap();
            let (table, _) = rtbake::io::exr::decode(&exr.bytes, &exr.path).unwrap();
            let px = img.get_pixel(64, 30).0;
            for (c, &got) in px.iter().enumerate() {
                let want = (rtbake::color::srgb::encode(table.get(0, 0, c as u32) as f64) * 255.0).round();
                assert!((got as f64 - want).abs() <= 1.0, "{}: channel {c} {got} vs {want}", f.path);
            }
            checked += 1;
        }
    }
    assert!(checked >= 2, "{checked} previews");
}

#[test]
fn skin_lut_preview_names_both_axes() {
    let files = bake("skin-color-lut");
    let f = files.iter().find(|f| f.path.ends_with("_preview_srgb.png")).unwrap();
    let img = image::load_from_memory(&f.bytes).unwrap().to_rgb8();
    // The y-axis name is drawn vertically in the left margin, beside the table.
    let left: Vec<u32> =
        (0..img.height()).filter(|&y| (0..14).any(|x| img.get_pixel(x, y).0.iter().all(|&v| v < 80))).collect();
    assert!(left.len() > 100, "no vertical y-axis name ({} rows)", left.len());
    assert!(f.meta.convention.contains("axis names"), "{}", f.meta.convention);
}

#[test]
fn the_normalised_fit_plot_says_it_is_normalised() {
    let files = bake("sss-gaussians-fit");
    let svg = files.iter().find(|f| f.path.ends_with("_plot.svg")).unwrap();
    let text = String::from_utf8(svg.bytes.clone()).unwrap();
    assert!(text.contains(rtbake::plot::profile::NORMALIZED_Y_LABEL), "y label of the normalised fit plot");
    // The un-normalised preset plots keep the profile units.
    let files = bake("sss-gaussians");
    let svg = files.iter().find(|f| f.path.ends_with("deon6_plot.svg")).unwrap();
    let text = String::from_utf8(svg.bytes.clone()).unwrap();
    assert!(text.contains("r R(r) (1/mm)") && !text.contains("R_total"));
}
