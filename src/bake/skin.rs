//! Skin-colour assets in `baked/skin/`: the melanin × hemoglobin lookup table (thesis §7.6, eq. 7.7, Fig. 7.9).

use super::{json_file, parse_params, text_file, Asset, BakeError, BakedFile};
use crate::manifest::{FileFormat, FileKind};
use crate::skin_color::lut::{bake_lut_with_progress, IndexForm, LutLayout};
use crate::skin_color::monte_carlo::McColorParams;
use crate::skin_color::two_layer::{SkinColorError, TwoLayerSkinModel};
use crate::skin_color::SkinColorParams;
use serde_json::Value;
use std::fmt::Write;

/// Asset name of the skin-colour table.
pub const SKIN_COLOR_LUT: &str = "skin-color-lut";
pub use crate::baked_layout::path::{
    SKIN_LUT_SIDECAR as SIDECAR_PATH, SKIN_LUT_STEM as LUT_STEM, SKIN_SAMPLES as SAMPLES_PATH,
    SKIN_SPECTRA as SPECTRA_PATH,
};
use crate::baked_layout::{SkinLutFiles, SkinLutIndex, SkinLutModel, SkinLutRange, SkinLutSidecar};

/// Absolute tolerance `verify` allows on the f32 table (libm differences across platforms are ~1e−15).
pub const LUT_TOLERANCE: f64 = 1e-6;

/// (Cm, Chd) points of the sample CSV: light to dark along melanin × pale to flushed along hemoglobin.
pub const SAMPLE_MELANIN: [f64; 7] = [0.0, 0.01, 0.035, 0.07, 0.15, 0.3, 0.5];
pub const SAMPLE_HEMOGLOBIN: [f64; 6] = [0.0, 0.01, 0.04, 0.1, 0.2, 0.32];
/// Points whose spectra R(λ) are written (the four corners of Table 7.1 and a medium tone).
pub const SPECTRUM_POINTS: [(f64, f64); 5] = [(0.0, 0.0), (0.5, 0.0), (0.0, 0.32), (0.5, 0.32), (0.07, 0.04)];

pub fn assets() -> Vec<Asset> {
    vec![
        Asset {
            name: SKIN_COLOR_LUT,
            summary: "skin colour LUT: melanin x hemoglobin -> linear sRGB albedo (spectral two-layer model, eq. 7.7)",
            default_params: || serde_json::to_value(SkinColorParams::default()).expect("params serialise"),
            bake: |v| {
                let p: SkinColorParams = parse_params(SKIN_COLOR_LUT, v)?;
                skin_color_lut_files(&p)
            },
            time_estimate: Some(|v, threads| {
                let p: SkinColorParams = parse_params(SKIN_COLOR_LUT, v)?;
                let layout = p.layout().map_err(invalid)?;
                let bands = p.model().map_err(invalid)?.wavelengths_nm().len();
                Ok(crate::skin_color::lut::time_estimate_seconds(&layout, p.lut_evaluation, bands, threads))
            }),
        },
        Asset {
            name: SKIN_COLOR_MC_DIFFERENCE,
            summary: "published skin colour LUT vs Monte Carlo transport: CIELAB dE*ab map (coarse MC grid, bilinear)",
            default_params: || serde_json::to_value(McColorParams::default()).expect("params serialise"),
            bake: |v| {
                let p: McColorParams = parse_params(SKIN_COLOR_MC_DIFFERENCE, v)?;
                skin_color_mc_difference_files(&p)
            },
            time_estimate: Some(|v, threads| {
                let p: McColorParams = parse_params(SKIN_COLOR_MC_DIFFERENCE, v)?;
                Ok(p.time_estimate_seconds(&SkinColorParams::default().physiology(), threads)?)
            }),
        },
    ]
}

/// Asset name of the published-LUT-versus-Monte-Carlo difference map.
pub const SKIN_COLOR_MC_DIFFERENCE: &str = "skin-color-mc-difference";

/// Every file of the difference asset: the published table (multipole, thesis defaults) against the Monte Carlo
/// grid of `p` ([`crate::skin_color::monte_carlo`]).
pub fn skin_color_mc_difference_files(p: &McColorParams) -> Result<Vec<BakedFile>, BakeError> {
    skin_color_mc_difference_files_for(&SkinColorParams::default(), p)
}

