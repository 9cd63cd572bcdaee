//! `rtbake aa <texture>`: SMAA / MLAA lookup textures, including variants, written into `--out DIR`.
//!
//! ```text
//! rtbake aa smaa-area --out DIR                                    # 160x560 RG8, byte-identical to upstream
//! rtbake aa smaa-area --ortho-offsets 0,-0.3,0.3 --diag-offsets 0:0,0.3:-0.3 --out DIR
//! rtbake aa smaa-area-v2.8 --format bin --out DIR                  # no U-shape smoothing
//! rtbake aa smaa-search --format h,rs --out DIR                    # SearchTex.h / SearchTex.rs
//! rtbake aa mlaa-v1.4 --max-distance 65 --out DIR                  # AreaMap65_v1.4.*
//! ```
//!
//! Flags that do not apply to the chosen texture are refused (exit 2) rather than ignored. Everything is computed
//! and validated before the output directory is touched; files are then written atomically. `--json` prints the
//! written files (path, size, sha256) on stdout.

use crate::cli::{parse_f64_list, prepare_out_dir, usage, usage_msg, Ctx};
use rtbake::aa::mlaa_area::MlaaVersion;
use rtbake::aa::smaa_area::SmaaAreaParams;
use rtbake::bake::aa::{mlaa_files_with_progress, mlaa_stem, search_files, smaa_area_files, SearchKind};
use rtbake::bake::TextureFormats;
use rtbake::bake::{BakeError, BakedFile};
use sha2::{Digest, Sha256};
use std::path::PathBuf;

/// The textures `rtbake aa` can generate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AaTexture {
    /// SMAA area texture, SMAA 2.8+ (160x560 RG8 with defaults; AreaTex).
    #[value(name = "smaa-area")]
    SmaaArea,
    /// SMAA area texture without U-shape smoothing, as shipped with v2.8 (AreaTex_v2.8).
    #[value(name = "smaa-area-v2.8")]
    SmaaAreaV28,
    /// SMAA search texture 64x16 R8 (SearchTex).
    #[value(name = "smaa-search")]
    SmaaSearch,
    /// SMAA v2.8 search table 66x33 storing 0/1/2 (SearchTex_v2.8).
    #[value(name = "smaa-search-v2.8")]
    SmaaSearchV28,
    /// SMAA 66x33 search table storing 0/127/254 before crop and flip (SearchTex_logical_precrop).
    #[value(name = "smaa-search-precrop")]
    SmaaSearchPrecrop,
    /// Jimenez MLAA v1.4+ area map, 5N x 5N RG8, N odd (AreaMap{N}_v1.4).
    #[value(name = "mlaa-v1.4")]
    MlaaV14,
    /// Jimenez MLAA v1.3 area map, 5N x 5N RG8 (AreaMap{N}_v1.3).
    #[value(name = "mlaa-v1.3")]
    MlaaV13,
    /// MLAA 2.0 area texture, quadratic distances, 5N x 5N RG8 (AreaTex_MLAAv2).
    #[value(name = "mlaa-v2")]
    MlaaV2,
}

/// Output formats (`--format`, comma-separated or repeated).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AaFormat {
    /// Raw payload, row-major, top row first, channels interleaved.
    Bin,
    /// DDS with DXGI R8G8_UNORM / R8_UNORM (non-sRGB), and `<stem>_dx9.dds` with the legacy header
    /// (D3DFMT_A8L8 / L8) for readers without DX10 support.
    Dds,
    /// KTX2 with VK_FORMAT_R8G8_UNORM / R8_UNORM, linear transfer.
    Ktx2,
    /// PNG (RG as RGB with B = 0; tagged linear).
    Png,
    /// C header (upstream AreaTex.h / SearchTex.h names and defines).
    H,
    /// Rust source (smaa-rs' items: `AREATEX_WIDTH: u32`, `AREATEX_SIZE: usize`, `static AREATEX_BYTES`, etc.).
    Rs,
    /// All of the above.
    All,
}

/// The files `--format` asks for (only these are encoded).
fn texture_formats(list: &[AaFormat]) -> TextureFormats {
    let mut f = TextureFormats::NONE;
    for fmt in list {
        match fmt {
            AaFormat::Bin => f.bin = true,
            AaFormat::Dds => f.dds = true,
            AaFormat::Ktx2 => f.ktx2 = true,
            AaFormat::Png => f.png = true,
            AaFormat::H => f.c_header = true,
            AaFormat::Rs => f.rust_source = true,
            AaFormat::All => f = TextureFormats::ALL,
        }
    }
    f
}

