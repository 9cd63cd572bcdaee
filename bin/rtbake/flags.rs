//! The one table from the library's parameter names (the fields its `InvalidInput.param` names) to the CLI flags
//! that set them. The library names fields; the commands rename them here when they report an error, each
//! keeping its own wording around the flag.

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
    ("hemoglobin_fraction", "--skin-hemoglobin"),
    // Monte Carlo transport
    ("g", "--g"),
    ("photons", "--photons"),
    ("batches", "--batches"),
    ("bin_mm", "--bin-mm"),
    ("bins", "--bins"),
    // importance-sampled kernels
    ("samples", "--samples"),
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
        let fields: std::collections::BTreeSet<_> = FIELD_FLAGS.iter().map(|(f, _)| f).collect();
        assert_eq!(fields.len(), FIELD_FLAGS.len(), "a field listed twice");
    }
}