/// [`skin_color_mc_difference_files`] for the table of `published` (its physiology, adding, spectral step, …;
/// the Monte Carlo runs the same physiology) — `rtbake skin-color --model mc`.
pub fn skin_color_mc_difference_files_for(
    published: &SkinColorParams,
    p: &McColorParams,
) -> Result<Vec<BakedFile>, BakeError> {
    use crate::baked_layout::path::{SKIN_MC_DIFFERENCE_CSV, SKIN_MC_DIFFERENCE_PNG, SKIN_MC_NODES};
    use crate::skin_color::monte_carlo::{difference_map, McColorGrid};
    let model = published.model().map_err(invalid)?;
    let grid = McColorGrid::simulate(p, &published.physiology())?;
    let map = difference_map(&model, &grid)?;
    let n = p.map_size;
    let (worst_i, worst) =
        map.iter()
            .enumerate()
            .fold((0, 0.0f64), |(bi, b), (i, t)| if t.delta_e_ab > b { (i, t.delta_e_ab) } else { (bi, b) });
    // Colour ramp black -> red -> yellow -> white over 0..scale, scale = max dE rounded up to a multiple of 5.
    let scale = ((worst / 5.0).ceil() * 5.0).max(5.0);
    let mut px = crate::image_buf::Image::from_vec(n, n, 3, vec![0u8; (3 * n * n) as usize]);
    for (k, t) in map.iter().enumerate() {
        let (i, j) = (k as u32 % n, k as u32 / n);
        // Row 0 of the map is Chd = 0, drawn at the top like the LUT preview.
        let c = crate::plot::sheet::difference_colour((t.delta_e_ab / scale) as f32);
        for (ch, v) in c.into_iter().enumerate() {
            px.set(i, j, ch as u32, v);
        }
    }
    let layout = LutLayout { width: n, height: n, index_form: IndexForm::NormalizedCbrt };
    let mut axes = lut_axes(&layout);
    axes.title = format!(
        "published skin LUT vs Monte Carlo (g {}): CIELAB dE*ab, black 0 > red > yellow > white {scale}; max {worst:.1}",
        p.g
    );
    let img = crate::plot::preview::labelled_preview(&px, &axes);
    let conv = format!(
        "plot for people: CIELAB dE*ab (D65 white) between the published skin-colour LUT (multipole + symmetric          adding, 1 nm) and Monte Carlo transport (g {}, {} photons per wavelength and node, {} nm, {}x{} nodes          uniform in u = cbrt(Cm/0.5), v = cbrt(Chd/0.32), ratio MC/published interpolated bilinearly), {n}x{n} texel centres; Cm along x, Chd down y",
        p.g, p.photons, p.mc_step_nm, p.mc_nodes, p.mc_nodes
    );
    let mut meta = crate::manifest::FileMeta::text(FileKind::Plot, FileFormat::Png, &conv);
    (meta.width, meta.height, meta.channels) = (img.width, img.height, img.channels);
    meta.sample_type = crate::manifest::SampleType::U8;
    meta.color_space = crate::manifest::ColorSpace::Srgb;
    let png = BakedFile {
        path: SKIN_MC_DIFFERENCE_PNG.into(),
        bytes: crate::io::png::encode_u8_as(&img, crate::io::png::PngColor::Srgb)?,
        meta,
    };
    let mut csv = String::from(
        "melanin_cm,hemoglobin_chd,published_r,published_g,published_b,mc_r,mc_g,mc_b,delta_e_ab,relative_luminance\n",
    );
    for t in &map {
        let [pr, pg, pb] = t.published_linear_rgb;
        let [mr, mg, mb] = t.monte_carlo_linear_rgb;
        writeln!(
            csv,
            "{:.8},{:.8},{pr:.8},{pg:.8},{pb:.8},{mr:.8},{mg:.8},{mb:.8},{:.6},{:.6}",
            t.melanin, t.hemoglobin, t.delta_e_ab, t.relative_luminance
        )
        .expect("string write");
    }
    let mut nodes = String::from("melanin_cm,hemoglobin_chd,mc_r,mc_g,mc_b,se_r,se_g,se_b,seed\n");
    for (k, (c, se)) in grid.linear_rgb.iter().zip(&grid.linear_rgb_se).enumerate() {
        let (i, j) = (k as u32 % p.mc_nodes, k as u32 / p.mc_nodes);
        let (cm, chd) = p.node(i, j);
        writeln!(
            nodes,
            "{cm:.8},{chd:.8},{:.8},{:.8},{:.8},{:.8},{:.8},{:.8},{}",
            c[0],
            c[1],
            c[2],
            se[0],
            se[1],
            se[2],
            p.seed.wrapping_add(k as u64)
        )
        .expect("string write");
    }
    let w = &map[worst_i];
    let csv_conv = format!(
        "one row per texel centre of the {n}x{n} map (Chd slowest): linear sRGB of the published LUT and of the \
         Monte Carlo grid (published times the bilinear node ratio), CIELAB dE*ab and (Y_mc - Y_published)/Y_published; largest dE*ab {worst:.2} at \
         Cm {:.4}, Chd {:.4}",
        w.melanin, w.hemoglobin
    );
    Ok(vec![
        png,
        text_file(SKIN_MC_DIFFERENCE_CSV, csv, FileKind::Csv, FileFormat::Csv, &csv_conv),
        text_file(
            SKIN_MC_NODES,
            nodes,
            FileKind::Csv,
            FileFormat::Csv,
            "Monte Carlo nodes: total diffuse reflectance (per entering flux) projected to linear sRGB with the LUT's \
             colour weights, its standard error per channel, and the node's seed",
        ),
    ])
}

