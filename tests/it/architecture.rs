//! The invariants of `ARCHITECTURE.md`, each a check over the source tree that fails when the code breaks it.
//!
//! Every check reads the code with comments, string literals and `#[cfg(test)]` modules removed (the rules are
//! about what the code does, not what its docs or test fixtures mention), except the literal checks, which read
//! the string literals only. Each check is run on the real tree (`src/`, `bin/`) and on a synthetic tree that
//! breaks it, which it must refuse.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Source files by path relative to the repository root (`src/runtime/aa/smaa.rs`).
struct Tree {
    files: BTreeMap<String, String>,
}

impl Tree {
    /// `src/` and `bin/` of the repository.
    fn of_repository() -> Tree {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = BTreeMap::new();
        for top in ["src", "bin"] {
            collect(root, &root.join(top), &mut files);
        }
        assert!(files.len() > 100, "the source tree was not found under {}", root.display());
        Tree { files }
    }

    fn of(files: &[(&str, &str)]) -> Tree {
        Tree { files: files.iter().map(|(p, t)| (p.to_string(), t.to_string())).collect() }
    }

    /// (path, code without comments, string literals and test modules).
    fn code(&self) -> impl Iterator<Item = (&str, String)> {
        self.files.iter().map(|(p, t)| (p.as_str(), strip(t).0))
    }

    /// (path, the string literals of the code outside test modules).
    fn literals(&self) -> impl Iterator<Item = (&str, Vec<String>)> {
        self.files.iter().map(|(p, t)| (p.as_str(), strip(t).1))
    }
}

fn collect(root: &Path, dir: &Path, out: &mut BTreeMap<String, String>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            collect(root, &p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            let rel = p.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
            out.insert(rel, std::fs::read_to_string(&p).unwrap());
        }
    }
}

/// The code with comments and string/char literal contents blanked, cut at the first `#[cfg(test)]` (the test
/// modules sit at the end of their files), and the string literals found before it.
fn strip(src: &str) -> (String, Vec<String>) {
    let src = match src.find("#[cfg(test)]") {
        Some(i) => &src[..i],
        None => src,
    };
    let b: Vec<char> = src.chars().collect();
    let (mut code, mut lits) = (String::with_capacity(src.len()), Vec::new());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            i += 2;
            while i + 1 < b.len() && !(b[i] == '*' && b[i + 1] == '/') {
                i += 1;
            }
            i += 2;
        } else if c == 'r' && (next == Some('"') || next == Some('#')) && !prev_is_ident(&b, i) {
            // Raw string r"…" / r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while j < b.len() && b[j] == '#' {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&'"') {
                code.push(c);
                i += 1;
                continue;
            }
            j += 1;
            let start = j;
            let close: String = std::iter::once('"').chain(std::iter::repeat_n('#', hashes)).collect();
            let close: Vec<char> = close.chars().collect();
            while j < b.len() && b[j..].iter().take(close.len()).ne(close.iter()) {
                j += 1;
            }
            lits.push(b[start..j.min(b.len())].iter().collect());
            code.push_str("\"\"");
            i = j + close.len();
        } else if c == '"' {
            let mut j = i + 1;
            let mut lit = String::new();
            while j < b.len() && b[j] != '"' {
                if b[j] == '\\' {
                    j += 1;
                }
                if j < b.len() {
                    lit.push(b[j]);
                }
                j += 1;
            }
            lits.push(lit);
            code.push_str("\"\"");
            i = j + 1;
        } else if c == '\'' && next.is_some() && b.get(i + 2) == Some(&'\'') {
            code.push_str("' '");
            i += 3;
        } else if c == '\'' && next == Some('\\') {
            let mut j = i + 2;
            while j < b.len() && b[j] != '\'' {
                j += 1;
            }
            code.push_str("' '");
            i = j + 1;
        } else {
            code.push(c);
            i += 1;
        }
    }
    (code, lits)
}

fn prev_is_ident(b: &[char], i: usize) -> bool {
    i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_')
}