#[derive(clap::Args)]
pub struct AaArgs {
    /// Texture to generate.
    #[arg(value_enum)]
    pub texture: AaTexture,
    /// MLAA only: cell size N in texels (= upstream NUM_DISTANCES, the number in AreaMap{N}; distances 0..N-1 px,
    /// or (N-1)^2 for mlaa-v2). v1.4: odd, 3..=1023 (default 33); v1.3: 2..=1024 (default 32); v2: 2..=1024
    /// (default 15).
    #[arg(long, value_name = "N")]
    pub max_distance: Option<u32>,
    /// SMAA area only: orthogonal cell size in texels (SMAA_AREATEX_MAX_DISTANCE; distances i^2 px), 1..=128,
    /// default 16.
    #[arg(long, value_name = "N")]
    pub ortho_max_distance: Option<u32>,
    /// SMAA area only: diagonal cell size in texels (SMAA_AREATEX_MAX_DISTANCE_DIAG; distances 0..N-1 px),
    /// 1..=128, default 20.
    #[arg(long, value_name = "N")]
    pub diag_max_distance: Option<u32>,
    /// SMAA area only: vertical subsample offsets in pixels, one slice each, each in (-0.5, 0.5), 1..=16 values;
    /// default 0,-0.25,0.25,-0.125,0.125,-0.375,0.375.
    #[arg(long, value_name = "A,B,...", allow_hyphen_values = true)]
    pub ortho_offsets: Option<String>,
    /// SMAA area only: diagonal subsample offsets x:y in pixels, one slice each, each component in (-0.5, 0.5),
    /// 1..=16 pairs; default 0:0,0.25:-0.25,-0.25:0.25,0.125:-0.125,-0.125:0.125.
    #[arg(long, value_name = "X:Y,...", allow_hyphen_values = true)]
    pub diag_offsets: Option<String>,
    /// smaa-area only: disable the SMAA 2.8+ U-shape smoothing (gives the v2.8 texture).
    #[arg(long)]
    pub no_u_smoothing: bool,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// File formats to write, comma-separated. Default: all for tables up to 1 MiB; above, the binary formats
    /// (bin,dds,ktx2,png) only — the C/Rust sources are ~6 bytes of text per texel byte (AreaMap1023 ≈ 300 MB
    /// each) and are written only when named (`--format h,rs` or `all`).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub format: Vec<AaFormat>,
    /// File name stem (default: the upstream name, e.g. AreaTex, SearchTex, AreaMap33_v1.4).
    #[arg(long, value_name = "NAME")]
    pub stem: Option<String>,
    #[command(flatten)]
    pub zstd: crate::cli::ZstdArg,
}

fn is_smaa_area(t: AaTexture) -> bool {
    matches!(t, AaTexture::SmaaArea | AaTexture::SmaaAreaV28)
}

fn mlaa_version(t: AaTexture) -> Option<MlaaVersion> {
    match t {
        AaTexture::MlaaV14 => Some(MlaaVersion::V1_4),
        AaTexture::MlaaV13 => Some(MlaaVersion::V1_3),
        AaTexture::MlaaV2 => Some(MlaaVersion::V2),
        _ => None,
    }
}

/// Refuses flags that do not apply to the texture.
fn check_applicable(a: &AaArgs) -> anyhow::Result<()> {
    let smaa_flags = [
        ("--ortho-max-distance", a.ortho_max_distance.is_some()),
        ("--diag-max-distance", a.diag_max_distance.is_some()),
        ("--ortho-offsets", a.ortho_offsets.is_some()),
        ("--diag-offsets", a.diag_offsets.is_some()),
    ];
    if !is_smaa_area(a.texture) {
        if let Some((flag, _)) = smaa_flags.iter().find(|(_, set)| *set) {
            return Err(usage_msg(format!("{flag} applies only to smaa-area and smaa-area-v2.8")));
        }
    }
    if a.no_u_smoothing && a.texture != AaTexture::SmaaArea {
        return Err(usage_msg("--no-u-smoothing applies only to smaa-area (smaa-area-v2.8 never smooths)"));
    }
    if a.max_distance.is_some() && mlaa_version(a.texture).is_none() {
        let hint = if is_smaa_area(a.texture) { " (use --ortho-max-distance / --diag-max-distance)" } else { "" };
        return Err(usage_msg(format!("--max-distance applies only to mlaa-v1.4, mlaa-v1.3 and mlaa-v2{hint}")));
    }
    if let Some(stem) = &a.stem {
        if stem.is_empty() || stem.contains(['/', '\\']) || stem.starts_with('.') {
            return Err(usage_msg(format!(
                "--stem must be a plain file name without '/' or a leading '.', got {stem:?}"
            )));
        }
    }
    Ok(())
}

