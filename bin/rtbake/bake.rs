//! `rtbake bake`, `rtbake verify`, `rtbake assets`.

use crate::cli::{file_set_err, usage, usage_msg, Ctx};
use rtbake::baked_dir::{self, FileStatus};
use serde_json::Value;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct BakeArgs {
    /// Assets to bake (default: all; `rtbake assets` lists them). Other assets already in the directory are kept.
    pub assets: Vec<String>,
    /// Output directory (created if missing; must be empty or an rtbake bake directory).
    #[arg(long, default_value = "baked", value_name = "DIR")]
    pub out: PathBuf,
    /// JSON object {"ASSET": {parameters…}} merged over each asset's embedded defaults.
    #[arg(long, value_name = "FILE")]
    pub asset_params: Option<PathBuf>,
    /// Sets the `ktx2_zstd` parameter of every asset baked (recorded in the manifest, so `verify` recomputes it).
    #[command(flatten)]
    pub zstd: crate::cli::ZstdArg,
}

#[derive(clap::Args)]
pub struct VerifyArgs {
    /// Bake directory holding manifest.json.
    #[arg(long, default_value = "baked", value_name = "DIR")]
    pub dir: PathBuf,
    /// The bake directory given without --dir (`rtbake verify baked`).
    #[arg(value_name = "DIR", conflicts_with = "dir")]
    pub dir_positional: Option<PathBuf>,
    /// File holding the expected sha256 of manifest.json (e.g. `sha256sum baked/manifest.json > baked.pin`, kept
    /// in version control): any edit of the manifest, however consistent, fails verification.
    #[arg(long, value_name = "FILE")]
    pub pin: Option<PathBuf>,
}

fn merge(base: &mut Value, over: &Value) {
    match (base, over) {
        (Value::Object(b), Value::Object(o)) => {
            for (k, v) in o {
                merge(b.entry(k.clone()).or_insert(Value::Null), v);
            }
        }
        (b, o) => *b = o.clone(),
    }
}

pub fn run_bake(a: BakeArgs, ctx: &Ctx) -> anyhow::Result<()> {
    let registry = rtbake::bake::registry();
    let names: Vec<&str> = registry.iter().map(|x| x.name).collect();
    for n in &a.assets {
        if !names.contains(&n.as_str()) {
            return Err(usage_msg(format!("unknown asset {n:?}; known assets: {}", names.join(", "))));
        }
    }
    let zstd = a.zstd.level()?;
    crate::cli::check_dir_name("--out", &a.out)?;
    let overrides: Value = match &a.asset_params {
        None => Value::Object(Default::default()),
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| usage(anyhow::anyhow!("--asset-params {}: {e}", p.display())))?;
            let v: Value = serde_json::from_str(&text)
                .map_err(|e| usage(anyhow::anyhow!("--asset-params {}: malformed JSON: {e}", p.display())))?;
            let obj = v
                .as_object()
                .ok_or_else(|| usage_msg(format!("--asset-params {}: expected a JSON object", p.display())))?;
            for k in obj.keys() {
                if !names.contains(&k.as_str()) {
                    return Err(usage_msg(format!("--asset-params {}: unknown asset {k:?}", p.display())));
                }
            }
            v
        }
    };
    let selected: Vec<&rtbake::bake::Asset> =
        registry.iter().filter(|x| a.assets.is_empty() || a.assets.iter().any(|n| n == x.name)).collect();
    let jobs: Vec<(&rtbake::bake::Asset, Value)> = selected
        .iter()
        .map(|asset| {
            let mut p = (asset.default_params)();
            if let Some(o) = overrides.get(asset.name) {
                merge(&mut p, o);
            }
            if let (Some(level), Some(obj)) = (zstd, p.as_object_mut()) {
                obj.insert(rtbake::bake::KTX2_ZSTD_PARAM.into(), level.into());
            }
            (*asset, p)
        })
        .collect();
    check_time(&jobs, a.asset_params.is_some(), ctx)?;
    check_out_dir(&a.out)?;
    let pb = ctx.progress(jobs.len() as u64, "baking");
    pb.set_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} assets, {elapsed}: {msg}")
            .expect("valid template"),
    );
    pb.enable_steady_tick(std::time::Duration::from_millis(200));
    let t0 = std::time::Instant::now();
    let progress = |k: usize, name: &str| {
        pb.set_position(k as u64);
        pb.set_message(name.to_string());
    };
    let summary = ctx.with_wait(|wait| baked_dir::bake_into_with(&a.out, &jobs, &progress, wait)).map_err(classify)?;
    pb.finish_and_clear();
    if ctx.json {
        ctx.emit_json(&serde_json::to_value(&summary)?);
    }
    ctx.info(format!(
        "baked {} asset(s), {} files ({:.1} KiB) into {} in {:.2} s",
        summary.assets.len(),
        summary.files_written,
        summary.bytes_written as f64 / 1024.0,
        summary.dir,
        t0.elapsed().as_secs_f64()
    ));
    Ok(())
}

