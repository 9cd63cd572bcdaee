//! The one table from the library's parameter names (the fields its `InvalidInput.param` names) to the CLI flags
//! that set them. The library names fields — in `param`, and in a message that suggests another setting, as the
//! field between backticks (`` `cpu` ``, `` `width` 2048 ``); [`render`] turns both into the flags of the command
//! that runs, once, where `cli::exit_with` prints an error. Some commands also rename a field here in their own
//! wording around the flag ([`flag_of`], [`flag_among`]).

use std::sync::OnceLock;

use rtbake::error::InvalidInput;

/// Field → flag. A field of three channels (`albedo[1]`) is looked up without its index.
const FIELD_FLAGS: &[(&str, &str)] = &[
    // profiles (`rtbake profile`, `fit`, `evaluate`, …)
    ("material", "--material"),
    ("profile_preset", "--profile-preset"),
    ("thickness_mm", "--thickness-mm"),
    ("radii", "--radii"),
    ("r_min_mm", "--r-min-mm"),
    ("r_max_mm", "--r-max-mm"),
    ("count", "--count"),
    // Burley's normalized diffusion
    ("albedo", "--burley-albedo"),
    ("d_mm", "--burley-d-mm"),
    ("mean_free_path_mm", "--burley-mfp-mm"),
    // physiological skin
    ("melanin_fraction", "--skin-melanin"),
    ("allow_unphysiological", "--allow-unphysiological"),
    ("hemoglobin_fraction", "--skin-hemoglobin"),
    // skin colour (`rtbake skin-color`): the point, the physiology, the spectral grid
    ("hemoglobin", "--hemoglobin"),
    ("melanin_blend", "--melanin-blend"),
    ("epidermal_hemoglobin_ratio", "--epidermal-hemoglobin-ratio"),
    ("thin_layer", "--thin-layer"),
    ("oxygenation", "--oxygenation"),
    ("hemoglobin_g_per_l", "--hemoglobin-g-per-l"),
    ("hemoglobin_molar_mass_g_per_mol", "--hemoglobin-molar-mass-g-per-mol"),
    ("epidermis_thickness_mm", "--epidermis-thickness-mm"),
    ("dermis_thickness_mm", "--dermis-thickness-mm"),
    ("eta_epidermis", "--eta-epidermis"),
    ("eta_dermis", "--eta-dermis"),
    ("eta_below_dermis", "--eta-below-dermis"),
    ("spectral_step_nm", "--spectral-step-nm"),
    ("mc_nodes", "--mc-nodes"),
    ("mc_step_nm", "--mc-step-nm"),
    ("map_size", "--map-size"),
    // Monte Carlo transport
    ("g", "--g"),
    ("photons", "--photons"),
    ("seed", "--seed"),
    ("batches", "--batches"),
    ("bin_mm", "--bin-mm"),
    ("bins", "--bins"),
    // importance-sampled kernels
    ("samples", "--samples"),
    // frames and images (`rtbake run …`)
    ("width", "--width"),
    ("height", "--height"),
    ("input", "--input"),
    ("color", "--color"),
    ("depth", "--depth"),
    ("mask", "--mask"),
    ("cpu", "--cpu"),
    ("no_wait", "--no-wait"),
    // screen-space subsurface scattering
    ("sss", "--sss"),
    ("sss_width", "--sss-width"),
    ("fovy_deg", "--fovy"),
    ("mm_per_world_unit", "--mm-per-world-unit"),
    ("alpha", "--alpha"),
    ("beta", "--beta"),
    ("gamma", "--gamma"),
    // antialiasing
    ("mode", "--mode"),
    ("k", "--k"),
    ("edges", "--edges"),
    ("predication", "--predication"),
    ("predication_threshold", "--predication-threshold"),
    ("predication_scale", "--predication-scale"),
    ("predication_strength", "--predication-strength"),
    ("depth_threshold", "--depth-threshold"),
    ("max_distance", "--max-distance"),
    ("ortho_max_distance", "--ortho-max-distance"),
    ("diag_max_distance", "--diag-max-distance"),
    ("ortho_offsets", "--ortho-offsets"),
    ("diag_offsets", "--diag-offsets"),
    // the skin frame (`rtbake run skin`)
    ("heads", "--heads"),
    ("distance_m", "--distance"),
    ("melanin", "--melanin"),
    ("msaa", "--msaa"),
    ("mesh", "--mesh"),
    ("mesh_units", "--mesh-units"),
    ("mesh_mm_per_unit", "--mesh-mm-per-unit"),
    ("shader", "--shader"),
    ("ts_map_size", "--ts-map-size"),
    ("light_azimuth_deg", "--light-azimuth"),
    ("light_elevation_deg", "--light-elevation"),
    ("transmittance", "--transmittance"),
    ("bloom", "--bloom"),
    ("albedo_map", "--albedo"),
    ("normal_map", "--normal-map"),
    ("wrinkles", "--wrinkles"),
    ("rig_weights", "--rig-weights"),
    // facial maps (`rtbake maps …`)
    ("channel", "--channel"),
    ("neutral", "--neutral"),
    ("target", "--target"),
    ("weights", "--weights"),
    ("normalize_weights", "--normalize-weights"),
    ("radius_texels", "--radius"),
    ("sigma_floor", "--sigma-floor"),
    ("rig_size", "--rig-size"),
    ("normal", "--normal"),
    ("base", "--base"),
    ("value_range", "--value-range"),
    ("cone", "--cone"),
    // transmittance tables
    ("s_mm", "--s"),
    ("s_max_mm", "--s-max"),
    // separable kernels and their fit
    ("range", "--range"),
    ("exponent", "--exponent"),
    ("strength", "--strength"),
    ("falloff", "--falloff"),
    ("grid_nodes", "--grid-nodes"),
    ("grid_extent_mm", "--grid-extent-mm"),
    ("grid_exponent", "--grid-exponent"),
    ("pixel_mm", "--pixel-mm"),
    // sum-of-Gaussians fits
    ("starts", "--starts"),
    ("normalize", "--normalize"),
    // plots
    ("plot", "--plot"),
];