/// The layers of `ARCHITECTURE.md`, bottom up: a module may import only from its own layer or below.
const LAYERS: &[(&str, u8)] = &[
    ("error", 1),
    ("image_buf", 1),
    ("color", 1),
    ("io", 2),
    ("diffusion", 3),
    ("aa", 3),
    ("spectral", 3),
    ("skin_color", 3),
    ("facial", 3),
    ("separable", 3),
    ("transmittance", 3),
    ("fitting", 3),
    ("sss_sampling", 3),
    ("study", 3),
    ("transport", 3),
    ("mesh", 3),
    ("shading", 3),
    ("plot", 4),
    ("manifest", 5),
    ("baked_layout", 5),
    ("bake", 6),
    ("baked_dir", 6),
    ("runtime", 7),
];

/// Imports the layers allow but the design forbids: (importer, imported, why).
const FORBIDDEN_IMPORTS: &[(&str, &str, &str)] = &[
    ("diffusion", "*", "diffusion is the base model: it imports only the foundations"),
    ("runtime", "bake", "the runtime reads baked files through baked_layout and manifest only"),
    ("runtime", "baked_dir", "the runtime reads baked files through baked_layout and manifest only"),
];

/// Files allowed one import that [`FORBIDDEN_IMPORTS`] refuses otherwise: (file, imported, why).
const ALLOWED_IMPORTS: &[(&str, &str, &str)] = &[(
    "src/diffusion/source.rs",
    "transport",
    "ProfileSource builds `--model mc` profiles with the Monte Carlo engine (transport compares itself with \
     diffusion's models, never through source.rs)",
)];

/// The top-level module of a `src/` file (`src/runtime/aa/smaa.rs` → `runtime`); None for `lib.rs` and `bin/`.
fn top_module(path: &str) -> Option<&str> {
    let rest = path.strip_prefix("src/")?;
    let top = rest.split('/').next().unwrap().trim_end_matches(".rs");
    (top != "lib").then_some(top)
}

/// The top-level modules `code` names through `crate::`.
fn crate_imports(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices("crate::") {
        if i > 0 && code[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_' || c == '$') {
            continue;
        }
        let name: String = code[i + 7..].chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
        if !name.is_empty() {
            out.insert(name);
        }
    }
    out
}

/// No upward import: every `src/` module has a layer and imports only its own layer or below; the pairs of
/// [`FORBIDDEN_IMPORTS`] are refused as well.
fn upward_imports(tree: &Tree) -> Vec<String> {
    let layer = |m: &str| LAYERS.iter().find(|(n, _)| *n == m).map(|(_, l)| *l);
    let mut bad = Vec::new();
    for (path, code) in tree.code() {
        let Some(me) = top_module(path) else { continue };
        let Some(my_layer) = layer(me) else {
            bad.push(format!(
                "{path}: module `{me}` has no layer in ARCHITECTURE.md (tests/it/architecture.rs LAYERS)"
            ));
            continue;
        };
        for dep in crate_imports(&code) {
            if dep == me {
                continue;
            }
            match layer(&dep) {
                Some(l) if l > my_layer => {
                    bad.push(format!("{path}: `{me}` (layer {my_layer}) imports `{dep}` (layer {l})"))
                }
                _ => {}
            }
            for (from, to, why) in FORBIDDEN_IMPORTS {
                let to_matches = *to == dep || (*to == "*" && layer(&dep).is_some_and(|l| l > 1));
                let allowed = ALLOWED_IMPORTS.iter().any(|(f, d, _)| *f == path && *d == dep);
                if *from == me && to_matches && !allowed {
                    bad.push(format!("{path}: `{me}` imports `{dep}`: {why}"));
                }
            }
        }
    }
    bad
}

/// `wgpu` only in `src/runtime/` (the passes take `&wgpu::Device`; nothing else knows the GPU).
fn wgpu_outside_runtime(tree: &Tree) -> Vec<String> {
    tree.code()
        .filter(|(p, _)| !p.starts_with("src/runtime/"))
        .filter(|(_, c)| has_word(c, "wgpu"))
        .map(|(p, _)| format!("{p}: uses wgpu outside src/runtime/"))
        .collect()
}

