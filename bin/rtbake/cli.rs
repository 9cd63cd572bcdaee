//! Shared command-line plumbing: output context, exit codes, `--params FILE` expansion, atomic output.

use std::ffi::OsString;
use std::path::Path;

/// Global output settings.
pub struct Ctx {
    pub json: bool,
    pub quiet: bool,
    /// Fail at once (exit 3) instead of waiting when another rtbake process holds an output directory's lock.
    pub no_wait: bool,
    /// `--max-memory` in bytes (None: half of physical memory).
    pub max_memory: Option<u64>,
    /// `--max-seconds` (None: [`DEFAULT_MAX_SECONDS`]).
    pub max_seconds: Option<f64>,
}

/// The default time budget of one command (`--max-seconds`).
pub const DEFAULT_MAX_SECONDS: f64 = 600.0;

impl Ctx {
    /// Human message on stderr (suppressed by --quiet).
    pub fn info(&self, msg: impl AsRef<str>) {
        if !self.quiet {
            eprintln!("{}", msg.as_ref());
        }
    }

    /// Prints a JSON value on stdout (one object, pretty, trailing newline).
    pub fn emit_json(&self, v: &serde_json::Value) {
        JSON_EMITTED.store(true, std::sync::atomic::Ordering::SeqCst);
        print_stdout(&format!("{}\n", serde_json::to_string_pretty(v).expect("JSON values serialise")));
    }

    /// Runs `f` with the lock-waiting policy of this invocation (waiting prints a message unless --quiet).
    pub fn with_wait<T>(&self, f: impl FnOnce(&rtbake::io::file_set::Wait) -> T) -> T {
        use rtbake::io::file_set::Wait;
        let say = |m: &str| self.info(m);
        if self.no_wait {
            f(&Wait::No)
        } else {
            f(&Wait::Yes(&say))
        }
    }

    /// The memory budget: `--max-memory`, else half of physical memory (8 GiB where it cannot be read).
    pub fn memory_budget(&self) -> (u64, String) {
        match self.max_memory {
            Some(b) => (b, format!("--max-memory {}", fmt_bytes(b))),
            None => {
                let phys = physical_memory_bytes();
                match phys {
                    Some(p) => (p / 2, format!("default --max-memory: half of this machine's {}", fmt_bytes(p))),
                    None => (8 << 30, "default --max-memory (physical memory unknown)".into()),
                }
            }
        }
    }

    /// Refuses, before allocating, work whose memory estimate exceeds the budget (exit 2, estimate and limit named).
    pub fn check_memory(&self, flags: &str, estimate_bytes: u64) -> anyhow::Result<()> {
        let (budget, source) = self.memory_budget();
        if estimate_bytes > budget {
            return Err(usage_msg(format!(
                "{flags}: this needs about {} of memory, more than the budget of {} ({source}); choose smaller sizes \
                 or raise --max-memory",
                fmt_bytes(estimate_bytes),
                fmt_bytes(budget)
            )));
        }
        Ok(())
    }

    /// Refuses, before any work, a job whose time estimate exceeds `--max-seconds` (exit 2, estimate, budget and
    /// flags named). The estimates come from the models (`time_estimate_seconds`), calibrated with the release
    /// build on the project's 2-core machine and scaled by the rayon thread count.
    pub fn check_time(&self, flags: &str, estimate_seconds: f64) -> anyhow::Result<()> {
        let (budget, source) = match self.max_seconds {
            Some(s) => (s, format!("--max-seconds {s}")),
            None => (DEFAULT_MAX_SECONDS, format!("default --max-seconds {DEFAULT_MAX_SECONDS}")),
        };
        if estimate_seconds > budget {
            return Err(usage_msg(format!(
                "{flags}: this is estimated to take about {} on {} thread(s), more than the time budget of {budget} s \
                 ({source}); choose smaller sizes or raise --max-seconds",
                fmt_seconds(estimate_seconds),
                rayon::current_num_threads()
            )));
        }
        Ok(())
    }

