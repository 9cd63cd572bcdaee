//! The physical tables of the spectral skin model, embedded as the published files (`src/spectral/data/`, each
//! naming its source in its header, byte for byte the files of the project's `data/` folder) and parsed once, at
//! first use, into fixed-size tables.
//!
//! - [`hemoglobin_extinction`]: S. Prahl, Oregon Medical Laser Center, "Optical Absorption of Hemoglobin" (1999),
//!   compiled from W. B. Gratzer (Med. Res. Council Labs, Holly Hill, London) and N. Kollias (Wellman
//!   Laboratories, Harvard Medical School, Boston).
//! - [`cie1931_2deg_cmf`]: CIE 018:2019 / CIE 15:2018 tables, exported from colour-science 0.4.7
//!   (`colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]`).
//! - [`cie_d65_spd`]: ISO 11664-2:2007 / CIE S 014-2, exported from colour-science 0.4.7
//!   (`colour.SDS_ILLUMINANTS["D65"]`).
//!
//! Every value is the correctly rounded f64 of its printed decimal (Rust's `f64` parsing), as a literal in the
//! source would be. `tests/it/skin_spectral_data.rs` checks the embedded files against the data folder and the
//! tables' published anchors.

use std::sync::OnceLock;

/// First wavelength of [`hemoglobin_extinction`], nm.
pub const HEMOGLOBIN_FIRST_NM: u32 = 250;
/// Wavelength step of [`hemoglobin_extinction`], nm.
pub const HEMOGLOBIN_STEP_NM: u32 = 2;
/// Rows of [`hemoglobin_extinction`] (250–1000 nm).
pub const HEMOGLOBIN_LEN: usize = 376;
/// First wavelength of the CIE tables, nm (1 nm steps to 780 nm, 401 rows).
pub const CIE_FIRST_NM: u32 = 380;
/// Number of rows of the CIE tables.
pub const CIE_LEN: usize = 401;

/// The embedded Prahl table (tab-separated: nm, HbO2, Hb).
pub const HEMOGLOBIN_FILE: (&str, &str) =
    ("hemoglobin_molar_extinction_prahl.tsv", include_str!("data/hemoglobin_molar_extinction_prahl.tsv"));
/// The embedded CIE 1931 2° observer (CSV: nm, x̄, ȳ, z̄).
pub const CIE_CMF_FILE: (&str, &str) =
    ("cie1931_2deg_cmf_380_780_1nm.csv", include_str!("data/cie1931_2deg_cmf_380_780_1nm.csv"));
/// The embedded D65 relative SPD (CSV: nm, S).
pub const CIE_D65_FILE: (&str, &str) = ("cie_d65_380_780_1nm.csv", include_str!("data/cie_d65_380_780_1nm.csv"));

/// Molar extinction coefficient ε of oxy- and deoxy-hemoglobin `[HbO2, Hb]` in water, **cm⁻¹/(mol/L), decadic**,
/// 250–1000 nm in 2 nm steps (row i is λ = 250 + 2i nm). Whole blood: μa [cm⁻¹] = ln(10) · ε · (150 g/L) /
/// (64500 g/mol).
pub fn hemoglobin_extinction() -> &'static [[f64; 2]; HEMOGLOBIN_LEN] {
    static TABLE: OnceLock<[[f64; 2]; HEMOGLOBIN_LEN]> = OnceLock::new();
    TABLE.get_or_init(|| table(HEMOGLOBIN_FILE, '\t', HEMOGLOBIN_FIRST_NM, HEMOGLOBIN_STEP_NM))
}

/// CIE 1931 2° standard observer colour-matching functions `[x̄, ȳ, z̄]`, 380–780 nm, 1 nm (dimensionless).
pub fn cie1931_2deg_cmf() -> &'static [[f64; 3]; CIE_LEN] {
    static TABLE: OnceLock<[[f64; 3]; CIE_LEN]> = OnceLock::new();
    TABLE.get_or_init(|| table(CIE_CMF_FILE, ',', CIE_FIRST_NM, 1))
}

/// CIE standard illuminant D65, relative spectral power distribution (S(560 nm) = 100 scale), 380–780 nm, 1 nm.
pub fn cie_d65_spd() -> &'static [f64; CIE_LEN] {
    static TABLE: OnceLock<[f64; CIE_LEN]> = OnceLock::new();
    TABLE.get_or_init(|| table::<1, CIE_LEN>(CIE_D65_FILE, ',', CIE_FIRST_NM, 1).map(|[s]| s))
}

/// The `N` rows of `C` values of an embedded table: `#` comment lines and the header line (starting with a letter)
/// skipped, the first column the wavelength `first_nm + i · step_nm` of row i. The files are compiled in, so a
/// malformed one is a bug of the crate (a panic naming the file and line), caught by the tests.
fn table<const C: usize, const N: usize>(
    (name, text): (&str, &str),
    sep: char,
    first_nm: u32,
    step_nm: u32,
) -> [[f64; C]; N] {
    let mut rows = [[0.0; C]; N];
    let mut n = 0;
    let data =
        text.lines().enumerate().filter(|(_, l)| !l.starts_with('#') && l.starts_with(|c: char| c.is_ascii_digit()));
    for (line, l) in data {
        let bad = |what: &str| -> ! { panic!("embedded {name}, line {}: {what}: {l:?}", line + 1) };
        let mut fields = l.split(sep).map(|t| t.trim().parse::<f64>().unwrap_or_else(|_| bad("not a number")));
        if n == N {
            bad("more rows than the table holds");
        }
        if fields.next() != Some(f64::from(first_nm + n as u32 * step_nm)) {
            bad("wavelength out of sequence");
        }
        for v in rows[n].iter_mut() {
            *v = fields.next().unwrap_or_else(|| bad("too few columns"));
        }
        if fields.next().is_some() {
            bad("too many columns");
        }
        n += 1;
    }
    assert_eq!(n, N, "embedded {name}: {n} rows, expected {N}");
    rows
}