/// `clap`, `anyhow` and `indicatif` only in `bin/` (the `cli` feature's crates).
fn cli_crates_in_library(tree: &Tree) -> Vec<String> {
    let mut bad = Vec::new();
    for (p, c) in tree.code().filter(|(p, _)| p.starts_with("src/")) {
        for krate in ["clap", "anyhow", "indicatif"] {
            if has_word(&c, &format!("{krate}::")) || has_word(&c, &format!("use {krate}")) {
                bad.push(format!("{p}: uses {krate} (the binary's crate) in the library"));
            }
        }
    }
    bad
}

fn has_word(code: &str, word: &str) -> bool {
    code.match_indices(word).any(|(i, _)| {
        let before = code[..i].chars().next_back();
        !before.is_some_and(|c| c.is_alphanumeric() || c == '_')
    })
}

/// The one place the runtime chooses between a GPU pass and its CPU twin.
const BACKEND_FILE: &str = "src/runtime/backend.rs";

/// No GPU-or-CPU choice outside [`BACKEND_FILE`]: no match on `Backend`/`Prepared` variants and no optional
/// device (`Option<&Gpu>`) in the library elsewhere.
fn backend_choices(tree: &Tree) -> Vec<String> {
    let mut bad = Vec::new();
    for (p, c) in tree.code().filter(|(p, _)| p.starts_with("src/") && *p != BACKEND_FILE) {
        for variant in ["Backend::Gpu", "Backend::Cpu", "Prepared::Gpu", "Prepared::Cpu"] {
            if has_word(&c, variant) {
                bad.push(format!("{p}: names `{variant}`; the choice is {BACKEND_FILE}'s (Backend::run/prepare)"));
            }
        }
        let squeezed: String = c.chars().filter(|c| !c.is_whitespace()).collect();
        let mut rest = squeezed.as_str();
        while let Some(i) = rest.find("Option<&") {
            let ty: String = rest[i + 8..].chars().take_while(|c| *c != '>' && *c != ',').collect();
            if ty.rsplit("::").next() == Some("Gpu") || ty.ends_with("Gpu") && ty.starts_with('\'') {
                bad.push(format!("{p}: takes an optional device `Option<&{ty}>`; take a `Backend` instead"));
            }
            rest = &rest[i + 8..];
        }
    }
    bad
}

/// Calls that create, write, move or remove files or directories.
const FILE_WRITES: &[&str] = &[
    "fs::write",
    "File::create",
    "OpenOptions",
    "fs::rename",
    "fs::copy",
    "hard_link",
    "remove_file",
    "remove_dir",
    "create_dir",
];

/// Where files are written besides `src/io/`: (path, call, why).
const FILE_WRITE_EXCEPTIONS: &[(&str, &str, &str)] = &[
    ("src/baked_dir/bake.rs", "*", "the bake stages its directory (then exchanges it through io::file_set)"),
    ("bin/rtbake/cli.rs", "create_dir", "`--out` directories are created before any work, to refuse them early"),
];

/// No file writing outside `src/io/` (and the exceptions of [`FILE_WRITE_EXCEPTIONS`]).
fn file_writes(tree: &Tree) -> Vec<String> {
    let mut bad = Vec::new();
    for (p, c) in tree.code().filter(|(p, _)| !p.starts_with("src/io/")) {
        for call in FILE_WRITES {
            let excused = FILE_WRITE_EXCEPTIONS.iter().any(|(f, k, _)| *f == p && (*k == "*" || call.contains(k)));
            if !excused && has_word(&c, call) {
                bad.push(format!("{p}: `{call}` outside src/io/"));
            }
        }
    }
    bad
}

/// A schema id: `rtbake-NAME/VERSION`.
fn is_schema_id(s: &str) -> bool {
    let Some(rest) = s.strip_prefix("rtbake-") else { return false };
    let Some((name, version)) = rest.split_once('/') else { return false };
    !name.is_empty()
        && name.chars().all(|c| c.is_ascii_lowercase() || c == '-' || c.is_ascii_digit())
        && !version.is_empty()
        && version.chars().all(|c| c.is_ascii_digit())
}