    /// [`Self::check_memory`] and [`Self::check_time`] of one job.
    pub fn check_budget(&self, flags: &str, estimate_bytes: u64, estimate_seconds: f64) -> anyhow::Result<()> {
        self.check_memory(flags, estimate_bytes)?;
        self.check_time(flags, estimate_seconds)
    }

    /// A progress bar on stderr, hidden when stderr is not a terminal or with --quiet.
    #[allow(dead_code)]
    pub fn progress(&self, len: u64, msg: &str) -> indicatif::ProgressBar {
        use std::io::IsTerminal;
        if self.quiet || !std::io::stderr().is_terminal() {
            return indicatif::ProgressBar::hidden();
        }
        let pb = indicatif::ProgressBar::new(len);
        pb.set_message(msg.to_string());
        pb
    }
}

/// Writes to stdout; a closed pipe (`rtbake … --json | head`) ends the program quietly instead of panicking.
pub fn print_stdout(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: cannot write to stdout: {e}");
        std::process::exit(1);
    }
}

/// Marks an error as bad usage / bad input (exit code 2).
#[derive(Debug)]
pub struct Usage(pub anyhow::Error);

impl std::fmt::Display for Usage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl std::error::Error for Usage {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}

/// Wraps any error as bad input (exit 2).
pub fn usage<E: Into<anyhow::Error>>(e: E) -> anyhow::Error {
    anyhow::Error::new(Usage(e.into()))
}

/// Bad input with a message.
pub fn usage_msg(msg: impl Into<String>) -> anyhow::Error {
    usage(anyhow::anyhow!(msg.into()))
}

/// Marks an error as "an output directory is locked by another process" under --no-wait (exit 3).
#[derive(Debug)]
pub struct Busy(pub anyhow::Error);

impl std::fmt::Display for Busy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl std::error::Error for Busy {}

/// Classifies a file-set error: locked → exit 3, output = input or unusable path → exit 2, I/O → exit 1.
pub fn file_set_err(e: rtbake::io::file_set::FileSetError) -> anyhow::Error {
    use rtbake::io::file_set::FileSetError as E;
    match e {
        E::Busy { .. } => anyhow::Error::new(Busy(anyhow::Error::new(e))),
        E::OutputIsInput { .. } | E::Unusable { .. } => usage(e),
        E::Io(_) => anyhow::Error::new(e),
    }
}

/// True if the error (or any cause) is bad input: a `Usage` marker or a library `InvalidInput`.
pub fn is_usage(e: &anyhow::Error) -> bool {
    e.downcast_ref::<Usage>().is_some()
        || e.chain().any(|c| {
            c.is::<Usage>()
                || c.is::<rtbake::error::InvalidInput>()
                || matches!(c.downcast_ref::<rtbake::bake::BakeError>(), Some(rtbake::bake::BakeError::Invalid(_)))
        })
}

/// Prints `error: …` with its cause chain on stderr and exits 2 (bad input) or 1 (runtime failure). With
/// `--json`, also prints one object `{"error": …, "param": …, "exit_code": …}` on stdout, so scripts parse every
/// outcome with one parser (`param` is the flag/field of a validation error, else null).
pub fn exit_with(e: &anyhow::Error, json: bool) -> ! {
    // The library names fields; every line is printed with the flags of this command (`flags::render`).
    let invalid: Vec<&rtbake::error::InvalidInput> = e.chain().filter_map(invalid_input).collect();
    let render = |s: String| crate::flags::render_line(&s, &invalid);
    let mut msg = format!("error: {}", render(e.to_string()));
    let mut last = render(e.to_string());
    let mut chain = vec![last.clone()];
    for cause in e.chain().skip(1) {
        let c = render(cause.to_string());
        if !last.contains(&c) {
            msg.push_str(&format!("\n  caused by: {c}"));
            chain.push(c.clone());
        }
        last = c;
    }
    eprintln!("{msg}");
    let busy = e.chain().any(|c| c.is::<Busy>());
    let code = if busy {
        3
    } else if is_usage(e) {
        2
    } else {
        1
    };
    // A command that already printed its JSON result (e.g. `verify`'s report listing the failures) keeps stdout to
    // that one object.
    if json && !JSON_EMITTED.load(std::sync::atomic::Ordering::SeqCst) {
        // Without a typed validation error, a message that starts with a flag (`--out …: exists`) names it.
        let param = invalid.first().map(|i| crate::flags::render_param(&i.param)).or_else(|| {
            let first = chain[0].split([' ', ':', '=']).next().unwrap_or("");
            (first.starts_with("--") && first.len() > 2).then(|| first.to_string())
        });
        emit_json_error(&chain.join(": "), param.as_deref(), code);
    }
    std::process::exit(code);
}

