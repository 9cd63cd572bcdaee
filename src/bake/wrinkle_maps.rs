//! The wrinkle-map conversions of `rtbake maps wrinkles` and `rtbake maps wrinkle-masks` (thesis ch. 8; Jimenez
//! et al., "Practical and Realistic Facial Wrinkles Animation", GPU Pro 2, 2011): decoded unit normals → the stored
//! wrinkle map (partial derivatives, §8.2, or the difference map d = 0.5 + 0.5 (w − b) of §8.2.1), eight zone
//! masks → two RGBA8 textures, and each one's report (`wrinkles.json`, schema [`schema::WRINKLES`];
//! `wrinkle_masks.json`, schema [`schema::WRINKLE_MASKS`]). Pure: files and reports in, nothing written; the CLI
//! decodes the inputs, checks the budget and writes the set.

use super::facial::{mask_convention, pd_wrinkle_files};
use super::{json_file, unorm8_texture_files, BakeError, BakedFile};
use crate::baked_layout::{path, schema};
use crate::facial::wrinkles::{self, ConeMode, GreenConvention, WrinkleEncoding};
use crate::image_buf::Image;
use crate::manifest::FileKind;
use serde_json::{json, Value};

/// The settings of one wrinkle conversion.
#[derive(Clone, Debug)]
pub struct WrinkleConversion {
    /// The input's file name, recorded in the report.
    pub input_name: String,
    /// Green convention of the inputs (outputs are always DirectX).
    pub green: GreenConvention,
    /// Normals outside the 45° cone of a PD map: clamped (and counted) or refused.
    pub cone: ConeMode,
    /// Stored map or difference map.
    pub encoding: WrinkleEncoding,
    /// Stored size, texels (area-downsampled, clamped per axis to the input).
    pub size: u32,
}

/// The files and report of a conversion, and a one-line summary for the user.
#[derive(Clone, Debug)]
pub struct WrinkleOutput {
    pub files: Vec<BakedFile>,
    /// `wrinkles.json`'s content (also the files' last entry).
    pub report: Value,
    pub summary: String,
}

/// How a difference map's texels are read.
const DIFFERENCE_CONVENTION: &str = "difference normal map d = 0.5 + 0.5*(w - b) of unit normals (thesis 8.2.1), RGB = xyz, A = 1; add 2*d - 1 to the base normal and renormalise; DirectX green";

/// Converts the decoded unit normals `normal` (and the base map `base`, same size; required by the difference
/// encoding, which the caller checks) into the wrinkle files and `wrinkles.json`.
pub fn wrinkle_files(
    normal: &Image<f32>,
    base: Option<&Image<f32>>,
    c: &WrinkleConversion,
) -> Result<WrinkleOutput, BakeError> {
    let (w, h) = (normal.width, normal.height);
    let mut files = Vec::new();
    let mut report = json!({
        "schema": schema::WRINKLES,
        "input": c.input_name,
        "input_green": c.green,
        "output_green": GreenConvention::DirectX,
        "encoding": c.encoding,
    });
    let summary = match (c.encoding, base) {
        (WrinkleEncoding::Difference, Some(base)) => {
            let (d, clamped) = wrinkles::difference_map(normal, base, c.green);
            let (ow, oh, small) = wrinkles::downsample(&d, w, h, 3, c.size);
            let img = wrinkles::difference_to_rgba8(ow, oh, &small);
            files.extend(unorm8_texture_files("wrinkle_difference", &img, FileKind::Lut, DIFFERENCE_CONVENTION)?);
            report["wrinkle"] = json!({"files": "wrinkle_difference.{bin,dds,ktx2,png}", "size": [ow, oh], "format": "R8G8B8A8_UNORM", "range_clamped_texels": clamped});
            format!("difference map {ow}x{oh}: {clamped} texels had components outside [-1, 1] and were clamped")
        }
        (WrinkleEncoding::Difference, None) => {
            return Err(crate::error::InvalidInput::new("base", "is required with the difference encoding").into())
        }
        (WrinkleEncoding::Pd, _) => {
            let (pd_files, mut wrinkle, base_report) = pd_wrinkle_files("", normal, base, c.green, c.cone, c.size)?;
            files.extend(pd_files);
            let count = |v: &Value, k: &str| v[k].as_u64().unwrap_or(0);
            let cone_clamped = count(&wrinkle, "cone_clamped_texels")
                + base_report.as_ref().map(|b| count(b, "cone_clamped_texels")).unwrap_or(0);
            let range_clamped = count(&wrinkle, "range_clamped_texels");
            wrinkle["relative_to_base"] = json!(base.is_some());
            wrinkle["range_clamped_texels"] = json!(range_clamped);
            if let Some(b) = base_report {
                report["base"] = b;
            }
            let (ow, oh) = (wrinkle["size"][0].as_u64().unwrap_or(0), wrinkle["size"][1].as_u64().unwrap_or(0));
            report["wrinkle"] = wrinkle;
            format!(
                "PD wrinkle map {ow}x{oh}: {cone_clamped} texels clamped to the 45-degree cone, {range_clamped} clamped to [-1, 1]"
            )
        }
    };
    report["composition"] = json!("n = normalize(base.xy + sum_z mask_z * weight_z * wrinkle.xy, 1), texel.rg -> 2*rg - 1 (thesis Listing 8.1; read .rg, not .gr)");
    files.push(json_file("wrinkles.json", &report, FileKind::Json, "wrinkle conversion report"));
    Ok(WrinkleOutput { files, report, summary })
}