/// Schema ids only in `src/baked_layout.rs` (a model that writes one takes it from its caller).
fn schema_ids(tree: &Tree) -> Vec<String> {
    let mut bad = Vec::new();
    for (p, lits) in tree.literals().filter(|(p, _)| *p != "src/baked_layout.rs") {
        for l in lits.iter().filter(|l| is_schema_id(l)) {
            bad.push(format!("{p}: schema id {l:?} outside src/baked_layout.rs"));
        }
    }
    bad
}

/// Flag literals the library must write: (path, flag, why).
const FLAG_LITERAL_EXCEPTIONS: &[(&str, &str, &str)] = &[
    (
        "src/io/ktx2.rs",
        "--zstd",
        "KTXwriterScParams records the writer's supercompression options in toktx's syntax (baked bytes), not a flag",
    ),
    (
        "src/diffusion/source.rs",
        "--model",
        "SKIN_MULTIPOLE_ERROR is recorded verbatim in the provenance of baked spectral profiles (baked bytes)",
    ),
];

/// A CLI flag: `--name` (lower case, digits, dashes).
fn is_flag(s: &str) -> bool {
    s.strip_prefix("--").is_some_and(|n| {
        n.starts_with(|c: char| c.is_ascii_lowercase())
            && n.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
    })
}

/// The flags a literal names (`"--k"`, `"--a/--b"`, `"--width {fw}"`, `"… or --cpu"`), outside a command line it
/// quotes (`` `rtbake run smaa --help` ``).
fn flags_in(l: &str) -> Vec<&str> {
    let quoted_command = |(i, s): &(usize, &str)| i % 2 == 1 && s.starts_with("rtbake ");
    let text = l.split('`').enumerate().filter(|p| !quoted_command(p)).map(|(_, s)| s);
    let tokens = text.flat_map(|s| s.split(|c: char| c.is_whitespace() || "/=[]:;,()'\"\\".contains(c)));
    tokens.filter(|t| is_flag(t)).collect()
}

/// No CLI flag literal in the library (`src/`): a parameter is named by its field (`"sss_width"`, `"width/height"`)
/// and a message names another setting as `` `field` ``; `bin/rtbake/flags.rs` maps both to flags. A literal that
/// names a flag (`"--fovy"`, `"--width {w} --height {h}"`, `"… or --cpu"`) is refused, outside
/// [`FLAG_LITERAL_EXCEPTIONS`].
fn flag_literals(tree: &Tree) -> Vec<String> {
    let mut bad = Vec::new();
    for (p, lits) in tree.literals() {
        if !p.starts_with("src/") {
            continue;
        }
        for l in &lits {
            for flag in flags_in(l) {
                if !FLAG_LITERAL_EXCEPTIONS.iter().any(|(f, x, _)| *f == p && *x == flag) {
                    bad.push(format!("{p}: CLI flag {flag} in {l:?}; the library names fields, not flags"));
                }
            }
        }
    }
    bad
}

/// The one table from fields to flags.
const FLAG_TABLE: &str = "bin/rtbake/flags.rs";

/// The fields of [`FLAG_TABLE`]'s rows (`("sss_width", "--sss-width"),`).
fn table_fields(tree: &Tree) -> BTreeSet<String> {
    let Some(text) = tree.files.get(FLAG_TABLE) else { return BTreeSet::new() };
    let rows = text.lines().map(str::trim).filter_map(|l| l.strip_prefix("(\"")?.split_once("\", \"--"));
    rows.map(|(field, _)| field.to_string()).collect()
}

/// The fields a library message names between backticks (`` `cpu` ``, `` `width` 2048 ``).
fn marked_fields(l: &str) -> Vec<&str> {
    let is_field = |s: &str| {
        s.starts_with(|c: char| c.is_ascii_lowercase())
            && s.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
    };
    l.split('`').skip(1).step_by(2).filter(|s| is_field(s)).collect()
}