/// The validation error `c` is, or a `Usage` marker wraps.
fn invalid_input<'a>(c: &'a (dyn std::error::Error + 'static)) -> Option<&'a rtbake::error::InvalidInput> {
    c.downcast_ref::<rtbake::error::InvalidInput>()
        .or_else(|| c.downcast_ref::<Usage>().and_then(|u| u.0.downcast_ref::<rtbake::error::InvalidInput>()))
}

/// Set once a command has printed its JSON result.
static JSON_EMITTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// The `--json` error object on stdout.
pub fn emit_json_error(error: &str, param: Option<&str>, exit_code: i32) {
    let v = serde_json::json!({"error": error, "param": param, "exit_code": exit_code});
    print_stdout(&format!("{}\n", serde_json::to_string_pretty(&v).expect("JSON values serialise")));
}

/// Whether `--json` is on the raw command line (for errors before the flags are parsed).
pub fn json_requested(argv: &[OsString]) -> bool {
    argv.iter().skip(1).take_while(|a| *a != "--").any(|a| a == "--json")
}

/// Every long flag of `cmd` and its subcommands that takes a value, as typed (`--burley-d-mm`).
fn value_flags(cmd: &clap::Command, out: &mut std::collections::HashSet<String>) {
    for a in cmd.get_arguments().filter(|a| a.get_action().takes_values()) {
        for l in a.get_long().into_iter().chain(a.get_all_aliases().unwrap_or_default()) {
            out.insert(format!("--{l}"));
        }
    }
    for s in cmd.get_subcommands() {
        value_flags(s, out);
    }
}

/// Joins a value-taking flag and a following value that starts with a minus sign and a digit (`--burley-d-mm
/// -1,1,1`, `--max-memory -1G`) into one token (`--burley-d-mm=-1,1,1`), so clap hands the value to the flag's
/// range check instead of reading it as an unknown option. Plain negative numbers already reach the checks.
pub fn join_negative_values(argv: Vec<OsString>, cmd: &clap::Command) -> Vec<OsString> {
    let mut flags = std::collections::HashSet::new();
    value_flags(cmd, &mut flags);
    let negative = |t: &str| {
        let b = t.as_bytes();
        b.len() >= 2
            && b[0] == b'-'
            && (b[1].is_ascii_digit() || (b[1] == b'.' && b.get(2).is_some_and(u8::is_ascii_digit)))
    };
    let mut out: Vec<OsString> = Vec::with_capacity(argv.len());
    let mut after_separator = false;
    for a in argv {
        let text = a.to_string_lossy().into_owned();
        if !after_separator && negative(&text) {
            if let Some(prev) = out.last().map(|p| p.to_string_lossy().into_owned()) {
                if !prev.contains('=') && flags.contains(&prev) {
                    out.pop();
                    out.push(format!("{prev}={text}").into());
                    continue;
                }
            }
        }
        after_separator |= text == "--";
        out.push(a);
    }
    out
}

/// clap's "invalid digit found in string" for a negative number given to an unsigned flag, said with the range:
/// the one the flag's help states (`1..=1e10`), else the type's (`0..=18446744073709551615`).
fn negative_unsigned_message(e: &clap::Error, cmd: &clap::Command, argv: &[OsString]) -> Option<(String, String)> {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if e.kind() != ErrorKind::ValueValidation {
        return None;
    }
    let (Some(ContextValue::String(arg)), Some(ContextValue::String(value))) =
        (e.get(ContextKind::InvalidArg), e.get(ContextKind::InvalidValue))
    else {
        return None;
    };
    let value = value.trim();
    // u64/usize flags fail in the integer parser; u32 flags in clap's own range check ("-5 is not in 0..=4294967295",
    // the type's range, not the flag's).
    let invalid_digit = std::error::Error::source(e)
        .and_then(|s| s.downcast_ref::<std::num::ParseIntError>())
        .is_some_and(|i| *i.kind() == std::num::IntErrorKind::InvalidDigit);
    if !(invalid_digit || value.parse::<i64>().is_ok_and(|v| v < 0)) {
        return None;
    }
    let flag = arg.split_whitespace().next().unwrap_or(arg).to_string();
    fn find(cmd: &clap::Command, long: &str) -> Option<String> {
        cmd.get_arguments()
            .find(|a| a.get_long() == Some(long))
            .map(|a| a.get_help().map(|h| h.to_string()).unwrap_or_default())
            .or_else(|| cmd.get_subcommands().find_map(|s| find(s, long)))
    }
    // The subcommand the user typed (its --width, not another command's).
    let mut sub = cmd;
    for a in argv.iter().skip(1) {
        if let Some(next) = sub.find_subcommand(a.to_string_lossy().as_ref()) {
            sub = next;
        }
    }
    let help = find(sub, flag.trim_start_matches('-')).or_else(|| find(cmd, flag.trim_start_matches('-')));
    let help = help.unwrap_or_default();
    // A range the help text states, e.g. "Photons per channel, 1..=1e10 (rounded …)".
    let stated = help
        .split(|c: char| c.is_whitespace() || c == ',' || c == '(' || c == ')')
        .map(|w| w.trim_end_matches(['.', ';', ':']))
        .find(|w| w.contains("..=") && w.chars().next().is_some_and(|c| c.is_ascii_digit()));
    let type_max = if invalid_digit { u64::MAX } else { u64::from(u32::MAX) };
    let range = stated.map(str::to_string).unwrap_or_else(|| format!("0..={type_max}"));
    let what = if value.starts_with('-') { "a negative number" } else { "not a whole number" };
    Some((flag.clone(), format!("{flag}: must be a whole number in {range}, got {value} ({what})")))
}

/// A clap parse error: with `--json`, the error object on stdout and clap's text on stderr; else clap's usual output.
/// An unsigned flag given a negative number is reported with its range (exit 2).
pub fn exit_clap(e: clap::Error, json: bool, cmd: &clap::Command, argv: &[OsString]) -> ! {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if let Some((flag, msg)) = negative_unsigned_message(&e, cmd, argv) {
        eprintln!("error: {msg}");
        if json {
            emit_json_error(&msg, Some(&flag), 2);
        }
        std::process::exit(2);
    }
    let code = e.exit_code();
    if !json || matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) || code == 0 {
        e.exit();
    }
    let rendered = e.render().to_string();
    eprint!("{rendered}");
    let first = rendered.lines().next().unwrap_or("").trim_start_matches("error: ").to_string();
    let param = match e.get(ContextKind::InvalidArg) {
        Some(ContextValue::String(s)) => Some(s.split_whitespace().next().unwrap_or(s).to_string()),
        _ => None,
    };
    emit_json_error(&first, param.as_deref(), code);
    std::process::exit(code);
}

