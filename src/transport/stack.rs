//! The layer stack the Monte Carlo transport runs in: plane-parallel layers, top first, each with per-channel
//! σa, σs (mm⁻¹), Henyey–Greenstein g and an absolute refractive index, between ambient media of index
//! `eta_above` and `eta_below` (MCML's geometry: L. Wang, S. L. Jacques, L. Zheng, "MCML — Monte Carlo modeling of
//! light transport in multi-layered tissues", Computer Methods and Programs in Biomedicine 47, 1995, §2–3).
//! The last layer may be semi-infinite.
//!
//! JSON (`rtbake transport --layers`): the diffusion layer-stack schema of [`crate::diffusion::layered`] plus an
//! optional `g` per layer (a number or `[r, g, b]`, default 0); scattering is given either as `sigma_s` or as
//! `sigma_s_prime` (σs = σs′/(1 − g)); the last layer's `thickness_mm` may be the string `"infinite"`:
//! `{"eta_above": 1.0, "eta_below": 1.0, "layers": [{"thickness_mm": 0.2, "eta": 1.4, "sigma_a": [..],
//! "sigma_s": [..], "g": 0.9}, ...]}`.

use crate::diffusion::layered::LayerStack;
use crate::error::InvalidInput;
use serde_json::{json, Value};

/// Largest refractive index accepted (indices are absolute, ≥ 1).
pub const MAX_ETA: f64 = 10.0;
/// Largest coefficient accepted, mm⁻¹ (a mean free path of 1 nm).
pub const MAX_COEFFICIENT_PER_MM: f64 = 1e6;
/// Most layers in a stack.
pub const MAX_LAYERS: usize = 64;

/// One layer (lengths in mm, coefficients in mm⁻¹, per channel R, G, B).
#[derive(Clone, Debug, PartialEq)]
pub struct McLayer {
    /// Thickness, mm; `f64::INFINITY` for a semi-infinite last layer.
    pub thickness_mm: f64,
    /// Absolute refractive index (≥ 1).
    pub eta: f64,
    pub sigma_a_per_mm: [f64; 3],
    /// Scattering coefficient σs (not reduced), mm⁻¹.
    pub sigma_s_per_mm: [f64; 3],
    /// Henyey–Greenstein anisotropy, in (−1, 1).
    pub g: [f64; 3],
}

/// A validated stack (see the module docs for the rules).
#[derive(Clone, Debug, PartialEq)]
pub struct McStack {
    eta_above: f64,
    eta_below: f64,
    layers: Vec<McLayer>,
}

fn check_eta(param: &str, eta: f64) -> Result<(), InvalidInput> {
    if !(eta.is_finite() && (1.0..=MAX_ETA).contains(&eta)) {
        return Err(InvalidInput::new(
            param,
            format!("must be an absolute refractive index in 1..={MAX_ETA} (eta < 1 is refused), got {eta}"),
        ));
    }
    Ok(())
}

fn check_coefficient(param: &str, v: f64) -> Result<(), InvalidInput> {
    if !(v.is_finite() && (0.0..=MAX_COEFFICIENT_PER_MM).contains(&v)) {
        return Err(InvalidInput::new(
            param,
            format!("must be a finite number in 0..={MAX_COEFFICIENT_PER_MM:e} mm^-1, got {v}"),
        ));
    }
    Ok(())
}

fn check_g(param: &str, g: f64) -> Result<(), InvalidInput> {
    if !(g.is_finite() && g > -1.0 && g < 1.0) {
        return Err(InvalidInput::new(param, format!("must be in the open interval (-1, 1), got {g}")));
    }
    Ok(())
}

/// σs = σs′/(1 − g): the scattering coefficient that keeps the reduced coefficient σs′ = σs(1 − g) of a diffusion
/// layer for a Henyey–Greenstein anisotropy g (so transport and diffusion see the same σs′).
pub fn sigma_s_from_reduced(sigma_s_prime_per_mm: f64, g: f64) -> f64 {
    sigma_s_prime_per_mm / (1.0 - g)
}

