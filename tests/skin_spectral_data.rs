//! The embedded tables in `src/spectral/data.rs` equal the attributed source files in `$RTBAKE_DATA_DIR`
//! (default `../shared/data` relative to the crate root). A missing source file is a failure, not a skip.
//! Regenerate with `python3 scripts/gen_spectral_data.py`.

use rtbake::spectral::data::{CIE1931_2DEG_CMF, CIE_D65_SPD, HEMOGLOBIN_EXTINCTION};
use std::path::PathBuf;

fn data_dir() -> PathBuf {
    std::env::var_os("RTBAKE_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"))
}

/// Numeric rows of a table (comment and header lines skipped).
fn rows(name: &str, sep: char) -> Vec<Vec<f64>> {
    let path = data_dir().join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (set RTBAKE_DATA_DIR to the physical data tables)", path.display()));
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#') && !l.starts_with("nm"))
        .map(|l| l.split(sep).map(|t| t.trim().parse::<f64>().unwrap()).collect())
        .collect()
}

#[test]
fn hemoglobin_table_matches_prahl_file() {
    let r = rows("hemoglobin_molar_extinction_prahl.tsv", '\t');
    assert_eq!(r.len(), HEMOGLOBIN_EXTINCTION.len());
    for (i, (row, emb)) in r.iter().zip(HEMOGLOBIN_EXTINCTION.iter()).enumerate() {
        assert_eq!(row[0], 250.0 + 2.0 * i as f64);
        assert_eq!([row[1], row[2]], *emb, "row {i}");
    }
}

#[test]
fn cie_tables_match_files() {
    let cmf = rows("cie1931_2deg_cmf_380_780_1nm.csv", ',');
    let d65 = rows("cie_d65_380_780_1nm.csv", ',');
    assert_eq!((cmf.len(), d65.len()), (401, 401));
    for i in 0..401 {
        assert_eq!(cmf[i][0], 380.0 + i as f64);
        assert_eq!([cmf[i][1], cmf[i][2], cmf[i][3]], CIE1931_2DEG_CMF[i], "CMF row {i}");
        assert_eq!(d65[i][1], CIE_D65_SPD[i], "D65 row {i}");
    }
    // Published anchors: ȳ(555) = 1.0 (CIE 1931), D65 S(560) = 100.
    assert_eq!(CIE1931_2DEG_CMF[175][1], 1.0);
    assert_eq!(CIE_D65_SPD[180], 100.0);
}
