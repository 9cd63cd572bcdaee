//! Scripts parse every `--json` outcome with one parser: a failure prints one JSON object
//! `{"error", "param", "exit_code"}` on stdout (the human message stays on stderr).

use crate::support::rtbake;

fn error_object(args: &[&str]) -> serde_json::Value {
    let o = rtbake(args);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!("{args:?}: stdout is not one JSON object ({e}): {:?}", String::from_utf8_lossy(&o.stdout))
    });
    assert_eq!(v["exit_code"].as_i64(), o.status.code().map(i64::from), "{args:?}");
    assert!(!String::from_utf8_lossy(&o.stderr).is_empty(), "{args:?}: stderr keeps the message");
    v
}

#[test]
fn validation_errors_name_the_parameter() {
    let v = error_object(&["--json", "kernel", "--samples", "2"]);
    assert_eq!(v["exit_code"], 2);
    assert!(v["param"].as_str().unwrap().contains("samples"), "{v}");
    assert!(v["error"].as_str().unwrap().contains("3..=63"), "{v}");
}

#[test]
fn usage_errors_from_the_parser_are_json_too() {
    let v = error_object(&["kernel", "--json", "--no-such-flag"]);
    assert_eq!(v["exit_code"], 2);
    assert_eq!(v["param"], "--no-such-flag");
    let v = error_object(&["--json", "verify", "--dir", "/nonexistent/rtbake"]);
    assert_eq!(v["exit_code"], 2);
    assert!(v["error"].as_str().unwrap().contains("--dir"), "{v}");
}

#[test]
fn a_failed_verify_report_carries_the_error_keys() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join("b");
    let o = rtbake(&["bake", "smaa-search", "--out", d.to_str().unwrap(), "--quiet"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let o = rtbake(&["verify", "--dir", d.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(0));
    let ok: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(ok.get("error").is_none() && ok.get("exit_code").is_none(), "a passing report has no error keys: {ok}");
    // One flipped byte: exit 1, the report listing the file, and the error object's keys beside it.
    let f = d.join("aa/smaa/SearchTex.bin");
    let mut b = std::fs::read(&f).unwrap();
    b[0] ^= 1;
    std::fs::write(&f, b).unwrap();
    let v = error_object(&["verify", "--dir", d.to_str().unwrap(), "--json"]);
    assert_eq!(v["exit_code"], 1, "{v}");
    assert_eq!(v["param"], serde_json::Value::Null);
    let error = v["error"].as_str().unwrap();
    assert!(error.starts_with("verify: 1 of ") && error.contains("files failed"), "{error}");
    let files = v["files"].as_array().unwrap();
    assert!(files.iter().any(|f| f["path"] == "aa/smaa/SearchTex.bin" && f["status"] != "ok"), "{v}");
}