/// Expands `--params FILE` (a JSON object of flag names to values) into flags inserted right after the
/// deepest subcommand on the command line, so flags given explicitly (which come later) override the file.
/// `true` → `--flag`, `false`/`null` → omitted, arrays → comma-separated, objects → rejected.
pub fn expand_params_file<C: clap::CommandFactory>(argv: Vec<OsString>) -> anyhow::Result<Vec<OsString>> {
    let Some(pos) = argv.iter().position(|a| a == "--params" || a.to_string_lossy().starts_with("--params=")) else {
        return Ok(argv);
    };
    let arg = argv[pos].to_string_lossy().into_owned();
    let (file, consumed) = if let Some(v) = arg.strip_prefix("--params=") {
        (v.to_string(), 1)
    } else {
        let v = argv.get(pos + 1).ok_or_else(|| usage_msg("--params needs a FILE"))?;
        (v.to_string_lossy().into_owned(), 2)
    };
    let text = std::fs::read_to_string(&file).map_err(|e| usage(anyhow::anyhow!("--params {file}: {e}")))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| usage(anyhow::anyhow!("--params {file}: malformed JSON: {e}")))?;
    let obj = json.as_object().ok_or_else(|| usage_msg(format!("--params {file}: expected a JSON object")))?;
    let mut flags: Vec<OsString> = Vec::new();
    for (k, v) in obj {
        let name = format!("--{}", k.replace('_', "-"));
        match v {
            serde_json::Value::Bool(true) => flags.push(name.into()),
            serde_json::Value::Bool(false) | serde_json::Value::Null => {}
            serde_json::Value::Number(n) => flags.extend([name.into(), n.to_string().into()]),
            serde_json::Value::String(s) => flags.extend([name.into(), s.into()]),
            serde_json::Value::Array(items) => {
                let parts: Result<Vec<String>, _> = items
                    .iter()
                    .map(|i| match i {
                        serde_json::Value::Number(n) => Ok(n.to_string()),
                        serde_json::Value::String(s) => Ok(s.clone()),
                        _ => Err(usage_msg(format!("--params {file}: \"{k}\" must be an array of numbers or strings"))),
                    })
                    .collect();
                flags.extend([name.into(), parts?.join(",").into()]);
            }
            serde_json::Value::Object(_) => {
                return Err(usage_msg(format!("--params {file}: \"{k}\" must not be an object")));
            }
        }
    }
    let mut rest: Vec<OsString> = argv.clone();
    rest.drain(pos..pos + consumed);
    // Find the deepest subcommand token.
    let mut cmd = C::command();
    let mut insert_at = 1;
    for (i, a) in rest.iter().enumerate().skip(1) {
        let s = a.to_string_lossy();
        if let Some(sub) = cmd.find_subcommand(s.as_ref()).cloned() {
            cmd = sub;
            insert_at = i + 1;
        }
    }
    let mut out = rest[..insert_at].to_vec();
    out.extend(flags);
    out.extend_from_slice(&rest[insert_at..]);
    Ok(out)
}