/// The flag that sets the library parameter `param`, if a flag does.
pub fn flag_of(param: &str) -> Option<&'static str> {
    let field = match param.split_once('[') {
        Some((f, rest)) if rest.ends_with(']') => f,
        _ => param,
    };
    FIELD_FLAGS.iter().find(|(f, _)| *f == field).map(|(_, flag)| *flag)
}

/// [`flag_of`] where the flag is one of those the command has (`allowed`); `None` otherwise.
pub fn flag_among(param: &str, allowed: &[&'static str]) -> Option<&'static str> {
    flag_of(param).filter(|f| allowed.contains(f))
}

/// The long flags (with their aliases) of the command that runs, set once by `main` ([`set_command`]).
static COMMAND_FLAGS: OnceLock<Vec<String>> = OnceLock::new();

/// Records the flags of the (sub)command `argv` invokes, so [`render`] renames only fields the command has a flag
/// for (a field of a baked asset's spec stays a field under `rtbake bake`).
pub fn set_command(cmd: &clap::Command, argv: &[std::ffi::OsString]) {
    let mut flags = Vec::new();
    let mut at = cmd;
    long_flags(at, &mut flags);
    for a in argv.iter().skip(1).filter_map(|a| a.to_str()) {
        if let Some(sub) = at.find_subcommand(a) {
            at = sub;
            long_flags(at, &mut flags);
        }
    }
    let _ = COMMAND_FLAGS.set(flags);
}

fn long_flags(cmd: &clap::Command, out: &mut Vec<String>) {
    for a in cmd.get_arguments() {
        for l in a.get_long().into_iter().chain(a.get_all_aliases().unwrap_or_default()) {
            out.push(format!("--{l}"));
        }
    }
}

/// The flag for `field` in the command that runs (every flag of the table before [`set_command`]).
fn command_flag(field: &str) -> Option<&'static str> {
    let flag = flag_of(field)?;
    match COMMAND_FLAGS.get() {
        Some(flags) if !flags.iter().any(|f| f == flag) => None,
        _ => Some(flag),
    }
}

/// `param` with each `/`-separated part's leading field replaced by its flag (`width/height` → `--width/--height`,
/// `ortho_offsets[3]` → `--ortho-offsets[3]`, `target cheek` → `--target cheek`); kept as it is unless every part
/// has a flag (a flag already, `layers[0].g`, a path `dir/thickness_mm.json`).
pub fn render_param(param: &str) -> String {
    let (head, value) = param.split_at(param.find(' ').unwrap_or(param.len()));
    let part = |p: &str| {
        let end = p.find(|c: char| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')).unwrap_or(p.len());
        let rest = &p[end..];
        let flag = command_flag(&p[..end]).filter(|_| end > 0 && (rest.is_empty() || rest.starts_with(['[', '.'])));
        flag.map(|f| format!("{f}{rest}"))
    };
    match head.split('/').map(part).collect::<Option<Vec<_>>>() {
        Some(parts) => format!("{}{value}", parts.join("/")),
        None => param.to_string(),
    }
}

/// `text` with every field written between backticks (`` `cpu` ``) replaced by its flag; other backticked text
/// and fields without a flag in this command are kept.
pub fn render_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(open) = rest.find('`') {
        out.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        match after.find('`').and_then(|close| command_flag(&after[..close]).map(|f| (close, f))) {
            Some((close, flag)) => {
                out.push_str(flag);
                rest = &after[close + 1..];
            }
            None => {
                out.push('`');
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// The error as the CLI reports it: its parameter and every field its message names, as flags.
pub fn render(e: &InvalidInput) -> InvalidInput {
    InvalidInput::new(render_param(&e.param), render_text(&e.message))
}

/// One line of an error's cause chain as the CLI prints it: each validation error of `invalid` it quotes, rendered
/// by [`render`], and any other marked field as its flag.
pub fn render_line(line: &str, invalid: &[&InvalidInput]) -> String {
    let mut line = line.to_string();
    for e in invalid {
        line = line.replace(&e.to_string(), &render(e).to_string());
    }
    render_text(&line)
}

/// Every field of the table (the architecture check reads the table's rows from this file's text).
#[cfg(test)]
pub fn fields() -> impl Iterator<Item = &'static str> {
    FIELD_FLAGS.iter().map(|(f, _)| *f)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fields map to their flags, per-channel fields without their index; anything else is not a flag.
    #[test]
    fn fields_map_to_flags() {
        assert_eq!(flag_of("thickness_mm"), Some("--thickness-mm"));
        assert_eq!(flag_of("albedo[2]"), Some("--burley-albedo"));
        assert_eq!(flag_of("melanin_fraction"), Some("--skin-melanin"));
        assert_eq!(flag_of("profile"), None);
        assert_eq!(flag_of("layers[0].sigma_a"), None);
        let set: std::collections::BTreeSet<_> = fields().collect();
        assert_eq!(set.len(), FIELD_FLAGS.len(), "a field listed twice");
    }

    /// Every row's flag is a flag of some `rtbake` command (no stale row).
    #[test]
    fn every_row_is_a_flag_of_the_cli() {
        fn all(cmd: &clap::Command, out: &mut Vec<String>) {
            long_flags(cmd, out);
            cmd.get_subcommands().for_each(|s| all(s, out));
        }
        let mut flags = Vec::new();
        all(&crate::command(), &mut flags);
        let stale: Vec<_> = FIELD_FLAGS.iter().filter(|(_, flag)| !flags.iter().any(|f| f == flag)).collect();
        assert!(stale.is_empty(), "rows whose flag is no flag of rtbake: {stale:?}");
    }

    /// The settings the `run`, `aa`, `kernel`, `fit separable`, `transmittance` and `maps` commands hand the library
    /// refuse bad values naming fields the table maps, so the CLI names the flag.
    #[test]
    fn the_commands_settings_name_fields_with_flags() {
        use rtbake::runtime::sss::{
            gaussian::GaussianSssParams, importance::ImportanceSssParams, separable::SssParams,
        };
        use rtbake::separable::kernel::KernelSpec;
        let bad_params = [
            SssParams { sss_width: -1.0, ..Default::default() }.validate(),
            SssParams { fovy_deg: 0.0, ..Default::default() }.validate(),
            ImportanceSssParams { mm_per_world_unit: 0.0, ..Default::default() }.validate(),
            GaussianSssParams { alpha: f32::NAN, ..Default::default() }.validate(),
            rtbake::runtime::skin::settings::TsSettings { map_size: 1, ..Default::default() }.validate(),
            rtbake::aa::smaa_area::SmaaAreaParams { ortho_max_distance: 0, ..Default::default() }
                .validate()
                .map(|_| ()),
            rtbake::aa::mlaa_area::validate(rtbake::aa::mlaa_area::MlaaVersion::V1_4, 0).map(|_| ()),
            KernelSpec { exponent: f64::NAN, ..KernelSpec::new(17, rtbake::separable::PUBLISHED) }.validate(),
            rtbake::separable::fit::ObjectiveSpec { grid_nodes: 4, ..Default::default() }.validate(),
            rtbake::transmittance::TableSettings { s_max_mm: -1.0, ..Default::default() }.validate(),
            rtbake::facial::hemoglobin_rig::check_settings(
                &rtbake::facial::hemoglobin_rig::RigSettings { sigma_floor: 0.0, ..Default::default() },
                64,
                64,
            ),
            "8x".parse::<rtbake::runtime::aa::modes::SmaaMode>().map(|_| ()),
        ];
        for r in bad_params {
            let e = r.expect_err("a bad value is refused");
            assert!(!e.param.starts_with('-'), "the library names a field, not a flag: {e}");
            assert!(render(&e).param.starts_with("--"), "{}: no row in the table", e.param);
        }
    }

    /// Parameters and marked fields become flags; pairs, indices and values after the field are kept; unmarked
    /// words, other backticked text and unknown fields are not touched.
    #[test]
    fn errors_render_with_flags() {
        assert_eq!(render_param("width/height"), "--width/--height");
        assert_eq!(render_param("diag_offsets[1].y"), "--diag-offsets[1].y");
        assert_eq!(render_param("target cheek"), "--target cheek");
        assert_eq!(render_param("layers[0].g"), "layers[0].g");
        assert_eq!(render_param("--thickness-mm"), "--thickness-mm");
        assert_eq!(render_param("--layers /tmp/d/thickness_mm.json:"), "--layers /tmp/d/thickness_mm.json:");
        assert_eq!(render_param("tmp/thickness_mm.json"), "tmp/thickness_mm.json");
        assert_eq!(render_param("width/layers"), "width/layers");
        let e = InvalidInput::new("width/height", "4x4: `width` 2 `height` 1 fits; or `cpu`, or `bloom` off");
        assert_eq!(render(&e).to_string(), "--width/--height 4x4: --width 2 --height 1 fits; or --cpu, or --bloom off");
        assert_eq!(render_text("see `rtbake run smaa --help`, `width`"), "see `rtbake run smaa --help`, --width");
        assert_eq!(render_text("`no_such_field` and a lone `"), "`no_such_field` and a lone `");
        let line = format!("cannot render: {e}");
        assert_eq!(render_line(&line, &[&e]), format!("cannot render: {}", render(&e)));
    }
}