fn invalid(e: SkinColorError) -> BakeError {
    match e {
        SkinColorError::Invalid(i) => BakeError::Invalid(i),
    }
}

/// The texel convention in words and formulas (manifest `convention`, sidecar).
pub fn convention(layout: &LutLayout) -> String {
    let (cm_max, chd_max) = (layout.index_form.melanin_max(), layout.index_form.hemoglobin_max());
    format!(
        "linear sRGB (IEC 61966-2-1 primaries, D65-normalised) diffuse albedo, RGB; column i (u, melanin) holds \
         Cm = {cm_max}*(i/(W-1))^3, row j (v, hemoglobin) holds Chd = {chd_max}*(j/(H-1))^3, top row first, row 0 \
         (texcoord v = 0) is Chd = 0; sample at texcoord = ((cbrt(Cm/{cm_max})*(W-1)+0.5)/W, \
         (cbrt(Chd/{chd_max})*(H-1)+0.5)/H) with W = {}, H = {}",
        layout.width, layout.height
    )
}

/// The preview's axes: melanin Cm along x, hemoglobin Chd down y, both on the table's cube-root index.
fn lut_axes(layout: &LutLayout) -> crate::plot::preview::PreviewAxes {
    let (cm_max, chd_max) = (layout.index_form.melanin_max(), layout.index_form.hemoglobin_max());
    // Texel i of n holds max*(i/(n-1))^3: a value v sits at i = cbrt(v/max)*(n-1).
    let ticks = |max: f64, n: u32| -> Vec<(f64, String)> {
        [0.0, 0.01, 0.05, 0.1, 0.2, 0.3, 0.5]
            .iter()
            .filter(|&&v| v <= max)
            .map(|&v| (((v / max).cbrt() * (n - 1) as f64 + 0.5) / n as f64, format!("{v}")))
            .collect()
    };
    crate::plot::preview::PreviewAxes {
        title: "skin colour LUT: diffuse albedo (linear sRGB, shown sRGB-encoded)".into(),
        x_label: format!("melanin fraction Cm (0..{cm_max}, cube-root axis)"),
        x_ticks: ticks(cm_max, layout.width),
        y_label: format!("hemoglobin fraction Chd (0..{chd_max}, cube-root)"),
        y_ticks: ticks(chd_max, layout.height),
    }
}

/// Every file of the skin-colour asset for `p`.
/// File name relative to the sidecar's own directory (the sidecar sits beside the files it lists, whether in a
/// bake's `skin/` or in `rtbake skin-color --out DIR`).
fn sibling(path: &str) -> &str {
    path.rsplit('/').next().unwrap_or(path)
}