impl McLayer {
    /// A layer from diffusion coefficients (σa, σs′ in mm⁻¹) and one anisotropy g ∈ (−1, 1), σs = σs′/(1 − g)
    /// ([`sigma_s_from_reduced`]). Errors name `g`; the rest is checked by [`McStack::new`].
    pub fn from_reduced(
        thickness_mm: f64,
        eta: f64,
        sigma_a_per_mm: [f64; 3],
        sigma_s_prime_per_mm: [f64; 3],
        g: f64,
    ) -> Result<Self, InvalidInput> {
        check_g("g", g)?;
        Ok(Self {
            thickness_mm,
            eta,
            sigma_a_per_mm,
            sigma_s_per_mm: sigma_s_prime_per_mm.map(|s| sigma_s_from_reduced(s, g)),
            g: [g; 3],
        })
    }
}

impl McStack {
    /// Validates: indices in 1..=[`MAX_ETA`], 1..=[`MAX_LAYERS`] layers, σa, σs finite in 0..=1e6 mm⁻¹, g ∈ (−1, 1),
    /// thickness finite > 0 except a semi-infinite (`INFINITY`) last layer, which needs σa > 0 in every channel
    /// (without absorption a photon's walk in a half-space has no finite mean length). Errors name the JSON field.
    pub fn new(eta_above: f64, eta_below: f64, layers: Vec<McLayer>) -> Result<Self, InvalidInput> {
        check_eta("eta_above", eta_above)?;
        check_eta("eta_below", eta_below)?;
        if layers.is_empty() || layers.len() > MAX_LAYERS {
            return Err(InvalidInput::new(
                "layers",
                format!("must list 1..={MAX_LAYERS} layers (top layer first), got {}", layers.len()),
            ));
        }
        let n = layers.len();
        for (j, l) in layers.iter().enumerate() {
            check_eta(&format!("layers[{j}].eta"), l.eta)?;
            let last = j + 1 == n;
            let t = l.thickness_mm;
            if !(t > 0.0 && (t.is_finite() || (last && t == f64::INFINITY))) || t.is_nan() {
                return Err(InvalidInput::new(
                    format!("layers[{j}].thickness_mm"),
                    format!(
                        "must be a finite number > 0 mm{}, got {t}",
                        if last { " or \"infinite\"" } else { " (only the last layer may be infinite)" }
                    ),
                ));
            }
            for c in 0..3 {
                check_coefficient(&format!("layers[{j}].sigma_a[{c}]"), l.sigma_a_per_mm[c])?;
                check_coefficient(&format!("layers[{j}].sigma_s[{c}]"), l.sigma_s_per_mm[c])?;
                check_g(&format!("layers[{j}].g[{c}]"), l.g[c])?;
                if t.is_infinite() && l.sigma_a_per_mm[c] <= 0.0 {
                    return Err(InvalidInput::new(
                        format!("layers[{j}].sigma_a[{c}]"),
                        "must be > 0 mm^-1 in a semi-infinite layer (photons would walk without end)",
                    ));
                }
            }
        }
        Ok(Self { eta_above, eta_below, layers })
    }

    /// Parses and validates the JSON of the module docs. Errors name the field (`layers[1].g[0]`, …).
    pub fn from_json_str(text: &str) -> Result<Self, InvalidInput> {
        let v: Value = serde_json::from_str(text)
            .map_err(|e| InvalidInput::new("layers", format!("file is not valid JSON: {e}")))?;
        Self::from_json(&v)
    }

