//! Prints the per-wavelength layer coefficients of rtbake's physiological two-layer skin (the ones its spectral
//! profiles and the skin-colour LUT use: Donner & Jensen 2006 mixing, `spectral::skin_layers`) as JSON, so an
//! independent transport code can be run on exactly the same stacks (`scripts/mcml_spectral_reference.py`).
//!
//! `cargo run --example skin_coefficients -- CM CHD [STEP_NM]` (STEP_NM divides 400, default 10). Output: one JSON
//! object with the physiology (thicknesses in mm, refractive indices) and, per wavelength, σa and σs′ of the
//! epidermis and the dermis in mm⁻¹.

use rtbake::spectral::colorimetry::SpectralGrid;
use rtbake::spectral::skin_layers::{check_concentrations, SkinPhysiology, DEFAULT_SPECTRAL_STEP_NM};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    anyhow::ensure!(args.len() == 2 || args.len() == 3, "usage: skin_coefficients CM CHD [STEP_NM]");
    let cm: f64 = args[0].parse()?;
    let chd: f64 = args[1].parse()?;
    let step: u32 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(DEFAULT_SPECTRAL_STEP_NM);
    let physiology = SkinPhysiology::default();
    check_concentrations("CM", cm, "CHD", chd, &physiology, false)?;
    let grid = SpectralGrid::new(step)?;
    let rows: Vec<_> = grid
        .wavelengths_nm()
        .into_iter()
        .map(|l| physiology.coefficients_at(l, cm, chd).expect("380-780 nm lies inside the chromophore tables"))
        .collect();
    let out = serde_json::json!({
        "melanin_fraction": cm,
        "hemoglobin_fraction": chd,
        "physiology": physiology,
        "units": "sigma in mm^-1, thickness in mm",
        "coefficients": rows,
    });
    println!("{}", serde_json::to_string_pretty(&out)?);
    Ok(())
}