pub fn skin_color_lut_files(p: &SkinColorParams) -> Result<Vec<BakedFile>, BakeError> {
    skin_color_lut_files_with_progress(p, &|_, _| {})
}

/// [`skin_color_lut_files`], reporting table rows as they complete (`progress(rows_done, rows)`).
pub fn skin_color_lut_files_with_progress(
    p: &SkinColorParams,
    progress: &(dyn Fn(u32, u32) + Sync),
) -> Result<Vec<BakedFile>, BakeError> {
    let layout = p.layout().map_err(invalid)?;
    let model = p.model().map_err(invalid)?;
    let img = bake_lut_with_progress(&model, &layout, p.lut_evaluation, progress).map_err(invalid)?;
    let conv = convention(&layout);
    let mut files = super::float_texture_files_with_preview(
        LUT_STEM,
        &img,
        FileKind::Lut,
        &conv,
        LUT_TOLERANCE,
        &lut_axes(&layout),
    )?;
    files.push(json_file(SIDECAR_PATH, &sidecar(p, &layout, &img), FileKind::Json, &conv));
    let samples_conv = "skin colour samples evaluated directly by the spectral model (not read from the table); \
        linear = linear sRGB albedo, srgb8 = IEC 61966-2-1 encoded 8-bit";
    files.push(text_file(
        SAMPLES_PATH,
        samples_csv(&model, &layout).map_err(invalid)?,
        FileKind::Csv,
        FileFormat::Csv,
        samples_conv,
    ));
    files.push(text_file(
        SPECTRA_PATH,
        spectra_csv(&model).map_err(invalid)?,
        FileKind::Csv,
        FileFormat::Csv,
        "total diffuse reflectance R(lambda) of the two-layer stack (before colorimetry), one column per (Cm, Chd)",
    ));
    Ok(files)
}