/// Parses a comma-separated list of floats, naming the flag in errors.
#[allow(dead_code)]
pub fn parse_f64_list(flag: &str, s: &str) -> anyhow::Result<Vec<f64>> {
    s.split(',')
        .map(|t| {
            let t = t.trim();
            t.parse::<f64>()
                .map_err(|_| usage_msg(format!("{flag}: '{t}' is not a number (expected a comma-separated list)")))
        })
        .collect()
}

/// Parses exactly three comma-separated floats (R,G,B).
#[allow(dead_code)]
pub fn parse_rgb(flag: &str, s: &str) -> anyhow::Result<[f64; 3]> {
    let v = parse_f64_list(flag, s)?;
    if v.len() != 3 {
        return Err(usage_msg(format!("{flag}: expected three comma-separated values R,G,B, got {}", v.len())));
    }
    Ok([v[0], v[1], v[2]])
}

/// Checks that an output directory exists (or can be created) and is writable, before any work. Nothing is
/// written to probe it (a kill cannot leave a probe file among the user's files).
#[allow(dead_code)]
pub fn prepare_out_dir(flag: &str, dir: &Path) -> anyhow::Result<()> {
    check_dir_name(flag, dir)?;
    std::fs::create_dir_all(dir)
        .map_err(|e| usage(anyhow::anyhow!("{flag} {}: cannot create directory: {e}", dir.display())))?;
    rtbake::io::file_set::check_dir_writable(dir)
        .map_err(|e| usage(anyhow::anyhow!("{flag} {}: directory is not writable: {e}", dir.display())))
}