/// Every field a library message names between backticks has a row in [`FLAG_TABLE`], so the CLI prints its flag.
fn unmapped_fields(tree: &Tree) -> Vec<String> {
    let table = table_fields(tree);
    let mut bad = Vec::new();
    for (p, lits) in tree.literals().filter(|(p, _)| p.starts_with("src/")) {
        for f in lits.iter().flat_map(|l| marked_fields(l)) {
            if !table.contains(f) {
                bad.push(format!("{p}: field `{f}` named in a message has no row in {FLAG_TABLE}"));
            }
        }
    }
    bad
}

/// No error enum wraps an `InvalidInput` transparently: kept as the source (`#[error("{0}")]`), the CLI finds it in
/// the cause chain to print its field as a flag (and to exit 2).
fn transparent_invalid_inputs(tree: &Tree) -> Vec<String> {
    let mut bad = Vec::new();
    for (p, code) in tree.code().filter(|(p, _)| p.starts_with("src/")) {
        for (i, _) in code.match_indices("#[error(transparent)]") {
            let variant = code[i + 21..].split([',', '}']).next().unwrap_or("");
            if has_word(variant, "InvalidInput") {
                bad.push(format!("{p}: a transparent InvalidInput variant ({})", variant.trim()));
            }
        }
    }
    bad
}

/// The module graph of `src/runtime/` (file → files it names through `crate::runtime::…`).
fn runtime_graph(tree: &Tree) -> BTreeMap<String, BTreeSet<String>> {
    let modules: BTreeSet<String> = tree
        .files
        .keys()
        .filter_map(|p| p.strip_prefix("src/"))
        .filter(|p| p.starts_with("runtime/"))
        .map(|p| p.trim_end_matches(".rs").trim_end_matches("/mod").replace('/', "::"))
        .collect();
    let mut graph = BTreeMap::new();
    for (p, code) in tree.code().filter(|(p, _)| p.starts_with("src/runtime/")) {
        let me = p["src/".len()..].trim_end_matches(".rs").trim_end_matches("/mod").replace('/', "::");
        let mut deps = BTreeSet::new();
        for (i, _) in code.match_indices("crate::runtime::") {
            let path: String =
                code[i + 7..].chars().take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':').collect();
            // The longest prefix that is a module file.
            let segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
            if let Some(m) = (1..=segs.len()).rev().map(|n| segs[..n].join("::")).find(|m| modules.contains(m)) {
                // A module's parent (`runtime`, a room's mod.rs) only re-exports or declares; it is not a dependency.
                if m != me && !me.starts_with(&format!("{m}::")) && m != "runtime" {
                    deps.insert(m);
                }
            }
        }
        graph.insert(me, deps);
    }
    graph
}

/// No module cycle in `src/runtime/`.
fn runtime_cycles(tree: &Tree) -> Vec<String> {
    let graph = runtime_graph(tree);
    let mut bad = Vec::new();
    for start in graph.keys() {
        // Depth-first search for a path back to `start`.
        let mut stack = vec![(start.clone(), vec![start.clone()])];
        let mut seen = BTreeSet::new();
        while let Some((m, path)) = stack.pop() {
            for d in graph.get(&m).into_iter().flatten() {
                if d == start {
                    let cycle = path.join(" → ") + " → " + start;
                    if !bad.iter().any(|b: &String| path.iter().all(|p| b.contains(p.as_str()))) {
                        bad.push(format!("module cycle: {cycle}"));
                    }
                } else if seen.insert(d.clone()) {
                    let mut p = path.clone();
                    p.push(d.clone());
                    stack.push((d.clone(), p));
                }
            }
        }
    }
    bad
}

fn assert_holds(name: &str, violations: Vec<String>) {
    assert!(violations.is_empty(), "{name} broken ({}):\n  {}", violations.len(), violations.join("\n  "));
}

