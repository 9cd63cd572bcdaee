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
