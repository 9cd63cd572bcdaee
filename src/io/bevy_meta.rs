//! Bevy asset settings (`<file>.meta`) for data textures.
//!
//! Bevy's `ImageLoader` ignores a file's own colour tags: `ImageLoaderSettings::is_srgb` defaults to `true`, which
//! binds 8-bit RGB(A) data as `*UnormSrgb` and rewrites R8/RG8 levels through an sRGB conversion (Bevy's own SMAA
//! plugin loads its LUTs with `is_srgb = false` for that reason). Bevy reads the settings of `path/to/file.ktx2` from
//! `path/to/file.ktx2.meta` (RON, `AssetMeta` of `bevy_asset::meta`, format version "1.0"), so every linear data
//! texture a Bevy app can load (KTX2, DDS, PNG) gets one saying `is_srgb: false`. The fields are the ones Bevy's
//! `ImageLoaderSettings` has no serde default for (`format`, `is_srgb`, `sampler`, `asset_usage`), with Bevy's
//! defaults except `is_srgb`; the loader path is the one Bevy ≥ 0.15 registers (`bevy_image`).

/// The asset-meta format version Bevy's `bevy_asset::meta::META_FORMAT_VERSION` expects.
pub const META_FORMAT_VERSION: &str = "1.0";
/// The type path of Bevy's image loader (crate `bevy_image`, Bevy 0.15 and later).
pub const IMAGE_LOADER: &str = "bevy_image::image_loader::ImageLoader";

/// The `.meta` path Bevy looks for beside `path`.
pub fn meta_path(path: &str) -> String {
    format!("{path}.meta")
}

/// Whether a file with this manifest container `format` and `color_space` gets a Bevy `.meta`: textures Bevy's
/// `ImageLoader` opens (KTX2, DDS, PNG) that hold linear data.
pub fn wants_meta(format: &str, color_space: &str) -> bool {
    matches!(format, "ktx2" | "dds" | "png") && color_space == "linear"
}

/// The RON text of a linear data texture's `.meta` (`is_srgb: false`, Bevy's defaults otherwise).
pub fn linear_image_meta() -> String {
    format!(
        "(\n    meta_format_version: \"{META_FORMAT_VERSION}\",\n    asset: Load(\n        loader: \"{IMAGE_LOADER}\",\n        \
         settings: (\n            format: FromExtension,\n            is_srgb: false,\n            sampler: Default,\n            \
         asset_usage: RenderAssetUsages(\"MAIN_WORLD | RENDER_WORLD\"),\n        ),\n    ),\n)\n"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meta_is_linear_and_named_after_the_texture() {
        let t = linear_image_meta();
        assert!(t.contains("is_srgb: false,") && !t.contains("is_srgb: true"));
        assert!(t.starts_with("(\n    meta_format_version: \"1.0\",\n"));
        assert_eq!(meta_path("aa/smaa/AreaTex.ktx2"), "aa/smaa/AreaTex.ktx2.meta");
        assert!(wants_meta("ktx2", "linear") && wants_meta("png", "linear") && wants_meta("dds", "linear"));
        assert!(!wants_meta("png", "srgb") && !wants_meta("exr", "linear") && !wants_meta("raw", "linear"));
    }
}