    /// [`from_json_str`](Self::from_json_str) on a parsed value.
    pub fn from_json(v: &Value) -> Result<Self, InvalidInput> {
        let obj = v.as_object().ok_or_else(|| InvalidInput::new("layers", "file must hold a JSON object"))?;
        for key in obj.keys() {
            if !["eta_above", "eta_below", "layers"].contains(&key.as_str()) {
                return Err(InvalidInput::new(key, "is not a known field (eta_above, eta_below, layers)"));
            }
        }
        let number = |val: Option<&Value>, param: &str, default: Option<f64>| -> Result<f64, InvalidInput> {
            match (val, default) {
                (None, Some(d)) => Ok(d),
                (Some(x), _) => {
                    x.as_f64().ok_or_else(|| InvalidInput::new(param, format!("must be a number, got {x}")))
                }
                (None, None) => Err(InvalidInput::new(param, "is required")),
            }
        };
        let rgb = |val: Option<&Value>, param: &str, default: Option<f64>| -> Result<[f64; 3], InvalidInput> {
            match val {
                Some(Value::Array(a)) if a.len() == 3 => {
                    let mut out = [0.0; 3];
                    for c in 0..3 {
                        out[c] = number(Some(&a[c]), &format!("{param}[{c}]"), None)?;
                    }
                    Ok(out)
                }
                Some(Value::Number(_)) => Ok([number(val, param, None)?; 3]),
                Some(x) => Err(InvalidInput::new(param, format!("must be a number or [r, g, b], got {x}"))),
                None => default.map(|d| [d; 3]).ok_or_else(|| InvalidInput::new(param, "is required")),
            }
        };
        let eta_above = number(obj.get("eta_above"), "eta_above", Some(1.0))?;
        let eta_below = number(obj.get("eta_below"), "eta_below", Some(1.0))?;
        let list = obj
            .get("layers")
            .and_then(Value::as_array)
            .ok_or_else(|| InvalidInput::new("layers", "is required: a list of layers, top first"))?;
        if list.len() > MAX_LAYERS {
            return Err(InvalidInput::new("layers", format!("must list 1..={MAX_LAYERS} layers, got {}", list.len())));
        }
        let mut layers = Vec::with_capacity(list.len());
        for (j, l) in list.iter().enumerate() {
            let p = |k: &str| format!("layers[{j}].{k}");
            let o = l.as_object().ok_or_else(|| InvalidInput::new(format!("layers[{j}]"), "must be an object"))?;
            for key in o.keys() {
                if !["thickness_mm", "eta", "sigma_a", "sigma_s", "sigma_s_prime", "g"].contains(&key.as_str()) {
                    return Err(InvalidInput::new(
                        p(key),
                        "is not a known field (thickness_mm, eta, sigma_a, sigma_s | sigma_s_prime, g)",
                    ));
                }
            }
            let thickness_mm = match o.get("thickness_mm") {
                Some(Value::String(s)) if s == "infinite" => f64::INFINITY,
                other => number(other, &p("thickness_mm"), None)?,
            };
            let g = rgb(o.get("g"), &p("g"), Some(0.0))?;
            for (c, &gc) in g.iter().enumerate() {
                check_g(&format!("{}[{c}]", p("g")), gc)?;
            }
            let sigma_s_per_mm = match (o.get("sigma_s"), o.get("sigma_s_prime")) {
                (Some(s), None) => rgb(Some(s), &p("sigma_s"), None)?,
                (None, Some(s)) => {
                    let sp = rgb(Some(s), &p("sigma_s_prime"), None)?;
                    [0, 1, 2].map(|c| sigma_s_from_reduced(sp[c], g[c]))
                }
                _ => {
                    return Err(InvalidInput::new(
                        p("sigma_s"),
                        "exactly one of sigma_s and sigma_s_prime (= sigma_s (1 - g)) is required, mm^-1",
                    ))
                }
            };
            layers.push(McLayer {
                thickness_mm,
                eta: number(o.get("eta"), &p("eta"), None)?,
                sigma_a_per_mm: rgb(o.get("sigma_a"), &p("sigma_a"), None)?,
                sigma_s_per_mm,
                g,
            });
        }
        Self::new(eta_above, eta_below, layers)
    }

    /// A diffusion layer stack (σa, σs′) as transport layers with anisotropy `g` (σs = σs′/(1 − g)), so the
    /// transport and the diffusion model see the same reduced coefficients.
    pub fn from_layer_stack(stack: &LayerStack, g: f64) -> Result<Self, InvalidInput> {
        let layers = stack
            .layers()
            .iter()
            .map(|l| McLayer::from_reduced(l.thickness_mm, l.eta, l.sigma_a, l.sigma_s_prime, g))
            .collect::<Result<Vec<_>, _>>()?;
        Self::new(stack.eta_above(), stack.eta_below(), layers)
    }

    /// A semi-infinite homogeneous medium of index `eta` under air (σs = σs′/(1 − g)); the dipole's geometry.
    pub fn semi_infinite(
        sigma_a_per_mm: [f64; 3],
        sigma_s_prime_per_mm: [f64; 3],
        g: f64,
        eta: f64,
    ) -> Result<Self, InvalidInput> {
        let layer = McLayer::from_reduced(f64::INFINITY, eta, sigma_a_per_mm, sigma_s_prime_per_mm, g)?;
        Self::new(1.0, eta, vec![layer])
    }