/// Refuses (exit 2), before any work, a bake whose assets' time estimates ([`rtbake::bake::Asset::time_estimate`],
/// on this process' threads) add up to more than the time budget (`--max-seconds`); a parameter the estimate
/// cannot read is named as the bake would name it.
fn check_time(jobs: &[(&rtbake::bake::Asset, Value)], from_file: bool, ctx: &Ctx) -> anyhow::Result<()> {
    let threads = rayon::current_num_threads();
    let mut seconds = 0.0;
    let mut costly = Vec::new();
    for (asset, params) in jobs {
        let s = asset.time_estimate_seconds(params, threads).map_err(|e| match e {
            rtbake::bake::BakeError::Invalid(_) => usage(anyhow::anyhow!("asset {}: {e}", asset.name)),
            other => anyhow::Error::new(other),
        })?;
        if s >= 1.0 {
            costly.push(format!("{} ~{}", asset.name, crate::cli::fmt_seconds(s)));
        }
        seconds += s;
    }
    let what = format!(
        "bake{} ({})",
        if from_file { " --asset-params" } else { "" },
        if costly.is_empty() { "every asset under a second".to_string() } else { costly.join(", ") }
    );
    ctx.check_time(&what, seconds)
}

/// Bad parameters and unusable directories are the user's to fix (exit 2); a directory locked by another process
/// under --no-wait exits 3; I/O failures are runtime (exit 1).
fn classify(e: baked_dir::BakeDirError) -> anyhow::Error {
    use baked_dir::BakeDirError as E;
    match e {
        E::Asset { source: rtbake::bake::BakeError::Invalid(_), .. } | E::Unusable { .. } | E::Manifest(_) => usage(e),
        E::Dir(d) => file_set_err(d),
        other => anyhow::Error::new(other),
    }
}

fn check_out_dir(dir: &Path) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(usage_msg(format!("--out {}: exists and is not a directory", dir.display())));
    }
    // The probe is a staging directory beside DIR, never a file inside it (a kill cannot leave a user file behind).
    rtbake::io::file_set::probe_writable(dir)
        .map_err(|e| usage(anyhow::anyhow!("--out {}: not writable: {e}", dir.display())))
}

pub fn run_verify(mut a: VerifyArgs, ctx: &Ctx) -> anyhow::Result<()> {
    if let Some(d) = a.dir_positional.take() {
        a.dir = d;
    }
    // Refused before the lock is taken (its file would be created beside the missing directory), unless a bake is
    // creating it or was killed swapping it (then verify waits for the lock or finishes the swap).
    if let Some(what) = rtbake::baked_dir::unverifiable(&a.dir) {
        return Err(usage_msg(format!("--dir {}: {what}", a.dir.display())));
    }
    if a.dir.is_dir() && !a.dir.join(rtbake::manifest::MANIFEST_NAME).exists() {
        return Err(usage_msg(format!("--dir {}: no manifest.json (not a bake directory)", a.dir.display())));
    }
    let pin = match &a.pin {
        None => None,
        Some(p) => Some(
            std::fs::read_to_string(p)
                .map_err(|e| usage(anyhow::anyhow!("--pin {}: cannot read: {e}", p.display())))?,
        ),
    };
    let registry = rtbake::bake::registry();
    let report =
        ctx.with_wait(|wait| baked_dir::verify_with(&a.dir, &registry, pin.as_deref(), wait)).map_err(|e| match e {
            baked_dir::BakeDirError::Manifest(rtbake::manifest::ManifestError::Read { .. }) => usage(anyhow::anyhow!(
                "--dir {}: no readable manifest.json (not a bake directory): {e}",
                a.dir.display()
            )),
            other => classify(other),
        })?;
    let failed = || format!("verify: {} of {} files failed in {}", report.problems, report.files.len(), report.dir);
    if ctx.json {
        let mut v = serde_json::to_value(&report)?;
        // On failure the report also carries the keys of every --json error object, so one parser serves all.
        if !report.is_ok() {
            v["error"] = failed().into();
            v["param"] = Value::Null;
            v["exit_code"] = 1.into();
        }
        ctx.emit_json(&v);
    }
    for f in &report.files {
        if f.status != FileStatus::Ok {
            eprintln!("{:<10} {}  {}", format!("{:?}", f.status).to_uppercase(), f.path, f.detail);
        }
    }
    if report.is_ok() {
        ctx.info(format!("verify: {} files OK in {}", report.files.len(), report.dir));
        Ok(())
    } else {
        Err(anyhow::anyhow!(failed()))
    }
}

pub fn run_assets(ctx: &Ctx) -> anyhow::Result<()> {
    let registry = rtbake::bake::registry();
    if ctx.json {
        let list: Vec<Value> = registry
            .iter()
            .map(|a| serde_json::json!({"name": a.name, "summary": a.summary, "default_params": (a.default_params)()}))
            .collect();
        ctx.emit_json(&Value::Array(list));
    } else {
        for a in &registry {
            println!("{:<28} {}", a.name, a.summary);
        }
    }
    Ok(())
}
