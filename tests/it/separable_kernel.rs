//! Separable-SSS kernel taps against the published `SeparableSSS` header and the kernel invariants
//! (thesis ch. 6; `specs/sss-fitting.md` §2).

use rtbake::separable::kernel::{generate, KernelSpec, Precision};
use rtbake::separable::{SeparableParams, PUBLISHED, TABLE_6_1};

/// The shipped header's kernels (strength 0.48, 0.41, 0.28; falloff 1.0, 0.37, 0.3), printed with 6 significant
/// digits (`%g`), centre first.
const SHIPPED_11: [[f64; 4]; 11] = [
    [0.560479, 0.669086, 0.784728, 0.0],
    [0.00471691, 0.000184771, 5.07566e-005, -2.0],
    [0.0192831, 0.00282018, 0.00084214, -1.28],
    [0.03639, 0.0130999, 0.00643685, -0.72],
    [0.0821904, 0.0358608, 0.0209261, -0.32],
    [0.0771802, 0.113491, 0.0793803, -0.08],
    [0.0771802, 0.113491, 0.0793803, 0.08],
    [0.0821904, 0.0358608, 0.0209261, 0.32],
    [0.03639, 0.0130999, 0.00643685, 0.72],
    [0.0192831, 0.00282018, 0.00084214, 1.28],
    [0.00471691, 0.000184771, 5.07565e-005, 2.0],
];

const SHIPPED_17: [[f64; 4]; 17] = [
    [0.536343, 0.624624, 0.748867, 0.0],
    [0.00317394, 0.000134823, 3.77269e-005, -2.0],
    [0.0100386, 0.000914679, 0.000275702, -1.53125],
    [0.0144609, 0.00317269, 0.00106399, -1.125],
    [0.0216301, 0.00794618, 0.00376991, -0.78125],
    [0.0347317, 0.0151085, 0.00871983, -0.5],
    [0.0571056, 0.0287432, 0.0172844, -0.28125],
    [0.0582416, 0.0659959, 0.0411329, -0.125],
    [0.0324462, 0.0656718, 0.0532821, -0.03125],
    [0.0324462, 0.0656718, 0.0532821, 0.03125],
    [0.0582416, 0.0659959, 0.0411329, 0.125],
    [0.0571056, 0.0287432, 0.0172844, 0.28125],
    [0.0347317, 0.0151085, 0.00871983, 0.5],
    [0.0216301, 0.00794618, 0.00376991, 0.78125],
    [0.0144609, 0.00317269, 0.00106399, 1.125],
    [0.0100386, 0.000914679, 0.000275702, 1.53125],
    [0.00317394, 0.000134823, 3.77269e-005, 2.0],
];

const SHIPPED_25: [[f64; 4]; 25] = [
    [0.530605, 0.613514, 0.739601, 0.0],
    [0.000973794, 1.11862e-005, 9.43437e-007, -3.0],
    [0.00333804, 7.85443e-005, 1.2945e-005, -2.52083],
    [0.00500364, 0.00020094, 5.28848e-005, -2.08333],
    [0.00700976, 0.00049366, 0.000151938, -1.6875],
    [0.0094389, 0.00139119, 0.000416598, -1.33333],
    [0.0128496, 0.00356329, 0.00132016, -1.02083],
    [0.017924, 0.00711691, 0.00347194, -0.75],
    [0.0263642, 0.0119715, 0.00684598, -0.520833],
    [0.0410172, 0.0199899, 0.0118481, -0.333333],
    [0.0493588, 0.0367726, 0.0219485, -0.1875],
    [0.0402784, 0.0657244, 0.04631, -0.0833333],
    [0.0211412, 0.0459286, 0.0378196, -0.0208333],
    [0.0211412, 0.0459286, 0.0378196, 0.0208333],
    [0.0402784, 0.0657244, 0.04631, 0.0833333],
    [0.0493588, 0.0367726, 0.0219485, 0.1875],
    [0.0410172, 0.0199899, 0.0118481, 0.333333],
    [0.0263642, 0.0119715, 0.00684598, 0.520833],
    [0.017924, 0.00711691, 0.00347194, 0.75],
    [0.0128496, 0.00356329, 0.00132016, 1.02083],
    [0.0094389, 0.00139119, 0.000416598, 1.33333],
    [0.00700976, 0.00049366, 0.000151938, 1.6875],
    [0.00500364, 0.00020094, 5.28848e-005, 2.08333],
    [0.00333804, 7.85443e-005, 1.2945e-005, 2.52083],
    [0.000973794, 1.11862e-005, 9.43437e-007, 3.0],
];