#[test]
fn the_repository_keeps_every_rule() {
    let tree = Tree::of_repository();
    assert_holds("no upward import", upward_imports(&tree));
    assert_holds("no wgpu outside src/runtime/", wgpu_outside_runtime(&tree));
    assert_holds("no CLI crate in the library", cli_crates_in_library(&tree));
    assert_holds("one GPU-or-CPU choice", backend_choices(&tree));
    assert_holds("no file writing outside src/io/", file_writes(&tree));
    assert_holds("schema ids only in baked_layout.rs", schema_ids(&tree));
    assert_holds("no CLI flag literal in the library", flag_literals(&tree));
    assert_holds("every field a message names has a flag", unmapped_fields(&tree));
    assert_holds("an InvalidInput stays in the cause chain", transparent_invalid_inputs(&tree));
    assert_holds("no module cycle in src/runtime/", runtime_cycles(&tree));
}

#[test]
fn the_stripper_keeps_code_and_drops_comments_strings_and_tests() {
    let (code, lits) =
        strip("use a; // wgpu\n/* wgpu */ let s = \"wgpu \\\" x\"; let r = r#\"raw \"q\"\"#; let c = '\"';\n#[cfg(test)]\nmod tests { wgpu }");
    assert!(!code.contains("wgpu"), "{code}");
    assert!(code.contains("use a;") && code.contains("let r ="), "{code}");
    assert_eq!(lits, vec!["wgpu \" x".to_string(), "raw \"q\"".to_string()]);
}

#[test]
fn an_upward_import_is_refused() {
    let bad = Tree::of(&[("src/diffusion/dipole.rs", "use crate::fitting::nnls;"), ("src/fitting/nnls.rs", "")]);
    assert_eq!(upward_imports(&bad).len(), 1, "{:?}", upward_imports(&bad));
    let bad = Tree::of(&[("src/aa/smaa_area.rs", "fn f() { crate::runtime::smaa::Smaa::new(); }")]);
    assert!(upward_imports(&bad)[0].contains("layer 7"), "{:?}", upward_imports(&bad));
    let bad = Tree::of(&[("src/runtime/loader.rs", "use crate::bake::registry;")]);
    assert!(upward_imports(&bad)[0].contains("through baked_layout"), "{:?}", upward_imports(&bad));
    let bad = Tree::of(&[("src/newthing/mod.rs", "")]);
    assert!(upward_imports(&bad)[0].contains("has no layer"));
    let good = Tree::of(&[
        ("src/runtime/loader.rs", "use crate::baked_layout::path; use crate::io::PixelFormat;"),
        ("src/fitting/nnls.rs", "use crate::diffusion::dipole; // crate::runtime in a comment"),
    ]);
    assert_holds("synthetic", upward_imports(&good));
}

#[test]
fn wgpu_outside_the_runtime_is_refused() {
    let bad = Tree::of(&[("src/mesh/camera.rs", "fn f(d: &wgpu::Device) {}")]);
    assert_eq!(wgpu_outside_runtime(&bad).len(), 1);
    let bad = Tree::of(&[("bin/rtbake/run.rs", "use wgpu;")]);
    assert_eq!(wgpu_outside_runtime(&bad).len(), 1);
    let good = Tree::of(&[
        ("src/runtime/gpu.rs", "fn f(d: &wgpu::Device) {}"),
        ("src/mesh/camera.rs", "//! wgpu's clip space\nfn f() { let s = \"wgpu\"; }"),
    ]);
    assert_holds("synthetic", wgpu_outside_runtime(&good));
}

#[test]
fn cli_crates_in_the_library_are_refused() {
    let bad = Tree::of(&[("src/fitting/evaluate.rs", "fn f() -> anyhow::Result<()> { Ok(()) }")]);
    assert_eq!(cli_crates_in_library(&bad).len(), 1);
    let good = Tree::of(&[("bin/rtbake/main.rs", "use clap::Parser; fn f() -> anyhow::Result<()> { Ok(()) }")]);
    assert_holds("synthetic", cli_crates_in_library(&good));
}

