//! The spectral tables embedded in `src/spectral/data/` are the attributed source files in `$RTBAKE_DATA_DIR`
//! (default `../shared/data` relative to the crate root), byte for byte, and the parsed tables hold their values.
//! Without that folder the file comparison is reported as skipped (a failure under `RTBAKE_REQUIRE_REFERENCE=1`)
//! and the parse and the published anchor values, which need nothing external, are still checked.

use rtbake::spectral::data::{
    cie1931_2deg_cmf, cie_d65_spd, hemoglobin_extinction, CIE_CMF_FILE, CIE_D65_FILE, HEMOGLOBIN_FILE,
};

/// Numeric rows of a table's text (comment and header lines skipped), parsed here independently of the crate.
fn rows(text: &str, sep: char) -> Vec<Vec<f64>> {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#') && !l.starts_with("nm"))
        .map(|l| l.split(sep).map(|t| t.trim().parse::<f64>().unwrap()).collect())
        .collect()
}

#[test]
fn embedded_files_are_the_data_folders_files() {
    let Some(dir) = crate::support::data_dir_for("embedded spectral tables vs their source files") else { return };
    for (name, text) in [HEMOGLOBIN_FILE, CIE_CMF_FILE, CIE_D65_FILE] {
        let source = std::fs::read_to_string(dir.join(name))
            .unwrap_or_else(|e| panic!("{name}: {e} (set RTBAKE_DATA_DIR to the physical data tables)"));
        assert!(source == text, "src/spectral/data/{name} differs from {}", dir.join(name).display());
    }
}

#[test]
fn hemoglobin_table_holds_the_prahl_rows() {
    let r = rows(HEMOGLOBIN_FILE.1, '\t');
    assert_eq!(r.len(), hemoglobin_extinction().len());
    for (i, (row, emb)) in r.iter().zip(hemoglobin_extinction().iter()).enumerate() {
        assert_eq!(row[0], 250.0 + 2.0 * i as f64);
        assert_eq!([row[1], row[2]], *emb, "row {i}");
    }
}

#[test]
fn cie_tables_hold_the_cie_rows() {
    let (cmf, d65) = (rows(CIE_CMF_FILE.1, ','), rows(CIE_D65_FILE.1, ','));
    assert_eq!((cmf.len(), d65.len()), (401, 401));
    for i in 0..401 {
        assert_eq!((cmf[i][0], d65[i][0]), (380.0 + i as f64, 380.0 + i as f64));
        assert_eq!([cmf[i][1], cmf[i][2], cmf[i][3]], cie1931_2deg_cmf()[i], "CMF row {i}");
        assert_eq!(d65[i][1], cie_d65_spd()[i], "D65 row {i}");
    }
}

/// Published anchors that need no external file: ȳ(555 nm) = 1.0 (CIE 1931 2°), D65 S(560 nm) = 100 (CIE),
/// and the Soret peak of oxy-hemoglobin at 414 nm (Prahl: ε = 524 280 cm⁻¹/M), the table's maximum.
#[test]
fn embedded_tables_hold_published_anchors() {
    assert_eq!(cie1931_2deg_cmf()[175][1], 1.0);
    assert_eq!(cie_d65_spd()[180], 100.0);
    let i414 = (414 - 250) / 2;
    assert_eq!(hemoglobin_extinction()[i414][0], 524280.0);
    assert!(hemoglobin_extinction().iter().all(|e| e[0] <= 524280.0));
}