/// Parses `x:y,x:y,...`.
fn parse_pairs(flag: &str, s: &str) -> anyhow::Result<Vec<[f64; 2]>> {
    s.split(',')
        .map(|t| {
            let t = t.trim();
            let (x, y) = t
                .split_once(':')
                .ok_or_else(|| usage_msg(format!("{flag}: '{t}' is not an x:y pair (expected e.g. 0.25:-0.25,...)")))?;
            let num = |v: &str| {
                v.trim().parse::<f64>().map_err(|_| usage_msg(format!("{flag}: '{v}' in '{t}' is not a number")))
            };
            Ok([num(x)?, num(y)?])
        })
        .collect()
}

/// Raw flags → validated SMAA area parameters.
fn smaa_params(a: &AaArgs) -> anyhow::Result<SmaaAreaParams> {
    let mut p = if a.texture == AaTexture::SmaaAreaV28 { SmaaAreaParams::v2_8() } else { SmaaAreaParams::default() };
    if let Some(n) = a.ortho_max_distance {
        p.ortho_max_distance = n;
    }
    if let Some(n) = a.diag_max_distance {
        p.diag_max_distance = n;
    }
    if let Some(s) = &a.ortho_offsets {
        p.ortho_offsets = parse_f64_list("--ortho-offsets", s)?;
    }
    if let Some(s) = &a.diag_offsets {
        p.diag_offsets = parse_pairs("--diag-offsets", s)?;
    }
    if a.no_u_smoothing {
        p.u_smoothing = false;
    }
    p.validate().map_err(usage)?;
    Ok(p)
}

/// The canonical command line reproducing an SMAA area texture (recorded in generated sources).
fn smaa_command(name: &str, p: &SmaaAreaParams) -> String {
    let ortho: Vec<String> = p.ortho_offsets.iter().map(|o| o.to_string()).collect();
    let diag: Vec<String> = p.diag_offsets.iter().map(|o| format!("{}:{}", o[0], o[1])).collect();
    let mut cmd = format!(
        "rtbake aa {name} --ortho-max-distance {} --diag-max-distance {} --ortho-offsets={} --diag-offsets={}",
        p.ortho_max_distance,
        p.diag_max_distance,
        ortho.join(","),
        diag.join(",")
    );
    if !p.u_smoothing && name == "smaa-area" {
        cmd.push_str(" --no-u-smoothing");
    }
    cmd
}

fn default_mlaa_n(v: MlaaVersion) -> u32 {
    match v {
        MlaaVersion::V1_4 => 33,
        MlaaVersion::V1_3 => 32,
        MlaaVersion::V2 => 15,
    }
}

/// Library bake errors: bad parameters are bad input (exit 2), anything else a runtime failure.
fn bake_err(e: BakeError) -> anyhow::Error {
    match e {
        BakeError::Invalid(i) => usage(i),
        other => other.into(),
    }
}

/// Payloads above this size get only the binary formats unless sources are asked for by name.
const SOURCES_BY_DEFAULT_MAX_BYTES: u64 = 1 << 20;
/// Generated sources above this size are announced on stderr before they are written.
const LARGE_SOURCE_WARN_BYTES: u64 = 64 << 20;

/// Texture payload in bytes (before anything is computed), for the format defaults.
fn payload_bytes(a: &AaArgs) -> anyhow::Result<u64> {
    Ok(match a.texture {
        AaTexture::SmaaArea | AaTexture::SmaaAreaV28 => {
            let (w, h) = smaa_params(a)?.validate().map_err(usage)?;
            w as u64 * h as u64 * 2
        }
        AaTexture::SmaaSearch | AaTexture::SmaaSearchV28 | AaTexture::SmaaSearchPrecrop => 66 * 33,
        AaTexture::MlaaV14 | AaTexture::MlaaV13 | AaTexture::MlaaV2 => {
            let v = mlaa_version(a.texture).expect("MLAA texture");
            let n = a.max_distance.unwrap_or(default_mlaa_n(v)) as u64;
            25 * n * n * 2
        }
    })
}