    /// A slab of `thickness_mm` and index `eta` in air on both sides (σs = σs′/(1 − g)); the multipole's geometry.
    pub fn slab(
        thickness_mm: f64,
        sigma_a_per_mm: [f64; 3],
        sigma_s_prime_per_mm: [f64; 3],
        g: f64,
        eta: f64,
    ) -> Result<Self, InvalidInput> {
        let layer = McLayer::from_reduced(thickness_mm, eta, sigma_a_per_mm, sigma_s_prime_per_mm, g)?;
        Self::new(1.0, 1.0, vec![layer])
    }

    pub fn eta_above(&self) -> f64 {
        self.eta_above
    }
    pub fn eta_below(&self) -> f64 {
        self.eta_below
    }
    pub fn layers(&self) -> &[McLayer] {
        &self.layers
    }

    /// The stack as JSON (the schema it is read from; σs as `sigma_s`).
    pub fn to_json(&self) -> Value {
        let layers: Vec<Value> = self
            .layers
            .iter()
            .map(|l| {
                json!({
                    "thickness_mm": if l.thickness_mm.is_finite() { json!(l.thickness_mm) } else { json!("infinite") },
                    "eta": l.eta,
                    "sigma_a": l.sigma_a_per_mm,
                    "sigma_s": l.sigma_s_per_mm,
                    "g": l.g,
                })
            })
            .collect();
        json!({"eta_above": self.eta_above, "eta_below": self.eta_below, "layers": layers})
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<McStack, InvalidInput> {
        McStack::from_json_str(text)
    }

    #[test]
    fn json_round_trip_and_reduced_scattering() {
        let s = parse(
            r#"{"eta_above": 1.0, "layers": [{"thickness_mm": 0.2, "eta": 1.4, "sigma_a": [1, 2, 3],
                "sigma_s_prime": [1, 1, 1], "g": 0.8}, {"thickness_mm": "infinite", "eta": 1.4, "sigma_a": 0.1,
                "sigma_s": [5, 6, 7]}]}"#,
        )
        .unwrap();
        assert!((s.layers()[0].sigma_s_per_mm[0] - 5.0).abs() < 1e-12);
        assert_eq!(s.layers()[1].g, [0.0; 3]);
        assert!(s.layers()[1].thickness_mm.is_infinite());
        assert_eq!(McStack::from_json(&s.to_json()).unwrap(), s);
    }

    #[test]
    fn bad_fields_are_named() {
        let base = |layer: &str| format!(r#"{{"layers": [{layer}]}}"#);
        let cases = [
            (base(r#"{"thickness_mm": 1, "eta": 0.9, "sigma_a": 1, "sigma_s": 1}"#), "layers[0].eta"),
            (base(r#"{"thickness_mm": 1, "eta": 1.3, "sigma_a": 1, "sigma_s": 1, "g": 1}"#), "layers[0].g[0]"),
            (base(r#"{"thickness_mm": 1, "eta": 1.3, "sigma_a": [1, -1, 1], "sigma_s": 1}"#), "layers[0].sigma_a[1]"),
            (base(r#"{"thickness_mm": 0, "eta": 1.3, "sigma_a": 1, "sigma_s": 1}"#), "layers[0].thickness_mm"),
            (base(r#"{"thickness_mm": "infinite", "eta": 1.3, "sigma_a": 0, "sigma_s": 1}"#), "layers[0].sigma_a[0]"),
            (base(r#"{"thickness_mm": 1, "eta": 1.3, "sigma_a": 1}"#), "layers[0].sigma_s"),
            (base(r#"{"thickness_mm": 1, "eta": 1.3, "sigma_a": 1, "sigma_s": 1, "mu": 2}"#), "layers[0].mu"),
            (r#"{"layers": []}"#.to_string(), "layers"),
            (r#"{"eta_above": 0.5, "layers": []}"#.to_string(), "eta_above"),
        ];
        for (text, param) in cases {
            assert_eq!(parse(&text).unwrap_err().param, param, "{text}");
        }
        let mid_infinite = r#"{"layers": [{"thickness_mm": "infinite", "eta": 1, "sigma_a": 1, "sigma_s": 1},
            {"thickness_mm": 1, "eta": 1, "sigma_a": 1, "sigma_s": 1}]}"#;
        assert_eq!(parse(mid_infinite).unwrap_err().param, "layers[0].thickness_mm");
    }
}