/// Writes a command's output files into `dir` as one set with the library's `write_file_set`: under the
/// directory's lock, all or nothing (a kill is rolled forward by the next command), an output that is one of
/// `inputs` refused (exit 2, both paths named), a lock held elsewhere under --no-wait exit 3.
#[allow(dead_code)]
/// `--zstd LEVEL`, shared by every command that writes KTX2 files (`aa`, `bake`, `transmittance`, `skin-color`,
/// `maps hemoglobin|wrinkles|masks`).
#[derive(clap::Args, Debug, Clone, Copy, Default)]
pub struct ZstdArg {
    /// Zstandard-supercompress every KTX2 file written (KTX2 supercompression scheme 2) at this level (1..=22;
    /// Bevy ships its SMAA LUTs at 15). Other formats are unchanged.
    #[arg(long, value_name = "LEVEL", allow_negative_numbers = true)]
    pub zstd: Option<i32>,
}

impl ZstdArg {
    /// The level, validated (exit 2 naming `--zstd` and the range).
    pub fn level(&self) -> anyhow::Result<Option<i32>> {
        if let Some(level) = self.zstd {
            rtbake::error::check_range("--zstd", level, 1, 22, "(Zstandard level)").map_err(usage)?;
        }
        Ok(self.zstd)
    }

    /// Supercompresses the uncompressed KTX2 files of `files` (recorded in their metadata) when `--zstd` is given.
    pub fn apply(&self, files: &mut [rtbake::bake::BakedFile]) -> anyhow::Result<()> {
        if let Some(level) = self.level()? {
            rtbake::bake::supercompress_ktx2(files, level).map_err(|e| anyhow::anyhow!("--zstd {level}: {e}"))?;
        }
        Ok(())
    }
}

/// File extensions that make a new output directory's name look like a file (`--out t.png`).
const FILE_EXTENSIONS: [&str; 14] =
    ["png", "exr", "json", "csv", "svg", "dds", "ktx2", "bin", "h", "hlsl", "glsl", "wgsl", "txt", "jpg"];

/// Refuses a directory output named like a file that does not exist yet (`--out t.png` would silently create a
/// directory `t.png`); an existing directory of that name is accepted.
pub fn check_dir_name(flag: &str, dir: &Path) -> anyhow::Result<()> {
    let ext = dir.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if let Some(ext) = ext.filter(|e| FILE_EXTENSIONS.contains(&e.as_str())) {
        if !dir.is_dir() {
            return Err(usage_msg(format!(
                "{flag} {}: this command writes several files into a directory, and this name ends in .{ext} like a \
                 file; give a directory (e.g. {flag} out/)",
                dir.display()
            )));
        }
    }
    Ok(())
}

pub fn write_set(
    ctx: &Ctx,
    flag: &str,
    dir: &Path,
    files: &[rtbake::bake::BakedFile],
    inputs: &[&Path],
) -> anyhow::Result<Vec<std::path::PathBuf>> {
    check_dir_name(flag, dir)?;
    // Bevy's `.meta` settings go beside every linear data texture, as `bake` writes them.
    let metas = rtbake::bake::bevy_meta_files(files);
    let list: Vec<(&str, &[u8])> = files.iter().chain(&metas).map(|f| (f.path.as_str(), f.bytes.as_slice())).collect();
    ctx.with_wait(|w| rtbake::io::file_set::write_file_set(dir, &list, inputs, w))
        .map_err(|e| file_set_err(e).context(format!("{flag} {}", dir.display())))
}

