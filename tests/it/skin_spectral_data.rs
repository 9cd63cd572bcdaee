//! The embedded tables in `src/spectral/data.rs` equal the attributed source files in `$RTBAKE_DATA_DIR`
//! (default `../shared/data` relative to the crate root). Without that folder the file comparison is reported as
//! skipped (a failure under `RTBAKE_REQUIRE_REFERENCE=1`) and the published anchor values, which need nothing
//! external, are still checked. Regenerate with `python3 scripts/gen_spectral_data.py`.

use rtbake::spectral::data::{CIE1931_2DEG_CMF, CIE_D65_SPD, HEMOGLOBIN_EXTINCTION};

/// Numeric rows of a table (comment and header lines skipped), or `None` when the data folder is absent.
fn rows(name: &str, sep: char) -> Option<Vec<Vec<f64>>> {
    let path = crate::support::data_dir_for("embedded spectral tables vs their source files")?.join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (set RTBAKE_DATA_DIR to the physical data tables)", path.display()));
    Some(
        text.lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#') && !l.starts_with("nm"))
            .map(|l| l.split(sep).map(|t| t.trim().parse::<f64>().unwrap()).collect())
            .collect(),
    )
}

#[test]
fn hemoglobin_table_matches_prahl_file() {
    let Some(r) = rows("hemoglobin_molar_extinction_prahl.tsv", '\t') else { return };
    assert_eq!(r.len(), HEMOGLOBIN_EXTINCTION.len());
    for (i, (row, emb)) in r.iter().zip(HEMOGLOBIN_EXTINCTION.iter()).enumerate() {
        assert_eq!(row[0], 250.0 + 2.0 * i as f64);
        assert_eq!([row[1], row[2]], *emb, "row {i}");
    }
}

#[test]
fn cie_tables_match_files() {
    let (Some(cmf), Some(d65)) = (rows("cie1931_2deg_cmf_380_780_1nm.csv", ','), rows("cie_d65_380_780_1nm.csv", ','))
    else {
        return;
    };
    assert_eq!((cmf.len(), d65.len()), (401, 401));
    for i in 0..401 {
        assert_eq!(cmf[i][0], 380.0 + i as f64);
        assert_eq!([cmf[i][1], cmf[i][2], cmf[i][3]], CIE1931_2DEG_CMF[i], "CMF row {i}");
        assert_eq!(d65[i][1], CIE_D65_SPD[i], "D65 row {i}");
    }
}

/// Published anchors that need no external file: ȳ(555 nm) = 1.0 (CIE 1931 2°), D65 S(560 nm) = 100 (CIE),
/// and the Soret peak of oxy-hemoglobin at 414 nm (Prahl: ε = 524 280 cm⁻¹/M), the table's maximum.
#[test]
fn embedded_tables_hold_published_anchors() {
    assert_eq!(CIE1931_2DEG_CMF[175][1], 1.0);
    assert_eq!(CIE_D65_SPD[180], 100.0);
    let i414 = (414 - 250) / 2;
    assert_eq!(HEMOGLOBIN_EXTINCTION[i414][0], 524280.0);
    assert!(HEMOGLOBIN_EXTINCTION.iter().all(|e| e[0] <= 524280.0));
}