/// Packs the eight zone masks (`masks[z]` for zone [`wrinkles::ZONES`]`[z]`, `w`×`h`, missing zones 0) into the two
/// RGBA8 textures at `size` and `wrinkle_masks.json`. Returns the files, the report and the packed size.
pub fn mask_files(
    masks: &[Option<Vec<f64>>; 8],
    w: u32,
    h: u32,
    size: u32,
) -> Result<(Vec<BakedFile>, Value, [u32; 2]), BakeError> {
    let packed = wrinkles::pack_zone_masks(masks, w, h, size);
    let mut files = Vec::new();
    for (i, img) in packed.iter().enumerate() {
        files.extend(unorm8_texture_files(&path::wrinkle_masks_stem("", i), img, FileKind::Lut, &mask_convention(i))?);
    }
    let given: Vec<&str> = wrinkles::ZONES.iter().zip(masks).filter(|(_, m)| m.is_some()).map(|(z, _)| *z).collect();
    let packed_size = [packed[0].width, packed[0].height];
    let report = json!({
        "schema": schema::WRINKLE_MASKS,
        "size": packed_size,
        "format": "R8G8B8A8_UNORM",
        "wrinkle_masks_0": {"r": "red", "g": "green", "b": "blue", "a": "brown"},
        "wrinkle_masks_1": {"r": "cyan", "g": "magenta", "b": "orange", "a": "gray"},
        "zones_given": given,
    });
    files.push(json_file("wrinkle_masks.json", &report, FileKind::Json, "wrinkle mask packing"));
    Ok((files, report, packed_size))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(n: u32) -> Image<f32> {
        Image::from_vec(n, n, 3, (0..n * n).flat_map(|_| [0.0, 0.0, 1.0]).collect())
    }

    /// A flat normal map converts to a neutral PD map (texels at 0.5 → 128) with nothing clamped, and the report
    /// carries its schema and the input's conventions.
    #[test]
    fn flat_normals_give_a_neutral_pd_map_and_a_report() {
        let c = WrinkleConversion {
            input_name: "n.png".into(),
            green: GreenConvention::OpenGl,
            cone: ConeMode::Clamp,
            encoding: WrinkleEncoding::Pd,
            size: 4,
        };
        let out = wrinkle_files(&flat(8), None, &c).unwrap();
        assert_eq!(out.report["schema"], schema::WRINKLES);
        assert_eq!(out.report["input_green"], "opengl");
        assert_eq!(out.report["encoding"], "pd");
        assert_eq!(out.report["wrinkle"]["size"], json!([4, 4]));
        assert_eq!(out.report["wrinkle"]["cone_clamped_texels"], 0);
        let bin = out.files.iter().find(|f| f.path == "wrinkle_pd.bin").unwrap();
        let neutral = wrinkles::encode_unorm8(0.5);
        assert!(bin.bytes.iter().all(|&b| b == neutral), "{:?}", &bin.bytes[..4]);
        assert_eq!(out.files.last().unwrap().path, "wrinkles.json");
        let no_base = WrinkleConversion { encoding: WrinkleEncoding::Difference, ..c };
        assert!(wrinkle_files(&flat(8), None, &no_base).unwrap_err().to_string().contains("base"));
    }

    /// The masks' report names the zones given and the packed size.
    #[test]
    fn masks_report_names_the_zones_given() {
        let mut masks: [Option<Vec<f64>>; 8] = Default::default();
        masks[2] = Some(vec![1.0; 16]);
        let (files, report, size) = mask_files(&masks, 4, 4, 2).unwrap();
        assert_eq!(size, [2, 2]);
        assert_eq!(report["zones_given"], json!(["blue"]));
        assert_eq!(report["schema"], schema::WRINKLE_MASKS);
        assert!(files.iter().any(|f| f.path == "wrinkle_masks_1.png"));
    }
}