#[test]
fn a_gpu_or_cpu_choice_outside_the_backend_is_refused() {
    let bad = Tree::of(&[(
        "src/runtime/skin/bloom.rs",
        "fn f(gpu: Option<&crate::runtime::device::Gpu>) { match gpu { Some(g) => {}, None => {} } }",
    )]);
    assert_eq!(backend_choices(&bad).len(), 1, "{:?}", backend_choices(&bad));
    let bad = Tree::of(&[("src/runtime/chain.rs", "fn f(b: Backend) { if let Backend::Gpu(g) = b {} }")]);
    assert_eq!(backend_choices(&bad).len(), 1);
    let bad = Tree::of(&[("src/runtime/chain.rs", "fn f(gpu: Option<&'g Gpu>) {}")]);
    assert_eq!(backend_choices(&bad).len(), 1);
    let good = Tree::of(&[
        (BACKEND_FILE, "match self { Backend::Gpu(g) => a(g), Backend::Cpu => b() }"),
        ("src/runtime/chain.rs", "fn f(gpu: impl Into<Backend<'g>>) { gpu.into().run(|g| a(g), || b()) }"),
        ("bin/rtbake/run.rs", "fn device(cpu: bool) -> Option<Gpu> { None } fn g(x: Option<&Gpu>) {}"),
    ]);
    assert_holds("synthetic", backend_choices(&good));
}

#[test]
fn file_writing_outside_io_is_refused() {
    let bad = Tree::of(&[("src/plot/line.rs", "fn save(p: &Path) { std::fs::write(p, b\"x\").unwrap(); }")]);
    assert_eq!(file_writes(&bad).len(), 1);
    let bad = Tree::of(&[("bin/rtbake/maps.rs", "let f = std::fs::File::create(p)?;")]);
    assert_eq!(file_writes(&bad).len(), 1);
    let bad = Tree::of(&[("bin/rtbake/cli.rs", "std::fs::remove_file(p)?;")]);
    assert_eq!(file_writes(&bad).len(), 1, "the cli.rs exception covers create_dir only");
    let good = Tree::of(&[
        ("src/io/atomic.rs", "std::fs::rename(a, b)?; std::fs::File::create(p)?;"),
        ("src/plot/line.rs", "fn f() {}\n#[cfg(test)]\nmod tests { fn t() { std::fs::write(p, b).unwrap(); } }"),
        ("bin/rtbake/cli.rs", "std::fs::create_dir_all(dir)?;"),
    ]);
    assert_holds("synthetic", file_writes(&good));
}

#[test]
fn a_schema_id_outside_the_layout_is_refused() {
    let bad = Tree::of(&[("src/bake/importance.rs", "json!({\"schema\": \"rtbake-importance-kernel/1\"})")]);
    assert_eq!(schema_ids(&bad).len(), 1);
    let good = Tree::of(&[
        ("src/baked_layout.rs", "pub const IMPORTANCE_KERNEL: &str = \"rtbake-importance-kernel/1\";"),
        ("src/bake/importance.rs", "json!({\"schema\": schema::IMPORTANCE_KERNEL, \"note\": \"rtbake-x\"})"),
    ]);
    assert_holds("synthetic", schema_ids(&good));
    assert!(is_schema_id("rtbake-manifest/1") && !is_schema_id("rtbake-manifest") && !is_schema_id("rtbake/1"));
}

#[test]
fn a_flag_literal_in_the_library_is_refused() {
    let bad = Tree::of(&[("src/diffusion/dipole.rs", "InvalidInput::new(\"--sigma-a\", \"must be > 0\")")]);
    assert_eq!(flag_literals(&bad).len(), 1);
    let bad = Tree::of(&[("src/runtime/chain.rs", "InvalidInput::new(\"--width/--height\", \"\")")]);
    assert_eq!(flag_literals(&bad).len(), 2);
    let bad = Tree::of(&[("src/runtime/skin/frame.rs", "format!(\"--width {fw} --height {fh} fits\")")]);
    assert_eq!(flag_literals(&bad).len(), 2);
    let bad = Tree::of(&[("src/io/device.rs", "format!(\"{w}x{h}; use --cpu or a smaller image\")")]);
    assert_eq!(flag_literals(&bad).len(), 1);
    let bad = Tree::of(&[("src/io/picture.rs", "format!(\"--zstd {level}\")")]);
    assert_eq!(flag_literals(&bad).len(), 1, "the ktx2.rs exception covers ktx2.rs only");
    let good = Tree::of(&[
        ("src/diffusion/dipole.rs", "InvalidInput::new(\"sigma_a\", \"must be > 0; or `cpu`, not x--y or --\")"),
        ("src/runtime/chain.rs", "InvalidInput::new(\"width/height\", format!(\"`width` {w}\"))"),
        ("src/io/ktx2.rs", "format!(\"--zstd {level}\")"),
        ("src/io/frame_sequence.rs", "format!(\"no {} found (see `rtbake run smaa --help` for the names)\")"),
        ("src/io/x.rs", "/// `--flag` in a doc\nfn f() {}\n#[cfg(test)]\nmod tests { const P: &str = \"--albedo\"; }"),
        ("bin/rtbake/cli.rs", "\"--json\""),
    ]);
    assert_holds("synthetic", flag_literals(&good));
}