/// Half a unit in the 6th significant digit of `printed` (what `%g` rounding leaves), plus f32 slack.
fn print_tolerance(printed: f64) -> f64 {
    if printed == 0.0 {
        return 1e-12;
    }
    let exp10 = printed.abs().log10().floor();
    0.5 * 10f64.powf(exp10 - 5.0) * (1.0 + 1e-6) + printed.abs() * 1e-7
}

fn check_against_shipped(n: usize, shipped: &[[f64; 4]]) {
    let k = generate(&KernelSpec::new(n, PUBLISHED)).unwrap();
    assert_eq!(k.taps.len(), shipped.len());
    for (i, (ours, theirs)) in k.taps.iter().zip(shipped).enumerate() {
        for j in 0..4 {
            let tol = print_tolerance(theirs[j]);
            assert!(
                (ours[j] - theirs[j]).abs() <= tol,
                "N={n} tap {i} component {j}: ours {} vs shipped {} (tolerance {tol:e})",
                ours[j],
                theirs[j]
            );
        }
    }
}

#[test]
fn f32_reproduces_the_shipped_11_17_25_tap_kernels_digit_for_digit() {
    check_against_shipped(11, &SHIPPED_11);
    check_against_shipped(17, &SHIPPED_17);
    check_against_shipped(25, &SHIPPED_25);
}

#[test]
fn seventeen_tap_centre_matches_the_published_value() {
    for precision in [Precision::F32, Precision::F64] {
        let spec = KernelSpec { precision, ..KernelSpec::new(17, PUBLISHED) };
        let c = generate(&spec).unwrap().taps[0];
        for (ours, theirs) in c.iter().zip([0.536343, 0.624624, 0.748867]) {
            assert!((ours - theirs).abs() <= 1e-6, "{precision:?}: centre {c:?}");
        }
        assert_eq!(c[3], 0.0);
    }
}

#[test]
fn f32_offsets_carry_the_shipped_asymmetry_and_f64_is_symmetric() {
    // The shipped 11-tap header prints 5.07566e-005 for the −2 tap and 5.07565e-005 for the +2 tap.
    let k32 = generate(&KernelSpec::new(11, PUBLISHED)).unwrap();
    assert_ne!(k32.taps[1][2], k32.taps[10][2]);
    let spec = KernelSpec { precision: Precision::F64, ..KernelSpec::new(11, PUBLISHED) };
    let k64 = generate(&spec).unwrap();
    for i in 1..=5 {
        let (neg, pos) = (k64.taps[i], k64.taps[11 - i]);
        for c in 0..3 {
            assert!((neg[c] - pos[c]).abs() <= 1e-15, "tap {i} channel {c}");
        }
    }
}

fn all_specs() -> Vec<KernelSpec> {
    let mut v = Vec::new();
    for n in [3, 5, 9, 11, 17, 21, 25, 33, 63] {
        for params in [PUBLISHED, TABLE_6_1, SeparableParams { strength: [1.0, 0.0, 0.5], falloff: [0.0, 2.0, 0.01] }] {
            for precision in [Precision::F32, Precision::F64] {
                v.push(KernelSpec { precision, ..KernelSpec::new(n, params) });
            }
        }
    }
    // Overrides used by other ports (RANGE 2.5 with 21 taps) and a non-integer exponent.
    v.push(KernelSpec { range: Some(2.5), ..KernelSpec::new(21, PUBLISHED) });
    v.push(KernelSpec { exponent: 2.5, ..KernelSpec::new(21, PUBLISHED) });
    v
}

#[test]
fn every_channel_sums_to_one() {
    for spec in all_specs() {
        let k = generate(&spec).unwrap();
        let tol = if spec.precision == Precision::F32 { 2e-6 } else { 1e-13 };
        for c in 0..3 {
            let s: f64 = k.taps.iter().map(|t| t[c]).sum();
            assert!((s - 1.0).abs() <= tol, "{spec:?} channel {c} sums to {s}");
            assert!(k.taps.iter().all(|t| t[c] >= 0.0));
        }
    }
}

#[test]
fn centre_first_then_minus_range_to_plus_range_without_duplicating_the_centre() {
    for spec in all_specs() {
        let k = generate(&spec).unwrap();
        let n = spec.samples;
        let r = k.range;
        let off: Vec<f64> = k.taps.iter().map(|t| t[3]).collect();
        assert_eq!(off[0], 0.0, "{spec:?}: centre first");
        // Exactly one zero offset: a port that shifts the wrong way leaves the centre twice.
        assert_eq!(off.iter().filter(|o| **o == 0.0).count(), 1, "{spec:?}: {off:?}");
        let tol = if spec.precision == Precision::F32 { 2e-6 * r } else { 1e-14 * r };
        assert!((off[1] + r).abs() <= tol && (off[n - 1] - r).abs() <= tol, "{spec:?}: {off:?}");
        // Strictly increasing after the centre, negative half then positive half.
        assert!(off[1..].windows(2).all(|w| w[0] < w[1]), "{spec:?}: {off:?}");
        assert!(off[1..=n / 2].iter().all(|o| *o < 0.0) && off[n / 2 + 1..].iter().all(|o| *o > 0.0));
        // Symmetric offsets (f32 within rounding).
        for i in 1..=n / 2 {
            assert!((off[i] + off[n - i]).abs() <= tol, "{spec:?}: {off:?}");
        }
    }
}

