//! Every CSV rtbake writes opens with the defaults of the programs people use: the first row is the header, no
//! comment lines, the same number of fields on every row (Python's `csv` module, numpy's `genfromtxt(names=True)`,
//! pandas' `read_csv` where installed; spreadsheets read the same way). Provenance and totals live in the JSON
//! sidecars and the manifest. Profile tables keep the header `r_mm,R_r,R_g,R_b[,T_r,T_g,T_b]` that rtbake's own
//! profile reader takes.

use crate::support::{baked_files_of_format, rtbake, tool_available};

/// Reads one CSV with the Python readers available and prints `OK <rows> <cols> <readers>` or the failure.
const READ_CSV: &str = r##"
import csv, sys
path = sys.argv[1]
with open(path, newline="") as f:
    rows = list(csv.reader(f))
header = rows[0]
assert header and not header[0].startswith("#"), "comment or empty first row: %r" % header[:1]
assert all(h.strip() for h in header), "empty column name"
assert all(len(r) == len(header) for r in rows[1:]), "ragged rows"
assert not any(r and r[0].startswith("#") for r in rows), "comment line"
readers = ["csv"]
try:
    import numpy
    a = numpy.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert list(a.dtype.names) == [h.replace(".", "") for h in header] or len(a.dtype.names) == len(header), a.dtype.names
    assert a.size == len(rows) - 1, (a.size, len(rows))
    readers.append("numpy")
except ImportError:
    pass
try:
    import pandas
    d = pandas.read_csv(path)
    assert list(d.columns) == header, (list(d.columns), header)
    assert d.shape == (len(rows) - 1, len(header)), d.shape
    readers.append("pandas")
except ImportError:
    pass
print("OK", len(rows) - 1, len(header), ",".join(readers))
"##;

fn check_csv(path: &std::path::Path) -> String {
    let out = std::process::Command::new("python3").arg("-c").arg(READ_CSV).arg(path).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success() && text.starts_with("OK "),
        "{}: {text} {}",
        path.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    text
}

fn python() -> bool {
    tool_available("CSV readers", "python3", &["-c", "import csv"], "install python3")
}

#[test]
fn csvs_of_a_fresh_bake_open_with_default_readers() {
    if !python() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut n = 0;
    for asset in ["diffusion-profiles", "skin-color-lut", "burley-profiles"] {
        let a = rtbake::bake::registry().into_iter().find(|a| a.name == asset).unwrap();
        for f in a.run(&(a.default_params)()).unwrap().into_iter().filter(|f| f.path.ends_with(".csv")) {
            let text = String::from_utf8(f.bytes.clone()).unwrap();
            assert!(!text.contains('#'), "{}: a comment in the CSV", f.path);
            let p = dir.path().join(f.path.replace('/', "_"));
            std::fs::write(&p, &f.bytes).unwrap();
            let readers = check_csv(&p);
            if f.path.starts_with("profiles/") && !f.path.ends_with("totals.csv") {
                assert!(text.starts_with("r_mm,R_r,R_g,R_b"), "{}", f.path);
                // rtbake's own reader takes the same file (the profile CSV layout users feed back in).
                rtbake::diffusion::tabulated::TabulatedProfile::from_csv_str(&text, &f.path).unwrap();
            }
            if n == 0 {
                eprintln!("CSV readers that ran: {readers}");
            }
            n += 1;
        }
    }
    assert!(n >= 18, "{n} CSVs");
}

#[test]
fn profile_and_transport_csv_commands_write_plain_csv() {
    if !python() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("skin1.csv");
    let o = rtbake(&["profile", "--material", "skin1", "--csv", p.to_str().unwrap(), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    check_csv(&p);
    let t = dir.path().join("mc.csv");
    let o = rtbake(&[
        "transport",
        "--material",
        "skin1",
        "--photons",
        "2000",
        "--bins",
        "20",
        "--csv",
        t.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&t).unwrap();
    assert!(text.starts_with("r_mm,R_r,R_g,R_b\n"), "{text}");
    check_csv(&t);
    // The transport CSV feeds the fits as a profile, as before.
    let o = rtbake(&["fit", "gaussians", "--profile-csv", t.to_str().unwrap(), "--count", "2", "--json", "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn every_committed_csv_opens_with_default_readers() {
    if !python() {
        return;
    }
    let files = baked_files_of_format("csv");
    assert!(files.len() >= 20);
    for (path, _) in files {
        check_csv(&path);
    }
}
