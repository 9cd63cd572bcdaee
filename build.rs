//! Captures rtbake's own source revision at build time for the bake manifest (`rtbake::manifest::SOURCE_TREE`).
//!
//! The revision is the git **tree id of `src/`** — the object id `git rev-parse HEAD:src` prints on a clean checkout —
//! computed here from the files themselves, so it needs no git, works from a crates.io tarball, reflects uncommitted
//! edits, and does not change when a commit touches only `baked/`, docs or tests. A commit id would: re-baking and
//! committing `baked/` moves HEAD, and the next re-bake of the same sources would then rewrite `manifest.json`.
//! `Cargo.lock` (which pins the encoders whose bytes end up in files) is recorded the same way, as a git blob id.

use std::fs;
use std::path::Path;

fn main() {
    let root = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let root = Path::new(&root);
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=Cargo.lock");
    let src_tree = tree_id(&root.join("src")).map(|id| hex(&id)).unwrap_or_else(|e| {
        println!("cargo:warning=rtbake: cannot hash src/ for the manifest's source_tree: {e}");
        "unknown".into()
    });
    let lock = match fs::read(root.join("Cargo.lock")) {
        Ok(bytes) => hex(&object_id("blob", &bytes)),
        Err(_) => "absent".into(),
    };
    println!("cargo:rustc-env=RTBAKE_SOURCE_TREE={src_tree}");
    println!("cargo:rustc-env=RTBAKE_CARGO_LOCK={lock}");
}

/// Git object id of a directory as a tree object: entries sorted by name (directories compare as `name/`), each
/// `"<mode> <name>\0<20-byte id>"`, modes 100644 (file), 100755 (executable), 40000 (directory). Empty directories
/// are absent from git trees and skipped here too.
fn tree_id(dir: &Path) -> std::io::Result<[u8; 20]> {
    let mut entries: Vec<(String, &'static str, [u8; 20])> = Vec::new();
    for e in fs::read_dir(dir)? {
        let e = e?;
        let name = e.file_name().to_string_lossy().into_owned();
        let ty = e.file_type()?;
        if ty.is_dir() {
            if fs::read_dir(e.path())?.next().is_none() {
                continue;
            }
            entries.push((format!("{name}/"), "40000", tree_id(&e.path())?));
        } else if ty.is_file() {
            let bytes = fs::read(e.path())?;
            entries.push((name, if is_executable(&e.path()) { "100755" } else { "100644" }, object_id("blob", &bytes)));
        }
    }
    entries.sort_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
    let mut body = Vec::new();
    for (name, mode, id) in &entries {
        body.extend_from_slice(mode.as_bytes());
        body.push(b' ');
        body.extend_from_slice(name.trim_end_matches('/').as_bytes());
        body.push(0);
        body.extend_from_slice(id);
    }
    Ok(object_id("tree", &body))
}

#[cfg(unix)]
fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    fs::metadata(p).is_ok_and(|m| m.permissions().mode() & 0o111 != 0)
}

#[cfg(not(unix))]
fn is_executable(_: &Path) -> bool {
    false
}

/// Git object id: SHA-1 of `"<kind> <len>\0" + body`.
fn object_id(kind: &str, body: &[u8]) -> [u8; 20] {
    let mut data = format!("{kind} {}\0", body.len()).into_bytes();
    data.extend_from_slice(body);
    sha1(&data)
}

fn hex(id: &[u8]) -> String {
    id.iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-1 (FIPS 180-4 §6.1), used only because git names objects with it.
fn sha1(data: &[u8]) -> [u8; 20] {
    let mut h: [u32; 5] = [0x6745_2301, 0xEFCD_AB89, 0x98BA_DCFE, 0x1032_5476, 0xC3D2_E1F0];
    let mut msg = data.to_vec();
    msg.push(0x80);
    while msg.len() % 64 != 56 {
        msg.push(0);
    }
    msg.extend_from_slice(&((data.len() as u64) * 8).to_be_bytes());
    for block in msg.chunks_exact(64) {
        let mut w = [0u32; 80];
        for (i, c) in block.chunks_exact(4).enumerate() {
            w[i] = u32::from_be_bytes([c[0], c[1], c[2], c[3]]);
        }
        for i in 16..80 {
            w[i] = (w[i - 3] ^ w[i - 8] ^ w[i - 14] ^ w[i - 16]).rotate_left(1);
        }
        let [mut a, mut b, mut c, mut d, mut e] = h;
        for (i, wi) in w.iter().enumerate() {
            let (f, k) = match i {
                0..=19 => ((b & c) | (!b & d), 0x5A82_7999),
                20..=39 => (b ^ c ^ d, 0x6ED9_EBA1),
                40..=59 => ((b & c) | (b & d) | (c & d), 0x8F1B_BCDC),
                _ => (b ^ c ^ d, 0xCA62_C1D6),
            };
            let t = a.rotate_left(5).wrapping_add(f).wrapping_add(e).wrapping_add(k).wrapping_add(*wi);
            e = d;
            d = c;
            c = b.rotate_left(30);
            b = a;
            a = t;
        }
        for (hi, v) in h.iter_mut().zip([a, b, c, d, e]) {
            *hi = hi.wrapping_add(v);
        }
    }
    let mut out = [0u8; 20];
    for (o, v) in out.chunks_exact_mut(4).zip(h) {
        o.copy_from_slice(&v.to_be_bytes());
    }
    out
}