#[test]
fn offsets_follow_the_power_law() {
    // 17 taps, RANGE 2, exponent 2: τ = −2 + i/4, offset = 2·sign(τ)·τ²/4.
    let spec = KernelSpec { precision: Precision::F64, ..KernelSpec::new(17, PUBLISHED) };
    let k = generate(&spec).unwrap();
    let mut expected: Vec<f64> = (0..17)
        .map(|i| {
            let tau = -2.0 + i as f64 * 0.25;
            tau.signum() * tau * tau / 2.0
        })
        .collect();
    let centre = expected.remove(8);
    expected.insert(0, centre);
    for (o, e) in k.taps.iter().zip(&expected) {
        assert!((o[3] - e.abs() * e.signum()).abs() < 1e-15, "{o:?} vs {e}");
    }
}

#[test]
fn strength_zero_is_the_identity_and_strength_mixes_linearly() {
    let p = SeparableParams { strength: [0.0, 0.0, 0.0], falloff: [1.0, 0.37, 0.3] };
    let k = generate(&KernelSpec { precision: Precision::F64, ..KernelSpec::new(9, p) }).unwrap();
    assert_eq!(&k.taps[0][..3], &[1.0, 1.0, 1.0]);
    assert!(k.taps[1..].iter().all(|t| t[0] == 0.0 && t[1] == 0.0 && t[2] == 0.0));
    // Full strength: the taps are the normalised profile; strength t mixes that with the identity.
    let full = SeparableParams { strength: [1.0; 3], ..p };
    let kf = generate(&KernelSpec { precision: Precision::F64, ..KernelSpec::new(9, full) }).unwrap();
    let half = SeparableParams { strength: [0.5; 3], ..p };
    let kh = generate(&KernelSpec { precision: Precision::F64, ..KernelSpec::new(9, half) }).unwrap();
    for c in 0..3 {
        assert!((kh.taps[0][c] - (0.5 + 0.5 * kf.taps[0][c])).abs() < 1e-15);
        for i in 1..9 {
            assert!((kh.taps[i][c] - 0.5 * kf.taps[i][c]).abs() < 1e-15);
        }
    }
}

#[test]
fn smaller_falloff_concentrates_weight_near_the_centre() {
    let narrow = SeparableParams { strength: [1.0; 3], falloff: [1.0, 0.3, 0.05] };
    let k = generate(&KernelSpec { precision: Precision::F64, ..KernelSpec::new(17, narrow) }).unwrap();
    // Weight beyond |offset| > 0.5: red (widest) > green > blue.
    let outer = |c: usize| -> f64 { k.taps.iter().filter(|t| t[3].abs() > 0.5).map(|t| t[c]).sum() };
    assert!(outer(0) > outer(1) && outer(1) > outer(2), "{} {} {}", outer(0), outer(1), outer(2));
}

#[test]
fn bad_input_names_the_field() {
    let bad = [
        (KernelSpec::new(16, PUBLISHED), "samples"),
        (KernelSpec::new(1, PUBLISHED), "samples"),
        (KernelSpec::new(65, PUBLISHED), "samples"),
        (KernelSpec::new(17, SeparableParams { strength: [1.2, 0.5, 0.5], ..PUBLISHED }), "strength"),
        (KernelSpec::new(17, SeparableParams { strength: [0.5, f64::NAN, 0.5], ..PUBLISHED }), "strength"),
        (KernelSpec::new(17, SeparableParams { falloff: [1.0, -0.1, 0.5], ..PUBLISHED }), "falloff"),
        (KernelSpec::new(17, SeparableParams { falloff: [1.0, 0.1, f64::INFINITY], ..PUBLISHED }), "falloff"),
        (KernelSpec { range: Some(0.0), ..KernelSpec::new(17, PUBLISHED) }, "range"),
        (KernelSpec { exponent: f64::NAN, ..KernelSpec::new(17, PUBLISHED) }, "exponent"),
    ];
    for (spec, field) in bad {
        let e = generate(&spec).unwrap_err();
        assert_eq!(e.param, field, "{e}");
    }
}