fn sidecar(p: &SkinColorParams, layout: &LutLayout, img: &crate::image_buf::Image<f32>) -> Value {
    let (cm_max, chd_max) = (layout.index_form.melanin_max(), layout.index_form.hemoglobin_max());
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for px in img.data.chunks_exact(3) {
        for c in 0..3 {
            lo[c] = lo[c].min(px[c]);
            hi[c] = hi[c].max(px[c]);
        }
    }
    let form = match layout.index_form {
        IndexForm::NormalizedCbrt => {
            "u = cbrt(Cm / 0.5), v = cbrt(Chd / 0.32) (eq. 7.7 normalised to Table 7.1's ranges)"
        }
        IndexForm::LiteralCbrt => "u = cbrt(Cm), v = cbrt(Chd) (eq. 7.7 as printed; ranges [0, 1])",
    };
    let sidecar = SkinLutSidecar {
        asset: SKIN_COLOR_LUT.into(),
        description: "Skin colour lookup table (Jimenez 2012, section 7.6, eq. 7.7, Fig. 7.9): total diffuse \
            reflectance of the spectral two-layer skin model (Donner et al. 2008) integrated against an illuminant and \
            the CIE 1931 2-degree observer (see model.colorimetry), as linear sRGB albedo."
            .into(),
        files: SkinLutFiles {
            linear_f32: sibling(&format!("{LUT_STEM}.exr")).into(),
            linear_f16: sibling(&format!("{LUT_STEM}_f16.exr")).into(),
            linear_f16_ktx2: sibling(&format!("{LUT_STEM}.ktx2")).into(),
            preview_srgb8_not_for_sampling: sibling(&format!("{LUT_STEM}_preview_srgb.png")).into(),
            samples: sibling(SAMPLES_PATH).into(),
            spectra: sibling(SPECTRA_PATH).into(),
        },
        color_space: "linear sRGB (IEC 61966-2-1 primaries); the PNG preview alone is sRGB-encoded".into(),
        width: layout.width,
        height: layout.height,
        channels: ["R".into(), "G".into(), "B".into()],
        index: SkinLutIndex {
            form: form.into(),
            u_axis: "columns, left to right: melanin fraction Cm".into(),
            v_axis: "rows, top row first: dermal hemoglobin fraction Chd; row 0 (texcoord v = 0) is Chd = 0".into(),
            melanin_max: cm_max,
            hemoglobin_max: chd_max,
            texel_to_concentration: format!(
                "node-inclusive: t_i = i/(W-1), Cm = {cm_max}*t_i^3; t_j = j/(H-1), Chd = {chd_max}*t_j^3"
            ),
            concentration_to_texcoord: format!(
                "texcoord.x = (cbrt(Cm/{cm_max})*(W-1)+0.5)/W, texcoord.y = (cbrt(Chd/{chd_max})*(H-1)+0.5)/H \
                 (texel centres at the nodes; bilinear filtering)"
            ),
            hlsl: format!(
                "float2 SkinColorUV(float cm, float chd) {{ const float2 n = float2({w}.0, {h}.0); \
                 float2 t = pow(saturate(float2(cm / {cm_max:?}, chd / {chd_max:?})), 1.0 / 3.0); \
                 return (t * (n - 1.0) + 0.5) / n; }}",
                w = layout.width,
                h = layout.height
            ),
            epidermal_hemoglobin: format!("Che = {} * Chd", p.epidermal_hemoglobin_ratio),
        },
        value_range: SkinLutRange { min: lo, max: hi },
        model: SkinLutModel {
            layers: "epidermis over dermis; air above; per-layer multipole totals R(0), T(0) with the exact \
                infinite image series (Donner & Jensen 2005)"
                .into(),
            adding: "symmetric: R = R1 + T1^2 R2 / (1 - R1 R2); directional: R = R1 + T1 R2 T1up / (1 - R1up R2)"
                .into(),
            dermis_bottom: "relative index eta_dermis / eta_below_dermis (default 1 = index-matched: a \
                semi-infinite dermis has no bottom face)"
                .into(),
            colorimetry: format!(
                "illuminant {}, {} nm steps over 380-780 nm, CIE 1931 2-degree observer, Y(perfect white) = 1, XYZ -> \
                 linear sRGB with [3.2406 -1.5372 -0.4986; -0.9689 1.8758 0.0415; 0.0557 -0.2040 1.0570]",
                serde_json::to_value(p.illuminant).expect("enum serialises").as_str().unwrap_or("?"),
                p.spectral_step_nm
            ),
            data: "hemoglobin: S. Prahl (OMLC 1999, Gratzer & Kollias), 2 nm, interpolated linearly to 1 nm; CIE \
                1931 2-degree CMFs and D65: CIE 018:2019 / ISO 11664-2 (1 nm)"
                .into(),
        },
        parameters: serde_json::to_value(p).expect("params serialise"),
    };
    serde_json::to_value(&sidecar).expect("sidecar serialises")
}

fn samples_csv(model: &TwoLayerSkinModel, layout: &LutLayout) -> Result<String, SkinColorError> {
    let mut s = String::from(
        "melanin_cm,hemoglobin_chd,texcoord_u,texcoord_v,\
         linear_r,linear_g,linear_b,srgb8_r,srgb8_g,srgb8_b\n",
    );
    for &chd in &SAMPLE_HEMOGLOBIN {
        for &cm in &SAMPLE_MELANIN {
            let p = model.evaluate(cm, chd, true)?;
            let (u, v) = layout.texcoord(cm, chd);
            let [r, g, b] = p.linear_rgb;
            let [r8, g8, b8] = p.srgb8;
            writeln!(s, "{cm},{chd},{u:.6},{v:.6},{r:.8},{g:.8},{b:.8},{r8},{g8},{b8}").expect("string write");
        }
    }
    Ok(s)
}

fn spectra_csv(model: &TwoLayerSkinModel) -> Result<String, SkinColorError> {
    let samples: Vec<_> =
        SPECTRUM_POINTS.iter().map(|&(cm, chd)| model.evaluate(cm, chd, true)).collect::<Result<_, _>>()?;
    let mut s = String::from("wavelength_nm");
    for p in &samples {
        write!(s, ",R_cm{}_chd{}", p.melanin, p.hemoglobin).expect("string write");
    }
    s.push('\n');
    for (i, l) in model.wavelengths_nm().iter().enumerate() {
        write!(s, "{l}").expect("string write");
        for p in &samples {
            write!(s, ",{:.8}", p.reflectance[i]).expect("string write");
        }
        s.push('\n');
    }
    Ok(s)
}