pub fn run(mut a: AaArgs, ctx: &Ctx) -> anyhow::Result<()> {
    check_applicable(&a)?;
    let payload = payload_bytes(&a)?;
    if a.format.is_empty() {
        a.format = if payload <= SOURCES_BY_DEFAULT_MAX_BYTES {
            vec![AaFormat::All]
        } else {
            ctx.info(format!(
                "{:.1} MiB table: writing bin, dds, ktx2, png; the C/Rust sources (~{} MiB each) only with --format h,rs",
                payload as f64 / (1u64 << 20) as f64,
                (6 * payload) >> 20
            ));
            vec![AaFormat::Bin, AaFormat::Dds, AaFormat::Ktx2, AaFormat::Png]
        };
    }
    let formats = texture_formats(&a.format);
    let sources = formats.c_header || formats.rust_source;
    if sources && 6 * payload > LARGE_SOURCE_WARN_BYTES {
        eprintln!(
            "warning: writing C/Rust sources of ~{} MiB each (payload {} bytes); --format bin,dds,ktx2,png skips them",
            (6 * payload) >> 20,
            payload
        );
    }
    let name = clap::ValueEnum::to_possible_value(&a.texture).map(|v| v.get_name().to_string()).unwrap_or_default();
    // Everything is computed and validated before the output directory is touched.
    let files: Vec<BakedFile> = match a.texture {
        AaTexture::SmaaArea | AaTexture::SmaaAreaV28 => {
            let p = smaa_params(&a)?;
            let default_stem = if a.texture == AaTexture::SmaaArea { "AreaTex" } else { "AreaTex_v2.8" };
            let from = format!("`{}`", smaa_command(&name, &p));
            smaa_area_files(a.stem.as_deref().unwrap_or(default_stem), &p, formats, &from).map_err(bake_err)?
        }
        AaTexture::SmaaSearch | AaTexture::SmaaSearchV28 | AaTexture::SmaaSearchPrecrop => {
            let (kind, stem) = match a.texture {
                AaTexture::SmaaSearch => (SearchKind::Current, "SearchTex"),
                AaTexture::SmaaSearchV28 => (SearchKind::V2_8, "SearchTex_v2.8"),
                _ => (SearchKind::LogicalPrecrop, "SearchTex_logical_precrop"),
            };
            search_files(kind, a.stem.as_deref().unwrap_or(stem), formats, &format!("`rtbake aa {name}`"))
                .map_err(bake_err)?
        }
        AaTexture::MlaaV14 | AaTexture::MlaaV13 | AaTexture::MlaaV2 => {
            let v = mlaa_version(a.texture).expect("MLAA texture");
            let n = a.max_distance.unwrap_or(default_mlaa_n(v));
            let stem = a.stem.clone().unwrap_or_else(|| mlaa_stem(v, n));
            let from = format!("`rtbake aa {name} --max-distance {n}`");
            let pb = ctx.progress(5 * n as u64, "MLAA area map rows");
            pb.set_style(
                indicatif::ProgressStyle::with_template("{msg} {bar:30} {pos}/{len} [{elapsed}]")
                    .expect("valid template"),
            );
            let files = mlaa_files_with_progress(v, n, &stem, formats, &from, &|done, _| pb.set_position(done as u64))
                .map_err(bake_err)?;
            pb.finish_and_clear();
            files
        }
    };
    // Only the requested formats were encoded.
    let mut files = files;
    a.zstd.apply(&mut files)?;
    // Bevy's `.meta` settings beside every linear data texture, listed with the set.
    rtbake::bake::add_bevy_meta_files(&mut files);
    prepare_out_dir("--out", &a.out)?;
    // The sha256 lines are hashed while the set is written (the write mostly waits for the page cache and the
    // disk flush): a rayon task beside the write, so with one thread (`RAYON_NUM_THREADS=1`) the process uses one
    // core and with two the hash overlaps the write. Same digests, printed only after the write succeeded. Under
    // --quiet without --json nothing prints them, so they are not computed.
    let hex = |f: &BakedFile| Sha256::digest(&f.bytes).iter().map(|b| format!("{b:02x}")).collect::<String>();
    let want_hashes = !ctx.quiet || ctx.json;
    let (result, shas) = rayon::join(
        || crate::cli::write_set(ctx, "--out", &a.out, &files, &[]),
        || want_hashes.then(|| files.iter().map(hex).collect::<Vec<String>>()),
    );
    result?;
    let Some(shas) = shas else { return Ok(()) };
    let mut written = Vec::new();
    for (f, sha) in files.iter().zip(shas) {
        let path = a.out.join(&f.path);
        ctx.info(format!("wrote {} ({} bytes, sha256 {sha})", path.display(), f.bytes.len()));
        written.push(serde_json::json!({
            "path": path.display().to_string(),
            "bytes": f.bytes.len(),
            "sha256": sha,
            "format": f.meta.format,
            "width": f.meta.width,
            "height": f.meta.height,
            "channels": f.meta.channels,
            "convention": f.meta.convention,
        }));
    }
    if ctx.json {
        ctx.emit_json(&serde_json::json!({ "texture": name, "out": a.out.display().to_string(), "files": written }));
    }
    Ok(())
}