#[test]
fn a_field_a_message_names_without_a_flag_is_refused() {
    let table = (
        FLAG_TABLE,
        "const FIELD_FLAGS: &[(&str, &str)] = &[\n    (\"cpu\", \"--cpu\"),\n    (\"width\", \"--width\"),\n];",
    );
    let bad = Tree::of(&[table, ("src/runtime/skin/frame.rs", "format!(\"{w}: or `cpu`, or `bloom` off\")")]);
    assert_eq!(
        unmapped_fields(&bad),
        vec![format!("src/runtime/skin/frame.rs: field `bloom` named in a message has no row in {FLAG_TABLE}")]
    );
    let good = Tree::of(&[
        table,
        ("src/runtime/skin/frame.rs", "format!(\"`width` {w}; or `cpu`; see `rtbake run --help`\")"),
        ("bin/rtbake/run.rs", "\"`bloom`\""),
    ]);
    assert_holds("synthetic", unmapped_fields(&good));
    assert!(table_fields(&Tree::of_repository()).len() > 50, "the table's rows were not found in {FLAG_TABLE}");
}

#[test]
fn a_transparent_invalid_input_is_refused() {
    let bad = Tree::of(&[(
        "src/aa/smaa_area.rs",
        "enum E {\n    #[error(transparent)]\n    Invalid(#[from] InvalidInput),\n}",
    )]);
    assert_eq!(transparent_invalid_inputs(&bad).len(), 1);
    let good = Tree::of(&[(
        "src/bake/mod.rs",
        "enum E {\n    #[error(\"{0}\")]\n    Invalid(#[from] crate::error::InvalidInput),\n    #[error(transparent)]\n    Io(#[from] io::IoError),\n}",
    )]);
    assert_holds("synthetic", transparent_invalid_inputs(&good));
}

#[test]
fn a_runtime_module_cycle_is_refused() {
    let bad = Tree::of(&[
        ("src/runtime/mod.rs", "pub mod skin;"),
        ("src/runtime/skin/mod.rs", "pub mod frame; pub mod texture_space;"),
        ("src/runtime/skin/frame.rs", "use crate::runtime::skin::texture_space::render;"),
        ("src/runtime/skin/texture_space.rs", "use crate::runtime::skin::frame::{self, row_of_heads};"),
    ]);
    let cycles = runtime_cycles(&bad);
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    assert!(cycles[0].contains("runtime::skin::frame") && cycles[0].contains("runtime::skin::texture_space"));
    let good = Tree::of(&[
        ("src/runtime/mod.rs", "pub mod skin; pub use skin::frame as skin_render;"),
        ("src/runtime/skin/mod.rs", "pub mod frame; pub mod heads; pub mod texture_space;"),
        ("src/runtime/skin/frame.rs", "use crate::runtime::skin::texture_space; use crate::runtime::skin::heads;"),
        ("src/runtime/skin/texture_space.rs", "use crate::runtime::skin::heads::row_of_heads;"),
        ("src/runtime/skin/heads.rs", "use crate::runtime::RuntimeError;"),
    ]);
    assert_holds("synthetic", runtime_cycles(&good));
}
