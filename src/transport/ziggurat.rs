//! Exponential random numbers by the ziggurat method (G. Marsaglia, W. W. Tsang, "The Ziggurat Method for
//! Generating Random Variables", J. Stat. Softw. 5(8), 2000, §2–3, their `REXP` with 256 layers).
//!
//! The area under f(x) = e⁻ˣ is covered by 256 layers of equal area v: layer i ≥ 1 is the rectangle of width xᵢ
//! between heights f(xᵢ) and f(xᵢ₊₁) (x₁ = r > x₂ > … > x₂₅₆ = 0, xᵢ₊₁ = −ln(v/xᵢ + e^{−xᵢ})); layer 0 is the
//! rectangle `[0, r]` × `[0, f(r)]` with the tail beyond r, of pseudo-width x₀ = v/f(r). A draw picks a layer i and
//! x = U·xᵢ uniformly; x < xᵢ₊₁ lies under the curve and is returned at once (98.9 % of draws); otherwise x is
//! accepted if a uniform height in the layer is below e⁻ˣ, or, in layer 0, the tail r + (−ln U′) is returned (the
//! exponential is memoryless). Every returned value is distributed exactly as −ln U; the common case costs a table
//! look-up and a multiplication instead of a logarithm.
//!
//! r and v are Marsaglia & Tsang's constants for 256 layers; the tables are computed from them in f64.

use super::rng::PhotonRng;

/// Start of the tail, r.
const R: f64 = 7.697_117_470_131_05;
/// Area of each layer, v = (r + 1)e⁻ʳ.
const V: f64 = 3.949_659_822_581_557e-3;
/// Layers.
const LAYERS: usize = 256;

/// The layer edges xᵢ and heights f(xᵢ), i = 0..=256.
#[derive(Clone, Debug)]
pub struct ExponentialZiggurat {
    x: [f64; LAYERS + 1],
    f: [f64; LAYERS + 1],
}

impl Default for ExponentialZiggurat {
    fn default() -> Self {
        Self::new()
    }
}

impl ExponentialZiggurat {
    /// The tables for 256 layers (module docs).
    pub fn new() -> Self {
        let (x, _) = Self::edges();
        let f = x.map(|xi| (-xi).exp());
        Self { x, f }
    }

    /// The edges, and x₂₅₆ as the recursion gives it before it is set to 0 (≈ 0 when r and v are consistent).
    fn edges() -> ([f64; LAYERS + 1], f64) {
        let mut x = [0.0; LAYERS + 1];
        x[0] = V / (-R).exp();
        x[1] = R;
        for i in 1..LAYERS - 1 {
            x[i + 1] = -(V / x[i] + (-x[i]).exp()).ln();
        }
        let last = -(V / x[LAYERS - 1] + (-x[LAYERS - 1]).exp()).ln();
        x[LAYERS] = 0.0;
        (x, last)
    }

    /// An exponential variate of mean 1 from `rng`: one word in the common case (the layer from its low 8 bits, U
    /// from its top 24 bits on the grid k/2²⁴, so x resolves a layer's width to 6·10⁻⁸ — the tail beyond r is drawn
    /// afresh with 32 bits), more in the rare rejection and tail cases. Two words with a 53-bit U were measured 7 %
    /// slower over the whole transport.
    #[inline]
    pub fn sample(&self, rng: &mut PhotonRng) -> f64 {
        loop {
            let word = rng.word();
            let i = (word & 0xff) as usize;
            let u = f64::from(word >> 8) * (1.0 / 16_777_216.0);
            let x = u * self.x[i];
            if x < self.x[i + 1] {
                return x;
            }
            if let Some(v) = self.slow(rng, i, x) {
                return v;
            }
        }
    }

    #[cold]
    #[inline(never)]
    fn slow(&self, rng: &mut PhotonRng, i: usize, x: f64) -> Option<f64> {
        if i == 0 {
            return Some(R - rng.uniform().ln());
        }
        let height = self.f[i] + (self.f[i + 1] - self.f[i]) * rng.uniform();
        (height < (-x).exp()).then_some(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The layers close: the recursion from r with area v ends at 0, and every layer has area v.
    #[test]
    fn layers_have_equal_area_and_close_at_zero() {
        let (x, last) = ExponentialZiggurat::edges();
        assert!(last.abs() < 1e-9, "x256 from the recursion: {last}");
        let z = ExponentialZiggurat::new();
        for (i, (xi, f)) in x.iter().zip(z.f.windows(2)).enumerate().take(LAYERS).skip(1) {
            let area = xi * (f[1] - f[0]);
            assert!((area - V).abs() < 1e-12, "layer {i}: {area}");
        }
        // Layer 0: the base rectangle plus the tail, r·f(r) + f(r) = v.
        assert!(((R + 1.0) * (-R).exp() - V).abs() < 1e-15);
    }

    /// P(X ≤ t) = 1 − e⁻ᵗ at quantiles across the body, the layer edges' region and beyond the tail start, within
    /// 4 binomial standard errors; mean 1 within 4 SE (variance 1).
    #[test]
    fn samples_follow_the_exponential_distribution() {
        let z = ExponentialZiggurat::new();
        let mut rng = PhotonRng::new(5, 17, 0);
        let n = 400_000;
        let ts = [0.01, 0.1, 0.5, 1.0, 2.0, 4.0, 7.0, 7.697, 9.0];
        let mut below = [0usize; 9];
        let mut sum = 0.0;
        for _ in 0..n {
            let v = z.sample(&mut rng);
            assert!(v >= 0.0 && v.is_finite());
            sum += v;
            for (b, t) in below.iter_mut().zip(ts) {
                *b += usize::from(v <= t);
            }
        }
        let nf = n as f64;
        assert!((sum / nf - 1.0).abs() < 4.0 / nf.sqrt(), "mean {}", sum / nf);
        for (b, t) in below.iter().zip(ts) {
            let p = 1.0 - (-t).exp();
            let se = (p * (1.0 - p) / nf).sqrt();
            let got = *b as f64 / nf;
            assert!((got - p).abs() < 4.0 * se + 1e-12, "P(X <= {t}) = {got}, expected {p} (SE {se})");
        }
    }
}