/// Writes a command's separate output files (`--csv`, `--out`, `--plot`, …): two or more in one directory as one
/// locked set (`write_file_set`: all or nothing, never seen mixed, refused when two flags name the same file), a
/// single file or files in different directories each atomically. Prints `wrote PATH` per file.
pub fn write_outputs(ctx: &Ctx, outputs: &[(&str, &Path, Vec<u8>)], inputs: &[&Path]) -> anyhow::Result<()> {
    let parent = |p: &Path| -> std::path::PathBuf {
        let d = p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        std::fs::canonicalize(d).unwrap_or_else(|_| d.to_path_buf())
    };
    let flags: Vec<&str> = outputs.iter().map(|o| o.0).collect();
    let one_dir = outputs.len() > 1 && outputs.iter().all(|o| parent(o.1) == parent(outputs[0].1));
    if one_dir {
        let dir = parent(outputs[0].1);
        let list: Vec<(String, &[u8])> = outputs
            .iter()
            .map(|(_, p, b)| {
                (p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(), b.as_slice())
            })
            .collect();
        let refs: Vec<(&str, &[u8])> = list.iter().map(|(n, b)| (n.as_str(), *b)).collect();
        ctx.with_wait(|w| rtbake::io::file_set::write_file_set(&dir, &refs, inputs, w))
            .map_err(|e| file_set_err(e).context(flags.join("/")))?;
    } else {
        for (_, path, bytes) in outputs {
            rtbake::io::atomic::write_atomic(path, bytes)?;
        }
    }
    for (_, path, _) in outputs {
        ctx.info(format!("wrote {}", path.display()));
    }
    Ok(())
}

/// `42 s`, `7.5 min` or `3.2 h`.
pub fn fmt_seconds(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.0} s")
    } else if s < 7200.0 {
        format!("{:.1} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

/// Parses `--max-seconds`: a positive, finite number of seconds.
pub fn parse_seconds(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(s) if s.is_finite() && s > 0.0 => Ok(s),
        _ => Err(format!("expected a positive number of seconds, got '{text}'")),
    }
}

/// `1.5 GiB`-style size.
pub fn fmt_bytes(b: u64) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = b as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < units.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{b} B")
    } else {
        format!("{v:.1} {}", units[u])
    }
}

/// The largest `--max-memory`: 1024 TiB (a larger value would wrap or read as "unlimited").
pub const MAX_MEMORY_BYTES: u64 = 1 << 50;

/// Parses `--max-memory`: bytes with an optional K, M, G or T suffix (powers of 1024), e.g. `12G`, at most 1024T.
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (num, shift) = match t.chars().last().map(|c| c.to_ascii_uppercase()) {
        Some('K') => (&t[..t.len() - 1], 10),
        Some('M') => (&t[..t.len() - 1], 20),
        Some('G') => (&t[..t.len() - 1], 30),
        Some('T') => (&t[..t.len() - 1], 40),
        _ => (t, 0),
    };
    let v: f64 = num.trim().parse().map_err(|_| format!("expected a size like 512M or 12G, got {s:?}"))?;
    let bytes = v * (1u64 << shift) as f64;
    if !(v.is_finite() && v > 0.0 && bytes <= MAX_MEMORY_BYTES as f64) {
        return Err(format!("must be a size in 1..=1024T (bytes, K, M, G or T), got {s:?}"));
    }
    Ok(bytes as u64)
}

/// Physical memory of this machine, if the platform says.
fn physical_memory_bytes() -> Option<u64> {
    #[cfg(unix)]
    {
        // SAFETY: sysconf only reads system configuration.
        let (pages, size) = unsafe { (libc::sysconf(libc::_SC_PHYS_PAGES), libc::sysconf(libc::_SC_PAGESIZE)) };
        if pages > 0 && size > 0 {
            return Some(pages as u64 * size as u64);
        }
    }
    None
}

/// `--adding`: how layers are combined at each spatial frequency (one flag type for every command).
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
pub enum AddingArg {
    /// DJ05 as printed (top-lit R, T in both roles).
    #[default]
    Symmetric,
    /// Kubelka 1954 (R↓, T↓, R↑, T↑ kept apart).
    Directional,
}

impl From<AddingArg> for rtbake::diffusion::layered::Adding {
    fn from(a: AddingArg) -> Self {
        match a {
            AddingArg::Symmetric => Self::Symmetric,
            AddingArg::Directional => Self::Directional,
        }
    }
}
